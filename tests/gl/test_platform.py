"""Which context each system gets: the headless order per ``sys.platform`` (backends faked),
windows asked of glfw (no DISPLAY check first), and the standalone (WGL/CGL/GLX) backend for real."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import REPO_ROOT as REPO
from PIL import Image

from glsandbox.errors import SandboxError
from glsandbox.gl import context



class FakeHost:
    def __init__(self, backend: str) -> None:
        self.backend = backend


def fake_backends(monkeypatch: pytest.MonkeyPatch, working: set[str]) -> list[str]:
    """Replace every headless opener: the ``working`` ones give a host, the others fail. Returns the calls."""
    calls: list[str] = []

    def opener(name: str):
        def open_it() -> FakeHost:
            calls.append(name)
            if name not in working:
                raise SandboxError(f"{name} backend unavailable (faked)")
            return FakeHost(name)
        return open_it

    for name in list(context.HEADLESS_OPENERS):
        monkeypatch.setitem(context.HEADLESS_OPENERS, name, opener(name))
    monkeypatch.delenv("GLSANDBOX_BACKEND", raising=False)
    return calls


@pytest.mark.parametrize(("platform", "expected"), [
    ("linux", "egl"), ("win32", "standalone"), ("darwin", "standalone"), ("cygwin", "standalone"),
    ("freebsd14", "egl"),
])
def test_auto_opens_the_first_headless_backend_of_each_system(monkeypatch, platform, expected) -> None:
    calls = fake_backends(monkeypatch, working={"egl", "osmesa", "standalone"})
    monkeypatch.setattr(sys, "platform", platform)
    assert context.open_context().backend == expected
    assert calls == [expected]


def test_linux_falls_back_from_egl_to_osmesa_and_never_tries_the_glx_standalone(monkeypatch) -> None:
    calls = fake_backends(monkeypatch, working={"osmesa", "standalone"})
    monkeypatch.setattr(sys, "platform", "linux")
    assert context.open_context().backend == "osmesa"
    assert calls == ["egl", "osmesa"]


@pytest.mark.parametrize("platform", ["win32", "darwin"])
def test_windows_and_macos_never_try_egl_or_osmesa(monkeypatch, platform) -> None:
    calls = fake_backends(monkeypatch, working={"egl", "osmesa"})
    monkeypatch.setattr(sys, "platform", platform)
    with pytest.raises(SandboxError) as error:
        context.open_context()
    assert calls == ["standalone"]
    assert str(error.value) == "no OpenGL available: standalone backend unavailable (faked)"


def test_every_reason_is_in_the_one_error_when_nothing_opens(monkeypatch) -> None:
    fake_backends(monkeypatch, working=set())
    monkeypatch.setattr(sys, "platform", "linux")
    with pytest.raises(SandboxError) as error:
        context.open_context()
    assert str(error.value) == ("no OpenGL available: egl backend unavailable (faked); "
                                "osmesa backend unavailable (faked)")


@pytest.mark.parametrize("name", ["egl", "osmesa", "standalone"])
def test_a_named_backend_is_the_only_one_tried(monkeypatch, name) -> None:
    calls = fake_backends(monkeypatch, working={"egl", "osmesa", "standalone"})
    monkeypatch.setattr(sys, "platform", "darwin")  # the order of auto plays no part
    assert context.open_context(name).backend == name
    assert calls == [name]


def test_the_headless_hint_names_this_systems_backends() -> None:
    assert context.headless_instead("linux") == "or use a headless backend: --backend egl (or osmesa)"
    assert context.headless_instead("win32") == "or use a headless backend: --backend standalone"
    assert context.headless_instead("darwin") == "or use a headless backend: --backend standalone"


def test_a_window_is_asked_of_glfw_even_with_no_display_variable(monkeypatch) -> None:
    asked: list[tuple] = []

    def window(size, title, samples, instead):
        asked.append((size, title))
        return FakeHost("window")

    monkeypatch.setattr(context, "_open_window", window)
    fake_backends(monkeypatch, working={"egl"})
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert context.open_context(window=True, size=(32, 16), title="t").backend == "window"
    assert asked == [((32, 16), "t")]


def test_glfws_own_reason_is_the_one_line_error(monkeypatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(SandboxError) as error:
        context.open_context("window", window=True, instead="or render it headless")
    message = str(error.value)
    assert "\n" not in message
    assert message.startswith("no display for a window: glfw could not open one (")
    assert "DISPLAY" in message  # glfw's X11 reason: the variable is missing
    assert message.endswith("or render it headless")
    assert context.window_unavailable() is not None


@pytest.mark.parametrize("platform", ["win32", "darwin"])
def test_no_window_on_windows_or_macos_offers_no_linux_fix(monkeypatch, platform) -> None:
    monkeypatch.setattr(sys, "platform", platform)
    message = context._no_window_message("no monitor", context.headless_instead())
    assert message == ("no display for a window: glfw could not open one (no monitor), "
                       "or use a headless backend: --backend standalone")


@pytest.mark.parametrize(("platform", "hint"), [
    ("linux", "on Linux it is GLX and needs an X display: use --backend egl or osmesa"),
    ("win32", "update the graphics driver"), ("darwin", "macOS 10.9 or later gives OpenGL 4.1 core"),
])
def test_a_standalone_context_that_fails_is_one_line_with_this_systems_fix(monkeypatch, platform, hint) -> None:
    import moderngl

    def refuse(**kwargs):
        assert kwargs == {"require": context.REQUIRED_GL}  # OpenGL 3.3 core, as every backend asks
        raise Exception("(standalone) XOpenDisplay:\n cannot open display")

    monkeypatch.setattr(moderngl, "create_standalone_context", refuse)
    monkeypatch.setattr(sys, "platform", platform)
    with pytest.raises(SandboxError) as error:
        context.open_context("standalone")
    assert str(error.value).startswith("standalone backend unavailable ((standalone) XOpenDisplay: cannot open "
                                       "display); " + hint)


def _render(backend: str, out: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "glsandbox", "render", "phong", "--size", "96x64",
                           "--backend", backend, "--out", str(out)],
                          capture_output=True, text=True, timeout=120, env=env, cwd=REPO)


@pytest.mark.slow
def test_the_standalone_context_draws_the_same_pixels_as_egl(xvfb_display, tmp_path) -> None:
    # moderngl's standalone context is WGL on Windows and CGL on macOS; on Linux it is
    # GLX, which Xvfb serves with the same llvmpipe: the code path (its loader, made
    # current, raw GL for stencil) is the one Windows and macOS take.
    env = {**os.environ, "DISPLAY": xvfb_display, "WAYLAND_DISPLAY": ""}
    standalone, egl = tmp_path / "standalone.png", tmp_path / "egl.png"
    for backend, out in (("standalone", standalone), ("egl", egl)):
        proc = _render(backend, out, env)
        assert proc.returncode == 0, proc.stderr
    a, b = (np.asarray(Image.open(path)) for path in (standalone, egl))
    assert a[..., :3].any()
    np.testing.assert_array_equal(a, b)
