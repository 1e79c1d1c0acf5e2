"""What the shader saw at a rasterised pixel, against the frame: the interpolated position projects
to the depth read back, its weights lie in the triangle the primitive ids name, and the planar
shadow's blend gives the colour read back."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.lesson import find_lesson
from glsandbox.story.raster import explain_raster_pixel, render_raster_story
from glsandbox.story.xray import xray

SIZE = (96, 72)


def _rows(gl, name: str, step: int = 9):
    scene = find_lesson(name)().scene()
    for y in range(2, SIZE[1], step):
        for x in range(3, SIZE[0], step):
            for row in explain_raster_pixel(gl, scene, SIZE, (x, y)).passes:
                yield scene, (x, y), row


@pytest.mark.parametrize("name", ["mirror", "phong", "texture"])
def test_the_interpolated_position_is_where_the_depth_test_was(gl, name: str) -> None:
    checked = 0
    for _, pixel, row in _rows(gl, name):
        fragment = row["fragment"]
        if fragment is None or "depth" not in row["wrote"]:
            continue
        checked += 1
        assert fragment["depth"] == pytest.approx(row["depth"], rel=2e-5, abs=1e-7), (pixel, row["name"])
        assert min(fragment["uvw"]) > -1e-3 and max(fragment["uvw"]) < 1 + 1e-3, (pixel, row["name"])
    assert checked > 20


def test_the_floor_and_the_reflected_floor_are_seen_as_drawn(gl) -> None:
    scene = find_lesson("mirror")().scene()
    plane = np.asarray(scene.mirror.plane)
    seen = {"draw": 0, "reflection": 0}
    for _, _, row in _rows(gl, "mirror", 5):
        f = row["fragment"]
        if f is None or f["node"] != "floor" or row["kind"] not in seen:
            continue
        seen[row["kind"]] += 1
        assert f["normal_unit"] == pytest.approx([0.0, 1.0, 0.0], abs=1e-9)
        side = float(plane[:3] @ np.asarray(f["position"]) + plane[3])
        assert (side < 0) == (row["kind"] == "reflection"), row  # the reflected floor lies behind the glass
    assert seen["draw"] and seen["reflection"]


def test_the_planar_shadow_blend_gives_the_colour_read_back(gl) -> None:
    scene = find_lesson("mirror")().scene()
    x = xray(gl, scene, SIZE)
    number = next(p.number for p in x.passes if p.step.kind == "planar_shadow")
    changed = np.any(x.passes[number - 1].color != x.passes[number - 2].color, axis=2)
    ys, xs = np.nonzero(changed)
    assert xs.size > 10
    for k in range(0, xs.size, max(1, xs.size // 12)):
        trace = explain_raster_pixel(gl, scene, SIZE, (int(xs[k]), int(ys[k])))
        row = trace.passes[number - 1]
        blend = row["blend"]
        assert blend is not None and blend["result"] == blend["read_back"] == row["color"][:3]
        assert blend["destination"] == row["color_before"][:3]
        assert "blend src·a + dst·(1 − a)" in render_raster_story(trace)
