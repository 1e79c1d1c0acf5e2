"""The panel is the optional ``panel`` extra: without imgui-bundle the window works and F1 says how to get it."""

from __future__ import annotations

import sys
import time
import tomllib

import pytest
from support import REPO_ROOT, LessonWindow

from glsandbox.app import panel


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
    project = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())
    assert not any(dep.startswith("imgui-bundle") for dep in project["project"]["dependencies"])
    (floor,) = project["project"]["optional-dependencies"]["panel"]
    assert floor.startswith("imgui-bundle>=")
    assert floor in project["dependency-groups"]["dev"]  # `uv run pytest` tests the panel


@pytest.mark.slow
def test_a_window_without_imgui_bundle_runs_and_f1_explains(window_env, tmp_path) -> None:
    # imgui_bundle shadowed by a package that cannot be imported, as where the extra is not installed
    (tmp_path / "imgui_bundle").mkdir()
    (tmp_path / "imgui_bundle" / "__init__.py").write_text("raise ImportError('not installed (test)')\n")
    window = LessonWindow(window_env, REPO_ROOT, "glsandbox", "run", "triangle", "--size", "160x120",
                          env={"PYTHONPATH": str(tmp_path), "GLSANDBOX_BACKEND": ""})
    window.key("F1")
    time.sleep(0.5)  # a frame or two: the key is handled in the loop
    assert window.close() == 0
    err = window.proc.stderr.read()
    assert err.splitlines() == [f"note: {panel.INSTALL_HINT}"]
