"""The pass runners: one module per pass kind, ``glsandbox/gl/passes/<kind>.py``,
holding one :class:`Runner` (``RUNNER``); and what every runner shares: the frame
it draws in, its signature, and the GL state every pass starts from.

:func:`runner` finds a kind's module by its name in
:data:`glsandbox.passes.PASS_KINDS` (its plan side is ``glsandbox/passes/<kind>.py``).
OpenGL keeps its state as loose global switches, so the executor puts back
(:func:`restore_state`) the groups a pass left changed before the next pass that
needs them, whatever the pass did or raised: a pass sets what it needs and never
has to undo it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.gl import rawgl
from glsandbox.gl.target import FRAME_COLOR_MASK
from glsandbox.passes import PASS_KINDS
from glsandbox.passes.plan_parts import Pass
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


class RunPass(Protocol):
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


#: A pass's state habits: (the groups of :data:`STATE_PARTS` it sets wholly itself before it
#: draws, so what the pass before left there need not be put back first; the groups it leaves
#: changed, or None for a pass of unknown habits: every group is put back before and after it).
StateHabits = Callable[[Pass], tuple[frozenset[str], frozenset[str] | None]]

NO_STATE: frozenset[str] = frozenset()


def touches_nothing(step: Pass) -> tuple[frozenset[str], frozenset[str] | None]:
    """The habits of a pass that sets and leaves none of the groups."""
    return NO_STATE, NO_STATE


def unknown_habits(step: Pass) -> tuple[frozenset[str], frozenset[str] | None]:
    """The habits of a pass that may change any group: it starts and ends in the default state."""
    return NO_STATE, None


def stencil_set(step: Pass) -> frozenset[str]:
    """A planar pass with a stencil state sets all of the stencil group (:func:`glsandbox.gl.planar_state.set_stencil`)."""
    return frozenset({"stencil"}) if step.stencil is not None else NO_STATE


@dataclass(frozen=True)
class Runner:
    """What the executor knows of one pass kind (culling aside: the executor sets it per draw)."""

    kind: str
    #: ``run(executor, frame, step, camera)``: the pass itself.
    run: RunPass
    #: Its state habits (:data:`StateHabits`).
    state: StateHabits
    #: It draws each node at :class:`FrameState`'s ``models`` and lights with its ``lights``, so a
    #: frame moved only by time may be drawn without the moved scene being made.
    moved: bool


#: The runners found so far, by kind (:func:`runner`).
RUNNERS: dict[str, Runner] = {}


def runner(kind: str) -> Runner:
    """The :class:`Runner` of pass kind ``kind`` (``glsandbox/gl/passes/<kind>.py``'s ``RUNNER``);
    a :class:`SandboxError` naming the kind when it has none."""
    found = RUNNERS.get(kind)
    if found is None:
        if kind not in PASS_KINDS:
            raise SandboxError(f"pass kind {kind!r} has no runner (it is not in glsandbox.passes.PASS_KINDS)")
        found = getattr(importlib.import_module(f"{__name__}.{kind}"), "RUNNER", None)
        if not isinstance(found, Runner) or found.kind != kind:
            raise SandboxError(f"pass kind {kind!r} has no runner (glsandbox/gl/passes/{kind}.py defines no "
                               f"RUNNER = Runner({kind!r}, ...))")
        RUNNERS[kind] = found
    return found


def all_moved(steps: Iterable[Pass]) -> bool:
    """Whether every pass of ``steps`` draws at the frame's models and lights (:attr:`Runner.moved`)."""
    return all(runner(step.kind).moved for step in steps)
