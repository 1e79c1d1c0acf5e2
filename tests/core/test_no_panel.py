"""The panel is the optional ``panel`` extra: without imgui-bundle the window works and F1 says how to get it."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from glsandbox import panel

REPO = Path(__file__).resolve().parents[2]
#: Run the glsandbox command with imgui_bundle unimportable, as where the extra is not installed.
WITHOUT_IMGUI = "import sys; sys.modules['imgui_bundle'] = None; from glsandbox.cli import main; sys.exit(main(sys.argv[1:]))"


def test_without_imgui_bundle_the_window_gets_a_stand_in(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "imgui_bundle", None)  # `import imgui_bundle` raises ImportError
    assert not panel.panel_available()
    stand_in = panel.open_panel(window=None)
    assert isinstance(stand_in, panel.NoPanel) and not stand_in.visible
    assert stand_in.draw(session=None) is None and stand_in.close() is None


def test_f1_without_the_panel_is_one_line_saying_how_to_install_it(capsys) -> None:
    panel.NoPanel().toggle()
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.splitlines() == [f"note: {panel.INSTALL_HINT}"]
    assert 'pip install "glsandbox[panel]"' in captured.err and "uv sync --extra panel" in captured.err


def test_the_panel_is_an_extra_not_a_dependency() -> None:
    import tomllib

    project = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert not any(dep.startswith("imgui-bundle") for dep in project["project"]["dependencies"])
    (floor,) = project["project"]["optional-dependencies"]["panel"]
    assert floor.startswith("imgui-bundle>=")
    assert floor in project["dependency-groups"]["dev"]  # `uv run pytest` tests the panel


def _xdotool(env: dict, *args: str) -> str:
    return subprocess.run(["xdotool", *args], capture_output=True, text=True, env=env, timeout=20).stdout.strip()


@pytest.mark.slow
def test_a_window_without_imgui_bundle_runs_and_f1_explains(xvfb_display) -> None:
    env = {**os.environ, "DISPLAY": xvfb_display, "WAYLAND_DISPLAY": "", "GLSANDBOX_BACKEND": ""}
    proc = subprocess.Popen([sys.executable, "-c", WITHOUT_IMGUI, "run", "triangle", "--size", "160x120"],
                            cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        window = ""
        deadline = time.monotonic() + 60
        while not window and time.monotonic() < deadline and proc.poll() is None:
            window = _xdotool(env, "search", "--name", "glsandbox: triangle").split("\n")[0]
            time.sleep(0.1)
        assert window, f"no window: {proc.poll()} {proc.stderr.read() if proc.poll() is not None else ''}"
        _xdotool(env, "windowfocus", "--sync", window)
        _xdotool(env, "key", "F1")
        time.sleep(0.5)
        _xdotool(env, "windowfocus", "--sync", window)
        _xdotool(env, "key", "Escape")
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert err.splitlines() == [f"note: {panel.INSTALL_HINT}"]
