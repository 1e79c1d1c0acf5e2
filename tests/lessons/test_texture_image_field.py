"""The texture lesson's image field: a refused path is one line, and in the window it stays red.

Typing a bad image path into the panel closed the window with exit 2; the
The manual promised the refusal in red, as the model lesson's mesh field does.
"""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from support import LessonWindow, need, run_cli

from glsandbox import SandboxError
from glsandbox.app.controls import parse_value
from glsandbox.files import save_png
from glsandbox.lesson import find_lesson


def image_param(name: str = "image"):
    return next(p for p in find_lesson("texture").all_params() if p.name == name)


def test_the_image_is_checked_when_it_is_given(tmp_path: Path) -> None:
    picture = tmp_path / "mine.png"
    save_png(np.full((4, 4, 4), 200, dtype=np.uint8), picture)
    assert parse_value(image_param(), str(picture)) == str(picture)
    assert parse_value(image_param("ground"), "labels") == "labels"
    for text, said in (("missing.png", "texture file missing.png not found"),
                       (str(tmp_path), "is a folder"),
                       (__file__, "is not an image Pillow can read")):
        with pytest.raises(SandboxError) as excinfo:
            parse_value(image_param(), text)
        message = str(excinfo.value)
        assert message.startswith(f"panel image={text}: ") and said in message, message


def test_render_refuses_a_bad_image_in_one_line(tmp_path: Path, gl) -> None:
    run = run_cli("render", "texture", "--set", "ground=nope.jpg", "--size", "32x24", "--out",
                  str(tmp_path / "out.png"), unchanged=tmp_path)
    assert run.returncode == 2 and run.stderr == "error: --set ground=nope.jpg: texture file nope.jpg not found\n"


# --- in the window (Xvfb, xdotool) ----------------------------------------------

SIZE = (640, 480)

OWN_LESSON = '''
from glsandbox import Lesson, Material, Node, Param, Scene, Texture, geometry


class Pictured(Lesson):
    """An image parameter checked only when drawn: the window keeps the last good frame."""
    params = (Param("image", "checker", "an image file or a built-in name"),)

    def build(self):
        texture = Texture(str(self.values["image"]))
        return Scene("pictured", nodes=(Node("cube", geometry.cube24(), material=Material(texture=texture)),))
'''


class Window(LessonWindow):
    """``glsandbox run ARGS`` on the test's X server, its panel's widget boxes in a file."""

    def __init__(self, display: str, cwd: Path, *args: str) -> None:
        self.layout = cwd / "layout.json"
        super().__init__(display, cwd, "glsandbox.cli", "run", *args, "--size", f"{SIZE[0]}x{SIZE[1]}",
                         env={"GLSANDBOX_PANEL_LAYOUT": str(self.layout)})

    def type_into(self, label: str, text: str) -> None:
        """Click the panel's text field ``label``, replace its text with ``text``, press Enter."""
        def box():
            return self.layout.exists() and json.loads(self.layout.read_text() or "{}").get("items", {}).get(label)

        x0, y0, x1, y1 = self._wait(box)
        self._xdotool("mousemove", "--sync", str(int((x0 + x1) / 2)), str(int((y0 + y1) / 2)))
        self._xdotool("click", "1")
        time.sleep(0.3)
        self._xdotool("key", "ctrl+a")
        self._xdotool("type", "--delay", "20", text)
        self._xdotool("key", "Return")
        time.sleep(1.0)  # a few frames

    def finish(self) -> tuple[int, str]:
        """ESC; the exit code and everything the window wrote on stderr."""
        code = self.close()
        return code, self.proc.stderr.read()


@pytest.fixture
def display(xvfb_display: str) -> str:
    if shutil.which("xdotool") is None:
        need("xdotool", "not installed (apt-get install xdotool)")
    return xvfb_display


@pytest.mark.slow
def test_a_refused_path_in_the_panel_keeps_the_window(display: str, tmp_path: Path) -> None:
    win = Window(display, tmp_path, "texture", "--set", "speed=0")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.type_into("image", "missing.png")
        assert win.proc.poll() is None  # still open
        assert "error" not in win.title()  # the lesson keeps drawing its last good value
    finally:
        code, err = win.finish()
    assert code == 0, err
    assert "error: panel image=missing.png: texture file missing.png not found" in err.splitlines()


@pytest.mark.slow
def test_a_value_only_drawing_refuses_keeps_the_last_good_frame(display: str, tmp_path: Path) -> None:
    """A lesson of one's own whose parameter is checked only when the texture loads: the
    window draws the last good frame, the error in its title and on stderr, until a good value."""
    (tmp_path / "pictured.py").write_text(OWN_LESSON)
    win = Window(display, tmp_path, "pictured.py")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.type_into("image", "missing.png")
        title = win.wait_title(lambda t: "lesson error" in t)
        assert "texture file missing.png not found" in title and win.proc.poll() is None
        win.type_into("image", "labels")
        win.wait_title(lambda t: "error" not in t)
    finally:
        code, err = win.finish()
    assert code == 0, err
    assert err.count("error: texture file missing.png not found") == 1  # said once, not every frame
