"""GL state for the planar passes: the stencil mirror and the planar shadow.

Course section "The stencil Test". Direct3D 11 bundles this state into
objects (``MarkMirrorDSS``, ``DrawReflectionDSS``, ``CullClockwiseRS``) set
per draw; OpenGL keeps it as loose global switches, so every pass here sets
what it needs and the executor puts back the defaults the other passes
assume after each one, whatever happened
(:func:`glsandbox.gl.passes.restore_state`). The raw calls moderngl lacks
(stencil, colour and depth write masks) go through
:mod:`glsandbox.gl.rawgl`.

The stencil state of each pass is the plan's
(:class:`glsandbox.plan.StencilState`, set by :func:`set_stencil`): the
mirror marks bit 0, the shadow bit 1, each with its own write and compare
masks, so one 8-bit buffer serves both without a clear in between.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any, Protocol

import moderngl
import numpy as np

from glsandbox import transforms
from glsandbox.gl import rawgl
from glsandbox.gl.passes import FrameState
from glsandbox.plan import CUTOUT_SHADOW_PROGRAM, Draw, Pass, StencilState, cutout_caster_material
from glsandbox.scene import Light, Material, Node

if TYPE_CHECKING:
    from glsandbox.planar import Mirror


class NodeDrawer(Protocol):
    """What the planar passes need from the executor that runs them
    (:class:`glsandbox.gl.executor.Executor`, which imports this module, so
    this one never imports it): the context, the raw GL calls moderngl lacks,
    and one node drawn with the pass's overrides (see
    :meth:`~glsandbox.gl.executor.Executor.draw_node`). ``camera`` is the
    executor's pass camera, handed back to it unread."""

    ctx: moderngl.Context
    raw: rawgl.RawGL

    def draw_node(self, node: Node, draw: Draw, camera: Any, *, model: np.ndarray | None = None,
                  front_face: str = "ccw", lights: tuple[Light, ...] | None = None,
                  material: Material | None = None) -> None: ...


# --- stencil state ---------------------------------------------------------------

_STENCIL_TESTS = {"always": rawgl.GL_ALWAYS, "equal": rawgl.GL_EQUAL, "not_equal": rawgl.GL_NOTEQUAL,
                  "never": rawgl.GL_NEVER}
_STENCIL_OPS = {"keep": rawgl.GL_KEEP, "replace": rawgl.GL_REPLACE, "invert": rawgl.GL_INVERT,
                "incr": rawgl.GL_INCR, "zero": rawgl.GL_ZERO}
#: A pass's ``blend`` factor names (:attr:`glsandbox.plan.Pass.blend`) as moderngl's.
BLEND_FACTORS = {"zero": moderngl.ZERO, "one": moderngl.ONE, "src_alpha": moderngl.SRC_ALPHA,
                 "one_minus_src_alpha": moderngl.ONE_MINUS_SRC_ALPHA, "dst_alpha": moderngl.DST_ALPHA,
                 "one_minus_dst_alpha": moderngl.ONE_MINUS_DST_ALPHA, "src_color": moderngl.SRC_COLOR,
                 "one_minus_src_color": moderngl.ONE_MINUS_SRC_COLOR, "dst_color": moderngl.DST_COLOR,
                 "one_minus_dst_color": moderngl.ONE_MINUS_DST_COLOR}


def set_stencil(raw: rawgl.RawGL, stencil: StencilState) -> None:
    """Turn the stencil test on with a pass's state: its write mask, its test
    (function, reference, compare mask), and what a fragment passing both the
    stencil and the depth test does; one failing either keeps the stencil."""
    raw.glEnable(rawgl.GL_STENCIL_TEST)
    raw.glStencilMask(stencil.write_mask)
    raw.glStencilFunc(_STENCIL_TESTS[stencil.test], stencil.ref, stencil.mask)
    raw.glStencilOp(rawgl.GL_KEEP, rawgl.GL_KEEP, _STENCIL_OPS[stencil.on_pass])  # stencil fail, depth fail, both pass


# --- the passes ------------------------------------------------------------------

#: ``left @ model`` by (id of ``left``, the float64 model's bytes): (``left``, the product). A
#: pass's matrix (the mirror's R, the shadow's) is kept by its immutable owner, so a node that does
#: not move is reflected or flattened once, not every frame; one moved in place has other bytes.
_PRODUCTS: dict[tuple[int, bytes], tuple[np.ndarray, np.ndarray]] = {}
#: Entries :data:`_PRODUCTS` keeps; past it, it starts again (a moving node adds one per frame).
_PRODUCTS_KEPT = 256


def _times(left: np.ndarray, model: Any) -> np.ndarray:
    """``left @ model`` (read-only), found again for a model of the same content."""
    matrix = np.asarray(model, dtype=np.float64)
    key = (id(left), matrix.tobytes())
    kept = _PRODUCTS.get(key)
    if kept is not None and kept[0] is left:  # (the entry holds ``left``: its id is not reused meanwhile)
        return kept[1]
    if len(_PRODUCTS) >= _PRODUCTS_KEPT:
        _PRODUCTS.clear()
    product = left @ matrix
    product.setflags(write=False)
    _PRODUCTS[key] = (left, product)
    return product


def mark_mirror(drawer: NodeDrawer, frame: FrameState, step: Pass, camera: Any) -> None:
    """``MarkMirrorDSS``: the glass's visible pixels get the mirror bit.

    The stencil test always passes; where the depth test passes too (nothing
    in front of the glass) the bit is replaced by 1 (the plan's
    :data:`~glsandbox.plan.MARK_MIRROR_STENCIL`). Colour and depth writes
    are off: this pass changes nothing but the stencil.
    """
    assert step.stencil is not None
    raw, nodes, models = drawer.raw, frame.nodes, frame.models
    set_stencil(raw, step.stencil)
    raw.glColorMask(0, 0, 0, 0)
    raw.glDepthMask(1 if step.depth_write else 0)  # (a state table may write it: the reflection is then hidden)
    for draw in step.draws:
        drawer.draw_node(nodes[draw.node], draw, camera, model=models.get(draw.node))


def reflected_lights(lights: tuple[Light, ...], reflection: np.ndarray) -> tuple[Light, ...]:
    """The lights seen in the mirror: each position through R. Shading the
    reflected point R·p with normal R·n and lights R·L for the real eye gives
    the colour of p seen from the reflected eye, which is what a mirror shows."""
    return tuple(Light(tuple(float(v) for v in transforms.transform_points(reflection, [l.position])[0]), l.color)
                 for l in lights)


#: The last lights reflected: (lights, mirror, their reflections), see :func:`_mirrored_lights`.
_LAST_MIRRORED: list[tuple[tuple[Light, ...], Mirror, tuple[Light, ...]]] = []


def _mirrored_lights(lights: tuple[Light, ...], mirror: Mirror) -> tuple[Light, ...]:
    """:func:`reflected_lights` through ``mirror``, once per set of lights: lights that do not move
    are reflected once, not every frame. The same objects as last time (a scene moved only by time
    keeps its lights tuple and mirror) are found without hashing them; others by value (Lights and
    Mirrors are immutable and compare by value)."""
    if _LAST_MIRRORED:
        last_lights, last_mirror, reflected = _LAST_MIRRORED[0]
        if last_lights is lights and last_mirror is mirror:
            return reflected
    reflected = _mirrored_by_value(lights, mirror)
    _LAST_MIRRORED[:] = [(lights, mirror, reflected)]
    return reflected


@functools.lru_cache(maxsize=16)
def _mirrored_by_value(lights: tuple[Light, ...], mirror: Mirror) -> tuple[Light, ...]:
    return reflected_lights(lights, mirror.matrix())


def reflection(drawer: NodeDrawer, frame: FrameState, step: Pass, camera: Any) -> None:
    """``DrawReflectionDSS``: the reflected nodes, only where the mirror bit is set.

    Each node is drawn with ``R @ model``. R has determinant -1, so a triangle
    that was counter-clockwise on screen is now clockwise: the front-face rule
    flips (the course's ``CullClockwise``) so the same faces are culled.
    Without the stencil (``mirror=no_stencil``) nothing stops the reflection
    outside the glass.
    """
    scene, nodes, models = frame.scene, frame.nodes, frame.models
    assert scene.mirror is not None
    if step.stencil is not None:  # read only: write mask 0
        set_stencil(drawer.raw, step.stencil)
    if step.depth_write is False:
        drawer.raw.glDepthMask(0)
    reflection = scene.mirror.matrix()
    lights = _mirrored_lights(frame.lights, scene.mirror)
    for draw in step.draws:
        node = nodes[draw.node]
        drawer.draw_node(node, draw, camera, model=_times(reflection, models.get(draw.node, node.model)),
                         front_face=step.front_face or "cw", lights=lights)


def mirror_surface(drawer: NodeDrawer, frame: FrameState, step: Pass, camera: Any) -> None:
    """The glass over its reflection, blended by its colour's alpha (the
    frame's own alpha is neither read nor written: it stays 1)."""
    ctx = drawer.ctx
    ctx.enable(moderngl.BLEND)
    ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
    for draw in step.draws:
        drawer.draw_node(frame.nodes[draw.node], draw, camera, model=frame.models.get(draw.node))


@functools.lru_cache(maxsize=16)
def _flat_material(color: tuple[float, ...]) -> Material:
    """The planar shadow's material, one object per colour: the executor keeps what it prepared
    for a draw while its material is the same object (Materials are immutable)."""
    return Material(color=color)


def planar_shadow(drawer: NodeDrawer, frame: FrameState, step: Pass, camera: Any) -> None:
    """The casters flattened by the lifted shadow matrix, dark and blended.

    Depth test on (the shadow must hide behind what stands in front of the
    floor), depth writes off. ``polygon_offset`` pulls the shadow towards the
    camera by ``factor * depth slope + units * smallest depth step``: -1, -1
    in standard depth, +1, +1 in reverse-Z where nearer means larger.
    With the stencil, a pixel is darkened only while its shadow bit is 0,
    and the bit is then set (``GL_INVERT`` under write mask 2), so the
    flattened cube's overlapping front and back faces darken it once.
    """
    scene, nodes, models = frame.scene, frame.nodes, frame.models
    shadow = scene.planar_shadow
    assert shadow is not None
    raw, ctx = drawer.raw, drawer.ctx
    if step.stencil is not None:
        set_stencil(raw, step.stencil)
    raw.glDepthMask(1 if step.depth_write else 0)
    ctx.enable(moderngl.BLEND)
    source, destination = step.blend or ("src_alpha", "one_minus_src_alpha")
    ctx.blend_func = (BLEND_FACTORS[source], BLEND_FACTORS[destination])
    if shadow.polygon_offset:
        sign = 1.0 if scene.depth_mode == "reverse_z" else -1.0
        ctx.polygon_offset = (sign, sign)
    flatten = shadow.matrix()
    flat = _flat_material(shadow.color)  # one colour, unlit, untextured
    for draw in step.draws:  # drawn without culling, as the plan says
        node = nodes[draw.node]
        material = flat
        if draw.program == CUTOUT_SHADOW_PROGRAM.key:  # a cut-out: its texture's alpha, the part's cutoff
            material = cutout_caster_material(node.material, shadow.color)
        drawer.draw_node(node, draw, camera, model=_times(flatten, models.get(draw.node, node.model)),
                         material=material)
