"""OpenGL contexts: headless EGL (default), headless OSMesa, or a glfw window.

This is the course's "device, context, swap chain" step. ``auto`` picks a
window when one is asked for and a display exists, else EGL, else OSMesa.
The backend comes from ``--backend`` or the ``GLSANDBOX_BACKEND`` variable.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.gl.rawgl import RawGL

BACKENDS = ("auto", "egl", "osmesa", "window")
#: OpenGL 3.3 core is all the lessons need; llvmpipe gives 4.5.
REQUIRED_GL = 330


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


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


#: What to do instead of a window, said by errors when none can open, for a
#: frame rendered offscreen (``glsandbox render`` with ``--backend window``).
HEADLESS_INSTEAD = "or use a headless backend: --backend egl (or osmesa)"


def open_context(backend: str | None = None, *, window: bool = False, size: tuple[int, int] = (640, 480),
                 title: str = "glsandbox", samples: int = 0, instead: str | None = None) -> GLHost:
    """Open a context. ``window=True`` asks for an on-screen window.

    With ``auto``, a window is used when asked for and a display exists;
    otherwise EGL, falling back to OSMesa. Errors say what is missing and
    how to install it; ``instead`` is the alternative they offer when no
    window can open (the command's own: ``glsandbox render``, ``--headless``),
    by default :data:`HEADLESS_INSTEAD`.
    """
    instead = instead or HEADLESS_INSTEAD
    name = requested_backend(backend)
    if name == "auto":
        if window and has_display():
            return _open_window(size, title, samples, instead)
        try:
            return _open_egl()
        except SandboxError as egl_error:
            try:
                return _open_osmesa()
            except SandboxError as osmesa_error:
                raise SandboxError(f"no OpenGL available: {egl_error}; {osmesa_error}") from None
    if name == "window":
        return _open_window(size, title, samples, instead)
    if window:
        raise SandboxError(f"backend {name!r} is headless and cannot open a window; use --backend window, {instead}")
    return _open_egl() if name == "egl" else _open_osmesa()


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
    if not has_display():
        raise SandboxError("no display for a window: set DISPLAY, or run under Xvfb "
                           f"(apt-get install xvfb; xvfb-run -a ...), {instead}")
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
        raise SandboxError(f"glfw could not open a window on display {os.environ.get('DISPLAY')!r} "
                           f"({_glfw_reason(exc)}): start an X server there or run under Xvfb, {instead}") from None
    finally:
        glfw.ERROR_REPORTING = reporting


def _glfw_window(glfw: Any, size: tuple[int, int], title: str, samples: int) -> GLHost:
    """The window and its context, once glfw is imported (its errors raise ``GLFWError``)."""
    if not glfw.init():
        raise SandboxError(f"glfw could not initialise on display {os.environ.get('DISPLAY')!r}; "
                           "is the X server running?")
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
