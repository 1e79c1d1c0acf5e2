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
from support import EXAMPLES_DIR, SPIN, assert_user_error, glsandbox, need, not_blank, run_cli

from glsandbox.files import load_png
from glsandbox.lesson import find_lesson


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


# --- new, and tour --lessons (moved from tests/core/test_lesson.py) ---------------------


def test_new_writes_a_lesson_and_a_scene_that_render_as_they_are(tmp_path: Path, gl) -> None:
    proc = run_cli("new", "my_lesson", "--dir", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    lesson, scene = tmp_path / "my_lesson.py", tmp_path / "my_lesson.toml"
    assert "class MyLesson(Lesson)" in lesson.read_text() and 'name = "my_lesson"' in scene.read_text()
    for source in (lesson, scene):
        out = tmp_path / f"{source.suffix[1:]}.png"
        proc = run_cli("render", str(source), "--out", str(out), "--size", "96x72", "--set", "time=1")
        assert proc.returncode == 0, proc.stderr
        assert not_blank(load_png(out)), source
    # its parameters are real: a slower turn is another picture, each shading another
    cls = find_lesson(str(lesson))
    assert {p.name for p in cls.params} == {"speed", "shading", "size"}
    a = gl.render(cls.from_settings(["time=1"]), (96, 72)).image
    b = gl.render(cls.from_settings(["time=1", "speed=0.3"]), (96, 72)).image
    c = gl.render(cls.from_settings(["time=1", "shading=gouraud"]), (96, 72)).image
    assert not np.array_equal(a, b) and not np.array_equal(a, c)
    # the scene's ball is drawn with the new shader file, whose rim is a uniform of its own
    assert 'shader = "my_lesson.glsl"' in scene.read_text() and (tmp_path / "my_lesson.glsl").is_file()
    rims = []
    for power in ("3", "1"):
        out = tmp_path / f"rim{power}.png"
        proc = run_cli("render", str(scene), "--out", str(out), "--size", "96x72", "--set", f"u.rim_power={power}")
        assert proc.returncode == 0, proc.stderr
        rims.append(load_png(out).astype(int))
    changed = np.any(rims[0] != rims[1], axis=-1)
    assert 0 < changed.mean() < 0.2  # only the ball, where the rim widened
    assert (rims[1][..., 2] - rims[0][..., 2])[changed].mean() > 5  # and bluer (rim_color is blue)


def test_new_refuses_to_overwrite_and_bad_names(tmp_path: Path) -> None:
    (tmp_path / "taken.toml").write_text("# mine\n")
    assert_user_error(run_cli("new", "taken", "--dir", str(tmp_path)), "taken.toml already exists", "not overwritten")
    assert (tmp_path / "taken.toml").read_text() == "# mine\n" and not (tmp_path / "taken.py").exists()
    assert not (tmp_path / "taken.glsl").exists()
    for name in ("9lives", "my-lesson", "_hidden", "a b", "../up"):
        assert_user_error(run_cli("new", name, "--dir", str(tmp_path)), "must be a Python identifier")
    assert_user_error(run_cli("new", "fine", "--dir", str(tmp_path / "nowhere")), "does not exist")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken.toml"]


def test_tour_lessons_dir_renders_each_file_and_goes_on_past_a_broken_one(tmp_path: Path, gl) -> None:
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "spin.py").write_text(SPIN)
    (mine / "room.toml").write_text((EXAMPLES_DIR / "mirror_room.toml").read_text())
    (mine / "broken.py").write_text("def oops(:\n")
    out = tmp_path / "tour"
    proc = run_cli("tour", "--lessons", str(mine), "--out", str(out), "--size", "64x48")
    assert proc.returncode == 1
    summary = json.loads((out / "tour.json").read_text())
    by_name = {r["lesson"]: r for r in summary["lessons"]}
    assert list(by_name) == ["broken", "room", "spin"]  # instead of the course's lessons
    assert by_name["spin"]["ok"] and by_name["room"]["ok"]
    assert "broken.py:1: syntax error" in by_name["broken"]["error"]
    assert not_blank(load_png(out / "room.png")) and load_png(out / "spin.png").shape == (48, 64, 4)
    assert "[1/3] broken: FAILED" in proc.stderr and "[3/3] spin: ok" in proc.stderr
    assert_user_error(run_cli("tour", "--lessons", str(tmp_path / "none"), "--out", str(out)), "not a folder")


# What a plain `glsandbox render` leaves out of its cold start (the goal: start-up <= 1.2x a raw
# ModernGL script): each is imported where it is used, and an eager import anywhere on the render
# path (glsandbox/__init__, scene, overlay, cli, lesson, ...) brings it back into sys.modules here.
# pyrr: transforms builds its two matrices itself; hashlib (OpenSSL): the mesh digests use BLAKE2's
# own module; Pillow's other format plugins: a PNG is written by name (files.png_bytes).
LAZY_AT_RENDER = ("glsandbox.mesh.load", "glsandbox.mesh.generate", "glsandbox.mesh.looks", "glsandbox.course_page",
                  "glsandbox.grading.rubric", "glsandbox.measure.golden", "glsandbox.app.window", "glsandbox.raytrace",
                  "glsandbox.camera", "glsandbox.planar", "trimesh", "tqdm", "imgui", "PIL.ImageDraw",
                  "PIL.ImageFont", "tomllib", "difflib", "json", "html", "pyrr", "hashlib", "PIL.BmpImagePlugin",
                  "PIL.GifImagePlugin", "PIL.JpegImagePlugin", "PIL.PpmImagePlugin")


@pytest.mark.slow  # a subprocess: a cold start is the point
def test_plain_render_does_not_import_what_it_does_not_use(tmp_path: Path) -> None:
    out = tmp_path / "cube.png"
    code = ("import sys\n"
            "before = set(sys.modules)\n"  # the interpreter's own start-up
            "from glsandbox.cli import main\n"
            f"sys.argv = ['glsandbox', 'render', 'indexed_cube', '--size', '64x48', '--out', {str(out)!r}]\n"
            "try:\n    main()\nexcept SystemExit as exc:\n    code = exc.code\nelse:\n    code = 0\n"
            "loaded = sorted(set(sys.modules) - before)\n"
            "import json\n"  # for this report only, after the list is taken
            "print(json.dumps({'code': code, 'loaded': loaded}))\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=180)
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    if report["code"] != 0:
        need("a GL backend", proc.stderr.strip())
    assert out.exists()
    loaded = set(report["loaded"])
    assert "glsandbox.frame" in loaded and "moderngl" in loaded  # it did render
    eager = sorted(m for m in loaded if m in LAZY_AT_RENDER or m.startswith(tuple(f"{n}." for n in LAZY_AT_RENDER)))
    assert not eager, f"imported by a plain render though it does not use them: {eager}"
