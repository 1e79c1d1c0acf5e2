"""The interactive window: its error and frame-rate bookkeeping, and under Xvfb: open a lesson,
send keys, read the screen, quit."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from support import COURSE_BLUE, LessonWindow, wait_for
from support import REPO_ROOT as REPO

from glsandbox.files import load_png
from glsandbox.lesson import find_lesson
from glsandbox.measure.golden import compare_images
from glsandbox.app.window import FrameRate, LessonErrors

slow = pytest.mark.slow  # windows under Xvfb


@slow
def test_window_shows_the_lesson_saves_screenshots_resizes_and_quits(window_env: str, tmp_path: Path,
                                                                      gl) -> None:
    win = LessonWindow(window_env, tmp_path, "lessons.indexed_cube", "--size", "320x240", "--set", "speed=0")
    try:
        title = win.wait_title(lambda t: "fps" in t)
        assert title.startswith("glsandbox: indexed_cube | ")
        screen = win.screen()
        # The window sits at the top left of the screen: course blue around a cube.
        assert tuple(screen[5, 5]) == COURSE_BLUE
        assert tuple(screen[120, 160]) != COURSE_BLUE
        assert tuple(screen[300, 500]) != COURSE_BLUE  # outside the window: the X root

        win.key("F12")
        shot = load_png(wait_for(tmp_path / "screenshots" / "indexed_cube-1.png"))
        assert shot.shape == (240, 320, 4)
        headless = gl.render(find_lesson("indexed_cube")(speed=0.0), (320, 240)).image
        assert compare_images(shot, headless).passed  # the window shows what headless renders

        win._xdotool("windowsize", "--sync", win.window, "400", "300")
        # The resize reaches the lesson's framebuffer a frame or two later; on a
        # loaded machine that can take a while, so take screenshots until one
        # has the new size (each F12 writes the next numbered file).
        resized = shot
        for number in range(2, 40):
            win.key("F12")
            resized = load_png(wait_for(tmp_path / "screenshots" / f"indexed_cube-{number}.png"))
            if resized.shape == (300, 400, 4):
                break
        assert resized.shape == (300, 400, 4)
        assert compare_images(resized, gl.render(find_lesson("indexed_cube")(speed=0.0), (400, 300)).image).passed
    finally:
        code = win.close()
    assert code == 0


@slow
def test_window_has_the_buffers_the_plan_asks_for(window_env: str, tmp_path: Path, gl) -> None:
    # Reverse-Z needs a float depth buffer, which a window's own framebuffer
    # does not have (24-bit integers); far away without polygon offset the
    # shadow would z-fight there. The window draws into the plan's target
    # (here with MSAA, resolved there) and copies it over, so it shows
    # exactly the headless frame.
    settings = ["depth=reverse_z", "offset=off", "distance=90", "fov=5.7", "far=200", "speed=0"]
    args = [a for s in settings for a in ("--set", s)]
    win = LessonWindow(window_env, tmp_path, "lessons.mirror", "--size", "320x240", "--samples", "4", *args)
    try:
        win.wait_title(lambda t: "fps" in t)
        win.key("F12")
        shot = load_png(wait_for(tmp_path / "screenshots" / "mirror-1.png"))
    finally:
        code = win.close()
    assert code == 0
    headless = gl.render(find_lesson("mirror").from_settings(settings), (320, 240), samples=4).image
    np.testing.assert_array_equal(shot, headless)  # alpha too: both opaque
    assert (shot[..., 3] == 255).all()


@slow
def test_r_reloads_shaders_and_a_broken_one_keeps_the_last_good_program(window_env: str, tmp_path: Path) -> None:
    shaders = tmp_path / "shaders"
    shutil.copytree(REPO / "shaders", shaders)
    basic = shaders / "basic.glsl"
    good = basic.read_text()
    win = LessonWindow(window_env, tmp_path, "lessons.triangle", "--size", "320x240",
                       env={"GLSANDBOX_SHADER_DIR": str(shaders)})
    try:
        win.wait_title(lambda t: "fps" in t)
        win.key("F1")  # the live controls off: the pixels read below are the frame's
        time.sleep(0.3)
        before = win.screen()[:240, :320]
        basic.write_text(good.replace("frag_color = u_color;", "frag_color = u_color * broken;"))
        win.key("r")
        title = win.wait_title(lambda t: "shader error" in t)
        assert "basic.glsl" in title and "broken" in title
        time.sleep(0.3)
        np.testing.assert_array_equal(win.screen()[:240, :320], before)  # still drawing with the old program
        # A visible edit, then R again: the new shader is used and the error is gone.
        basic.write_text(good.replace("frag_color = u_color;", "frag_color = vec4(0.0, 1.0, 0.0, 1.0);"))
        win.key("r")
        win.wait_title(lambda t: "fps" in t and "shader error" not in t)
        time.sleep(0.3)
        assert tuple(win.screen()[120, 80]) == (0, 255, 0)
    finally:
        code = win.close()
    assert code == 0
    assert "error: shader does not compile" in win.proc.stderr.read()


@slow
def test_a_model_file_renders_in_the_window_through_both_renderers(window_env: str, tmp_path: Path, gl) -> None:
    """A scene file naming an STL, opened with
    ``glsandbox run``, ray traced (the gpu engine through the BVH: 1,280 triangles) and
    rasterized; each window screenshot matches the headless render of the same settings."""
    import trimesh

    from glsandbox.lesson import scene_file_lesson

    trimesh.creation.icosphere(subdivisions=3).export(tmp_path / "ball.stl")
    scene = tmp_path / "ball.toml"
    scene.write_text('[camera]\neye = [0, 0, 4]\n\n[[lights]]\nposition = [1, 2, 4]\n\n'
                     '[[nodes]]\nname = "ball"\nmesh = "ball.stl"\nfit = true\nshading = "phong"\n'
                     'color = [0.9, 0.5, 0.2]\n')
    for number, renderer in enumerate(("ray", "raster"), start=1):
        win = LessonWindow(window_env, tmp_path, "glsandbox.cli", "run", str(scene), "--size", "160x120",
                           "--set", f"renderer={renderer}")
        try:
            win.wait_title(lambda t: "fps" in t)
            win.key("F12")
            shot = load_png(wait_for(tmp_path / "screenshots" / f"ball-{number}.png"))  # numbers go on across runs
        finally:
            code = win.close()
        assert code == 0
        headless = gl.render(scene_file_lesson(scene)(renderer=renderer), (160, 120)).image
        assert compare_images(shot, headless).passed, renderer
        centre, corner = shot[60, 80].astype(int), shot[5, 5].astype(int)
        assert centre[0] > centre[2] + 30 and corner[2] > corner[0] + 100, renderer  # an orange ball on blue


def test_lesson_errors_show_the_first_kind_set_and_print_each_new_error_once(capsys) -> None:
    errors = LessonErrors()
    assert errors.report("draw", "bad value") == "bad value"
    assert errors.report("file", "lesson.py:3: oops") == "lesson.py:3: oops"  # the file's error comes first
    assert errors.report("draw", "bad value") == "lesson.py:3: oops"
    assert capsys.readouterr().err == "error: bad value\nerror: lesson.py:3: oops\n"  # the repeat not printed
    assert errors.report("file", "") == "bad value"  # the file reads again: the draw error shows
    assert errors.report("draw", "") == ""
    assert capsys.readouterr().err == ""


def test_frame_rate_counts_frames_over_half_second_windows() -> None:
    rate = FrameRate(every=0.5, start=10.0)
    assert [rate.tick(10.0 + 0.1 * k) for k in range(1, 5)] == [False] * 4 and rate.fps == 0.0
    assert rate.tick(10.5) and rate.fps == pytest.approx(10.0)  # five frames in 0.5 s
    assert not rate.tick(10.9) and rate.tick(11.5) and rate.fps == pytest.approx(2.0)


@slow
def test_max_frames_ends_the_window_after_that_many_frames(xvfb_display: str, tmp_path: Path) -> None:
    script = ("from glsandbox.lesson import find_lesson\n"
              "from glsandbox.app.window import run_window\n"
              "run_window(find_lesson('triangle')(), (64, 48), max_frames=3)\n"
              "print('done')\n")
    # Without max_frames the window would wait for ESC and the run time out.
    proc = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "DISPLAY": xvfb_display})
    assert (proc.returncode, proc.stdout) == (0, "done\n"), proc.stderr
