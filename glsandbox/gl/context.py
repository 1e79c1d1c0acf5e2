"""OpenGL contexts: headless (EGL, OSMesa, or moderngl's standalone WGL/CGL) or a glfw window.

This is the course's "device, context, swap chain" step. ``auto`` opens a
window when one is asked for (glfw says, in one line, when it cannot);
otherwise it tries the headless backends that exist on this system, in
order (:func:`headless_order`): EGL then OSMesa on Linux, moderngl's own
standalone context on Windows (WGL) and macOS (CGL), where there is no EGL
or OSMesa. The backend comes from ``--backend`` or the ``GLSANDBOX_BACKEND``
variable. Every backend asks for OpenGL 3.3 core, which macOS's 4.1 core
profile gives.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.gl.rawgl import RawGL

BACKENDS = ("auto", "egl", "osmesa", "standalone", "window")
#: OpenGL 3.3 core is all the lessons need; llvmpipe gives 4.5, macOS 4.1.
REQUIRED_GL = 330


def headless_order(platform: str | None = None) -> tuple[str, ...]:
    """The headless backends ``auto`` tries on ``platform`` (default ``sys.platform``), in order.

    Windows and macOS have neither EGL nor OSMesa as system libraries, but
    moderngl's standalone context (WGL, CGL) needs no display there. On
    Linux that standalone context is GLX, which needs an X server, so EGL
    (no display at all) comes first and Mesa's OSMesa is the fallback.
    """
    platform = sys.platform if platform is None else platform
    if platform.startswith(("win32", "cygwin", "darwin")):
        return ("standalone",)
    return ("egl", "osmesa")


@dataclass
class GLHost:
    """A live context: moderngl's handle, how it was made, and its raw-GL loader."""

    ctx: moderngl.Context
    backend: str
    get_proc: Callable[[str], int]
    window: Any = None  # the glfw window, for the window backend
    _on_release: Callable[[], None] | None = None
    _make_current: Callable[[], None] | None = None
    raw: RawGL = field(init=False)

    def __post_init__(self) -> None:
        self.raw = RawGL(self.get_proc)
        self.raw.disable_dither()

    def make_current(self) -> None:
        """Make this context current on this thread.

        Needed when a process holds several contexts: opening the second one
        makes it current, and GL calls for the first would go to the wrong
        context (or crash). Cheap enough to call once per frame.
        """
        if self._make_current is not None:
            self._make_current()

    @property
    def renderer(self) -> str:
        return f"{self.ctx.info['GL_RENDERER']} / {self.ctx.info['GL_VERSION']}"

    def release(self) -> None:
        """Free the context (and close the window)."""
        try:
            self.ctx.release()
        finally:
            if self._on_release is not None:
                self._on_release()
                self._on_release = None


def requested_backend(backend: str | None) -> str:
    """The backend asked for: the argument, else ``GLSANDBOX_BACKEND``, else auto."""
    name = backend or os.environ.get("GLSANDBOX_BACKEND") or "auto"
    name = name.strip().lower()
    if name not in BACKENDS:
        source = "--backend" if backend else "GLSANDBOX_BACKEND"
        raise SandboxError(f"unknown backend {name!r} (from {source}); choose one of {', '.join(BACKENDS)}")
    return name


def headless_instead(platform: str | None = None) -> str:
    """What errors offer when no window can open, for a frame rendered offscreen
    (``glsandbox render`` with ``--backend window``): this system's headless backends."""
    first, *rest = headless_order(platform)
    return f"or use a headless backend: --backend {first}" + "".join(f" (or {name})" for name in rest)


def open_context(backend: str | None = None, *, window: bool = False, size: tuple[int, int] = (640, 480),
                 title: str = "glsandbox", samples: int = 0, instead: str | None = None) -> GLHost:
    """Open a context. ``window=True`` asks for an on-screen window.

    With ``auto``, a window is opened by glfw when one is asked for (no
    environment variable is checked first: glfw knows the system's
    displays; its own reason is the error when it cannot). Otherwise the
    headless backends of :func:`headless_order` are tried in turn. Errors say
    what is missing and how to install it; ``instead`` is the alternative
    they offer when no window can open (the command's own: ``glsandbox
    render``, ``--headless``), by default :func:`headless_instead`.
    """
    instead = instead or headless_instead()
    name = requested_backend(backend)
    if name == "window" or (name == "auto" and window):
        return _open_window(size, title, samples, instead)
    if window:
        raise SandboxError(f"backend {name!r} is headless and cannot open a window; use --backend window, {instead}")
    if name != "auto":
        return HEADLESS_OPENERS[name]()
    errors = []
    for candidate in headless_order():
        try:
            return HEADLESS_OPENERS[candidate]()
        except SandboxError as exc:
            errors.append(str(exc))
    raise SandboxError(f"no OpenGL available: {'; '.join(errors)}")


def _standalone_hint(platform: str | None = None) -> str:
    platform = sys.platform if platform is None else platform
    if platform.startswith(("win32", "cygwin")):
        return "update the graphics driver (OpenGL 3.3 is needed; a remote desktop session may offer only 1.1)"
    if platform.startswith("darwin"):
        return "macOS 10.9 or later gives OpenGL 4.1 core"
    return "on Linux it is GLX and needs an X display: use --backend egl or osmesa"


def _open_standalone() -> GLHost:
    """moderngl's own standalone context: WGL on Windows, CGL on macOS (GLX on Linux)."""
    try:
        ctx = moderngl.create_standalone_context(require=REQUIRED_GL)
    except Exception as exc:  # glcontext raises plain Exceptions with the reason
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SandboxError(f"standalone backend unavailable ({reason}); {_standalone_hint()}") from None
    loader = ctx.mglo._context  # glcontext's context: it resolves any GL entry point, as for EGL
    return GLHost(ctx, "standalone", loader.load, _make_current=loader.__enter__)


def _open_egl() -> GLHost:
    try:
        ctx = moderngl.create_standalone_context(backend="egl", require=REQUIRED_GL)
    except Exception as exc:  # glcontext raises plain Exceptions with the reason
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SandboxError(
            f"EGL backend unavailable ({reason}); install EGL with: apt-get install libegl1 libegl-mesa0 "
            "libgl1-mesa-dri"
        ) from None
    loader = ctx.mglo._context  # glcontext's EGL context: it resolves any GL entry point
    # Entering glcontext's context calls eglMakeCurrent (it also remembers the
    # previous one, which we never restore: this context stays current).
    return GLHost(ctx, "egl", loader.load, _make_current=loader.__enter__)


def _open_osmesa() -> GLHost:
    from glsandbox.gl.osmesa import OSMesaContext

    osmesa = OSMesaContext()
    try:
        moderngl.init_context(osmesa)
        ctx = moderngl.get_context()
    except Exception as exc:
        osmesa.release()
        raise SandboxError(f"OSMesa backend unavailable: {' '.join(str(exc).split())}") from None
    if ctx.version_code < REQUIRED_GL:
        raise SandboxError(f"OSMesa gave OpenGL {ctx.version_code}, need {REQUIRED_GL}")
    return GLHost(ctx, "osmesa", osmesa.load_opengl_function, _on_release=osmesa.release,
                  _make_current=osmesa.make_current)


def _glfw_reason(exc: Exception) -> str:
    """pyGLFW's ``GLFWError`` text, ``(65550) b'X11: Failed to open display :77'``, as ``X11: Failed ...``."""
    text = " ".join(str(exc).split())
    m = re.fullmatch(r"\(\d+\)\s*b?(['\"])(.*)\1", text)
    return m.group(2) if m else text


def _open_window(size: tuple[int, int], title: str, samples: int, instead: str) -> GLHost:
    try:
        import glfw
    except Exception as exc:  # the wheel bundles libglfw, but it needs X11 libraries
        raise SandboxError(f"glfw is unavailable ({exc}); apt-get install libx11-6 libxrandr2 libxinerama1 "
                           "libxcursor1 libxi6") from None
    # pyGLFW reports GLFW's errors as Python warnings by default (a second line on
    # stderr before ours): while the window is set up they are raised instead,
    # and each becomes the reason in one error line.
    reporting = glfw.ERROR_REPORTING
    glfw.ERROR_REPORTING = "raise"
    try:
        return _glfw_window(glfw, size, title, samples)
    except glfw.GLFWError as exc:
        glfw.ERROR_REPORTING = "ignore"
        glfw.terminate()  # whatever the failed set-up opened (a no-op before glfw.init)
        raise SandboxError(_no_window_message(_glfw_reason(exc), instead)) from None
    finally:
        glfw.ERROR_REPORTING = reporting


def _no_window_message(reason: str, instead: str) -> str:
    """One line for a window glfw could not open: its reason, and what to do on this system."""
    display = os.environ.get("DISPLAY")
    where = f" on display {display!r}" if display else ""
    if sys.platform.startswith(("win32", "cygwin", "darwin")):
        return f"no display for a window: glfw could not open one ({reason}), {instead}"
    return (f"no display for a window: glfw could not open one{where} ({reason}): start an X server"
            f"{' there' if display else ''} or run under Xvfb (apt-get install xvfb; xvfb-run -a ...), {instead}")


def window_unavailable() -> str | None:
    """Why glfw cannot open a window here (its reason, one line), or None when it can.

    Asks glfw itself (it initialises and terminates), for callers that want
    to skip window work up front rather than fail in the middle of it.
    """
    import glfw

    reporting = glfw.ERROR_REPORTING
    glfw.ERROR_REPORTING = "raise"
    try:
        if not glfw.init():
            return "glfw could not initialise"
        return None
    except glfw.GLFWError as exc:
        return _glfw_reason(exc)
    finally:
        glfw.ERROR_REPORTING = "ignore"
        glfw.terminate()
        glfw.ERROR_REPORTING = reporting


def _glfw_window(glfw: Any, size: tuple[int, int], title: str, samples: int) -> GLHost:
    """The window and its context, once glfw is imported (its errors raise ``GLFWError``)."""
    if not glfw.init():
        raise SandboxError(_no_window_message("glfw could not initialise", headless_instead()))
    glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
    glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
    glfw.window_hint(glfw.DEPTH_BITS, 24)
    glfw.window_hint(glfw.STENCIL_BITS, 8)
    glfw.window_hint(glfw.SAMPLES, samples if samples > 1 else 0)
    glfw.window_hint(glfw.RESIZABLE, True)
    handle = glfw.create_window(size[0], size[1], title, None, None)
    if not handle:
        glfw.terminate()
        raise SandboxError("glfw could not create an OpenGL 3.3 core window on this display")
    glfw.make_context_current(handle)
    glfw.swap_interval(0)
    try:
        ctx = moderngl.create_context(require=REQUIRED_GL)
    except Exception as exc:
        glfw.destroy_window(handle)
        glfw.terminate()
        raise SandboxError(f"window context unusable: {' '.join(str(exc).split())}") from None

    def close() -> None:
        glfw.destroy_window(handle)
        glfw.terminate()

    def get_proc(name: str) -> int:
        return glfw.get_proc_address(name) or 0

    return GLHost(ctx, "window", get_proc, window=handle, _on_release=close,
                  _make_current=lambda: glfw.make_context_current(handle))


#: The headless backends by name (tests replace them with fakes).
HEADLESS_OPENERS: dict[str, Callable[[], GLHost]] = {
    "egl": _open_egl, "osmesa": _open_osmesa, "standalone": _open_standalone,
}
