"""Gölge testi: shadow rays, self-intersection at large coordinates, occluders beyond the light."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from glsandbox.raytrace import AABB, SHADOW_EPSILON, Plane, Ray, Shape, Sphere, Triangle, in_shadow, shadow_ray


def random_unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def plane_hits(seed: int, count: int) -> Iterator[tuple[Plane, np.ndarray, np.ndarray]]:
    """(plane, hit point, light) with the hit point at coordinates 1e4..1e6 and the light on its lit side."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        scale = 10 ** rng.uniform(4, 6)
        anchor = rng.uniform(-1, 1, size=3) * scale
        normal = random_unit(rng)
        plane = Plane.through(normal, anchor)
        target = anchor + np.cross(normal, random_unit(rng)) * rng.uniform(0, 100)
        eye = target + (normal + 0.8 * random_unit(rng)) * 10 ** rng.uniform(0, 4)
        if float(normal @ (eye - target)) <= 0:
            continue
        ray = Ray(eye, target - eye)
        t = plane.intersect(ray)
        assert t is not None
        point = ray.at(t)  # as a renderer gets it: rounded, a hair off the plane
        towards = normal + 0.9 * random_unit(rng)
        if float(normal @ towards) <= 0.05 * np.linalg.norm(towards):
            continue
        light = point + towards * 10 ** rng.uniform(0, 4)
        yield plane, point, light


def test_plane_hit_points_at_1e4_to_1e6_never_shadow_themselves() -> None:
    shadowed = [
        (p, light) for plane, p, light in plane_hits(1, 400) if in_shadow(p, light, [plane], normal=plane.normal)
    ]
    assert shadowed == []


def test_plane_self_shadowing_without_a_normal_uses_the_relative_step_along_the_ray() -> None:
    shadowed = [(p, light) for plane, p, light in plane_hits(2, 400) if in_shadow(p, light, [plane])]
    assert shadowed == []


def test_control_without_any_offset_the_plane_shadows_itself() -> None:
    # epsilon=0 starts the shadow ray exactly at the rounded hit point: about
    # half of them lie a hair below the plane and "hit" it at a tiny t.
    acne = sum(in_shadow(p, light, [plane], normal=plane.normal, epsilon=0.0) for plane, p, light in plane_hits(1, 200))
    assert acne > 20


def sphere_hits(seed: int, count: int) -> Iterator[tuple[Sphere, np.ndarray]]:
    """(sphere, hit point) with the sphere at coordinates 1e4..1e6, radius 1..1e3."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        scale = 10 ** rng.uniform(4, 6)
        sphere = Sphere(rng.uniform(-1, 1, size=3) * scale, 10 ** rng.uniform(0, 3))
        r = sphere.radius
        target = sphere.center + random_unit(rng) * r * 0.9
        eye = target + random_unit(rng) * r * 10 ** rng.uniform(0.5, 3)
        ray = Ray(eye, target - eye)
        t = sphere.intersect(ray)
        if t is None:  # eye inside the sphere: not a primary hit
            continue
        yield sphere, ray.at(t)


def test_sphere_hit_points_facing_the_light_are_lit() -> None:
    rng = np.random.default_rng(3)
    shadowed, checked = [], 0
    for sphere, p in sphere_hits(4, 400):
        n = sphere.normal_at(p)
        towards = n + 0.9 * random_unit(rng)
        light = p + towards * sphere.radius * 10 ** rng.uniform(-1, 2)
        checked += 1
        if in_shadow(p, light, [sphere], normal=n):
            shadowed.append((sphere, p, light))
    assert shadowed == []
    assert checked > 300


def test_sphere_hit_points_facing_away_are_shadowed_by_the_sphere_itself() -> None:
    rng = np.random.default_rng(5)
    lit, checked = [], 0
    for sphere, p in sphere_hits(6, 200):
        n = sphere.normal_at(p)
        light = sphere.center - (n + 0.5 * random_unit(rng)) * sphere.radius * 3  # beyond the far side
        if float(n @ (light - p)) >= -0.05 * np.linalg.norm(light - p):
            continue
        checked += 1
        if not in_shadow(p, light, [sphere], normal=n):
            lit.append((sphere, p, light))
    assert lit == []
    assert checked > 100


class GeometricSphere:
    """A sphere traced by the course's geometric test, which has no error bound."""

    def __init__(self, sphere: Sphere) -> None:
        self.sphere = sphere

    def intersect(self, ray: Ray) -> float | None:
        return self.sphere.intersect(ray, method="geometric")


def test_control_without_any_offset_only_the_bounded_sphere_test_keeps_from_shadowing_itself() -> None:
    """A shadow ray leaving the surface with no offset at all: the course's geometric test meets
    the sphere again at t ≈ 0 (acne); the stable test's own error bound takes that root as 0
    wherever the point is on the surface to its own rounding. A point made from a far eye's
    ``t·D`` can be off by more (that is what the offset, ``error=``, is for): a rare few."""
    rng = np.random.default_rng(3)
    acne = bounded = 0
    for sphere, p in sphere_hits(4, 200):
        n = sphere.normal_at(p)
        light = p + (n + 0.5 * random_unit(rng)) * sphere.radius
        acne += in_shadow(p, light, [GeometricSphere(sphere)], normal=n, epsilon=0.0)
        bounded += in_shadow(p, light, [sphere], normal=n, epsilon=0.0)
    assert acne > 10
    assert bounded * 10 < acne, (bounded, acne)


# --- occluders between, beyond and behind ---------------------------------------------

POINT = np.array([0.0, 0.0, 0.0])
LIGHT = np.array([0.0, 0.0, 10.0])


@pytest.mark.parametrize(
    ("occluder", "blocked"),
    [
        (Sphere((0, 0, 5), 1), True),  # between
        (Sphere((0, 0, 15), 1), False),  # beyond the light
        (Sphere((0, 0, -5), 1), False),  # behind the point
        (Sphere((0, 3, 5), 1), False),  # beside the segment
        (Plane((0, 0, 1), -5), True),  # z = 5, between
        (Plane((0, 0, 1), -12), False),  # z = 12, beyond the light (erratum #10's situation)
        (Triangle((-1, -1, 4), (1, -1, 4), (0, 2, 4)), True),
        (Triangle((-1, -1, 14), (1, -1, 14), (0, 2, 14)), False),
        (AABB((-1, -1, 3), (1, 1, 4)), True),
        (AABB((-1, -1, 11), (1, 1, 12)), False),
        (Sphere((0, 0, 10), 3), True),  # the light inside a sphere: its wall is between
    ],
)
def test_only_occluders_between_the_point_and_the_light_shadow(occluder: Shape, blocked: bool) -> None:
    assert in_shadow(POINT, LIGHT, [occluder], normal=(0, 0, 1)) is blocked
    assert in_shadow(POINT, LIGHT, [occluder]) is blocked


def test_occluder_exactly_at_the_light_distance_does_not_block() -> None:
    # 0 < t < distance is strict: a plane through the light itself is not between.
    plane = Plane((0, 0, 1), -10)
    ray, distance = shadow_ray(POINT, LIGHT)
    assert plane.intersect(ray) == distance
    assert not in_shadow(POINT, LIGHT, [plane])


def test_normal_is_flipped_to_the_lights_side() -> None:
    plane = Plane((0, 0, 1), 0)  # z = 0, normal up
    ray, distance = shadow_ray(POINT, (0, 0, -10), normal=(0, 0, 1))
    assert ray.origin[2] < 0  # offset downwards, towards the light
    assert distance == pytest.approx(10, abs=1e-8)
    assert not in_shadow(POINT, (0, 0, -10), [plane], normal=(0, 0, 1))


def test_offset_is_relative_to_the_point_magnitude() -> None:
    for scale in (1.0, 1e4, 1e6):
        p = np.array([scale, -scale / 2, 0.0])
        ray, _ = shadow_ray(p, p + (0, 0, 5), normal=(0, 0, 1))
        assert ray.origin[2] == pytest.approx(SHADOW_EPSILON * scale, rel=1e-12)
