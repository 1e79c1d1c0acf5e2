"""The course notes' worked examples #1-#10, through the public API, to 1e-9 (float64)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import (
    INSIDE_TESTS,
    POINT_IN_TRIANGLE,
    Plane,
    Ray,
    Sphere,
    Triangle,
    cross,
    diffuse_factor,
    dot,
    first_hit,
    in_shadow,
    length,
    nearest_hit,
    normalize,
    phong,
    reflect,
    shadow_ray,
)

TOL = 1e-9

R1 = (30.0, -80.0, -60.0)
R2 = (-30.0, -80.0, -60.0)
V0 = (30.0, -40.0, 60.0)
N = (0.0, 0.6, -0.8)


def close(actual: object, expected: object) -> None:
    np.testing.assert_allclose(np.asarray(actual, dtype=float), np.asarray(expected, dtype=float), rtol=0, atol=TOL)


# --- #1 Vektörel işlemler -----------------------------------------------------


def test_01_cross_product_length_and_normal() -> None:
    c = cross(R1, R2)
    close(c, (0, 3600, -4800))
    close(length(c), 6000)
    close(normalize(c), N)


def test_01_dot_is_the_scalar_product() -> None:
    close(dot(R1, R2), 30 * -30 + 80 * 80 + 60 * 60)


# --- #2 Işın-Düzlem ------------------------------------------------------------


def test_02_plane_through_v0_has_d_72_in_the_course_convention() -> None:
    plane = Plane.through(N, V0)
    close(plane.d, 72.0)  # N·P + D = 0, D = −(N·V0)
    close(dot(N, V0) + plane.d, 0.0)


def test_02_ray_meets_the_plane_at_t_90() -> None:
    plane = Plane(N, 72.0)
    ray = Ray((0, 0, 0), (0, 0, 1))
    t = plane.intersect(ray)
    assert t is not None
    close(t, 90.0)
    close(ray.at(t), (0, 0, 90))


# --- #3 Işın-Üçgen: the plane is hit, the triangle is not --------------------


def test_03_triangle_vertices_and_normal() -> None:
    tri = Triangle(V0, np.add(V0, R1), np.add(V0, R2))
    close(tri.v1, (60, -120, 0))
    close(tri.v2, (0, -120, 0))
    close(tri.normal, N)


@pytest.mark.parametrize("method", sorted(INSIDE_TESTS))
def test_03_ray_of_example_2_misses_the_triangle(method: str) -> None:
    tri = Triangle(V0, np.add(V0, R1), np.add(V0, R2))
    assert tri.intersect(Ray((0, 0, 0), (0, 0, 1)), method=method) is None


def test_03_all_six_inside_tests_agree_miss_although_the_plane_is_hit() -> None:
    tri = Triangle(V0, np.add(V0, R1), np.add(V0, R2))
    ray = Ray((0, 0, 0), (0, 0, 1))
    assert Plane.through(tri.normal, tri.v0).intersect(ray) == pytest.approx(90.0, abs=TOL)
    assert {name: tri.intersect(ray, method=name) for name in INSIDE_TESTS} == dict.fromkeys(INSIDE_TESTS)
    assert len(INSIDE_TESTS) == 6
    # the course's second step alone, on the plane point (0, 0, 90)
    assert not any(tri.contains((0, 0, 90), method=m) for m in POINT_IN_TRIANGLE)


# --- #4 Işın-Küre ---------------------------------------------------------------


@pytest.mark.parametrize("method", ["geometric", "stable"])
def test_04_sphere_hit_t_35(method: str) -> None:
    sphere = Sphere((0, 0, 100), 75)
    ray = Ray((0, 0, 0), (0, 0.6, 0.8))
    t = sphere.intersect(ray, method=method)
    assert t is not None
    close(t, 35.0)
    close(ray.at(t), (0, 21, 28))


def test_04_intermediate_values_s_m2_q() -> None:
    l = np.subtract((0, 0, 100), (0, 0, 0))  # noqa: E741 (the course's l)
    s = dot(l, (0, 0.6, 0.8))
    m2 = dot(l, l) - s * s
    close(s, 80)
    close(m2, 3600)
    close(np.sqrt(75 * 75 - m2), 45)


# --- #5 normal and Yansıma vektörü ---------------------------------------------


def test_05_normal_and_reflected_direction() -> None:
    sphere = Sphere((0, 0, 100), 75)
    normal = sphere.normal_at((0, 21, 28))
    close(normal, (0, 0.28, -0.96))
    close(dot((0, 0.6, 0.8), normal), -0.6)
    close(reflect((0, 0.6, 0.8), normal), (0, 0.936, -0.352))


# --- #6 the reflected ray meets the plane y = 255 -------------------------------


def test_06_reflected_ray_meets_plane_at_t_250() -> None:
    sphere = Sphere((0, 0, 100), 75)
    primary = Ray((0, 0, 0), (0, 0.6, 0.8))
    hit = first_hit(primary, [sphere])
    assert hit is not None
    reflected = Ray(hit.point, reflect(primary.direction, hit.normal))
    plane = Plane((0, -1, 0), 255)
    t = plane.intersect(reflected)
    assert t is not None
    close(t, 250)
    close(reflected.at(t), (0, 255, -60))


# --- #7 Phong: diffuse ----------------------------------------------------------


def test_07_diffuse_of_red_with_n_dot_l_08_is_204() -> None:
    normal, to_light = (0, 0, 1), (0, 0.6, 0.8)
    close(diffuse_factor(normal, to_light), 0.8)
    color = phong(normal, to_light, (0, 0, 1), (255, 0, 0), (1, 1, 1), ka=0, kd=1, ks=0, shininess=32)
    close(color, (204, 0, 0))


# --- #8 the 2013 exam: red sphere, reflection, blue sphere ------------------------

RED = Sphere((80, 15, 0), 10)
BLUE = Sphere((72, 121, 0), 35)
EXAM_RAY = Ray((0, 0, 0), (0.96, 0.28, 0))


@pytest.mark.parametrize("method", ["geometric", "stable"])
def test_08_red_sphere_hit(method: str) -> None:
    t = RED.intersect(EXAM_RAY, method=method)
    assert t is not None
    close(t, 75)
    close(EXAM_RAY.at(t), (72, 21, 0))


def test_08_nearest_hit_is_red_then_reflected_ray_hits_blue() -> None:
    t, index = nearest_hit(EXAM_RAY, [RED, BLUE])
    assert index == 0
    close(t, 75)
    hit = first_hit(EXAM_RAY, [RED, BLUE])
    assert hit is not None and hit.shape is RED
    close(hit.normal, (-0.8, 0.6, 0))
    reflected_dir = reflect(EXAM_RAY.direction, hit.normal)
    close(reflected_dir, (0, 1, 0))
    reflected = Ray(hit.point, reflected_dir)
    t2, index2 = nearest_hit(reflected, [RED, BLUE])  # the red sphere must not hit itself
    assert index2 == 1
    close(t2, 65)
    close(reflected.at(t2), (72, 86, 0))


# --- #9 the 2013 exam: shadow (and the notes' typo) ------------------------------

LIGHT_2013 = (100, 117, 0)
RED_HIT = (72, 21, 0)


def test_09_direction_to_light_is_from_the_red_hit_point_not_the_blue_centre() -> None:
    # The notes subtract (72, 121, 0) (the blue centre) but their (28, 96, 0)
    # is L − (72, 21, 0): the red hit point (a typo in the notes).
    to_light = np.subtract(LIGHT_2013, RED_HIT)
    close(to_light, (28, 96, 0))
    close(length(to_light), 100)
    close(normalize(to_light), (0.28, 0.96, 0))
    assert not np.allclose(np.subtract(LIGHT_2013, BLUE.center), (28, 96, 0))


def test_09_blue_sphere_at_75_before_the_light_at_100_so_in_shadow() -> None:
    ray = Ray(RED_HIT, (0.28, 0.96, 0))
    t = BLUE.intersect(ray)
    assert t is not None
    close(t, 75)
    assert t < 100
    normal = RED.normal_at(RED_HIT)
    assert in_shadow(RED_HIT, LIGHT_2013, [RED, BLUE], normal=normal)
    assert in_shadow(RED_HIT, LIGHT_2013, [RED, BLUE])


def test_09_shadow_ray_is_the_course_ray_up_to_the_documented_offset() -> None:
    ray, distance = shadow_ray(RED_HIT, LIGHT_2013, normal=RED.normal_at(RED_HIT))
    offset = 2.0**-32 * 72  # SHADOW_EPSILON · max |P_i|
    assert abs(distance - 100) <= 2 * offset
    np.testing.assert_allclose(ray.direction, (0.28, 0.96, 0), atol=2 * offset / 100)
    t = BLUE.intersect(ray)
    assert t is not None and abs(t - 75) <= 2 * offset


def test_09_red_sphere_without_the_blue_one_does_not_shadow_its_own_hit_point() -> None:
    assert not in_shadow(RED_HIT, LIGHT_2013, [RED], normal=RED.normal_at(RED_HIT))


# --- #10 the 2012 exam: the erratum ---------------------------------------------

LIGHT_2012 = (0, 10, -29)
P_2012 = (0, -8, -5)


def test_10_distance_direction_and_plane() -> None:
    to_light = np.subtract(LIGHT_2012, P_2012)
    close(length(to_light), 30)
    close(normalize(to_light), (0, 0.6, -0.8))
    plane = Plane.through((0, -0.6, 0.8), (0, 20, -34))
    close(plane.d, 39.2)
    t = plane.intersect(Ray(P_2012, normalize(to_light)))
    assert t is not None
    close(t, 40)


def test_10_erratum_plane_hit_at_40_is_beyond_light_at_30_so_point_is_lit() -> None:
    # The notes conclude "t_light < t, so it is in shadow": wrong. The plane is
    # crossed at t = 40, beyond the light at 30: nothing lies between P and the
    # light, P is LIT. In shadow iff 0 < t < distance (as the notes' #9 uses).
    plane = Plane.through((0, -0.6, 0.8), (0, 20, -34))
    assert not in_shadow(P_2012, LIGHT_2012, [plane])


def test_10_erratum_the_same_plane_moved_between_p_and_the_light_does_shadow() -> None:
    # Control: the same plane shifted to cross the segment at t = 20 (< 30).
    moved = Plane((0, -0.6, 0.8), 39.2 - 20.0)
    t = moved.intersect(Ray(P_2012, (0, 0.6, -0.8)))
    assert t is not None
    close(t, 20)
    assert in_shadow(P_2012, LIGHT_2012, [moved])
