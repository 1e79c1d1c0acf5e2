"""Phong boyama modeli and Yansıma vektörü."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import diffuse_factor, phong, reflect, specular_factor

N = (0.0, 0.0, 1.0)
L = (0.0, 0.6, 0.8)
RED = (255.0, 0.0, 0.0)
WHITE = (1.0, 1.0, 1.0)


def test_coefficients_must_sum_to_one_and_the_error_names_them() -> None:
    # 0.1 + 0.4 + 0.3 (the raster lesson's weights) is 0.8, not 1.
    with pytest.raises(ValueError, match=r"ka=0\.1, kd=0\.4, ks=0\.3") as info:
        phong(N, L, N, RED, WHITE, 0.1, 0.4, 0.3, 32)
    assert "ka + kd + ks = 1" in str(info.value)
    with pytest.raises(ValueError, match="ka=-0.5"):
        phong(N, L, N, RED, WHITE, -0.5, 1.0, 0.5, 32)
    with pytest.raises(ValueError, match="shininess"):
        phong(N, L, N, RED, WHITE, 0.2, 0.5, 0.3, -1)
    phong(N, L, N, RED, WHITE, 0.2, 0.5, 0.3, 32)  # 0.2 + 0.5 + 0.3 rounds to 1: accepted


def test_ambient_only_is_the_objects_colour() -> None:
    np.testing.assert_allclose(phong(N, L, N, RED, WHITE, 1, 0, 0, 8), RED)


def test_diffuse_is_cos_theta_times_colour_and_ignores_the_eye() -> None:
    for eye in [(0, 0, 1), (1, 0, 0), (0, -0.6, 0.8)]:
        np.testing.assert_allclose(phong(N, L, eye, RED, WHITE, 0, 1, 0, 8), (204, 0, 0), atol=1e-9)
    assert diffuse_factor(N, (0, 0, 5)) == 1.0  # normal incidence: maximum
    assert diffuse_factor(N, (1, 0, 0)) == 0.0  # 90°: minimum
    assert diffuse_factor(N, (0, 0, -1)) == 0.0  # behind: clamped


def test_specular_peaks_along_the_mirrored_light_direction() -> None:
    mirrored = (0.0, -0.6, 0.8)  # the light direction reflected about N
    assert specular_factor(N, L, mirrored, 32) == pytest.approx(1.0)
    np.testing.assert_allclose(phong(N, L, mirrored, RED, WHITE, 0, 0, 1, 32), (255, 255, 255))
    off = specular_factor(N, L, (0.0, -0.5, 0.866), 32)
    assert 0 < off < 1
    assert specular_factor(N, L, (0, 1, 0.1), 32) == 0.0  # R·E < 0: clamped to 0
    assert specular_factor(N, (0, 0, -1), (0, 0, -1), 32) == 0.0  # light behind the surface


def test_light_colour_tints_diffuse_and_specular_not_ambient() -> None:
    yellow = (1.0, 1.0, 0.0)
    c = phong(N, (0, 0, 1), (0, 0, 1), (100, 200, 50), yellow, 0.5, 0.25, 0.25, 1)
    expected = 0.5 * np.array([100, 200, 50]) + 0.25 * np.array([100, 200, 0]) + 0.25 * np.array([255, 255, 0])
    np.testing.assert_allclose(c, expected)
    unit = phong(N, (0, 0, 1), (0, 0, 1), (0.4, 0.8, 0.2), WHITE, 0.5, 0.25, 0.25, 1, specular_color=(1, 1, 1))
    np.testing.assert_allclose(unit, 0.5 * np.array([0.4, 0.8, 0.2]) + 0.25 * np.array([0.4, 0.8, 0.2]) + 0.25)


def test_reflection_formula_batches_and_non_unit_normals() -> None:
    np.testing.assert_allclose(reflect((1, -1, 0), (0, 1, 0)), (1, 1, 0))
    np.testing.assert_allclose(reflect((1, -1, 0), (0, 5, 0)), (1, 1, 0))  # normalized inside
    batch = reflect([[1, -1, 0], [0, 0, 2]], (0, 0, 1))
    np.testing.assert_allclose(batch, [[1, -1, 0], [0, 0, -2]])
    with pytest.raises(ValueError):
        reflect((1, 0, 0), (0, 0, 0))
