"""Helpers for the hand-written raw-ModernGL baselines: matrices by hand, a
framebuffer, a read-back. No glsandbox code: the baselines must show what a
frame costs without the framework. (Mesh and image *data* may come from
glsandbox.geometry / glsandbox.images: they are arrays, uploaded once.)"""

from __future__ import annotations

import moderngl
import numpy as np


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


def rotate_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])


def translate(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def scale(x: float, y: float, z: float) -> np.ndarray:
    return np.diag([x, y, z, 1.0])


def gl(m: np.ndarray) -> bytes:
    """A matrix as GLSL expects it (column-major float32)."""
    return np.asarray(m, dtype="f4").T.tobytes()


def framebuffer(ctx: moderngl.Context, size: tuple[int, int], depth: bool = True) -> moderngl.Framebuffer:
    return ctx.framebuffer(color_attachments=[ctx.renderbuffer(size, 4)],
                           depth_attachment=ctx.depth_renderbuffer(size) if depth else None)


def read(fbo: moderngl.Framebuffer, size: tuple[int, int]) -> np.ndarray:
    """The frame as (H, W, 4) uint8, top row first (a view, no copy)."""
    return np.frombuffer(fbo.read(components=4, alignment=1), dtype=np.uint8).reshape(size[1], size[0], 4)[::-1]
