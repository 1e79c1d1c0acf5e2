"""The X-ray of a rasterised frame: its passes rebuild the frame, and a pixel's passes tell the stencil mirror."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from glsandbox.files import load_png
from glsandbox.lesson import find_lesson
from glsandbox.story.raster import explain_raster_pixel, render_raster_story
from glsandbox.story.xray import pass_name, xray
from glsandbox.plan import plan
from support import run_cli

SIZE = (160, 120)


@pytest.mark.parametrize("name,settings", [("mirror", ()), ("phong", ()), ("texture", ()), ("shadow_map", ()),
                                           ("ray_phong", ("renderer=raster",)), ("transform_order", ())])
def test_the_passes_rebuild_the_frame(gl, name: str, settings: tuple[str, ...]) -> None:
    scene = find_lesson(name).from_settings(settings).scene()
    x = xray(gl, scene, SIZE)
    normal = gl.render_scene(scene, SIZE).image
    assert np.array_equal(x.frame, normal)
    assert np.array_equal(x.rebuilt(), normal)
    if all(vp.renderer == "raster" for vp in scene.viewports):  # (a traced viewport is an image pass then)
        frame_passes = [step for step in plan(scene).passes if step.target == "frame"]
        assert [p.name for p in x.passes] == [pass_name(step) for step in frame_passes]


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


def test_render_xray_writes_each_pass(gl, tmp_path: Path) -> None:
    out = tmp_path / "passes"
    run = run_cli("render", "mirror", "--xray", str(out), "--size", "80x60")
    assert run.returncode == 0, run.stderr
    names = sorted(p.name for p in out.iterdir())
    assert "contact_sheet.png" in names
    assert "03_mark_mirror_viewport_0_stencil.png" in names
    stencil = load_png(out / "03_mark_mirror_viewport_0_stencil.png")
    assert stencil.shape == (60, 80, 4) and (stencil[..., 0] > 0).any()
    run = run_cli("explain", "mirror", "--pixel", "40,30", "--size", "80x60")
    assert run.returncode == 0 and "mark mirror viewport 0" in run.stdout


def test_render_needs_out_or_xray(tmp_path: Path) -> None:
    from support import assert_user_error

    assert_user_error(run_cli("render", "mirror"), "--out", "--xray")
    afile = tmp_path / "f.png"
    afile.write_bytes(b"")
    assert_user_error(run_cli("render", "mirror", "--xray", str(afile)), "is a file")


def test_notebook_explain_of_a_rasterised_pixel(gl) -> None:
    import glsandbox

    story = glsandbox.explain("mirror", (40, 30), (80, 60))
    assert "mark mirror viewport 0" in repr(story) and "<pre" in story._repr_html_()
    assert story.rgba8 == gl.render(find_lesson("mirror")(), (80, 60)).image[30, 40].tolist()


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
