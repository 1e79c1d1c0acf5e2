"""Shadow-ray offsets from a bound on the hit point's rounding error (pbrt-v4), in
the course API (:func:`in_shadow`, :func:`shadow_ray`), against the teaching
variant's relative epsilon that ``ray_phong``'s ``far_eye`` scene shows failing."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import SHADOW_EPSILON, Plane, Ray, Sphere, first_hit, in_shadow, shadow_ray
from glsandbox.lessons.ray_phong import far_eye, self_shadowed


@pytest.mark.parametrize("eye_distance", [10.0, 1e4, 1e6, 1e7, 1e9])
def test_lit_points_never_shadow_themselves_whatever_the_eye_distance(eye_distance) -> None:
    assert self_shadowed(eye_distance, None) == 0


def test_the_simple_epsilon_shadows_lit_points_when_the_eye_is_far() -> None:
    assert self_shadowed(10.0, SHADOW_EPSILON) == 0  # near: the simple offset is enough
    assert self_shadowed(1e7, SHADOW_EPSILON) > 40  # far: a tenth or more shadow themselves
    rows = far_eye("x")[1]
    assert "0 of 400" in rows[2] and "0 of 400" not in rows[1]


@pytest.mark.parametrize("offset", [0.0, 1e3, 1e6])
def test_a_contact_shadow_a_millionth_deep_survives(offset) -> None:
    # A unit sphere resting on the plane y = offset; a floor point 1e-3 from the contact,
    # the light up on the other side: the sphere's bottom is between them, 1e-6 above.
    centre = np.array([offset, offset + 1.0, -offset])
    ball, floor = Sphere(tuple(centre), 1.0), Plane((0.0, 1.0, 0.0), -offset)
    light = centre + (-4.0, 3.0, 0.0)
    target = centre + (0.03, -1.0, 0.0)
    eye = target + (0.0, 0.1, 5.0)  # a grazing view along z: slope 0.02 passes under the sphere
    hit = first_hit(Ray(tuple(eye), tuple(target - eye)), [ball, floor])
    assert hit is not None and hit.shape is floor
    assert in_shadow(hit, light, [ball, floor])
    ray, _ = shadow_ray(hit, light)
    assert 0.0 < ray.origin[1] - offset <= 4 * float(np.abs(hit.error).max()) + np.spacing(offset)  # by the bound only


def test_the_offset_leaves_towards_the_light_and_by_at_least_the_bound() -> None:
    point = np.array([1e6, 2.0, -3.0])
    error = np.array([1e-9, 1e-9, 1e-9])
    ray, distance = shadow_ray(point, (1e6, -5.0, -3.0), (0.0, 1.0, 0.0), error=error)
    assert point[1] - ray.origin[1] >= 1e-9  # the light is below: the origin moves down
    assert ray.origin[0] == point[0] and ray.origin[2] == point[2]
    assert distance == pytest.approx(7.0)
