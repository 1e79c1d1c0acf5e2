"""``plan``, ``list -v`` and ``render`` say what happens, run in this process."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import run_cli

from glsandbox.frame import with_samples
from glsandbox.lesson import all_lessons, find_lesson


def run(*args: str) -> tuple[int, str, str]:
    result = run_cli(*args)
    return result.returncode, result.stdout, result.stderr


def test_plan_of_a_ray_traced_lesson_prints_its_trace_and_no_raster_draws() -> None:
    status, out, err = run("plan", "ray_phong", "--set", "renderer=ray")
    assert status == 0 and err == ""
    lines = out.splitlines()
    assert lines[:4] == ["plan for ray_phong", "buffers: colour RGBA8, no MSAA", "programs:", "  overlay"]
    assert lines[5].startswith("  1. trace viewport 0 (GLSL ray tracer, float32, 1 primary ray per pixel, ")
    assert "depth 24" not in out and "phong[" not in out and "draw viewport" not in out
    # the same lesson rasterized: Phong draws with a depth buffer, no trace
    status, out, _ = run("plan", "ray_phong", "--set", "renderer=raster")
    assert "depth 24" in out and "draw viewport 0 (depth test)" in out and "trace" not in out


def test_list_verbose_shows_each_lessons_own_defaults() -> None:
    status, out, _ = run("list", "-v")
    assert status == 0
    blocks: dict[str, list[str]] = {}
    for line in out.splitlines():
        if not line.startswith(" "):
            blocks[line.split()[0]] = []
        else:
            blocks[list(blocks)[-1]].append(line.strip())
    ray_lessons = [cls.name for cls in all_lessons() if cls.defaults.get("renderer") == "ray"]
    assert len(ray_lessons) >= 5
    for cls in all_lessons():
        want = cls().values["renderer"]  # what the lesson renders with when nothing is set
        assert f"--set renderer={want} (raster|ray|ray_numpy): who draws the 3D content: the rasterizer or the " \
               "ray tracer (the same Scene)" in blocks[cls.name], cls.name
    assert any(line.startswith("--set renderer=ray ") for line in blocks["ray_phong"])
    assert any(line.startswith("--set renderer=raster ") for line in blocks["phong"])


@pytest.mark.parametrize("settings, warned", [
    (["--set", "renderer=ray", "--set", "shading=gouraud"], ["shading=gouraud (nodes 'ground', 'ellipsoid')"]),
    (["--set", "renderer=ray_numpy", "--set", "normals=naive"], ["normals=naive (nodes 'ground', 'ellipsoid')"]),
    (["--set", "renderer=ray", "--samples", "4"], ["--samples 4: MSAA smooths rasterized edges only"]),
    (["--set", "renderer=ray", "--set", "shading=gouraud", "--samples", "2"], ["shading=gouraud", "--samples 2"]),
    (["--set", "renderer=raster", "--set", "shading=gouraud", "--samples", "4"], []),
    (["--set", "renderer=ray", "--set", "shading=blinn_phong"], []),  # the ray tracer does Blinn-Phong
])
def test_a_setting_the_renderer_ignores_is_one_warning_line(settings: list[str], warned: list[str],
                                                            tmp_path: Path, gl) -> None:
    out = tmp_path / "out.png"
    status, stdout, err = run("render", "phong", "--size", "32x24", "--out", str(out), *settings)
    assert status == 0 and out.is_file() and stdout.startswith("wrote ")
    lines = err.splitlines()
    assert len(lines) == len(warned), err
    for line, part in zip(lines, warned):
        assert line.startswith("warning: ") and part in line, line


def test_the_sampled_picture_really_is_the_same_and_the_warning_says_it_once(tmp_path: Path, capsys, gl) -> None:
    plain, four = tmp_path / "plain.png", tmp_path / "four.png"
    run("render", "ray_spheres", "--size", "40x30", "--out", str(plain))
    status, _, err = run("render", "ray_spheres", "--size", "40x30", "--samples", "4", "--out", str(four))
    assert status == 0 and plain.read_bytes() == four.read_bytes()  # the warning's claim
    assert err.startswith("warning: --samples 4: ") and err.count("\n") == 1
    # a window draws many frames: the warning is said once per run, not per frame
    from glsandbox.frame import FrameRenderer

    renderer = FrameRenderer(gl.host)
    scene = with_samples(find_lesson("ray_spheres")().scene(), 4)
    capsys.readouterr()
    try:
        for _ in range(3):
            renderer.draw(scene, (40, 30))
    finally:
        renderer.close()
    assert capsys.readouterr().err.count("warning: --samples 4") == 1
