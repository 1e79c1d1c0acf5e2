"""F2 in the window prints the story of the pixel under the mouse cursor."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import LessonWindow

pytestmark = pytest.mark.slow  # windows under Xvfb


@pytest.mark.parametrize("lesson,expected", [("ray_spheres", "Nearest hit (min_indis): big"),
                                             ("mirror", "mark mirror viewport 0")])
def test_f2_tells_the_pixel_under_the_cursor(window_env: str, tmp_path: Path, lesson: str, expected: str) -> None:
    win = LessonWindow(window_env, tmp_path, f"lessons.{lesson}", "--size", "320x240")
    try:
        win.wait_title(lambda t: "fps" in t)
        win._xdotool("mousemove", "--window", win.window, "160", "120")
        win.key("F2")
    finally:
        code = win.close()  # Escape comes after F2: the frame that handles F2 prints the story first
    assert code == 0
    stdout = win.proc.stdout.read()
    assert f"{lesson}: pixel 160,120 of 320x240" in stdout, (stdout, win.proc.stderr.read())
    assert expected in stdout
