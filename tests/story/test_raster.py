"""A rasterised pixel's story (glsandbox/story/raster.py): pass by pass from the frame's X-ray,
the stencil test as the course's DrawReflectionDSS states it, and the story's numbered lines."""

from __future__ import annotations

import numpy as np

from glsandbox.lesson import find_lesson
from glsandbox.story.raster import RasterTrace, explain_raster_pixel, render_raster_story
from glsandbox.story.xray import xray

SIZE = (160, 120)


def test_mirror_pixel_pass_by_pass(gl) -> None:
    """A pixel of the glass: marked 0 -> 1, the reflection drawn where the stencil is 1, the glass blended
    over it; a pixel of the floor outside the mirror: the reflection's stencil test fails there."""
    scene = find_lesson("mirror")().scene()
    x = xray(gl, scene, SIZE)
    mark = next(p for p in x.passes if p.name.startswith("mark mirror"))
    inside = np.argwhere(mark.stencil == 1)
    outside = np.argwhere(mark.stencil == 0)
    assert inside.size and outside.size
    y, x_ = inside[len(inside) // 2]
    trace = explain_raster_pixel(gl, scene, SIZE, (int(x_), int(y)))
    rows = {row["name"].split(" viewport")[0]: row for row in trace.passes}
    assert rows["mark mirror"]["stencil_before"] == 0 and rows["mark mirror"]["stencil"] == 1
    assert rows["reflection"]["stencil_passes"] is True
    assert "colour" in rows["mirror surface"]["wrote"] and rows["mirror surface"]["blended"]
    assert trace.rgba8 == x.frame[y, x_].tolist()
    story = render_raster_story(trace)
    assert "stencil 0 → 1" in story and "blended over" in story
    y, x_ = outside[len(outside) // 2]
    rows = {row["name"].split(" viewport")[0]: row for row in explain_raster_pixel(gl, scene, SIZE,
                                                                                   (int(x_), int(y))).passes}
    assert rows["reflection"]["stencil_passes"] is False and rows["reflection"]["wrote"] == []


def test_a_rasterised_pixel_beside_a_traced_viewport_leaves_it_untraced(gl) -> None:
    """The model lesson's traced viewport is not the raster pixel's: its story draws the same passes
    with that viewport left blank, and tells the pixel as the whole frame shows it."""
    scene = find_lesson("model")().scene()
    traced = [i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"]
    raster = next(i for i, vp in enumerate(scene.viewports) if vp.renderer == "raster")
    assert traced, "the model lesson has a ray-traced viewport beside its raster one"
    vx, vy, w, h = scene.viewports[raster].pixels(*SIZE)
    pixel = (vx + w // 2, SIZE[1] - vy - h // 2 - 1)
    trace = explain_raster_pixel(gl, scene, SIZE, pixel)
    normal = gl.render_scene(scene, SIZE).image
    assert trace.rgba8 == normal[pixel[1], pixel[0]].tolist()
    assert [row["name"] for row in trace.passes] == [p.name for p in xray(gl, scene, SIZE).passes]
    assert any("left untraced" in note for note in trace.notes)


def _row(number: int, name: str, kind: str, wrote: list[str], **values) -> dict:
    row = {"pass": number, "name": name, "kind": kind, "wrote": wrote, "stencil_state": None, "nodes": [],
           "stencil_passes": None, "blended": False, "color_before": [0, 0, 0, 255], "color": [0, 0, 0, 255],
           "depth_before": None, "depth": None, "stencil_before": None, "stencil": None}
    return row | values


def test_the_story_tells_each_pass_by_what_it_wrote() -> None:
    """A hand-made trace: a clear, a draw the stencil test stops, a blended draw; one line each, then the colour."""
    trace = RasterTrace("t", (3, 4), (8, 6), 0, [
        _row(1, "clear viewport 0", "clear", ["colour", "depth", "stencil"], color=[0, 32, 153, 255], depth=0.0,
             stencil=0),
        _row(2, "reflection viewport 0", "reflection", [], stencil_state="== 1", stencil_passes=False,
             stencil_before=0, nodes=["floor"]),
        _row(3, "glass viewport 0", "mirror_surface", ["colour"], blended=True, color_before=[0, 32, 153, 255],
             color=[40, 60, 160, 255], node="glass", triangle=1, depth=0.5, stencil=1),
    ], [40, 60, 160, 255], 0.0, ["a note"])
    lines = render_raster_story(trace).splitlines()
    assert lines[0].startswith("t: pixel 3,4 of 8x6, rasterised (viewport 0)")
    assert "reverse-Z" in lines[1] and lines[2] == "note: a note"
    assert lines[3] == "1. clear viewport 0: cleared to colour (0, 32, 153), depth 0, stencil 0"
    assert lines[4].startswith("2. reflection viewport 0 [stencil == 1] (floor): the stencil test fails here")
    assert lines[5] == ("3. glass viewport 0: colour (0, 32, 153) → (40, 60, 160) (blended over the colour before; "
                        "glass, triangle 1); depth kept (0.5), stencil kept (1)")
    assert lines[6] == "4. Final colour: (40, 60, 160) in 8-bit levels"
