"""The glsandbox command: output files, and every bad input (in this process, where the contract is
checked on each run; in a subprocess where the process is the point: no GL library, no display)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support import REPO_ROOT as REPO
from support import assert_user_error, glsandbox, run_cli

from glsandbox.files import load_png


def test_list_shows_the_lessons() -> None:
    proc = run_cli("list")
    assert proc.returncode == 0
    names = [line.split()[0] for line in proc.stdout.splitlines()]
    assert names[:3] == ["clear_and_swap", "triangle", "indexed_cube"]


def test_plan_prints_the_lessons_plan() -> None:
    proc = run_cli("plan", "indexed_cube", "--samples", "4")
    assert proc.returncode == 0
    assert "buffers: colour RGBA8, depth 24, MSAA 4x" in proc.stdout


def test_render_writes_the_png(tmp_path: Path, gl) -> None:
    out = tmp_path / "cube.png"
    proc = run_cli("render", "indexed_cube", "--out", str(out), "--size", "256x256", "--set", "time=0.5")
    assert proc.returncode == 0, proc.stderr
    image = load_png(out)
    np.testing.assert_array_equal(image, gl.render(__import__("glsandbox.lesson", fromlist=["x"])
                                                   .find_lesson("indexed_cube")(time=0.5), (256, 256)).image)


def test_render_a_scene_file(tmp_path: Path, gl) -> None:
    scene = tmp_path / "box.toml"
    scene.write_text('[[nodes]]\nmesh = "cube"\ncolor = [1, 0, 0]\nshading = "solid"\n')
    out = tmp_path / "box.png"
    proc = run_cli("render", str(scene), "--out", str(out), "--size", "64x64")
    assert proc.returncode == 0, proc.stderr
    image = load_png(out)
    assert tuple(image[32, 32]) == (255, 0, 0, 255)


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["render", "indexed_cub", "--out", "{out}"], ["unknown lesson 'indexed_cub'", "did you mean 'indexed_cube'"]),
        (["render", "indexed_cube", "--out", "{out}", "--set", "spede=2"],
         ["--set spede", "did you mean 'speed'"]),
        (["render", "indexed_cube", "--out", "{out}", "--set", "speed=fast"], ["--set speed=fast", "a number"]),
        (["render", "indexed_cube", "--out", "{out}", "--set", "flip=back"], ["--set flip=back", "none, front, top"]),
        (["render", "indexed_cube", "--out", "{out}", "--set", "time=-1"], ["--set time=-1", "at least 0"]),
        (["render", "indexed_cube", "--out", "{out}", "--set", "nonsense"], ["expected key=value"]),
        (["render", "indexed_cube", "--out", "{out}", "--size", "640by480"], ["--size '640by480'"]),
        (["render", "indexed_cube", "--out", "{out}", "--size", "0x10"], ["--size '0x10'"]),
        (["render", "indexed_cube", "--out", "{out}", "--backend", "vulkan"], ["unknown backend 'vulkan'"]),
        (["render", "indexed_cube", "--out", "{out}", "--samples", "64"], ["--samples 64"]),
        (["render", "indexed_cube", "--out", "{tmp}/missing/dir/x.png"], ["folder", "does not exist"]),
        (["render", "indexed_cube", "--out", "{tmp}/x.jpg"], ["must be a .png"]),
        (["render", "indexed_cube", "--out", "/proc/glsandbox.png"], ["/proc/glsandbox.png"]),
    ],
)
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path: Path, args: list[str], fragments: list[str],
                                                         gl) -> None:
    out = tmp_path / "out.png"
    filled = [a.replace("{out}", str(out)).replace("{tmp}", str(tmp_path)) for a in args]
    proc = run_cli(*filled, unchanged=tmp_path)
    assert_user_error(proc, *fragments)
    assert list(tmp_path.iterdir()) == []  # nothing written, not even a temporary file


def test_backend_from_environment_is_validated(tmp_path: Path) -> None:
    proc = run_cli("render", "triangle", "--out", str(tmp_path / "x.png"), env={"GLSANDBOX_BACKEND": "dx11"})
    assert_user_error(proc, "unknown backend 'dx11' (from GLSANDBOX_BACKEND)")


def test_malformed_scene_file_names_file_and_line(tmp_path: Path) -> None:
    scene = tmp_path / "bad.toml"
    scene.write_text('[camera]\neye = [0, 3, 10]\n\n[[nodes]]\nmesh = "cube"\ncolor = [1, 0,, 0]\n')
    out = tmp_path / "x.png"
    assert_user_error(run_cli("render", str(scene), "--out", str(out)), f"{scene}:6: malformed TOML")
    scene.write_text('[[nodes]]\nmesh = "sphere9"\n')
    assert_user_error(run_cli("render", str(scene), "--out", str(out)), f"{scene}:2: nodes[0].mesh")
    assert not out.exists()


def test_shader_that_does_not_compile_names_file_and_line(tmp_path: Path, gl) -> None:
    shaders = tmp_path / "shaders"
    shaders.mkdir()
    source = (REPO / "shaders" / "basic.glsl").read_text().splitlines()
    line = next(i for i, text in enumerate(source, start=1) if "frag_color = u_color;" in text)
    source[line - 1] = source[line - 1].replace("u_color", "u_colour")
    (shaders / "basic.glsl").write_text("\n".join(source) + "\n")
    out = tmp_path / "x.png"
    proc = run_cli("render", "triangle", "--out", str(out), env={"GLSANDBOX_SHADER_DIR": str(shaders)})
    assert_user_error(proc, f"{shaders / 'basic.glsl'}:{line}:", "u_colour")
    assert not out.exists()


@pytest.mark.slow  # several subprocesses: the process is the point
def test_no_gl_available_says_what_to_install(tmp_path: Path) -> None:
    broken = {"__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "none.json"), "EGL_PLATFORM": "surfaceless",
              "GLSANDBOX_OSMESA": str(tmp_path / "libOSMesa-missing.so")}
    out = tmp_path / "x.png"
    assert_user_error(glsandbox("render", "triangle", "--out", str(out), "--backend", "egl", env=broken),
                      "EGL backend unavailable", "apt-get install")
    assert_user_error(glsandbox("render", "triangle", "--out", str(out), "--backend", "osmesa", env=broken),
                      "OSMesa backend unavailable")
    assert_user_error(glsandbox("render", "triangle", "--out", str(out), env=broken), "no OpenGL available")
    no_display = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.run([sys.executable, "-m", "glsandbox.cli", "run", "triangle", "--backend", "window"],
                          capture_output=True, text=True, env=no_display, timeout=60)
    assert_user_error(proc, "no display", "Xvfb")
    assert not out.exists()


@pytest.mark.slow
def test_tour_writes_images_gallery_and_json(tmp_path: Path, gl) -> None:
    out = tmp_path / "tour"
    proc = run_cli("tour", "--out", str(out), "--size", "128x96")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "tour.json").read_text())
    names = [r["lesson"] for r in summary["lessons"]]
    assert names[:3] == ["clear_and_swap", "triangle", "indexed_cube"]
    for entry in summary["lessons"]:
        assert entry["ok"] and entry["render_ms"] > 0 and entry["plan"]["passes"]
        assert load_png(out / entry["image"]).shape == (96, 128, 4)
    page = (out / "index.html").read_text()
    assert all(f'src="{n}.png"' in page for n in names)
    assert "Küp: vertex + index buffer" in page and "plan for indexed_cube" in page
    assert f"[1/{len(names)}] clear_and_swap: ok" in proc.stderr  # progress


@pytest.mark.slow
def test_tour_goes_on_when_a_lesson_fails_and_exits_non_zero(tmp_path: Path, gl) -> None:
    shaders = tmp_path / "shaders"
    shaders.mkdir()
    (shaders / "basic.glsl").write_text("#version 330 core\nthis is not glsl\n")
    out = tmp_path / "tour"
    proc = run_cli("tour", "--out", str(out), "--size", "64x64", env={"GLSANDBOX_SHADER_DIR": str(shaders)})
    assert proc.returncode == 1
    summary = json.loads((out / "tour.json").read_text())
    by_name = {r["lesson"]: r for r in summary["lessons"]}
    assert by_name["clear_and_swap"]["ok"]  # draws nothing, needs no shader
    assert not by_name["indexed_cube"]["ok"] and "basic.glsl:2" in by_name["indexed_cube"]["error"]
    assert (out / "clear_and_swap.png").exists() and not (out / "indexed_cube.png").exists()
    assert "FAILED" in proc.stderr and "failed: " in proc.stderr
