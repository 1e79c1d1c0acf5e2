"""glsandbox.transforms: the DirectX conversion, order strings, the projection and look_at. No GL.

(Geometry is in tests/core/test_geometry.py, plans in tests/core/test_plan.py.)"""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import transforms
from glsandbox.errors import SandboxError


def test_directx_matrix_conversion_flips_rotation_sense_about_y() -> None:
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    # XMMatrixRotationY (row-vector form, left-handed).
    dx = np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(transforms.from_directx_matrix(dx), transforms.rotate_y(-angle), atol=1e-15)
    # A DirectX point transformed then converted equals converted then transformed.
    p = np.array([1.0, 2.0, 3.0])
    via_dx = (np.append(p, 1.0) @ dx)[:3]
    via_gl = transforms.transform_points(transforms.from_directx_matrix(dx), transforms.from_directx_point(p)[None])[0]
    np.testing.assert_allclose(transforms.from_directx_point(via_dx), via_gl, atol=1e-12)


def test_compose_applies_the_order_string_left_to_right() -> None:
    S, T, R = transforms.scale(0.3, 1, 0.3), transforms.translate(4, 0, 0), transforms.rotate_y(np.pi / 2)
    np.testing.assert_array_equal(transforms.compose("STR", S=S, T=T, R=R), R @ T @ S)
    # Translate then scale: the distance 4 shrinks to 4 * 0.3 = 1.2 (course).
    m = transforms.compose("TSR", S=S, T=T, R=np.eye(4))
    assert transforms.transform_points(m, np.zeros((1, 3)))[0, 0] == pytest.approx(1.2)
    with pytest.raises(SandboxError, match="valid orders: STR, SRT"):
        transforms.parse_order("SST")


def test_perspective_matches_the_textbook_formula() -> None:
    m = transforms.perspective(45.0, 16 / 9, 0.01, 100.0)
    f = 1 / np.tan(np.radians(22.5))
    assert m[0, 0] == pytest.approx(f * 9 / 16)
    assert m[1, 1] == pytest.approx(f)
    assert m[3, 2] == -1.0
    # The near plane maps to depth -1 and the far plane to +1.
    for z, ndc in ((-0.01, -1.0), (-100.0, 1.0)):
        clip = m @ np.array([0, 0, z, 1.0])
        assert clip[2] / clip[3] == pytest.approx(ndc)


def test_look_at_and_perspective_are_pyrrs_matrices_bit_for_bit() -> None:
    # transforms builds them itself (importing pyrr cost every cold start ~6 ms):
    # the same operations as pyrr's, so every lesson's pixels stay as they were.
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "invalid escape sequence")
        import pyrr

    rng = np.random.default_rng(24)
    cameras = [((0.0, 3.0, 10.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
               ((0.0, 1.5, -5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))]
    cameras += [tuple(tuple(rng.normal(size=3) * scale) for scale in (50.0, 5.0, 1.0)) for _ in range(300)]
    for eye, target, up in cameras:
        ours = transforms.look_at(eye, target, up)
        theirs = pyrr.matrix44.create_look_at(np.array(eye), np.array(target), np.array(up), dtype=np.float64).T
        assert np.array_equal(ours, theirs), (eye, target, up)
    lenses = [(45.0, 800 / 600, 0.01, 100.0), (90.0, 1.0, 0.5, 30.0)]
    lenses += [(float(rng.uniform(1, 179)), float(rng.uniform(0.2, 5)), near := float(rng.uniform(1e-3, 5)),
                near + float(rng.uniform(1e-3, 1e4))) for _ in range(300)]
    for lens in lenses:
        ours = transforms.perspective(*lens)
        theirs = pyrr.matrix44.create_perspective_projection(*lens, dtype=np.float64).T
        assert np.array_equal(ours, theirs) and np.array_equal(np.signbit(ours), np.signbit(theirs)), lens


def test_look_at_puts_the_target_straight_ahead() -> None:
    view = transforms.look_at((0, 3, 10), (0, 0, 0), (0, 1, 0))
    eye_space = view @ np.array([0, 0, 0, 1.0])
    np.testing.assert_allclose(eye_space[:2], 0, atol=1e-12)
    assert eye_space[2] == pytest.approx(-np.sqrt(109))  # in front: negative z
    with pytest.raises(SandboxError, match="parallel to the view direction"):
        transforms.look_at((0, 0, 0), (0, 0, 5), (0, 0, 1))
