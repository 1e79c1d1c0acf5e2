"""A ray-traced pixel's story: replaying the record gives the rendered pixel, and the notes' examples read right."""

from __future__ import annotations

import json

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.frame import single_viewport
from glsandbox.lesson import find_lesson
from glsandbox.plan import TRACE_OPTIONS
from glsandbox.raytrace.render import render
from glsandbox.scene import Scene
from glsandbox.story import explain, parse_pixel
from glsandbox.story.ray_pixel import explain_ray_pixel, locate_pixel
from support import EXAMPLES_DIR, course_ray

#: Every ray lesson (its scenes), and raster lessons and a scene file traced by the numpy engine.
CASES = [
    ("ray_camera", ()), ("ray_triangle", ()), ("ray_spheres", ()), ("ray_interactive", ()),
    ("ray_acceleration", ()),
    *[("ray_phong", (f"scene={s}",)) for s in ("demo", "exam2013", "exam2012", "far_eye")],
    ("mirror", ("renderer=ray_numpy",)), ("phong", ("renderer=ray_numpy",)), ("texture", ("renderer=ray_numpy",)),
    (str(EXAMPLES_DIR / "mirror_room.toml"), ("renderer=ray_numpy",)),
]
SIZE = (96, 72)


def traced_frame(scene: Scene, size: tuple[int, int]) -> np.ndarray:
    """The frame's ray-traced viewports as the frame traces them (the numpy engine), overlays left out."""
    width, height = size
    frame = np.zeros((height, width, 4), dtype=np.uint8)
    for i, vp in enumerate(scene.viewports):
        x, y, w, h = vp.pixels(width, height)
        if vp.renderer == "raster" or w <= 0 or h <= 0:
            continue
        top = height - y - h
        frame[top:top + h, x:x + w] = render(single_viewport(scene, i), (w, h), "numpy", **TRACE_OPTIONS)
    return frame


@pytest.mark.parametrize("name,settings", CASES, ids=[f"{n.split('/')[-1]}{'-' + s[0] if s else ''}"
                                                      for n, s in CASES])
def test_replayed_trace_is_the_rendered_pixel(name: str, settings: tuple[str, ...]) -> None:
    scene = find_lesson(name).from_settings(settings).scene()
    frame = traced_frame(scene, SIZE)
    checked = 0
    for y in range(1, SIZE[1], 9):
        for x in range(2, SIZE[0], 11):
            trace = explain_ray_pixel(scene, SIZE, (x, y))
            expected = frame[y, x].tolist()
            assert trace.rgba8 == expected, (name, x, y)
            assert trace.replay() == expected, (name, x, y)
            # Each light's recorded term adds up to the recorded local colour, bounce by bounce.
            for bounce in trace.bounces:
                if bounce.lit:
                    total = np.sum([light.term for light in bounce.lights], axis=0)
                    assert np.allclose(total, bounce.local, rtol=0, atol=1e-12)
            checked += 1
    assert checked >= 40


def test_worked_example_4_sphere_t_35() -> None:
    story = course_ray("ray_spheres", "0,0.6,-0.8")
    first = story.record.bounces[0]
    big = next(test for test in first.tests if test.node == "big")
    assert big.verdict == "hit"
    assert big.values["s"] == pytest.approx(80, abs=1e-9)
    assert big.values["m2"] == pytest.approx(3600, abs=1e-9)
    assert big.values["q"] == pytest.approx(45, abs=1e-9)
    assert first.hit == "big" and first.t == pytest.approx(35, abs=1e-9)
    assert first.point == pytest.approx([0, 21, -28], abs=1e-9)  # the notes' (0, 21, 28), z mirrored
    assert first.normal == pytest.approx([0, 0.28, 0.96], abs=1e-9)


def test_exam_2013_shadow_and_reflection() -> None:
    story = course_ray("ray_phong", "0.96,0.28,0", "scene=exam2013")
    red, blue = story.record.bounces[:2]
    assert red.hit == "red" and red.t == pytest.approx(75, abs=1e-9)
    assert red.point == pytest.approx([72, 21, 0], abs=1e-9) and red.normal == pytest.approx([-0.8, 0.6, 0], abs=1e-9)
    light = red.lights[0]
    assert light.to_light == pytest.approx([0.28, 0.96, 0], abs=1e-9)
    assert light.distance == pytest.approx(100, abs=1e-9)
    assert light.blocked and light.blocker == "blue"
    assert light.blocker_s * light.distance == pytest.approx(75, abs=1e-6)  # the blue sphere at t = 75 < 100
    assert light.term == pytest.approx(light.ambient, abs=0)  # in shadow, the ambient term alone
    assert red.next == "reflection" and blue.direction == pytest.approx([0, 1, 0], abs=1e-9)
    assert blue.hit == "blue" and blue.t == pytest.approx(65, abs=1e-9)


def test_mesh_misses_say_why() -> None:
    """ray_triangle's one triangle: every pixel is a hit, or a miss with the plane met outside it."""
    scene = find_lesson("ray_triangle")().scene()
    verdicts = set()
    for x in range(0, 96, 8):
        trace = explain_ray_pixel(scene, SIZE, (x, 36))
        for test in trace.bounces[0].tests:
            if test.kind == "mesh":
                verdicts.add(test.verdict)
                if test.verdict in ("outside", "behind", "parallel", "culled"):
                    assert test.values["counts"][test.verdict] >= 1
                if test.verdict == "outside":
                    tri = test.values["nearest"]
                    assert tri["u"] < 0 or tri["v"] < 0 or tri["u"] + tri["v"] > 1
    assert {"hit", "outside"} <= verdicts or {"hit", "box"} <= verdicts


def test_json_record_round_trips() -> None:
    story = course_ray("ray_spheres", "0,0.6,-0.8")
    record = json.loads(story.to_json())
    assert record["rgba8"] == story.rgba8
    assert record["bounces"][0]["tests"][0]["values"]["q"] == pytest.approx(45)
    assert "<pre" in story._repr_html_() and "min_indis" in repr(story)


def test_bad_pixels_are_one_line_errors() -> None:
    scene = find_lesson("ray_spheres")().scene()
    with pytest.raises(SandboxError, match="outside the 96x72 frame"):
        explain_ray_pixel(scene, SIZE, (96, 0))
    with pytest.raises(SandboxError, match="rasterised"):  # the command tells a raster pixel's story instead
        explain_ray_pixel(find_lesson("phong")().scene(), SIZE, (1, 1))
    with pytest.raises(SandboxError, match="X,Y"):
        parse_pixel("1;2")
    with pytest.raises(SandboxError, match="takes no parameters"):
        explain(scene, (1, 1), time=1)


def test_split_viewports_find_their_pixel() -> None:
    """A frame of two viewports: the pixel's viewport and its own pixel in it."""
    scene = find_lesson("ray_phong").from_settings(["renderer=ray_numpy"]).scene()
    from dataclasses import replace

    left, = scene.viewports
    two = replace(scene, viewports=(replace(left, rect=(0.0, 0.0, 0.5, 1.0)), replace(left, rect=(0.5, 0.0, 0.5, 1.0))))
    index, local, size = locate_pixel(two, SIZE, (60, 10))
    assert (index, local, size) == (1, (12, 10), (48, 72))
    frame = traced_frame(two, SIZE)
    assert explain_ray_pixel(two, SIZE, (60, 10)).replay() == frame[10, 60].tolist()


def test_the_frame_shows_the_story_where_no_overlay_covers_it(gl) -> None:
    """The whole frame (GL, overlays and all) of ray_spheres traced by the numpy engine: each grid
    pixel is the story's colour, or the story says an overlay covers it."""
    lesson = find_lesson("ray_spheres").from_settings(["renderer=ray_numpy"])
    frame = gl.render(lesson, SIZE).image
    covered = 0
    for y in range(1, SIZE[1], 7):
        for x in range(1, SIZE[0], 7):
            trace = explain_ray_pixel(lesson.scene(), SIZE, (x, y))
            if trace.notes:
                covered += 1
                assert "overlay 'figures'" in trace.notes[0]
            else:
                assert trace.rgba8 == frame[y, x].tolist(), (x, y)
    assert covered > 0
