"""Benchmark: an empty frame in glsandbox's offscreen target versus a plain moderngl framebuffer.

Both sides clear colour and depth the way a frame starts (every channel, alpha 1, then the
RGB mask: ``_raw.clear``) and read the frame back, at the course's 800x600 and at 1080p.
The target is what every glsandbox frame is drawn into (``glsandbox.gl.target``): its
depth buffer comes through raw GL calls, the framebuffer's from moderngl. Goal:
the target costs what a framebuffer costs at every size (<= 1.05x).
"""

from __future__ import annotations

import numpy as np

from _raw import clear, read

SIZES = ((800, 600), (1920, 1080))
COLOR = (0.0, 0.125, 0.6)


class EmptyFrames:
    """Both sides at one size, made on the first frame (a run that leaves the row out makes nothing)."""

    def __init__(self, env, size: tuple[int, int]) -> None:
        self.env, self.size = env, size
        self.fbo = self.target = None

    def plain(self, k: int) -> np.ndarray:
        if self.fbo is None:
            ctx = self.env.renderer.host.ctx
            self.fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size, 4)],
                                       depth_attachment=ctx.depth_renderbuffer(self.size))
        self.fbo.use()
        clear(self.fbo, *COLOR)
        return read(self.fbo, self.size)

    def ours(self, k: int) -> np.ndarray:
        from glsandbox.gl.target import OffscreenTarget, clear_opaque
        from glsandbox.plan import Buffers

        if self.target is None:
            self.target = OffscreenTarget(self.env.renderer.host, self.size, Buffers(depth=True, stencil=False,
                                                                                     samples=0))
        self.target.framebuffer.use()
        clear_opaque(self.target.framebuffer, COLOR, 1.0)
        return self.target.read()


def cases(env) -> list:
    from glsandbox.measure.bench import LESSON_FRAME_GOAL, Case, Side, same_pixels

    found = []
    for size in SIZES:
        frames = EmptyFrames(env, size)
        found.append(Case("empty frame vs framebuffer", f"{size[0]}x{size[1]}", Side("moderngl framebuffer",
                          frames.plain), Side("offscreen target", frames.ours), repeat=20, goal=LESSON_FRAME_GOAL,
                          compare=same_pixels))
    return found
