"""Draws a scene's overlays: one textured rectangle per image, blended on top.

Run by :class:`~glsandbox.gl.executor.Executor` for the plan's ``overlay``
passes. Each image becomes a texture (kept per overlay name and updated when
its pixels change, so a label that changes every frame reuses one texture),
scaled to the region's size (:meth:`~glsandbox.overlay.Overlay.drawn_image`),
and is copied texel for pixel by ``shaders/overlay.glsl`` with straight-alpha
blending: ``rgb = a*src + (1-a)*dst``. The frame's alpha is not written
(:data:`glsandbox.gl.target.FRAME_COLOR_MASK`), so the frame stays opaque.
"""

from __future__ import annotations

import moderngl
import numpy as np

from glsandbox.overlay import Overlay
from glsandbox.plan import Pass
from glsandbox.scene import Scene


class OverlayDrawer:
    """Textures and the attribute-less vertex array for overlay passes."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        # name -> (texture, the image it holds: the array last drawn under that name)
        self._textures: dict[str, tuple[moderngl.Texture, np.ndarray]] = {}
        self._vao: tuple[int, moderngl.VertexArray] | None = None

    def _texture(self, overlay: Overlay, image: np.ndarray) -> moderngl.Texture:
        """The texture holding ``image``, the overlay's image as drawn (read-only)."""
        entry = self._textures.get(overlay.name)
        if entry is not None and entry[1] is image:
            return entry[0]  # the same array as last time (a panel made once): nothing to compare
        if entry is not None and entry[1].shape == image.shape and np.array_equal(entry[1], image):
            self._textures[overlay.name] = (entry[0], image)  # equal pixels in a new array: nothing to upload
            return entry[0]
        h, w = image.shape[:2]
        data = np.ascontiguousarray(image, dtype=np.uint8)
        if entry is not None and entry[0].size == (w, h):
            texture = entry[0]
            texture.write(data, alignment=1)  # a label whose text changes: the same texture, new texels
        else:
            if entry is not None:
                entry[0].release()
            texture = self.ctx.texture((w, h), 4, data, alignment=1)
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._textures[overlay.name] = (texture, image)
        return texture

    def _vertex_array(self, program: moderngl.Program) -> moderngl.VertexArray:
        if self._vao is None or self._vao[0] != program.glo:  # programs are rebuilt by shader reloads
            if self._vao is not None:
                self._vao[1].release()
            self._vao = (program.glo, self.ctx.vertex_array(program, []))
        return self._vao[1]

    def draw(self, scene: Scene, step: Pass, framebuffer: moderngl.Framebuffer, size: tuple[int, int],
             program: moderngl.Program) -> None:
        """Draw the overlays named by ``step`` into ``framebuffer`` (``size`` pixels)."""
        region = (0, 0, *size) if step.viewport < 0 else scene.viewports[step.viewport].pixels(*size)
        by_name = {o.name: o for o in scene.overlays}
        viewport = scene.viewports[step.viewport] if step.viewport >= 0 else None
        camera = viewport.camera if viewport is not None and viewport.camera is not None else scene.camera
        vao = self._vertex_array(program)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
        framebuffer.scissor = region
        try:
            for draw in step.draws:
                overlay = by_name[draw.node].seen_by(camera, region)  # a figure in the world: projected now
                rect = overlay.placement(region)
                self._texture(overlay, overlay.drawn_image(region)).use(location=0)
                program["u_image"].value = 0
                program["u_origin"].value = rect[:2]
                framebuffer.viewport = rect
                vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        finally:
            framebuffer.scissor = None
            self.ctx.disable(moderngl.BLEND)
            self.ctx.blend_func = moderngl.DEFAULT_BLENDING

    def release(self) -> None:
        for texture, _ in self._textures.values():
            texture.release()
        self._textures.clear()
        if self._vao is not None:
            self._vao[1].release()
            self._vao = None
