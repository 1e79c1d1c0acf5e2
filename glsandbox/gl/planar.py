"""GL state for the planar passes: the stencil mirror and the planar shadow.

Course section "The stencil Test". Direct3D 11 bundles this state into
objects (``MarkMirrorDSS``, ``DrawReflectionDSS``, ``CullClockwiseRS``) set
per draw; OpenGL keeps it as loose global switches, so every pass here sets
what it needs and :func:`restore_state` puts back the defaults the other
passes assume, whatever happened (``finally``). The raw calls moderngl lacks
(stencil, colour and depth write masks) go through
:mod:`glsandbox.gl.rawgl`.

Stencil bits (:data:`glsandbox.plan.MIRROR_STENCIL_BIT`, ``SHADOW_STENCIL_BIT``):
the mirror marks bit 0, the shadow bit 1, each with its own write and compare
masks, so one 8-bit buffer serves both without a clear in between.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl
import numpy as np

from glsandbox import transforms
from glsandbox.gl import rawgl
from glsandbox.plan import MIRROR_STENCIL_BIT, SHADOW_STENCIL_BIT, Pass
from glsandbox.scene import Light, Node, Scene

if TYPE_CHECKING:
    from glsandbox.gl.executor import Executor, PassCamera

GL_INVERT = 0x150A


# --- the passes ------------------------------------------------------------------


def run_planar_pass(executor: Executor, scene: Scene, step: Pass, nodes: dict[str, Node],
                    camera: PassCamera) -> None:
    """Run one ``mark_mirror``, ``reflection``, ``mirror_surface`` or ``shadow`` pass."""
    runners = {"mark_mirror": _mark_mirror, "reflection": _reflection,
               "mirror_surface": _mirror_surface, "shadow": _shadow}
    try:
        runners[step.kind](executor, scene, step, nodes, camera)
    finally:
        restore_state(executor, scene)


def restore_state(executor: Executor, scene: Scene) -> None:
    """The state every other pass assumes: no stencil test, all write masks on,
    no blending, no polygon offset, counter-clockwise front faces, the
    scene's own lights."""
    raw, ctx = executor.host.raw, executor.ctx
    raw.glDisable(rawgl.GL_STENCIL_TEST)
    raw.glStencilMask(0xFF)
    raw.glStencilFunc(rawgl.GL_ALWAYS, 0, 0xFF)
    raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_KEEP)
    raw.glColorMask(1, 1, 1, 1)
    raw.glDepthMask(1)
    ctx.disable(moderngl.BLEND)
    ctx.blend_func = moderngl.DEFAULT_BLENDING
    ctx.polygon_offset = (0.0, 0.0)
    ctx.front_face = "ccw"
    executor._lights = scene.lights


def _mark_mirror(executor: Executor, scene: Scene, step: Pass, nodes: dict[str, Node],
                 camera: PassCamera) -> None:
    """``MarkMirrorDSS``: the glass's visible pixels get the mirror bit.

    The stencil test always passes; where the depth test passes too (nothing
    in front of the glass) the bit is replaced by 1. Colour and depth writes
    are off: this pass changes nothing but the stencil.
    """
    raw = executor.host.raw
    raw.glEnable(rawgl.GL_STENCIL_TEST)
    raw.glStencilMask(MIRROR_STENCIL_BIT)
    raw.glStencilFunc(rawgl.GL_ALWAYS, MIRROR_STENCIL_BIT, 0xFF)
    raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_REPLACE)  # stencil fail, depth fail, both pass
    raw.glColorMask(0, 0, 0, 0)
    raw.glDepthMask(0)
    for draw in step.draws:
        executor._draw(nodes[draw.node], draw, camera)


def reflected_lights(lights: tuple[Light, ...], reflection: np.ndarray) -> tuple[Light, ...]:
    """The lights seen in the mirror: each position through R. Shading the
    reflected point R·p with normal R·n and lights R·L for the real eye gives
    the colour of p seen from the reflected eye, which is what a mirror shows."""
    return tuple(Light(tuple(float(v) for v in transforms.transform_points(reflection, [l.position])[0]), l.color)
                 for l in lights)


def _reflection(executor: Executor, scene: Scene, step: Pass, nodes: dict[str, Node],
                camera: PassCamera) -> None:
    """``DrawReflectionDSS``: the reflected nodes, only where the mirror bit is set.

    Each node is drawn with ``R @ model``. R has determinant -1, so a triangle
    that was counter-clockwise on screen is now clockwise: the front-face rule
    flips (the course's ``CullClockwise``) so the same faces are culled.
    Without the stencil (``mirror=no_stencil``) nothing stops the reflection
    outside the glass.
    """
    assert scene.mirror is not None
    raw = executor.host.raw
    if step.stencil:
        raw.glEnable(rawgl.GL_STENCIL_TEST)
        raw.glStencilMask(0x00)  # read only
        raw.glStencilFunc(rawgl.GL_EQUAL, MIRROR_STENCIL_BIT, MIRROR_STENCIL_BIT)
        raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_KEEP)
    reflection = scene.mirror.matrix()
    executor._lights = reflected_lights(scene.lights, reflection)
    for draw in step.draws:
        node = nodes[draw.node]
        executor._draw(node, draw, camera, model=reflection @ node.model, front_face="cw")


def _mirror_surface(executor: Executor, scene: Scene, step: Pass, nodes: dict[str, Node],
                    camera: PassCamera) -> None:
    """The glass over its reflection, blended by its colour's alpha."""
    ctx = executor.ctx
    ctx.enable(moderngl.BLEND)
    ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
    for draw in step.draws:
        executor._draw(nodes[draw.node], draw, camera)


def _shadow(executor: Executor, scene: Scene, step: Pass, nodes: dict[str, Node],
            camera: PassCamera) -> None:
    """The casters flattened by the lifted shadow matrix, dark and blended.

    Depth test on (the shadow must hide behind what stands in front of the
    floor), depth writes off. ``polygon_offset`` pulls the shadow towards the
    camera by ``factor * depth slope + units * smallest depth step``: -1, -1
    in standard depth, +1, +1 in reverse-Z where nearer means larger.
    With the stencil, a pixel is darkened only while its shadow bit is 0,
    and the bit is then set (``GL_INVERT`` under write mask 2), so the
    flattened cube's overlapping front and back faces darken it once.
    """
    shadow = scene.shadow
    assert shadow is not None
    raw, ctx = executor.host.raw, executor.ctx
    if step.stencil:
        raw.glEnable(rawgl.GL_STENCIL_TEST)
        raw.glStencilMask(SHADOW_STENCIL_BIT)
        raw.glStencilFunc(rawgl.GL_EQUAL, 0, SHADOW_STENCIL_BIT)
        raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, GL_INVERT)
    raw.glDepthMask(0)
    ctx.enable(moderngl.BLEND)
    ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
    if shadow.polygon_offset:
        sign = 1.0 if scene.depth_mode == "reverse_z" else -1.0
        ctx.polygon_offset = (sign, sign)
    ctx.disable(moderngl.CULL_FACE)
    flatten = shadow.matrix()
    color = np.asarray(shadow.color, dtype="f4").tobytes()
    for draw in step.draws:
        node = nodes[draw.node]
        program = executor._programs[draw.program][1]
        vao, gpu = executor._vao(node.mesh, draw.program)
        program["m_model"].write(transforms.gl_bytes(flatten @ node.model))
        program["m_view"].write(camera.view_bytes)
        program["m_proj"].write(camera.proj_bytes)
        program["u_color"].write(color)
        vao.render(gpu.mode, vertices=gpu.count)
