"""The X-ray of a rasterised frame: its passes rebuild the frame, and ``render --xray`` writes each one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from glsandbox.files import load_png
from glsandbox.lesson import find_lesson
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
