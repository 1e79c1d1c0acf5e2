"""Helpers for the hand-written raw-ModernGL baselines: matrices by hand, a
framebuffer, a read-back. No glsandbox code: the baselines must show what a
frame costs without the framework. (Mesh and image *data* may come from
glsandbox.geometry / glsandbox.images: they are arrays, uploaded once.)"""

from __future__ import annotations

import ctypes
from types import SimpleNamespace

import moderngl
import numpy as np


#: Per-vertex colours, interpolated (the course's Tutorial 04 cube); the same transform as glsandbox's.
VERTEX_COLOR_VS = """#version 330 core
uniform mat4 m_model; uniform mat4 m_view; uniform mat4 m_proj;
in vec3 in_position; in vec3 in_color; out vec3 v_color;
void main() { gl_Position = m_proj * m_view * m_model * vec4(in_position, 1.0); v_color = in_color; }
"""
VERTEX_COLOR_FS = """#version 330 core
in vec3 v_color; out vec4 frag_color;
void main() { frag_color = vec4(v_color, 1.0); }
"""


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """gluLookAt: the camera at ``eye`` looking at ``target`` (column vectors)."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    fwd = target - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, fwd)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, true_up, -fwd
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    """gluPerspective (clip depth -1..1)."""
    f = 1.0 / np.tan(np.radians(fov_y) / 2.0)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])


def reverse_z(proj: np.ndarray) -> np.ndarray:
    """The projection for reverse-Z: clip z' = (w - z) / 2 puts near at 1 and far at 0 (kept by glClipControl 0..1)."""
    remap = np.eye(4)
    remap[2, 2:] = (-0.5, 0.5)
    return remap @ proj


def rotate_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def rotate_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def rotate_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])


def translate(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def eye_relative(view: np.ndarray, eye) -> np.ndarray:
    """``view @ T(eye)``: the view for positions relative to the eye (glsandbox's camera-relative
    raster, docs/numerics.md); models go with :func:`from_eye`."""
    return view @ translate(*eye)


def from_eye(model: np.ndarray, eye) -> np.ndarray:
    """``T(-eye) @ model`` in float64: the model matrix relative to the eye."""
    return translate(*(-np.asarray(eye, dtype=np.float64))) @ model


def scale(x: float, y: float, z: float) -> np.ndarray:
    return np.diag([x, y, z, 1.0])


def gl(m: np.ndarray) -> bytes:
    """A matrix as GLSL expects it (column-major float32)."""
    return np.asarray(m, dtype="f4").T.tobytes()


#: Frames are opaque, as glsandbox's (its ``glsandbox.gl.target.FRAME_COLOR_MASK``): every clear writes
#: alpha 1 and the draws never write alpha, so translucent draws leave the frame opaque.
COLOR_MASK = (True, True, True, False)
#: Every channel: the mask a clear is made with (see :func:`clear`).
ALL_CHANNELS = (True, True, True, True)


def clear(fbo: moderngl.Framebuffer, red: float, green: float, blue: float, depth: float = 1.0,
          viewport: tuple[int, int, int, int] | None = None) -> None:
    """Clear the way the fastest correct raw program does: every channel, alpha 1, then the RGB
    mask for the draws. A clear under a partial colour mask is no plain clear on llvmpipe (it
    reads and writes every pixel: +0.5 ms at 800x600, +2 ms at 1080p); with alpha 1 written the
    picture is the same. moderngl applies a framebuffer's ``color_mask`` at its ``clear()`` and
    ``use()`` only, so the framebuffer is bound again after the clear (as glColorMask would do)."""
    fbo.color_mask = ALL_CHANNELS
    fbo.clear(red, green, blue, 1.0, depth=depth, viewport=viewport)
    fbo.color_mask = COLOR_MASK
    fbo.use()


def opaque(fbo: moderngl.Framebuffer) -> moderngl.Framebuffer:
    """The framebuffer cleared to opaque black, with alpha writes off for the draws (:func:`clear`)."""
    clear(fbo, 0.0, 0.0, 0.0)
    return fbo


def framebuffer(ctx: moderngl.Context, size: tuple[int, int], depth: bool = True) -> moderngl.Framebuffer:
    return opaque(ctx.framebuffer(color_attachments=[ctx.renderbuffer(size, 4)],
                                  depth_attachment=ctx.depth_renderbuffer(size) if depth else None))


def read(fbo: moderngl.Framebuffer, size: tuple[int, int]) -> np.ndarray:
    """The frame as (H, W, 4) uint8, top row first (a view, no copy)."""
    return np.frombuffer(fbo.read(components=4, alignment=1), dtype=np.uint8).reshape(size[1], size[0], 4)[::-1]


# --- the GL calls moderngl 5.13 lacks: stencil state, write masks, clip control, a depth-stencil buffer ---

GL_STENCIL_TEST, GL_STENCIL_BUFFER_BIT = 0x0B90, 0x0400
GL_ALWAYS, GL_EQUAL = 0x0207, 0x0202
GL_KEEP, GL_REPLACE, GL_INVERT = 0x1E00, 0x1E01, 0x150A
GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE, GL_ZERO_TO_ONE = 0x8CA1, 0x935E, 0x935F
_UINT, _INT, _BOOL = ctypes.c_uint, ctypes.c_int, ctypes.c_ubyte
_NAMES = ctypes.POINTER(_UINT)
#: C signatures (return type first) of the entry points the baselines call through ctypes.
_PROTOTYPES = {
    "glEnable": (None, _UINT), "glDisable": (None, _UINT), "glClear": (None, _UINT),
    "glStencilFunc": (None, _UINT, _INT, _UINT), "glStencilOp": (None, _UINT, _UINT, _UINT),
    "glStencilMask": (None, _UINT), "glClearStencil": (None, _INT), "glClearDepth": (None, ctypes.c_double),
    "glColorMask": (None, _BOOL, _BOOL, _BOOL, _BOOL), "glDepthMask": (None, _BOOL),
    "glClipControl": (None, _UINT, _UINT),
    "glGenFramebuffers": (None, _INT, _NAMES), "glBindFramebuffer": (None, _UINT, _UINT),
    "glGenRenderbuffers": (None, _INT, _NAMES), "glBindRenderbuffer": (None, _UINT, _UINT),
    "glRenderbufferStorage": (None, _UINT, _UINT, _INT, _INT),
    "glFramebufferRenderbuffer": (None, _UINT, _UINT, _UINT, _UINT), "glCheckFramebufferStatus": (_UINT, _UINT),
}


def gl_calls(ctx: moderngl.Context) -> SimpleNamespace:
    """The entry points of ``_PROTOTYPES`` as ctypes functions, from the context's own loader
    (glcontext's EGL and glsandbox's OSMesa context both resolve names with ``load``):
    ``gl.StencilFunc(...)`` calls ``glStencilFunc``."""
    load = ctx.mglo._context.load
    calls = {}
    for name, (restype, *argtypes) in _PROTOTYPES.items():
        address = load(name)
        if not address:
            raise RuntimeError(f"{name} is not available from this context")
        calls[name[2:]] = ctypes.CFUNCTYPE(restype, *argtypes)(address)
    return SimpleNamespace(**calls)


def depth_stencil_framebuffer(ctx: moderngl.Context, gl: SimpleNamespace,
                              size: tuple[int, int]) -> moderngl.Framebuffer:
    """RGBA8 colour and a 32-bit float depth + 8-bit stencil renderbuffer (moderngl's are depth-only)."""
    framebuffer, depth_stencil = _UINT(0), _UINT(0)
    color = ctx.renderbuffer(size, 4)
    gl.GenFramebuffers(1, ctypes.byref(framebuffer))
    gl.GenRenderbuffers(1, ctypes.byref(depth_stencil))
    gl.BindFramebuffer(0x8D40, framebuffer.value)  # GL_FRAMEBUFFER
    gl.BindRenderbuffer(0x8D41, depth_stencil.value)  # GL_RENDERBUFFER
    gl.RenderbufferStorage(0x8D41, 0x8CAD, *size)  # GL_DEPTH32F_STENCIL8
    gl.FramebufferRenderbuffer(0x8D40, 0x8CE0, 0x8D41, color.glo)  # GL_COLOR_ATTACHMENT0
    gl.FramebufferRenderbuffer(0x8D40, 0x821A, 0x8D41, depth_stencil.value)  # GL_DEPTH_STENCIL_ATTACHMENT
    complete = gl.CheckFramebufferStatus(0x8D40) == 0x8CD5  # GL_FRAMEBUFFER_COMPLETE
    gl.BindRenderbuffer(0x8D41, 0)
    gl.BindFramebuffer(0x8D40, 0)
    if not complete:
        raise RuntimeError(f"depth-stencil framebuffer {size} is incomplete")
    fbo = ctx.detect_framebuffer(framebuffer.value)
    fbo.extra = color  # keep the colour renderbuffer with the framebuffer
    return opaque(fbo)
