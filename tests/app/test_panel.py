"""The window's live controls under Xvfb: click the panel, compare with headless renders."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import replace
import shlex
import time
from pathlib import Path

import numpy as np
import pytest
from support import REPO_ROOT as REPO
from support import LessonWindow, wait_for

from glsandbox.cli import parse_size
from glsandbox.files import load_png
from glsandbox.lesson import find_lesson
from glsandbox.measure.compare import build_variants, compare_variants, difference_image

pytestmark = pytest.mark.slow  # windows under Xvfb

SIZE = (640, 480)


class PanelWindow(LessonWindow):
    """A lesson window whose panel writes its widgets' rectangles (GLSANDBOX_PANEL_LAYOUT)."""

    def __init__(self, display: str, cwd: Path, *args: str) -> None:
        self.layout_path = cwd / "layout.json"
        super().__init__(display, cwd, *args, "--size", f"{SIZE[0]}x{SIZE[1]}",
                         env={"GLSANDBOX_PANEL_LAYOUT": str(self.layout_path)})
        self.shots = 0
        self.cwd = cwd

    def layout(self) -> dict:
        wait_for(self.layout_path)
        return json.loads(self.layout_path.read_text())

    def items(self) -> dict[str, list[float]]:
        return self.layout()["items"]

    def click(self, label: str) -> None:
        """Click the middle of the widget's box (a checkbox's box is at its left end)."""
        x0, y0, x1, y1 = self._wait(lambda: self.items().get(label))
        x = x0 + 8 if label in ("pause", "split into tiles", "difference view", "specular") else (x0 + x1) / 2
        self._xdotool("mousemove", "--sync", str(int(x)), str(int((y0 + y1) / 2)))
        self._xdotool("click", "1")
        time.sleep(0.3)
        self._xdotool("mousemove", "--sync", str(SIZE[0] + 50), str(SIZE[1] + 50))  # off the window: no tooltip
        time.sleep(0.2)  # a few frames: the press and release reach ImGui one frame apart

    def hold(self, label: str, seconds: float = 0.4) -> None:
        """Press on the middle of the widget's frame and hold a few frames (a slider takes the
        value under the mouse only while its button stays down), then let go."""
        x0, y0, x1, y1 = self._wait(lambda: self.items().get(label))
        self._xdotool("mousemove", "--sync", str(int(x0 + 0.4 * (x1 - x0))), str(int((y0 + y1) / 2)))
        self._xdotool("mousedown", "1")
        time.sleep(seconds)
        self._xdotool("mouseup", "1")
        time.sleep(0.3)
        self._xdotool("mousemove", "--sync", str(SIZE[0] + 50), str(SIZE[1] + 50))  # off the window: no tooltip
        time.sleep(0.2)

    def shot(self) -> np.ndarray:
        """F12: the window's frame as drawn (never the panel)."""
        self.shots += 1
        self.key("F12")
        return load_png(wait_for(next_shot(self.cwd, self.shots)))


def next_shot(cwd: Path, number: int) -> Path:
    folder = cwd / "screenshots"
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        found = sorted(folder.glob(f"*-{number}.png")) if folder.exists() else []
        if found:
            return found[0]
        time.sleep(0.1)
    raise AssertionError(f"screenshot {number} was not written")




def test_clicking_a_checkbox_renders_what_the_same_set_renders_headless(window_env: str, tmp_path: Path, gl) -> None:
    win = PanelWindow(window_env, tmp_path, "lessons.phong", "--set", "speed=0")
    try:
        win.wait_title(lambda t: "fps" in t)
        before = win.screen()
        win.click("specular")
        after_shot = win.shot()
        after = win.screen()
        panel_left = int(win.layout()["rect"][0]) - 1
    finally:
        code = win.close()
    assert code == 0
    headless = gl.render(find_lesson("phong").from_settings(["speed=0", "specular=off"]), SIZE).image
    np.testing.assert_array_equal(after_shot, headless)  # the frame: exactly the headless picture
    # On the screen, left of the panel, the window shows the same pixels, and they changed.
    region = np.s_[:SIZE[1], :panel_left]
    np.testing.assert_array_equal(after[region], headless[region][..., :3])
    assert not np.array_equal(before[region], after[region])


def test_the_copied_set_line_renders_the_window_picture_pixel_for_pixel(window_env: str, tmp_path: Path,
                                                                       gl) -> None:
    win = PanelWindow(window_env, tmp_path, "lessons.indexed_cube", "--set", "flip=front")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.click("Time & camera")
        win.click("pause")  # the line carries the time of the frame it describes
        for key in ("a", "w", "Left", "Up", "x"):  # turn, move, orbit, lower: a camera no lesson has
            win.key(key)
        time.sleep(0.3)
        win.click("copy --set line")
        shot = win.shot()
    finally:
        code = win.close()
    assert code == 0
    lines = [ln for ln in win.proc.stderr.read().splitlines() if ln.startswith("set line: ")]
    assert lines, "the copy button printed no line"
    args = shlex.split(lines[-1].removeprefix("set line: "))
    settings = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    assert any(s.startswith("camera=") for s in settings) and "flip=front" in settings
    assert any(s.startswith("time=") for s in settings)
    size = parse_size(args[args.index("--size") + 1])
    headless = gl.render(find_lesson("indexed_cube").from_settings(settings), size).image
    np.testing.assert_array_equal(shot, headless)
    # and the camera moved: the lesson's own camera draws another picture
    plain = gl.render(find_lesson("indexed_cube").from_settings([s for s in settings if not s.startswith("camera=")]),
                      size).image
    assert not np.array_equal(shot, plain)


def test_f1_hides_the_panel_and_the_screen_then_shows_the_frame(window_env: str, tmp_path: Path, gl) -> None:
    # Under load a fixed sleep after a key may grab the screen before the window has drawn
    # the next frame: each grab waits instead for the state it expects (the frame, or
    # anything else with the panel), failing only if it never comes.
    headless = gl.render(find_lesson("triangle")(), SIZE).image[..., :3]
    win = PanelWindow(window_env, tmp_path, "lessons.triangle")

    def grab():
        return np.ascontiguousarray(win.screen()[:SIZE[1], :SIZE[0]])

    try:
        win.wait_title(lambda t: "fps" in t)
        shown = win._wait(lambda: (g := grab()) is not None and not np.array_equal(g, headless) and [g])[0]
        win.key("F1")
        hidden = win._wait(lambda: (g := grab()) is not None and np.array_equal(g, headless) and [g])[0]
        win.key("F1")
        again = win._wait(lambda: (g := grab()) is not None and not np.array_equal(g, headless) and [g])[0]
    finally:
        code = win.close()
    assert code == 0
    np.testing.assert_array_equal(hidden, headless)
    assert not np.array_equal(shown, headless)  # the panel was over the frame
    np.testing.assert_array_equal(again, shown)


def test_live_compare_splits_the_window_into_the_compare_tiles(window_env: str, tmp_path: Path, gl) -> None:
    win = PanelWindow(window_env, tmp_path, "lessons.phong", "--set", "speed=0")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.click("Compare")
        win.click("split into tiles")  # the lesson's first parameter, shading, with all its choices
        tiles = win.shot()
        win.click("difference view")
        difference = win.shot()
    finally:
        code = win.close()
    assert code == 0
    variants, columns = build_variants(find_lesson("phong"), ["shading=phong,gouraud,blinn_phong"], ["speed=0"])
    result = compare_variants(variants, columns, SIZE, gl)
    np.testing.assert_array_equal(tiles, result.image)  # the same tiles and labels as glsandbox compare
    a, b = (gl.render_scene(replace(v.scene, overlays=()), SIZE).image for v in variants[:2])
    expected = difference_image(a, b)
    np.testing.assert_array_equal(difference[:-40], expected[:-40])  # above the label at the bottom
    assert difference[:-40, ..., :3].any()  # phong and gouraud differ somewhere


def _bench(display: str, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "DISPLAY": display, "WAYLAND_DISPLAY": "", "GLSANDBOX_BACKEND": "egl"}
    return subprocess.run([sys.executable, "-m", "glsandbox.cli", "bench", "--quick", "--only", "panel", *args],
                          capture_output=True, text=True, timeout=300, env=env, cwd=REPO)


def test_the_panel_bench_row_times_a_window_frame_with_and_without_the_panel(window_env: str,
                                                                           tmp_path: Path) -> None:
    out = tmp_path / "bench.json"
    proc = _bench(window_env, "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    (case,) = json.loads(out.read_text())["cases"]
    assert case["group"] == "window" and case["goal"] == 1.15
    assert case["baseline"] == "window frame, no panel" and case["subject"] == "window frame + panel"
    assert case["ratio"] > 0.5  # drawing more never takes much less time; the figure itself is printed, not asserted


def test_the_panel_bench_row_without_a_display_says_why_in_one_line() -> None:
    proc = _bench("")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "error: --only panel: no benchmark case matched (see glsandbox bench); skipped: panel (window frame with "
        "the live controls): no display; run under Xvfb, e.g. xvfb-run glsandbox bench --only panel"]


def test_a_scene_files_shader_uniforms_get_sliders_that_redraw_the_frame(window_env: str, tmp_path: Path,
                                                                         gl) -> None:
    """``glsandbox run scene.toml``: the shader's [nodes.uniforms] are widgets of their kinds; the
    gain slider, pressed and held, redraws the frame with the new value, and the copied --set line
    (``u.gain=...``) renders it headless pixel for pixel."""
    from support import write_uniform_scene

    from glsandbox.lesson import scene_file_lesson

    scene = write_uniform_scene(tmp_path)
    win = PanelWindow(window_env, tmp_path, "glsandbox.cli", "run", str(scene))
    try:
        win.wait_title(lambda t: "fps" in t)
        items = win._wait(lambda: (found := win.items()) and "u.gain" in found and found)
        before = win.shot()
        win.hold("u.gain")  # on the slider, left of its label: somewhere in its range, -2..2
        after = win.shot()
        win.click("Time & camera")
        win.click("copy --set line")
    finally:
        code = win.close()
    assert code == 0
    assert {"u.gain", "u.base_color", "u.offset", "u.flat_look"} <= set(items)
    assert not np.array_equal(before, after)
    lines = [ln for ln in win.proc.stderr.read().splitlines() if ln.startswith("set line: ")]
    args = shlex.split(lines[-1].removeprefix("set line: "))
    settings = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    gain = [s for s in settings if s.startswith("u.gain=")]
    assert gain and float(gain[0].split("=")[1]) != 0.5, settings
    headless = gl.render(scene_file_lesson(scene).from_settings(settings), SIZE).image
    np.testing.assert_array_equal(after, headless)
    np.testing.assert_array_equal(before, gl.render(scene_file_lesson(scene)(), SIZE).image)
