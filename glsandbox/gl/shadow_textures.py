"""Shadow maps on the GPU: the depth textures, the pass that fills one, and
what a receiver's draw binds (the maths: :mod:`glsandbox.shadowmap`).

A map is a depth texture attached alone to a framebuffer (no colour: the
pass writes depth only), ``DEPTH_COMPONENT32F`` where the context gives it
(else moderngl's ``DEPTH_COMPONENT24``). It is sampled with a comparison sampler
(``compare_func='<='``: GLSL's ``sampler2DShadow``), which returns 1 where
the receiver's depth is at most the stored depth (lit) and 0 where a caster
is nearer (shadowed); nearest filtering, so that each comparison is one
texel and the percentage-closer filter's grid is the phong shader's own.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Collection
from typing import Any

import moderngl
import numpy as np

from glsandbox import transforms
from glsandbox.gl import depth as gl_depth
from glsandbox.gl.passes import FrameState
from glsandbox.plan import CUTOUT_SHADOW_PROGRAM, Pass, cutout_caster_material
from glsandbox.scene import ShadowMap
from glsandbox.shadowmap import light_frame


class ShadowMaps:
    """The depth textures of the lights' shadow maps, kept between frames by
    (light, size), with the light matrix and settings of the frame's last pass."""

    def __init__(self, ctx: moderngl.Context, raw: Any = None) -> None:
        self.ctx = ctx
        self.raw = raw  # glsandbox.gl.rawgl.RawGL: the 32-bit float depth format moderngl does not offer
        #: Whether each map's depth is 32-bit float (else moderngl's 24-bit fixed point), by (light, size).
        self.float_depth: dict[tuple[int, int], bool] = {}
        self._maps: dict[tuple[int, int], tuple[moderngl.Texture, moderngl.Framebuffer]] = {}
        #: light -> (its map's texture, light projection @ view (float64), its ShadowMap, the
        #: receivers' uniforms (:meth:`use`'s answer) by the receiving pass's origin and the unit, a
        #: texel's width at unit distance)
        self._current: dict[int, tuple[moderngl.Texture, np.ndarray, ShadowMap,
                                       dict[tuple[bytes, int], tuple[tuple[str, bytes], ...]], float]] = {}

    def target(self, light: int, size: int) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        key = (light, size)
        if key not in self._maps:
            texture = self.ctx.depth_texture((size, size))
            # 32-bit float depth where the context gives it (core since OpenGL 3.0): the map's
            # depths are compared with depths the same matrix makes, so 24-bit fixed point is
            # not the limit at any scale, but a float keeps 24 bits of mantissa at every depth
            # and fixed point only 2^-24 steps of the whole range.
            self.float_depth[key] = bool(self.raw is not None and self.raw.float_depth_texture(texture.glo, (size, size)))
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            texture.repeat_x = texture.repeat_y = False
            texture.compare_func = "<="
            self._maps[key] = (texture, self.ctx.framebuffer(depth_attachment=texture))
        return self._maps[key]

    def drawn(self, light: int, texture: moderngl.Texture, matrix: np.ndarray, settings: ShadowMap,
              footprint: float) -> None:
        """Light ``light``'s map was drawn with ``matrix`` (projection @ view, float64); ``footprint``:
        a texel's width at unit distance from the light (:meth:`~glsandbox.shadowmap.LightFrame.footprint`)."""
        self._current[light] = (texture, np.asarray(matrix, dtype=np.float64), settings, {}, footprint)

    def use(self, light: int, unit: int, origin: np.ndarray | None = None) -> tuple[tuple[str, bytes], ...]:
        """Light ``light``'s map on texture unit ``unit``; returns the receiver's uniforms as
        ``(name, bytes)`` (the executor writes those a program has and that changed).
        ``origin``: the receiving pass's (its positions are relative to it, see
        :class:`~glsandbox.gl.executor.PassCamera`): the light's matrix is taken times
        ``T(origin)`` in float64, so a receiver far from the world's origin looks its map up
        as precisely as one near it."""
        texture, matrix, settings, relative, footprint = self._current[light]
        texture.use(unit)
        key = b"" if origin is None else np.asarray(origin, dtype=np.float64).tobytes()
        found = relative.get((key, unit))  # (every receiver of a pass asks with the same origin)
        if found is None:
            moved = matrix.copy()
            if origin is not None:
                moved[:, 3] += matrix[:, :3] @ np.asarray(origin, dtype=np.float64)  # M @ T(o)
            found = relative[key, unit] = (*_settings_bytes(unit, settings), ("u_shadow_footprint",
                                                                             struct.pack("f", footprint)),
                                           ("u_shadow_matrix", transforms.gl_bytes(moved)))
        return found

    def bind(self, light: int, unit: int, program: moderngl.Program, members: Collection[str],
             origin: np.ndarray | None = None) -> None:
        """Light ``light``'s map on texture unit ``unit``, and the receiver's uniforms."""
        for name, data in self.use(light, unit, origin):
            if name in members:
                program[name].write(data)

    def release(self) -> None:
        for texture, framebuffer in self._maps.values():
            framebuffer.release()
            texture.release()
        self._maps.clear()
        self._current.clear()
        self.float_depth.clear()


@functools.lru_cache(maxsize=64)
def _settings_bytes(unit: int, settings: ShadowMap) -> tuple[tuple[str, bytes], ...]:
    """The sampler's unit, the biases and the texel size as uniform bytes, once per map settings."""
    return (("u_shadow_map", struct.pack("i", unit)), ("u_shadow_bias", struct.pack("f", settings.bias)),
            ("u_shadow_slope_bias", struct.pack("f", settings.slope_bias)),
            ("u_shadow_texel", struct.pack("f", 1.0 / settings.size)))


def run_shadow_map_pass(executor: Any, frame: FrameState, step: Pass, camera: Any) -> None:
    """Fill light N's map (``step.camera == "light N"``): clear its depth to 1,
    draw the casters' depth from the light, then give the frame back its target.

    The map always uses OpenGL's standard depth (clip -1..1, test LESS), also
    in a reverse-Z frame: its depth is compared only with depths made by the
    same light matrix in the phong shader.
    """
    assert step.camera is not None and step.camera.startswith("light ")
    scene, ctx, models = frame.scene, executor.ctx, frame.models
    light_index = int(step.camera.split()[1])
    light = frame.lights[light_index]  # (where the frame's motion put it)
    assert light.shadow is not None
    texture, framebuffer = executor.shadow_maps.target(light_index, light.shadow.size)
    fitted = light_frame(scene, light, models)  # fitted to the casters where the frame has them
    view, proj = fitted.view, fitted.proj
    gl_depth.end_depth_mode(ctx, executor.raw, scene)
    try:
        framebuffer.use()
        framebuffer.viewport = (0, 0, light.shadow.size, light.shadow.size)
        framebuffer.clear(depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        pass_camera = executor.pass_camera(view, proj, np.asarray(light.position, dtype=np.float64))
        for draw in step.draws:
            node = frame.nodes[draw.node]
            model = models.get(draw.node)
            if draw.program == CUTOUT_SHADOW_PROGRAM.key:  # a cut-out: depth only where its texels are drawn
                executor.draw_node(node, draw, pass_camera, model=model,
                                   material=cutout_caster_material(node.material, node.material.color))
            else:
                executor.draw_node(node, draw, pass_camera, model=model)
    finally:
        gl_depth.begin_depth_mode(ctx, executor.raw, scene)
        frame.framebuffer.use()
    executor.shadow_maps.drawn(light_index, texture, proj @ view, light.shadow, fitted.footprint(light.shadow.size))
