"""Offscreen render targets: colour, and the depth and stencil a plan asks for.

A target is a framebuffer object whose colour is a moderngl renderbuffer and
whose depth (24 bits) or packed depth-stencil (24 + 8 bits) attachment comes
from :mod:`glsandbox.gl.rawgl`. With MSAA the frame is resolved into a
single-sample framebuffer before it is read back.

Frames are opaque: a target's alpha is 1 everywhere, as the
window shows the frame, so PNGs, goldens and the gallery keep what the
screen shows. The rule lives here, in :data:`FRAME_COLOR_MASK`.
"""

from __future__ import annotations

import moderngl
import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.gl.context import GLHost
from glsandbox.plan import Buffers

#: The colour write mask every frame is drawn with: red, green and blue, never
#: alpha. Every clear writes alpha 1 (:func:`clear_opaque`) and a target's
#: framebuffer carries this mask for the draws (moderngl applies a framebuffer's
#: ``color_mask`` at every ``use()`` and ``clear()``), so no pass touches the 1:
#: frames are opaque at no cost per frame. Blending reads the source's alpha only
#: (``SRC_ALPHA, ONE_MINUS_SRC_ALPHA``), never the frame's. A pass that sets the
#: mask itself puts this one back (:func:`glsandbox.gl.passes.restore_state`).
FRAME_COLOR_MASK = (True, True, True, False)
#: Every channel: the mask a clear is made with (:func:`clear_opaque`).
ALL_CHANNELS = (True, True, True, True)


def clear_opaque(framebuffer: moderngl.Framebuffer, rgb: tuple[float, float, float], depth: float,
                 viewport: tuple[int, int, int, int] | None = None) -> None:
    """Clear ``viewport`` (moderngl scissors to it) to ``rgb`` with alpha 1 and ``depth``, then put the
    framebuffer's own mask back for the draws.

    The clear writes every channel: under a partial mask llvmpipe cannot clear
    by filling, it reads and writes every pixel (+0.5 ms at 800x600, +2 ms at
    1080p). Alpha 1 is what the masked clear kept, so the picture is
    the same. moderngl applies a framebuffer's mask at its ``clear()`` and
    ``use()`` only (setting ``color_mask`` alone reaches no GL state), so the
    framebuffer is bound again after the clear (it is the bound one while a
    frame is drawn; its viewport is set before each pass draws).
    """
    mask = framebuffer.color_mask
    every = ALL_CHANNELS if not isinstance(mask[0], tuple) else (ALL_CHANNELS,) * len(mask)  # (an X-ray's 2 attachments)
    if mask == every:
        framebuffer.clear(*rgb, 1.0, depth=depth, viewport=viewport)
        return
    framebuffer.color_mask = every
    framebuffer.clear(*rgb, 1.0, depth=depth, viewport=viewport)
    framebuffer.color_mask = mask
    framebuffer.use()


class OffscreenTarget:
    """A framebuffer of ``size`` with the buffers the plan lists."""

    def __init__(self, host: GLHost, size: tuple[int, int], buffers: Buffers, primitive_ids: bool = False) -> None:
        ctx = host.ctx
        width, height = size
        limit = ctx.info["GL_MAX_RENDERBUFFER_SIZE"]
        if not (0 < width <= limit and 0 < height <= limit):
            raise SandboxError(f"size {width}x{height} is outside what this context allows (1..{limit})")
        if buffers.samples > ctx.max_samples:
            raise SandboxError(f"--samples {buffers.samples} is more than this context allows ({ctx.max_samples})")
        self.host = host
        self.size = size
        self.buffers = buffers
        samples = buffers.samples
        self._color = ctx.renderbuffer(size, 4, samples=samples)
        self._fbo_name, self._depth_name = host.raw.create_depth_framebuffer(
            self._color.glo, size, samples, stencil=buffers.stencil, depth=buffers.depth,
            float_depth=buffers.float_depth)
        # The X-ray's primitive ids (shaders/common/primitive_id.glsl): (node, triangle) as two
        # unsigned integers a pixel, colour attachment 1 (single-sample frames only).
        self._ids = ctx.renderbuffer(size, 2, dtype="u4") if primitive_ids and not samples else None
        if self._ids is not None:
            host.raw.attach_color(self._fbo_name, 1, self._ids.glo)
        self.framebuffer: moderngl.Framebuffer = ctx.detect_framebuffer(self._fbo_name)
        self._resolved: moderngl.Framebuffer | None = None
        if samples:
            self._resolved = ctx.framebuffer(color_attachments=[ctx.renderbuffer(size, 4)])
            self._resolved.clear(0.0, 0.0, 0.0, 1.0)  # the resolve copies alpha 1 here, or keeps this 1
        self.framebuffer.clear(0.0, 0.0, 0.0, 1.0)  # every sample: opaque before the first clear of a frame
        self.framebuffer.color_mask = FRAME_COLOR_MASK if self._ids is None else (FRAME_COLOR_MASK, ALL_CHANNELS)

    def bits(self) -> tuple[int, int]:
        """(depth bits, stencil bits) actually allocated."""
        return self.host.raw.attachment_bits(self._fbo_name)

    def resolved(self) -> moderngl.Framebuffer:
        """The single-sample framebuffer holding the frame (MSAA resolved into it first)."""
        if self._resolved is None:
            return self.framebuffer
        self.host.ctx.copy_framebuffer(self._resolved, self.framebuffer)
        return self._resolved

    def read(self) -> np.ndarray:
        """The frame as an (H, W, 4) uint8 RGBA array, top row first, alpha 255.

        The array is a read-only view of the bytes GL returned, flipped by a
        negative stride: copying a fresh 800x600 frame costs more than drawing
        it (page faults on new memory), so nothing is copied here.
        """
        data = self.resolved().read(components=4, alignment=1)
        return np.frombuffer(data, dtype=np.uint8).reshape(self.size[1], self.size[0], 4)[::-1]

    def read_ids(self) -> np.ndarray | None:
        """The primitive ids, (H, W, 2) uint32 (node number, triangle), top row first; None
        unless the target was made with them."""
        if self._ids is None:
            return None
        data = self.framebuffer.read(components=2, attachment=1, dtype="u4")
        return np.frombuffer(data, dtype=np.uint32).reshape(self.size[1], self.size[0], 2)[::-1]

    def release(self) -> None:
        # The framebuffer object is ours (rawgl made it); moderngl only wraps it.
        self.host.raw.delete_framebuffer(self._fbo_name, self._depth_name)
        self._color.release()
        if self._ids is not None:
            self._ids.release()
        if self._resolved is not None:
            for rb in self._resolved.color_attachments:
                rb.release()
            self._resolved.release()
