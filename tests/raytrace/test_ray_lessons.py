"""The ray-tracing lessons: figures from the course, and their pictures (goldens at 256x256)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.lesson import find_lesson
from glsandbox.raytrace import render

RAY_LESSONS = ["ray_camera", "ray_triangle", "ray_spheres", "ray_phong", "ray_acceleration", "ray_interactive"]
# ray_acceleration's rock line shows times (they change every run): its golden turns it off.
GOLDEN_CASES = [(name, ("rock=off",) if name == "ray_acceleration" else ()) for name in RAY_LESSONS] + [
    ("ray_phong", ("scene=exam2013",)), ("ray_phong", ("scene=exam2012",))]


def overlay_text_rows(lesson_name: str, *settings: str) -> list[str]:
    """The rows a lesson's panels print (re-computed by the lesson's own module)."""
    import importlib

    module = importlib.import_module(f"lessons.{lesson_name}")
    if lesson_name == "ray_phong":
        which = dict(s.split("=") for s in settings).get("scene", "demo")
        return getattr(module, which)("x")[1]
    if lesson_name == "ray_triangle":
        return module.panels(False)[1]
    if lesson_name == "ray_spheres":
        return module.figures()
    return []


def test_ray_lessons_default_to_the_ray_tracer_and_switch_to_raster():
    for name in RAY_LESSONS:
        cls = find_lesson(name)
        assert cls().values["renderer"] == "ray"
        assert {vp.renderer for vp in cls().scene().viewports} == {"ray"}
        assert {vp.renderer for vp in cls.from_settings(["renderer=raster"]).scene().viewports} == {"raster"}


def test_exam_2013_figures():
    rows = "\n".join(overlay_text_rows("ray_phong", "scene=exam2013"))
    assert "red hit t = 75 at (72, 21, 0), N = (-0.8, 0.6, 0)" in rows
    assert "reflected (0, 1, 0) hits blue at t = 65" in rows
    assert "distance 100, blue at t = 75 < 100: in shadow" in rows


def test_exam_2012_figures_and_erratum():
    rows = "\n".join(overlay_text_rows("ray_phong", "scene=exam2012"))
    assert "distance 30" in rows and "D = 39.2" in rows and "t = 40" in rows
    assert "P is LIT" in rows


def test_sphere_and_triangle_figures():
    spheres = "\n".join(overlay_text_rows("ray_spheres"))
    assert "s = 80, m^2 = 3600, q = 45" in spheres and "t = s - q = 35 (stable: 35), P = (0, 21, 28)" in spheres
    triangle = "\n".join(overlay_text_rows("ray_triangle"))
    assert "D = 72; ray (0,0,1): t = 90, triangle: miss" in triangle
    assert "all six agree on 4800 rays: yes" in triangle


def test_acceleration_counts_fewer_tests_with_aabb():
    from lessons.ray_acceleration import table

    rows = table("ray_acceleration", False)
    counts = {row[0]: int(row[1].replace(",", "")) for row in rows[2:]}
    assert counts["AABB"] < counts["none"] / 5 and counts["both"] == counts["AABB"]
    assert counts["BVH"] < counts["AABB"] / 5 and counts["BVH+backface"] <= counts["BVH"]


def test_acceleration_times_the_bvh_on_a_rock():
    from lessons.ray_acceleration import rock_rows

    rows = rock_rows()
    assert "5,120 triangles" in rows[0] and rows[2].startswith("BVH ") and "x faster" in rows[2]
    tests = [int(row.split(" ms, ")[1].split(" shape")[0].replace(",", "")) for row in rows[1:]]
    assert tests[1] < tests[0] / 100  # the BVH tests a tiny share of the rock's triangles


def test_exam_scenes_shadow_the_2013_hit_point():
    """The red sphere's hit point of #8 is dark in the traced picture: the blue sphere blocks the light."""
    cls = find_lesson("ray_phong")
    scene = cls(scene="exam2013").scene()
    lit = render(scene, (64, 48), shadows=False)
    shadowed = render(scene, (64, 48))
    assert shadowed[..., :3].sum() < lit[..., :3].sum()


@pytest.mark.parametrize("name, settings", GOLDEN_CASES, ids=lambda v: v if isinstance(v, str) else "-".join(v))
def test_ray_lesson_golden(gl, golden, name, settings):
    lesson = find_lesson(name).from_settings(list(settings))
    image = gl.render(lesson, (256, 256)).image
    suffix = "-" + "-".join(s.replace("=", "_") for s in settings) if settings else ""
    golden(image, f"raytrace/{name}{suffix}")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
