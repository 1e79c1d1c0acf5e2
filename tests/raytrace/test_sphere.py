"""Işın-Küre kesim testi: geometric (the course) vs stable (Ray Tracing Gems ch. 7).

References are exact: the float inputs are turned into ``Decimal`` exactly and
the quadratic ``a·t² − 2·b·t + c = 0`` is solved with 80 significant digits.
"""

from __future__ import annotations

import warnings
from decimal import Decimal, localcontext

import numpy as np
import pytest

from glsandbox.raytrace import Ray, RayTraceError, Sphere


def exact_t(origin: np.ndarray, direction: np.ndarray, center: np.ndarray, radius: float) -> Decimal | None:
    """Nearest positive root, exactly for the given float64 inputs (to 80 digits)."""
    with localcontext() as ctx:
        ctx.prec = 80
        l = [Decimal(float(c)) - Decimal(float(o)) for c, o in zip(center, origin, strict=True)]  # noqa: E741
        d = [Decimal(float(x)) for x in direction]
        a = sum(x * x for x in d)
        b = sum(x * y for x, y in zip(l, d, strict=True))
        c = sum(x * x for x in l) - Decimal(radius) * Decimal(radius)
        disc = b * b - a * c
        if disc < 0:
            return None
        root = disc.sqrt()
        for t in ((b - root) / a, (b + root) / a):
            if t > 0:
                return +t
        return None


def error(t: float | None, reference: Decimal | None) -> float:
    if t is None or reference is None:
        return 0.0 if t is None and reference is None else float("inf")
    return abs(float(Decimal(t) - reference))


def far_ray(rng: np.random.Generator, distance: float, miss_distance: float) -> tuple[Ray, Sphere]:
    """A unit sphere ``distance`` away whose centre passes ``miss_distance`` from the ray."""
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    perpendicular = np.cross(direction, rng.normal(size=3))
    perpendicular /= np.linalg.norm(perpendicular)
    return Ray((0.0, 0.0, 0.0), direction), Sphere(direction * distance + perpendicular * miss_distance, 1.0)


def test_radius_1_at_distance_1e8_stable_keeps_the_digits_geometric_loses_them() -> None:
    sphere = Sphere((0.0, 0.5, 1e8), 1.0)
    ray = Ray((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    with localcontext() as ctx:
        ctx.prec = 80
        reference = Decimal(10**8) - Decimal("0.75").sqrt()  # t = 1e8 − sqrt(r² − m²), m = 0.5
        assert abs(exact_t(ray.origin, ray.direction, sphere.center, 1.0) - reference) < Decimal("1e-60")  # type: ignore[operator]
    # |l|² = 1e16 + 0.25 rounds to 1e16, so the geometric m² comes out 0 and q = 1:
    assert error(sphere.intersect(ray, method="geometric"), reference) > 0.1
    # the stable form is off by about one ulp of 1e8 (1.5e-8)
    assert error(sphere.intersect(ray, method="stable"), reference) < 4 * np.spacing(1e8)


def test_many_far_spheres_stable_error_is_a_few_ulps_geometric_is_not() -> None:
    rng = np.random.default_rng(7)
    stable, geometric = [], []
    for _ in range(150):
        ray, sphere = far_ray(rng, 1e8, rng.uniform(0.0, 0.99))
        reference = exact_t(ray.origin, ray.direction, sphere.center, 1.0)
        assert reference is not None
        stable.append(error(sphere.intersect(ray, method="stable"), reference))
        geometric.append(error(sphere.intersect(ray, method="geometric"), reference))
    assert max(stable) < 1e-6  # t ≈ 1e8: that is 1e-14 relative
    assert np.median(geometric) > 1e-2  # digits below the units are gone (or the hit is lost)


def test_grazing_silhouette_rays_are_classified_correctly_by_the_stable_form() -> None:
    # Rays passing r·(1 ± 1e-6 .. 1e-3) from the centre of a unit sphere 1e6..1e9 away.
    rng = np.random.default_rng(8)
    wrong_stable = wrong_geometric = 0
    for _ in range(200):
        side = 1.0 if rng.uniform() < 0.5 else -1.0
        ray, sphere = far_ray(rng, 10 ** rng.uniform(6, 9), 1.0 + side * 10 ** rng.uniform(-6, -3))
        hit = exact_t(ray.origin, ray.direction, sphere.center, 1.0) is not None
        wrong_stable += (sphere.intersect(ray, method="stable") is not None) != hit
        wrong_geometric += (sphere.intersect(ray, method="geometric") is not None) != hit
    assert wrong_stable == 0
    assert wrong_geometric > 0  # the course's m² = l² − s² cannot tell them apart


def test_small_sphere_radius_1e_6() -> None:
    sphere = Sphere((0.0, 0.5e-6, 1.0), 1e-6)
    ray = Ray((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    reference = exact_t(ray.origin, ray.direction, sphere.center, 1e-6)
    assert reference is not None
    assert error(sphere.intersect(ray, method="stable"), reference) < 4 * np.spacing(1.0)
    # geometric: m² = l² − s² with l² ≈ 1 leaves ~4 of the 16 digits of r² = 1e-12
    assert error(sphere.intersect(ray, method="geometric"), reference) > 1e3 * np.spacing(1.0)


@pytest.mark.parametrize("method", ["stable", "geometric"])
def test_ray_starting_inside_returns_the_exit(method: str) -> None:
    sphere = Sphere((1.0, 2.0, 3.0), 5.0)
    assert sphere.intersect(Ray((1.0, 2.0, 3.0), (0.0, 0.0, 1.0)), method=method) == pytest.approx(5.0)
    assert sphere.intersect(Ray((1.0, 2.0, 3.0), (0.0, 0.0, 2.0)), method=method) == pytest.approx(2.5)
    assert sphere.intersect(Ray((1.0, 2.0, 6.0), (0.0, 0.0, -1.0)), method=method) == pytest.approx(8.0)
    assert sphere.intersect(Ray((1.0, 2.0, 6.0), (0.0, 0.0, 1.0)), method=method) == pytest.approx(2.0)


@pytest.mark.parametrize("method", ["stable", "geometric"])
def test_behind_beside_and_on_the_surface(method: str) -> None:
    sphere = Sphere((0.0, 0.0, 10.0), 2.0)
    assert sphere.intersect(Ray((0, 0, 0), (0, 0, -1)), method=method) is None  # behind
    assert sphere.intersect(Ray((0, 0, 0), (1, 0, 0)), method=method) is None  # beside
    assert sphere.intersect(Ray((0, 3, 0), (0, 0, 1)), method=method) is None  # passes outside
    # origin on the surface: heading in gives the far side, heading out nothing
    assert sphere.intersect(Ray((0, 0, 8), (0, 0, 1)), method=method) == pytest.approx(4.0)
    assert sphere.intersect(Ray((0, 0, 8), (0, 0, -1)), method=method) is None


def test_non_unit_directions_measure_t_in_units_of_the_direction() -> None:
    sphere = Sphere((0, 0, 100), 75)
    for method in ("stable", "geometric"):
        assert sphere.intersect(Ray((0, 0, 0), (0, 6, 8)), method=method) == pytest.approx(3.5, abs=1e-12)


def test_no_warnings_for_misses_tangents_and_zero_directions() -> None:
    sphere = Sphere((0.0, 0.0, 10.0), 2.0)
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        t = sphere.intersect_many(
            [[0, 0, 0], [0, 2, 0], [0, 0, 12], [0, 0, 0]], [[0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 0, 0]]
        )
    assert t[0] == np.inf and t[2] == np.inf and t[3] == np.inf
    assert t[1] == pytest.approx(10.0)  # tangent: a (double) hit


def test_bad_spheres_and_methods() -> None:
    with pytest.raises(ValueError):
        Sphere((0, 0, 0), 0.0)
    with pytest.raises(ValueError):
        Sphere((0, 0, 0), -1.0)
    with pytest.raises(RayTraceError, match="unknown sphere method"):
        Sphere((0, 0, 0), 1.0).intersect(Ray((0, 0, -5), (0, 0, 1)), method="fast")


def test_normal_is_outward_unit() -> None:
    sphere = Sphere((1, 1, 1), 2)
    np.testing.assert_allclose(sphere.normal_at((3, 1, 1)), (1, 0, 0))
    np.testing.assert_allclose(sphere.normal_at((1, 1, -1)), (0, 0, -1))
