"""What every built-in lesson promises, checked across all of them (each lesson's own
promises are in tests/lessons/test_<lesson>.py)."""

from __future__ import annotations

from glsandbox.lesson import all_lessons, find_lesson

RAY_LESSONS = ["ray_camera", "ray_triangle", "ray_spheres", "ray_phong", "ray_acceleration", "ray_interactive"]


def test_ray_lessons_default_to_the_ray_tracer_and_switch_to_raster():
    for name in RAY_LESSONS:
        cls = find_lesson(name)
        assert cls().values["renderer"] == "ray"
        assert {vp.renderer for vp in cls().scene().viewports} == {"ray"}
        assert {vp.renderer for vp in cls.from_settings(["renderer=raster"]).scene().viewports} == {"raster"}


def test_every_lesson_has_a_course_section_and_builds_a_scene_at_any_time() -> None:
    for cls in all_lessons():
        assert cls.course_section and cls.title
        for t in (0.0, 1.25):
            scene = cls(time=t).scene()
            assert scene.viewports
