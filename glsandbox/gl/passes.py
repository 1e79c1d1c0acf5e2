"""What every pass runner shares: the frame it draws in, its signature, and the
GL state every pass starts from.

The runners themselves are registered in one place,
:data:`glsandbox.gl.executor.PASS_RUNNERS` (their describers in
:data:`glsandbox.plan.PASS_DESCRIBERS`). OpenGL keeps its state as loose
global switches, so after every pass the executor calls
:func:`restore_state`, whatever the pass did or raised: a pass sets what it
needs and never has to undo it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import moderngl

from glsandbox.gl import rawgl
from glsandbox.gl.target import FRAME_COLOR_MASK
from glsandbox.plan import Pass
from glsandbox.scene import Light, Node, Scene


@dataclass(frozen=True)
class FrameState:
    """The frame being drawn: its scene, its nodes by name, and its target.

    ``models`` and ``lights`` are where the nodes and lights are in this frame: a headless frame
    moved only by time hands its motion's model matrices (by node name) and lights to the
    executor without making the moved scene (:meth:`glsandbox.frame.FrameRenderer.render_motion`);
    a runner draws a node at ``models.get(name, node.model)`` and lights with ``lights``, not
    with ``scene.lights``. Any other frame: no models, the scene's lights."""

    scene: Scene
    nodes: dict[str, Node]
    framebuffer: moderngl.Framebuffer
    size: tuple[int, int]
    models: Mapping[str, Any]
    lights: tuple[Light, ...]


class PassRunner(Protocol):
    """``runner(executor, frame, step, camera)``: run one pass. ``camera`` is the
    executor's pass camera for a pass drawn into the frame through a viewport
    (its viewport and depth test already set), None for any other."""

    def __call__(self, executor: Any, frame: FrameState, step: Pass, camera: Any) -> None: ...


#: The groups of state :func:`restore_state` puts back.
STATE_PARTS = frozenset({"stencil", "masks", "blend", "offset", "cull"})


def restore_state(ctx: moderngl.Context, raw: rawgl.RawGL, parts: frozenset[str] = STATE_PARTS) -> None:
    """The state every pass assumes: no stencil test, stencil and depth
    writes on, colour writes on but alpha (the frame's rule,
    :data:`~glsandbox.gl.target.FRAME_COLOR_MASK`: frames stay opaque), no
    blending, no polygon offset, no culling, counter-clockwise front faces.
    ``parts`` (of :data:`STATE_PARTS`): only those groups, for a pass known to change no other."""
    if "stencil" in parts:
        raw.glDisable(rawgl.GL_STENCIL_TEST)
        raw.glStencilMask(0xFF)
        raw.glStencilFunc(rawgl.GL_ALWAYS, 0, 0xFF)
        raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_KEEP)
    if "masks" in parts:
        raw.glColorMask(*FRAME_COLOR_MASK)
        raw.glDepthMask(1)
    if "blend" in parts:
        ctx.disable(moderngl.BLEND)
        ctx.blend_func = moderngl.DEFAULT_BLENDING
    if "offset" in parts:
        ctx.polygon_offset = (0.0, 0.0)
    if "cull" in parts:
        ctx.disable(moderngl.CULL_FACE)
        ctx.front_face = "ccw"
