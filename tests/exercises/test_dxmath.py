"""The course's DirectXMath matrices (glsandbox/exercises/dxmath.py), row vectors and left-handed:
``XMMatrixLookAtLH`` and ``XMMatrixPerspectiveFovLH`` as the course writes them out, the unit
cube's twelve edges, and the matrix exercises' edge probe."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises import dxmath


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def test_look_at_is_xm_matrix_look_at_lh() -> None:
    eye, at, up = np.array([1.0, 4.0, -9.0]), np.array([0.5, 0.0, 2.0]), np.array([0.0, 1.0, 0.0])
    z = _unit(at - eye)  # left-handed: the camera looks along +z
    x = _unit(np.cross(up, z))
    y = np.cross(z, x)
    expected = np.array([[x[0], y[0], z[0], 0], [x[1], y[1], z[1], 0], [x[2], y[2], z[2], 0],
                         [-x @ eye, -y @ eye, -z @ eye, 1]])
    assert np.allclose(dxmath.look_at_lh(eye, at, up), expected, atol=1e-12)
    assert np.allclose(np.append(at, 1) @ expected, [0, 0, np.linalg.norm(at - eye), 1])  # v·M: at is ahead


def test_perspective_is_xm_matrix_perspective_fov_lh() -> None:
    fov, aspect, near, far = math.pi / 3, 1.5, 0.1, 50.0
    h = 1 / math.tan(fov / 2)
    q = far / (far - near)
    expected = np.array([[h / aspect, 0, 0, 0], [0, h, 0, 0], [0, 0, q, 1], [0, 0, -q * near, 0]])
    m = dxmath.perspective_fov_lh(fov, aspect, near, far)
    assert np.allclose(m, expected, atol=1e-12)
    for depth, z_over_w in ((near, 0.0), (far, 1.0)):  # DirectX's depth range: 0 at near, 1 at far
        clip = np.array([0.0, 0.0, depth, 1.0]) @ m
        assert math.isclose(clip[2] / clip[3], z_over_w, abs_tol=1e-12)


def test_the_cube_has_twelve_edges_three_at_each_corner() -> None:
    assert len(dxmath.CUBE_EDGES) == 12
    assert sorted(np.bincount(np.ravel(dxmath.CUBE_EDGES)).tolist()) == [3] * 8
    segments = dxmath.cube_segments(np.eye(4))
    assert segments.shape == (12, 2, 4)
    assert all(np.count_nonzero(a[:3] != b[:3]) == 1 for a, b in segments)


def test_the_probe_camera_sees_the_origin_in_the_middle() -> None:
    clip = np.array([0.0, 0.0, 0.0, 1.0]) @ dxmath.camera()
    assert abs(clip[0]) < 1e-12 and abs(clip[1]) < 1e-12 and 0 < clip[2] < clip[3]
    assert dxmath.row(np.eye(4)) == [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
                                     [0.0, 0.0, 0.0, 1.0]]
    assert dxmath.as_matrix("not a matrix") is None and dxmath.as_matrix(dxmath.row(np.eye(4))).shape == (4, 4)


def test_the_edge_probe_tells_the_students_edges_from_the_references() -> None:
    draw = dxmath.edge_probe(lambda m, i: dxmath.cube_segments(m @ dxmath.camera()))
    reference = [dxmath.row(np.eye(4))] * 4
    classes, _, own = draw(reference, reference, {}, 64)
    assert classes.shape == (64, 64) and set(np.unique(classes)) == {0, 1} and own.tolist() == [1] * 4  # all grey
    shifted = dxmath.row(np.eye(4))
    shifted[3][0] = 1.5  # a translation along x (row vectors: the last row): the student's cube moves right
    classes, _, own = draw(reference, [reference[0], shifted, "oops", reference[0]], {3: "raised"}, 64)
    assert own.tolist() == [1, 4, 5, 5]
    tile = lambda i: classes[(i // 2) * 32:(i // 2 + 1) * 32, (i % 2) * 32:(i % 2 + 1) * 32]  # noqa: E731
    assert {2, 3} <= set(np.unique(tile(1))) and (tile(2) == 5).all() and (tile(3) == 5).all()
