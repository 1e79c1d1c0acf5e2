"""``glsandbox compare``: labelled tiles in one frame, identical variants found, bad values refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support import run_cli

from glsandbox.cli import main
from glsandbox.errors import SandboxError
from glsandbox.files import load_png
from glsandbox.lesson import find_lesson
from glsandbox.measure.compare import build_variants, compare_variants, compose, parse_vary, tile_rects
from glsandbox.plan import plan

ORDERS = "order=STR,SRT,RST,RTS,TSR,TRS"


def test_variants_are_built_and_validated_before_rendering() -> None:
    lesson = find_lesson("transform_order")
    variants, columns = build_variants(lesson, [ORDERS], ["time=1"])
    assert columns == 3 and [v.label for v in variants][:2] == ["order=STR", "order=SRT"]
    grid, columns = build_variants(find_lesson("indexed_cube"), ["flip=none,front,top", "time=0,0.5"], [])
    assert columns == 3 and len(grid) == 6
    assert grid[3].label == "flip=none, time=0.5"  # second row: the second --vary's next value
    with pytest.raises(SandboxError, match="--vary order=XYZ: .*valid orders"):
        parse_vary(lesson, "order=STR,XYZ")
    with pytest.raises(SandboxError, match="has no parameter 'oder'"):
        parse_vary(lesson, "oder=STR")
    with pytest.raises(SandboxError, match="already varied"):
        build_variants(lesson, [ORDERS], ["order=STR"])
    with pytest.raises(SandboxError, match="empty value"):
        parse_vary(lesson, "order=STR,,SRT")


def test_composed_scene_gives_each_variant_its_own_viewports_and_camera() -> None:
    variants, columns = build_variants(find_lesson("transform_order"), ["view=single,split"], ["time=1"])
    scene = compose(variants, columns, (400, 200))
    assert len(scene.viewports) == 1 + 6
    assert scene.viewports[0].camera == variants[0].scene.camera
    assert scene.viewports[1].camera == variants[1].scene.camera  # the split view's own camera
    assert all(n.viewports for n in scene.nodes)
    assert len({n.name for n in scene.nodes}) == len(scene.nodes)
    assert tile_rects(2, 2) == [(0.0, 0.0, 0.5, 1.0), (0.5, 0.0, 0.5, 1.0)]
    assert plan(scene).passes[-1].kind == "overlay"


def test_six_orders_compare_into_four_classes(gl) -> None:
    variants, columns = build_variants(find_lesson("transform_order"), [ORDERS], ["time=1", "overlay=off"])
    result = compare_variants(variants, columns, (384, 256), gl)
    labels = [[variants[i].label for i in g] for g in result.groups]
    assert sorted(map(sorted, labels)) == sorted(map(sorted, [["order=STR"], ["order=SRT", "order=RST"],
                                                               ["order=RTS"], ["order=TSR", "order=TRS"]]))
    assert len(result.pairs) == 6 and all(p["share"] > 0 for p in result.pairs)
    report = result.report()
    assert "identical: order=SRT = order=RST; order=TSR = order=TRS" in report
    assert result.image.shape == (256, 384, 4)


def test_cli_writes_the_labelled_image_and_the_table(tmp_path: Path, gl) -> None:  # gl: a backend, or a skip
    out = tmp_path / "orders.png"
    proc = run_cli("compare", "transform_order", "--vary", ORDERS, "--set", "time=0", "--set", "overlay=off",
                   "--size", "384x256", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    printed = proc.stdout
    assert "identical: order=STR = order=SRT = order=RST; order=RTS = order=TSR = order=TRS" in printed
    assert "distinct pictures: 2" in printed and "differing px" in printed
    image = load_png(out)
    assert image.shape == (256, 384, 4)
    # Each tile carries its label at the bottom-right: the yellow label text is there.
    corner = image[256 - 20:, 128 - 60:128]
    assert np.any((corner[..., 0] > 200) & (corner[..., 1] > 180) & (corner[..., 2] < 120))


def test_cli_works_for_other_lessons_and_a_grid(tmp_path: Path, gl) -> None:
    out = tmp_path / "grid.png"
    proc = run_cli("compare", "triangle", "--vary", "topology=strip,list", "--vary", "cull=on,off",
                   "--size", "128x128", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    printed = proc.stdout
    # The course's claim: the strip and the list give the same pixels.
    assert "topology=strip, cull=on = topology=list, cull=on" in printed
    assert out.exists()


@pytest.mark.parametrize("args, message", [
    (["--vary", "order=STR,XYZ"], "--vary order=XYZ"),
    (["--vary", "speed=1,fast"], "--vary speed=fast: expected a number"),
    (["--vary", "nope=1,2"], "has no parameter 'nope'"),
    (["--vary", "order"], "expected key=value1,value2"),
    ([], "at least one --vary"),
])
# Refused before a context opens, so these can run in this process.
def test_cli_refuses_bad_values_with_exit_2_and_writes_nothing(tmp_path: Path, capsys, args, message) -> None:
    out = tmp_path / "bad.png"
    assert main(["compare", "transform_order", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.parametrize(("lesson", "vary"), [("mirror", "mirror=stencil,off,no_stencil"), ("mirror", "shadow=on,off"),
                                             ("phong", "lights=0,2")])
def test_variants_that_cannot_share_a_frame_are_stitched_tile_by_tile(gl, lesson: str, vary: str) -> None:
    # A mirror owns the frame's stencil; lights belong to a whole scene: such
    # variants are rendered alone at the tile size and placed in the frame.
    from glsandbox.measure.compare import composable, tile_rects
    from glsandbox.scene import Viewport

    variants, columns = build_variants(find_lesson(lesson), [vary], [])
    assert composable(variants) is not None
    size = (300, 200)
    result = compare_variants(variants, columns, size, gl)
    assert len(result.groups) == len(variants)  # every value changes the picture
    for variant, tile in zip(variants, tile_rects(len(variants), columns)):
        x, y, w, h = Viewport(rect=tile).pixels(*size)
        top = size[1] - y - h
        alone = gl.render_scene(variant.scene, (w, h)).image
        # Identical except where the tile's label is drawn (bottom-right corner).
        np.testing.assert_array_equal(result.image[top:top + h // 2, x:x + w], alone[: h // 2])


def test_an_empty_grid_cell_is_black_even_on_a_reused_target(gl) -> None:
    # Three tiles in a 2x2 grid leave the bottom-right cell empty; the target of
    # that size already holds a full phong frame, which must not show through.
    size = (400, 200)
    variants, columns = build_variants(find_lesson("phong"), ["shading=phong,gouraud,blinn_phong"], [])
    gl.render(find_lesson("phong")(), size)
    image = gl.render_scene(compose(variants, columns, size), size).image
    assert (image[100:, 200:, :3] == 0).all()
    assert image[:100, :200, :3].any()


def test_at_time_zero_the_six_orders_give_the_readmes_two_pictures_with_their_trails_left_out(gl) -> None:
    """The figures compare ``overlay=off`` renders: a lesson's trail (a line mesh, no
    Overlay) stays out as the report says, so S and R commuting shows at time 0."""
    variants, columns = build_variants(find_lesson("transform_order"), [ORDERS], ["time=0"])
    assert all(v.plain is not None and not any(n.name.startswith("trail") for n in v.plain.nodes)
               for v in variants)
    assert any(n.name.startswith("trail") for n in variants[0].scene.nodes)  # the tiles keep them
    result = compare_variants(variants, columns, (384, 256), gl)
    assert len(result.groups) == 2
    assert "without overlays" in result.report()
