"""Scene -> Plan: only the passes, shader variants and buffers a scene needs.

This is how "simulate only the effects a scene calls for" stays honest: the
plan is a pure function of the Scene, printed by ``glsandbox plan LESSON`` and
pinned per lesson by a test. Nothing in here touches GL; the executor in
:mod:`glsandbox.gl.executor` runs a plan as written, and allocates only the
buffers the plan lists.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import functools
import math
import weakref
from collections.abc import Mapping
from typing import Any, Callable

import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh
from glsandbox.overlay import Overlay
from glsandbox.scene import Camera, Color, Material, Node, Scene, _copy_with
from glsandbox.shadowmap import casters, casting_light, receivers


@dataclass(frozen=True, order=True)
class ProgramVariant:
    """A shader file compiled with a set of ``#define`` lines.

    ``shader`` is a built-in program's name (``phong``: ``shaders/phong.glsl``),
    or with ``user`` the path of a node's own GLSL file (:attr:`Node.shader`).
    """

    shader: str
    defines: tuple[tuple[str, str], ...] = ()
    user: bool = False
    #: ``shader[DEFINE,NAME=value]``: names the compiled program in plans and caches.
    key: str = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        flags = ",".join(name if value == "" else f"{name}={value}" for name, value in self.defines)
        object.__setattr__(self, "key", f"{self.shader}[{flags}]" if self.defines else self.shader)


@dataclass(frozen=True)
class Buffers:
    """What the render target must have. The stencil exists only when a pass uses it."""

    depth: bool
    stencil: bool
    samples: int
    #: A 32-bit float depth buffer (reverse-Z) instead of 24-bit integers.
    float_depth: bool = False

    def describe(self) -> str:
        parts = ["colour RGBA8"]
        if self.depth:
            parts.append("depth 32F" if self.float_depth else "depth 24")
        if self.stencil:
            parts.append("stencil 8")
        parts.append(f"MSAA {self.samples}x" if self.samples > 1 else "no MSAA")
        return ", ".join(parts)


@dataclass(frozen=True)
class Draw:
    """One node drawn with one program variant (in a ``trace`` pass: traced, shaded as ``program`` says)."""

    node: str
    program: str  # a ProgramVariant key; in a trace pass, the shading the ray tracer gives the node
    cull_back_faces: bool
    texture: str | None = None  # what texture unit 0 holds, only for textured nodes
    #: Alpha blending on and depth writes off (a material's ``alpha_mode = "blend"``).
    blend: bool = False
    #: The light whose shadow map texture unit 1 holds (:data:`SHADOW_MAP_UNIT`), for receivers.
    shadow_map: int | None = None

    def describe(self) -> str:
        return (f"{self.node} with {self.program}" + ("" if self.cull_back_faces else " (no culling)")
                + (" (blended, no depth writes)" if self.blend else "")
                + (f" + texture unit 0: {self.texture}" if self.texture else "")
                + (f" + texture unit {SHADOW_MAP_UNIT}: shadow map {self.shadow_map}"
                   if self.shadow_map is not None else ""))


#: Stencil comparisons a pass may use (``glStencilFunc``).
STENCIL_TESTS = ("always", "equal")
#: What a fragment that passes the stencil and depth tests does to the
#: written bits (``glStencilOp``'s third operation).
STENCIL_OPS = ("keep", "replace", "invert")


@dataclass(frozen=True)
class StencilState:
    """The stencil state of one pass: Direct3D's depth-stencil state (the
    course's ``MarkMirrorDSS``, ``DrawReflectionDSS``), which OpenGL sets
    with ``glStencilFunc``, ``glStencilMask`` and ``glStencilOp``.

    A fragment passes when ``stencil & mask`` compares by ``test`` with
    ``ref & mask`` (``always``: every fragment passes). Where it passes both
    the stencil and the depth test, ``on_pass`` updates the bits of
    ``write_mask``: ``keep`` leaves them, ``replace`` writes ``ref``'s,
    ``invert`` flips them. A fragment that fails either test leaves the
    stencil as it was.
    """

    test: str
    ref: int
    mask: int = 0xFF  # the compare mask
    write_mask: int = 0x00
    on_pass: str = "keep"

    def __post_init__(self) -> None:
        if self.test not in STENCIL_TESTS:
            raise SandboxError(f"unknown stencil test {self.test!r}; use one of {', '.join(STENCIL_TESTS)}")
        if self.on_pass not in STENCIL_OPS:
            raise SandboxError(f"unknown stencil operation {self.on_pass!r}; use one of {', '.join(STENCIL_OPS)}")
        for name in ("ref", "mask", "write_mask"):
            if not 0 <= getattr(self, name) <= 0xFF:
                raise SandboxError(f"stencil {name} must lie in 0..255 (an 8-bit buffer), got {getattr(self, name)!r}")

    def describe(self) -> str:
        """``always, replace 1``; ``equal 1, keep``; ``equal 0 on bit 2, set it``."""
        test = self.test
        if self.test != "always":
            test += f" {self.ref}" + ("" if self.mask in (0xFF, self.ref) else f" on bit {self.mask}")
        if self.on_pass == "replace":
            update = f"replace {self.ref & self.write_mask}"
        elif self.on_pass == "invert":
            # Under "equal" with those bits 0 in ref, a flip can only set them.
            clear_before = (self.test == "equal" and self.write_mask != 0
                            and self.write_mask & self.mask == self.write_mask and self.ref & self.write_mask == 0)
            update = "set it" if clear_before else f"invert bits {self.write_mask}"
        else:
            update = "keep"
        return f"{test}, {update}"


@dataclass(frozen=True)
class Pass:
    """One step of the frame, restricted to one viewport.

    ``kind`` is one of :data:`PASS_KINDS`: each has a describer here
    (:data:`PASS_DESCRIBERS`) and a runner in the executor
    (:data:`glsandbox.gl.executor.PASS_RUNNERS`). ``target`` is what the pass
    draws into: ``"frame"``, or a named offscreen (``"shadow map 0"``: light
    0's depth texture). ``camera`` is what it looks through: ``"viewport"``
    (the viewport's camera, or the scene's), ``"light N"`` (light N's shadow
    camera, :func:`glsandbox.shadowmap.light_camera`), or None for passes
    that draw no 3D content (clears, overlays).
    """

    kind: str
    viewport: int  # -1: the whole target
    clear_color: tuple[float, float, float, float] | None = None
    clear_depth: bool = False
    clear_stencil: bool = False
    draws: tuple[Draw, ...] = ()
    depth_test: bool = False

    #: Planar passes (:data:`PLANAR_PASS_KINDS`): the stencil state (None: no
    #: stencil test), and what else the pass does differently, as text (see
    #: :func:`planar_passes`).
    stencil: StencilState | None = None
    detail: str = ""
    target: str = "frame"
    camera: str | None = "viewport"

    def describe(self) -> str:
        describer = PASS_DESCRIBERS.get(self.kind)
        if describer is None:
            raise SandboxError(f"pass kind {self.kind!r} has no describer (plan.PASS_DESCRIBERS)")
        return describer(self)


def describe_clear_pass(step: Pass) -> str:
    what = []
    if step.clear_color is not None:
        what.append("colour (" + ", ".join(f"{c:g}" for c in step.clear_color) + ")")
    if step.clear_depth:
        what.append("depth")
    if step.clear_stencil:
        what.append("stencil")
    return f"clear viewport {step.viewport}: " + " + ".join(what)


def describe_draws(step: Pass) -> str:
    """Each draw as :meth:`Draw.describe` says it, or ``nothing``."""
    return "; ".join(d.describe() for d in step.draws) or "nothing"


def describe_draw_pass(step: Pass) -> str:
    depth = "depth test" if step.depth_test else "no depth test"
    return f"draw viewport {step.viewport} ({depth}): {describe_draws(step)}"


def describe_trace_pass(step: Pass) -> str:
    nodes = "; ".join(f"{d.node} ({d.program}" + (f", texture {d.texture}" if d.texture else "") + ")"
                      for d in step.draws) or "nothing"
    return f"trace viewport {step.viewport} ({step.detail}): {nodes}"


@dataclass(frozen=True)
class Plan:
    """The passes of one frame, in order, and what they need."""

    scene: str
    buffers: Buffers
    programs: tuple[ProgramVariant, ...]
    passes: tuple[Pass, ...]
    #: ``node: notes`` for each node whose mesh was loaded from a file (its
    #: :attr:`~glsandbox.geometry.Mesh.notes`: triangles, degenerate faces
    #: dropped, where the normals came from); empty for built-in meshes.
    meshes: tuple[str, ...] = ()
    #: What the frame does differently from what the scene asks (a node's own
    #: shader in a ray-traced viewport: :func:`user_shader_note`).
    notes: tuple[str, ...] = ()
    #: What of the nodes' model files is not drawn (each mesh's
    #: :attr:`~glsandbox.geometry.Mesh.warnings`, once each): ``render``, ``run``
    #: and ``tour`` print them as ``warning:`` lines.
    warnings: tuple[str, ...] = ()

    def describe(self) -> str:
        """A readable listing, as ``glsandbox plan`` prints it."""
        lines = [f"plan for {self.scene}", f"buffers: {self.buffers.describe()}", "programs:"]
        lines += [f"  {p.key}" for p in self.programs] or ["  (none)"]
        lines.append("passes:")
        lines += [f"  {i}. {p.describe()}" for i, p in enumerate(self.passes, start=1)]
        if self.meshes:
            lines.append("meshes:")
            lines += [f"  {line}" for line in self.meshes]
        if self.notes:
            lines.append("notes:")
            lines += [f"  {line}" for line in self.notes]
        lines += [f"warning: {line}" for line in self.warnings]
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        result = {
            "scene": self.scene,
            "buffers": {"depth": self.buffers.depth, "stencil": self.buffers.stencil,
                        "samples": self.buffers.samples},
            "programs": [p.key for p in self.programs],
            "passes": [p.describe() for p in self.passes],
        }
        if self.meshes:
            result["meshes"] = list(self.meshes)
        if self.notes:
            result["notes"] = list(self.notes)
        if self.warnings:
            result["warnings"] = list(self.warnings)
        return result


def program_for(node: Node, lights: int = 0, shadow_light: int | None = None, shadow_pcf: int = 1) -> ProgramVariant:
    """The shader variant a node needs: ``basic`` with its colour source, or
    ``phong`` (:func:`lit_program_for`) when its material is lit; ``TEXTURED``
    only when it has a texture. ``lights`` is the number of lights in the scene;
    ``shadow_light`` the light whose shadow map a lit node receives (None: none),
    filtered ``shadow_pcf`` texels wide.
    A node with a shader of its own gets that file, with ``NUM_LIGHTS`` (and
    ``TEXTURED``) defined, whatever its material's shading."""
    material = node.material
    if node.shader is not None:
        return _user_variant(str(node.shader), lights, material.texture is not None)
    if material.lit:
        return lit_program_for(node, lights, shadow_light, shadow_pcf)
    return _basic_variant(material.shading == "vertex_color", material.texture is not None,
                          material.alpha_mode == "mask")


@functools.cache
def _user_variant(path: str, lights: int, textured: bool) -> ProgramVariant:
    return ProgramVariant(path, (("NUM_LIGHTS", str(lights)), *_texture_defines(textured)), user=True)


def user_shader_note(viewport: int, node: Node) -> str:
    """What a ray-traced viewport does with a node that has a shader of its own."""
    return (f"viewport {viewport} is ray-traced: the ray tracer cannot run GLSL, so node {node.name!r} "
            f"(shader {node.shader}) is traced with its material ({node.material.shading})")


def user_shader_notes(scene: Scene) -> tuple[str, ...]:
    """One :func:`user_shader_note` per node with its own shader in each ray-traced viewport."""
    return tuple(user_shader_note(index, node) for index, viewport in enumerate(scene.viewports)
                 if viewport.renderer != "raster" for node in scene.nodes
                 if node.shader is not None and node.shown_in(index))


def _texture_defines(textured: bool) -> tuple[tuple[str, str], ...]:
    return (("TEXTURED", ""),) if textured else ()


def _mask_defines(mask: bool) -> tuple[tuple[str, str], ...]:
    """``ALPHA_MASK``: fragments whose alpha is below the material's cutoff are discarded."""
    return (("ALPHA_MASK", ""),) if mask else ()


# One ProgramVariant object per combination: planning runs every frame.
@functools.cache
def _basic_variant(vertex_color: bool, textured: bool, mask: bool = False) -> ProgramVariant:
    source = "VERTEX_COLOR" if vertex_color else "SOLID_COLOR"
    return ProgramVariant("basic", ((source, ""), *_texture_defines(textured), *_mask_defines(mask)))


def lit_program_for(node: Node, lights: int, shadow_light: int | None = None, shadow_pcf: int = 1) -> ProgramVariant:
    """The ``phong`` variant for a lit node (course section "Lighting").

    ``NUM_LIGHTS`` sizes the light loop to the lights present (no unused
    slots are looped over); ``PER_VERTEX`` evaluates the formula at the
    vertices (Gouraud), ``BLINN`` uses the half vector, ``NAIVE_NORMALS``
    the course's ``mul(Input.Norm, world)`` instead of the normal matrix.
    A model file's materials add ``VERTEX_COLOR`` (the mesh colour times the
    vertex colours), ``TWO_SIDED`` (back faces lit with the normal reversed)
    and ``ALPHA_MASK`` (cut-outs), each only for a material that asks.
    ``SHADOW_LIGHT i`` looks light i's shadow map up (:mod:`glsandbox.shadowmap`) with a
    ``SHADOW_PCF`` x ``SHADOW_PCF`` grid of comparisons (a constant: the loop unrolls).
    """
    material = node.material
    return _lit_variant(lights, material.shading, material.normals, material.texture is not None,
                        material.vertex_colors, material.double_sided, material.alpha_mode == "mask",
                        shadow_light, shadow_pcf)


@functools.cache
def _lit_variant(lights: int, shading: str, normals: str, textured: bool, vertex_colors: bool = False,
                 two_sided: bool = False, mask: bool = False, shadow_light: int | None = None,
                 shadow_pcf: int = 1) -> ProgramVariant:
    defines: list[tuple[str, str]] = [("NUM_LIGHTS", str(lights))]
    if shading == "gouraud":
        defines.append(("PER_VERTEX", ""))
    if shading == "blinn_phong":
        defines.append(("BLINN", ""))
    if normals == "naive":
        defines.append(("NAIVE_NORMALS", ""))
    defines.extend(_texture_defines(textured))
    if vertex_colors:
        defines.append(("VERTEX_COLOR", ""))
    if two_sided:
        defines.append(("TWO_SIDED", ""))
    defines.extend(_mask_defines(mask))
    if shadow_light is not None:
        defines += [("SHADOW_LIGHT", str(shadow_light)), ("SHADOW_PCF", str(shadow_pcf))]
    return ProgramVariant("phong", tuple(defines))


_FLAT: weakref.WeakKeyDictionary[Mesh, bool] = weakref.WeakKeyDictionary()


def _is_flat(node: Node) -> bool:
    """Whether a mesh lies in one plane: then it cannot hide parts of itself.
    Meshes are immutable, so the answer is kept per mesh object."""
    flat = _FLAT.get(node.mesh)
    if flat is None:
        flat = _FLAT[node.mesh] = _coplanar(node.mesh.positions)
    return flat


def _coplanar(positions: np.ndarray) -> bool:
    """Whether the points lie in one plane: the smallest singular value of the points about their
    mean is at most 1e-9 of the largest (an SVD). Two exact short cuts give the SVD's answer
    without it on a big mesh (a tenth of its time):

    - a coordinate that is 0.0 at every point (a model in a coordinate plane): that column of the
      centred points is exactly zero, so the smallest singular value is 0, which the SVD finds
      up to its rounding (a few ulps of the largest, far below 1e-9 of it): flat;
    - the 3x3 Gram matrix ``G = AᵀA`` of the centred points ``A`` has the squared singular values
      as eigenvalues. Rounding moves each entry of ``G`` by at most ``n·ε·‖a_j‖‖a_k‖``, its
      eigenvalues by at most ``n·ε·trace(G)`` (Weyl; the bound ``error`` below doubles it and
      covers the 3x3 eigensolver's own). When the smallest still exceeds 1e-6 of the largest, the
      singular values' ratio exceeds 1e-3, a million times the limit: not flat. Otherwise
      (nearly flat: squaring loses the digits that decide) the SVD answers.
    """
    points = np.asarray(positions, dtype=np.float64)
    quick = points.ndim == 2 and points.shape[0] >= 3 and points.shape[1] == 3
    if quick and any(column.min() == 0.0 == column.max() for column in points.T):
        return True
    spread = points - points.mean(axis=0)
    if quick:
        gram = spread.T @ spread
        low, _, high = np.linalg.eigvalsh(gram)
        error = 4.0 * (spread.shape[0] + 3) * np.finfo(np.float64).eps * float(np.trace(gram))
        if low - error > 1e-6 * (high + error):
            return False
    singular = np.linalg.svd(spread, compute_uv=False)
    return len(singular) < 3 or singular[2] <= 1e-9 * max(singular[0], 1e-300)


_CENTRES: weakref.WeakKeyDictionary[Mesh, np.ndarray] = weakref.WeakKeyDictionary()


def _distance(node: Node, camera: Camera | np.ndarray) -> float:
    """How far the centre of a node's bounding box lies from the eye, in world space:
    blended nodes are drawn farthest first, so each blends over what lies behind it
    (sorted by part, not by triangle: a part that wraps round another can still be
    wrong, as in any rasterizer that sorts objects). ``camera``: a camera, or the eye's position."""
    centre = _CENTRES.get(node.mesh)
    if centre is None:  # meshes are immutable: once per mesh, not per frame
        points = np.asarray(node.mesh.positions, dtype=np.float64)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2.0 if points.size else np.zeros(3)
        _CENTRES[node.mesh] = centre
    world = np.asarray(node.model, dtype=np.float64) @ np.append(centre, 1.0)
    return float(np.linalg.norm(world[:3] - np.asarray(camera.eye if isinstance(camera, Camera) else camera,
                                                        dtype=np.float64)))


def _farthest_first(blended: list[tuple[Node, Any]], camera: Camera | np.ndarray) -> list[tuple[Node, Any]]:
    """``(node, anything)`` pairs of blended nodes in drawing order: farthest from the eye first
    (``camera``: a camera, or the eye's position)."""
    return sorted(blended, key=lambda pair: -_distance(pair[0], camera))


def _mirrored_eye(mirror: Any, camera: Camera) -> np.ndarray:
    """The eye's mirror image: seen in the mirror, a node lies as far as it lies from this point
    (the reflection is an isometry), so blended reflected nodes are sorted from it."""
    return (mirror.matrix() @ np.append(np.asarray(camera.eye, dtype=np.float64), 1.0))[:3]


def motion_decisions(scene: Scene, models: Mapping[str, Any] | None = None) -> tuple:
    """What of :func:`plan`'s answer depends on where nodes, lights and cameras are: the order
    of each viewport's blended draws (:func:`_distance`) and which casters the planar shadow
    keeps or culls, and why (:func:`glsandbox.planar.shadow_casters`). Everything else of a
    plan depends on the scene's other parts. So two scenes that differ only in model
    matrices, light positions and cameras (:func:`glsandbox.scene.moved_scene`) and have
    equal decisions have equal plans: the frame renderer keeps the plan between such frames.

    Which nodes take part (blended ones per viewport, the casters) depends on none of what
    moves, so a moved scene finds them once per scene it was moved from (every frame asks).

    ``models`` (model matrices by node name, :func:`glsandbox.scene.motion_parts`): the
    decisions of ``scene`` with those nodes moved there, the same as those of the moved scene,
    which a headless frame does not make."""
    origin = scene.__dict__.get("_moved_from")  # (glsandbox.scene.scene_origin, inline)
    if origin is None and models is not None:
        origin = scene  # (the parts depend on nothing that moves: kept on the scene itself)
    parts = None if origin is None else origin.__dict__.get("_decision_parts")
    if parts is None:
        parts = _decision_parts(scene)
        if origin is not None:
            origin.__dict__["_decision_parts"] = parts
    blended, reflected, casters = parts
    nodes, viewports = scene.nodes, scene.viewports
    if models and (blended or reflected):  # the nodes sorted by where they are: as moved_scene moves them
        nodes = tuple(_copy_with(node, model=models[node.name]) if node.name in models else node for node in nodes)
    decisions: list[object] = []
    for index, shown in blended:
        pairs = [(nodes[i], None) for i in shown]
        decisions.append(tuple(node.name for node, _ in _farthest_first(pairs, viewports[index].camera or scene.camera)))
    for index, shown in reflected:  # the blended nodes the mirror reflects, in their order seen in it
        eye = _mirrored_eye(scene.mirror, viewports[index].camera or scene.camera)
        pairs = [(nodes[i], None) for i in shown]
        decisions.append(("mirror", tuple(node.name for node, _ in _farthest_first(pairs, eye))))
    shadow = scene.planar_shadow
    if shadow is not None:
        placed = {}
        for name, i in casters:
            node = nodes[i]
            placed[name] = (node.model if not models or name not in models else models[name], node.mesh.positions)
        from glsandbox.planar import shadow_casters  # loaded already: the scene holds a PlanarShadow

        decisions.append(shadow_casters(shadow, placed))
    return tuple(decisions)


def _decision_parts(scene: Scene) -> tuple[tuple, tuple, tuple]:
    """The nodes :func:`motion_decisions` looks at, by index into ``scene.nodes``: per viewport
    (every one, when any node is blended) the blended nodes it shows, per viewport showing
    any the blended nodes the mirror reflects, and the planar shadow's casters (name, index
    of the last node of that name) that are nodes of the scene."""
    nodes = scene.nodes
    glass = scene.mirror.node if scene.mirror is not None else None
    blended = [i for i, node in enumerate(nodes) if node.material.alpha_mode == "blend" and node.name != glass]
    by_viewport = tuple((index, tuple(i for i in blended if nodes[i].shown_in(index)))
                        for index in range(len(scene.viewports))) if blended else ()
    reflected_parts: tuple = ()
    mirror = scene.mirror
    if mirror is not None:
        reflected = [i for i, node in enumerate(nodes)
                     if node.name in mirror.reflected and node.material.alpha_mode == "blend"]
        reflected_parts = tuple((index, shown) for index in range(len(scene.viewports))
                                if (shown := tuple(i for i in reflected if nodes[i].shown_in(index))))
    casters: tuple = ()
    if scene.planar_shadow is not None:
        last = {node.name: i for i, node in enumerate(nodes)}
        casters = tuple((name, last[name]) for name in scene.planar_shadow.casters if name in last)
    return by_viewport, reflected_parts, casters


def _needs_depth(scene: Scene) -> bool:
    """A depth buffer is needed only where something can hide something else:
    two nodes in one viewport, or one mesh that is not flat."""
    if not scene.depth_test:
        return False
    for index in range(len(scene.viewports)):
        shown = 0
        for node in scene.nodes:
            if node.shown_in(index):
                shown += 1
                if shown > 1 or not _is_flat(node):
                    return True
    return False


# --- ray-traced viewports (renderer=ray, ray_numpy) -----------------------------

#: The options every ray-traced viewport is traced with (:func:`glsandbox.frame.trace_viewports`
#: passes them to :func:`glsandbox.raytrace.render.render`; the plan's trace passes say them).
TRACE_OPTIONS: dict[str, Any] = {"max_depth": 2, "shadows": True}

#: Who traces a viewport of each ray renderer.
TRACERS = {"ray": "GLSL ray tracer, float32", "ray_numpy": "numpy ray tracer, float64"}

#: Shadings the ray tracer gives another name: Gouraud is a raster approximation
#: (the ray tracer shades every pixel with the Phong formula).
TRACED_SHADING = {"gouraud": "phong"}


def traced_scene(scene: Scene, images: dict[int, Overlay]) -> Scene:
    """The scene the rasterizer draws once the ray-traced viewports are traced.

    Each viewport in ``images`` (by index) is traced: it keeps its clear, loses
    its nodes, and shows its traced image as its first overlay (so the
    scene's own overlays still land on top); its renderer becomes ``raster``.
    Viewports without an image (a ray viewport too small to hold a pixel)
    keep their nodes away too. A pure function: :func:`plan` uses it with
    placeholder images to print the frame that will be drawn.
    """
    ray = {i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"}
    everywhere = tuple(range(len(scene.viewports)))
    nodes = []
    for node in scene.nodes:
        shown = tuple(v for v in (node.viewports if node.viewports is not None else everywhere) if v not in ray)
        if shown:
            nodes.append(node if shown == node.viewports or (node.viewports is None and shown == everywhere)
                         else replace(node, viewports=shown))
    viewports = tuple(replace(vp, renderer="raster") for vp in scene.viewports)
    traced = tuple(images[i] for i in sorted(images))
    return replace(scene, nodes=tuple(nodes), viewports=viewports, overlays=(*traced, *scene.overlays))


def traced_image_name(viewport: int) -> str:
    """The overlay name of a viewport's traced image."""
    return f"raytrace/{viewport}"


_PLACEHOLDER = np.zeros((1, 1, 4), dtype=np.uint8)


def traced_reflectivity(scene: Scene, node: Node) -> float:
    """The share of a node's colour the ray tracer takes from the reflected ray: its
    ``material.reflectivity``; for the glass of the scene's stencil mirror
    (:class:`glsandbox.planar.Mirror`) at least ``1 - alpha``, the share of the
    reflection the rasterizer blends under the glass. The ray tracer reflects
    everything in front of the glass, not only the mirror's ``reflected`` nodes:
    the answer the stencil approximation aims at."""
    value = float(node.material.reflectivity)
    if scene.mirror is not None and node.name == scene.mirror.node:
        value = max(value, 1.0 - float(node.material.color[3]))
    return value


def _trace_pass(scene: Scene, index: int) -> Pass:
    """What tracing viewport ``index`` does: the tracer, its options, and each node as it is shaded."""
    viewport = scene.viewports[index]
    lights = len(scene.lights)
    draws = []
    for node in scene.nodes:
        if not node.shown_in(index):
            continue
        material = node.material
        shading = TRACED_SHADING.get(material.shading, material.shading)
        reflects = traced_reflectivity(scene, node)
        texture = material.texture
        draws.append(Draw(node.name, shading + (f", reflects {reflects:g}" if reflects > 0 else ""),
                          node.cull_back_faces, texture=texture.describe() if texture is not None else None))
    how = [TRACERS[viewport.renderer], "1 primary ray per pixel"]
    if lights:
        how.append(f"shadow rays to {lights} light{'s' if lights != 1 else ''}" if TRACE_OPTIONS["shadows"]
                   else "no shadow rays")
    if any(", reflects" in d.program for d in draws):
        how.append(f"reflections up to {TRACE_OPTIONS['max_depth']} bounces")
    if any(d.texture for d in draws):
        how.append("textures sampled bilinearly in their base level")
    how.append(f"shown as overlay {traced_image_name(index)}")
    return Pass("trace", index, draws=tuple(draws), detail=", ".join(how))


def ignored_settings_notes(scene: Scene) -> tuple[str, ...]:
    """What a ray-traced viewport ignores of what the scene asks, one note each: Gouraud
    shading and naive normals (raster approximations: the ray tracer shades every pixel
    with the normal matrix), texture filters other than ``linear`` (a ray samples the
    base level bilinearly), the planar mirror and shadow (raster techniques: the ray
    tracer traces reflection and shadow rays), MSAA (one ray per pixel), reverse-Z
    (a depth buffer)."""
    ray = [i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"]
    if not ray:
        return ()
    where = f"viewport {ray[0]} is" if len(ray) == 1 else f"viewports {', '.join(map(str, ray))} are"
    shown = [node for node in scene.nodes if any(node.shown_in(i) for i in ray)]
    notes = []
    for what, picked, instead in (
            ("shading=gouraud", [n.name for n in shown if n.material.shading == "gouraud"],
             "shaded per pixel (Phong), the picture of shading=phong"),
            ("normals=naive", [n.name for n in shown if n.material.normals == "naive"],
             "shaded with the normal matrix, the picture of normals=correct")):
        if picked:
            notes.append(f"{where} ray-traced: {what} (node{'s' if len(picked) > 1 else ''} "
                         f"{', '.join(repr(name) for name in picked)}) is a raster approximation; "
                         f"the ray tracer ignores it: {instead}")
    filtered = {}
    for node in shown:
        texture = node.material.texture
        if texture is not None and texture.filter != "linear":
            filtered.setdefault(texture.filter, []).append(node.name)
    for name, nodes in filtered.items():
        notes.append(f"{where} ray-traced: texture filter {name} (node{'s' if len(nodes) > 1 else ''} "
                     f"{', '.join(repr(n) for n in nodes)}) is the rasterizer's sampler; the ray tracer samples "
                     "the base level bilinearly (filter=linear, no mipmaps: a ray has no footprint)")
    if scene.mirror is not None and any(node.name == scene.mirror.node for node in shown):
        how = "through the stencil" if scene.mirror.stencil else "without the stencil (it leaks)"
        notes.append(f"{where} ray-traced: the planar mirror {scene.mirror.node!r} drawn {how} is a raster "
                     "technique; the ray tracer traces reflection rays off the glass instead")
    planar = scene.planar_shadow
    if planar is not None and any(node.name == planar.receiver for node in shown):
        notes.append(f"{where} ray-traced: the planar shadow on {planar.receiver!r} is a raster technique; "
                     "the ray tracer casts shadow rays to the lights instead")
    mapped = [i for i, light in enumerate(scene.lights) if light.shadow is not None]
    if mapped and any(node.receives_shadow and node.material.lit for node in shown):
        notes.append(f"{where} ray-traced: light {mapped[0]}'s shadow map is a raster technique; the ray tracer "
                     "casts shadow rays to the lights instead (exact: no resolution, bias or filter)")
    if scene.samples > 1:
        every = "every viewport is" if len(ray) == len(scene.viewports) else f"{where}"
        notes.append(f"--samples {scene.samples}: MSAA smooths rasterized edges only and {every} ray-traced "
                     "with 1 ray per pixel, so its picture does not change")
    if scene.depth_mode != "standard":
        notes.append(f"{where} ray-traced: depth mode {scene.depth_mode} is the rasterizer's depth buffer; "
                     "the ray tracer compares hit distances in float64/float32 and ignores it")
    return tuple(notes)


def renderer_notes(scene: Scene) -> tuple[str, ...]:
    """Everything a frame does differently from what the scene asks, because of who renders
    it: a node's own shader traced with its material, settings the ray tracer ignores."""
    return (*user_shader_notes(scene), *ignored_settings_notes(scene))


def plan(scene: Scene) -> Plan:
    """Plan a frame: per viewport a clear, then a draw of the nodes it shows.

    Ray-traced viewports are traced first (a ``trace`` pass each, saying
    with what); then the frame is planned as the rasterizer draws it, each
    traced image an overlay of its viewport (:func:`traced_scene`).

    Depth is allocated, cleared and tested only when something can hide
    something else (see :func:`_needs_depth`); MSAA only when asked for; the
    stencil only when a pass uses it (a stencil mirror or shadow, :func:`planar_passes`).
    With ``scene.plan_mode == "all"`` every buffer and test that leaves the
    picture unchanged is forced on: the plan is a superset of the needed one.
    """
    ray = [i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"]
    if ray:
        images = {i: Overlay(traced_image_name(i), _PLACEHOLDER, viewport=i, position=(0, 0), scalable=False) for i in ray}
        drawn = plan(traced_scene(scene, images))
        return replace(drawn, passes=(*(_trace_pass(scene, i) for i in ray), *drawn.passes),
                       meshes=tuple(f"{node.name}: {', '.join(node.mesh.notes)}" for node in scene.nodes
                                    if node.mesh.notes),
                       notes=renderer_notes(scene), warnings=mesh_warnings(scene))
    # plan_mode "all": the everything-on baseline. Depth and stencil are allocated
    # and cleared in every viewport, and the depth test runs in every draw pass
    # (unless the scene turned depth testing off, which would change the picture).
    force = scene.plan_mode == "all"
    uses_depth = _needs_depth(scene) or (force and scene.depth_test) or _has_planar_effects(scene)
    programs: set[ProgramVariant] = set()
    passes, shadow_light = shadow_map_passes(scene, programs)
    shadow_pcf = scene.lights[shadow_light].shadow.pcf if shadow_light is not None else 1  # type: ignore[union-attr]
    for index, viewport in enumerate(scene.viewports):
        color = viewport.clear_color if viewport.clear_color is not None else scene.clear_color
        passes.append(Pass("clear", index, clear_color=color, clear_depth=uses_depth,
                           clear_stencil=force or _needs_stencil(scene), camera=None))
        draws, blended = [], []
        for node in scene.nodes:
            if not node.shown_in(index):
                continue
            if scene.mirror is not None and node.name == scene.mirror.node:
                continue  # the mirror's glass is drawn by the mirror passes
            receives = shadow_light if node.receives_shadow and viewport.renderer == "raster" else None
            variant = program_for(node, len(scene.lights), receives, shadow_pcf)
            programs.add(variant)
            texture = node.material.texture
            blend = node.material.alpha_mode == "blend"
            (blended if blend else draws).append(
                (node, Draw(node.name, variant.key, node.cull_back_faces,
                            texture=texture.describe() if texture is not None else None, blend=blend,
                            shadow_map=receives if "SHADOW_LIGHT" in dict(variant.defines) else None)))
        camera = viewport.camera or scene.camera
        draws = [d for _, d in draws] + [d for _, d in _farthest_first(blended, camera)]
        if draws:
            passes.append(Pass("draw", index, draws=tuple(draws), depth_test=uses_depth))
        passes.extend(planar_passes(scene, index, programs))
    overlay_steps = overlay_passes(scene)
    if overlay_steps:
        programs.add(OVERLAY_PROGRAM)
    passes.extend(overlay_steps)
    samples = scene.samples if scene.samples > 1 else 0
    return Plan(
        scene=scene.name,
        buffers=Buffers(depth=uses_depth, stencil=any(p.clear_stencil for p in passes), samples=samples,
                        float_depth=uses_depth and scene.depth_mode == "reverse_z"),
        programs=tuple(sorted(programs)),
        passes=tuple(passes),
        meshes=tuple(f"{node.name}: {', '.join(node.mesh.notes)}" for node in scene.nodes if node.mesh.notes),
        notes=user_shader_notes(scene),
        warnings=mesh_warnings(scene),
    )


def mesh_warnings(scene: Scene) -> tuple[str, ...]:
    """What the scene's model files hold that is not drawn, each line once."""
    return tuple(dict.fromkeys(line for node in scene.nodes for line in node.mesh.warnings))


# --- overlays (labels and figures over the frame) ----------------------------

#: The program that draws overlay images texel for pixel (``shaders/overlay.glsl``).
OVERLAY_PROGRAM = ProgramVariant("overlay")


def overlay_passes(scene: Scene) -> list[Pass]:
    """One ``overlay`` pass per region that has overlays, after every 3D pass.

    The pass lists the overlays by name as draws of the overlay program; its
    viewport is the region they are clipped to (-1: the whole frame). A scene
    without overlays gets no pass and no overlay program.
    """
    if not scene.overlays:
        return []
    regions: dict[int, list[Draw]] = {}
    for overlay in scene.overlays:
        region = -1 if overlay.viewport is None else overlay.viewport
        regions.setdefault(region, []).append(Draw(overlay.name, OVERLAY_PROGRAM.key, False))
    # Viewport regions in order, then the frame-wide ones, which may lie across several viewports.
    order = sorted(regions, key=lambda region: (region < 0, region))
    return [Pass("overlay", region, draws=tuple(regions[region]), camera=None) for region in order]


def describe_overlay_pass(step: Pass) -> str:
    where = "frame" if step.viewport < 0 else f"viewport {step.viewport}"
    return f"overlay {where} (blended, no depth test): " + ", ".join(d.node for d in step.draws)


# --- planar effects: the stencil mirror and the planar shadow (course "The stencil Test") ---

#: Pass kinds that only a scene with a mirror or a shadow receiver gets, in frame order.
PLANAR_PASS_KINDS = ("mark_mirror", "reflection", "mirror_surface", "planar_shadow")
#: The stencil bit of the mirror's pixels, and the bit of pixels already shadowed.
#: Separate bits (with write and compare masks) let both effects share one buffer.
MIRROR_STENCIL_BIT = 0x1
PLANAR_SHADOW_STENCIL_BIT = 0x2
#: ``MarkMirrorDSS``: every fragment of the glass that passes the depth test
#: sets the mirror bit.
MARK_MIRROR_STENCIL = StencilState("always", MIRROR_STENCIL_BIT, write_mask=MIRROR_STENCIL_BIT, on_pass="replace")
#: ``DrawReflectionDSS``: only where the mirror bit is set; the stencil is read, not written.
REFLECTION_STENCIL = StencilState("equal", MIRROR_STENCIL_BIT, mask=MIRROR_STENCIL_BIT)
#: A pixel is darkened only while its shadow bit is clear, and the bit is then set
#: (flipped from 0), so overlapping shadow triangles darken it once.
PLANAR_SHADOW_STENCIL = StencilState("equal", 0, mask=PLANAR_SHADOW_STENCIL_BIT, write_mask=PLANAR_SHADOW_STENCIL_BIT, on_pass="invert")
#: Shadows are drawn in one flat colour.
PLANAR_SHADOW_PROGRAM = ProgramVariant("basic", (("SOLID_COLOR", ""),))
#: A textured cut-out's planar shadow: the flat colour only where its texture's alpha reaches the cutoff.
CUTOUT_SHADOW_PROGRAM = ProgramVariant("basic", (("SOLID_COLOR", ""), ("TEXTURED", ""), ("ALPHA_MASK", ""),
                                                 ("CUTOUT_SHADOW", "")))


def cutout_shadow(material: Any) -> float | None:
    """How a caster's planar shadow is cut out as the part is (drawn with :data:`CUTOUT_SHADOW_PROGRAM`):
    the cutoff its texture's alpha is compared with (the part's alpha is its colour's alpha times the
    texture's), None for a caster that is not a textured cut-out (its whole shadow is drawn), and
    ``inf`` for one cut out everywhere (it casts none)."""
    if material.alpha_mode != "mask":
        return None
    alpha = float(material.color[3]) if len(material.color) > 3 else 1.0
    if material.texture is None:
        return None if alpha >= material.alpha_cutoff else math.inf
    if alpha <= 0.0 or material.alpha_cutoff / alpha > 1.0:
        return math.inf if material.alpha_cutoff > 0.0 else None
    return material.alpha_cutoff / alpha


def caster_program(node: Node, whole: ProgramVariant) -> ProgramVariant | None:
    """The program a caster is drawn with into a planar shadow or a shadow map: ``whole`` (its
    whole shape), :data:`CUTOUT_SHADOW_PROGRAM` for a textured cut-out (its drawn texels only),
    or None for a caster that casts nothing: a blended part (light passes it as a camera ray
    does, glsandbox draws no partial shadows) or a cut-out cut away everywhere. The ray
    engines' shadow rays follow the same rule (:mod:`glsandbox.raytrace.world`)."""
    material = node.material
    if material.alpha_mode == "blend":
        return None
    cut = cutout_shadow(material) if node.mesh.uvs is not None or material.texture is None else None
    if cut == math.inf:
        return None
    return whole if cut is None else CUTOUT_SHADOW_PROGRAM


def cutout_caster_material(material: Material, color: Color) -> Material:
    """What a caster drawn with :data:`CUTOUT_SHADOW_PROGRAM` is drawn with: one flat ``color``,
    the part's texture, and the cutoff its texels' alpha must reach (:func:`cutout_shadow`)."""
    cutoff = cutout_shadow(material)
    return Material(color=color, texture=material.texture, alpha_mode="mask",
                    alpha_cutoff=float(cutoff) if cutoff is not None else 0.0)


def _has_planar_effects(scene: Scene) -> bool:
    return scene.mirror is not None or scene.planar_shadow is not None


def _needs_stencil(scene: Scene) -> bool:
    """The stencil buffer exists only for a stencil mirror or a stencil shadow."""
    return bool((scene.mirror is not None and scene.mirror.stencil)
                or (scene.planar_shadow is not None and scene.planar_shadow.stencil))


def planar_passes(scene: Scene, index: int, programs: set[ProgramVariant]) -> list[Pass]:
    """The mirror's and the shadow's passes for viewport ``index``, after its draw pass.

    Mirror (stencil): ``mark_mirror`` draws the glass into the stencil only
    (colour and depth writes off, depth test on, so what stands in front of
    the glass keeps its pixels unmarked; the course's ``MarkMirrorDSS``);
    ``reflection`` draws the reflected nodes with R @ model where the stencil
    holds the mirror bit (``DrawReflectionDSS``), with the front-face rule
    flipped (det R = -1, ``CullClockwise``) and the lights reflected too;
    ``mirror_surface`` blends the glass over it. Without the stencil the
    reflection pass has no stencil test and leaks outside the glass.

    Shadow: one ``shadow`` pass drawing the casters with the lifted shadow
    matrix, blended, without depth writes and without culling (the flattened
    cube's front and back faces both cover the shadow). With the stencil each
    pixel is darkened once: test "shadow bit clear", then set it.
    """
    if not _has_planar_effects(scene):
        return []
    nodes = {node.name: node for node in scene.nodes}
    passes: list[Pass] = []
    mirror = scene.mirror
    if mirror is not None and mirror.node in nodes and nodes[mirror.node].shown_in(index):
        glass = nodes[mirror.node]
        glass_variant = program_for(glass, len(scene.lights))
        programs.add(glass_variant)
        glass_draw = Draw(glass.name, glass_variant.key, glass.cull_back_faces)
        if mirror.stencil:
            passes.append(Pass("mark_mirror", index, draws=(glass_draw,), depth_test=True,
                               stencil=MARK_MIRROR_STENCIL))
        reflected, blended = [], []
        for name in mirror.reflected:
            if name not in nodes:
                raise SandboxError(f"mirror reflects {name!r}, which is not a node of the scene")
            node = nodes[name]
            if node.shown_in(index):
                variant = program_for(node, len(scene.lights))  # a cut-out's ALPHA_MASK too, as in the main pass
                programs.add(variant)
                blend = node.material.alpha_mode == "blend"
                (blended if blend else reflected).append((node, Draw(name, variant.key, node.cull_back_faces,
                                                                     blend=blend)))
        # Blended parts after the opaque ones, farthest first as seen in the mirror: from the eye's
        # mirror image (the reflection is an isometry, so its distances are the reflected ones).
        mirrored = _mirrored_eye(mirror, scene.viewports[index].camera or scene.camera)
        reflected = [d for _, d in reflected] + [d for _, d in _farthest_first(blended, mirrored)]
        passes.append(Pass("reflection", index, draws=tuple(reflected), depth_test=True,
                           stencil=REFLECTION_STENCIL if mirror.stencil else None,
                           detail="front faces clockwise, lights reflected"))
        passes.append(Pass("mirror_surface", index, draws=(glass_draw,), depth_test=True, detail="blended"))
    shadow = scene.planar_shadow
    if shadow is not None and shadow.receiver in nodes and nodes[shadow.receiver].shown_in(index):
        models = {name: (nodes[name].model, nodes[name].mesh.positions) for name in shadow.casters if name in nodes}
        from glsandbox.planar import shadow_casters  # loaded already: the scene holds a PlanarShadow

        casting = shadow_casters(shadow, models)
        how = [f"lift {shadow.lift:g}"]
        if shadow.polygon_offset:
            how.append("polygon offset")
        how.append("blended, no depth writes")
        culled = [f"{name} culled ({why})" for name, why in casting.culled]
        if casting.reason:
            culled.append(f"culled: {casting.reason}")
        draws = []
        for name in casting.kept:
            if not nodes[name].shown_in(index):
                continue
            variant = caster_program(nodes[name], PLANAR_SHADOW_PROGRAM)
            if variant is None:
                continue  # blended, or cut out everywhere: it casts nothing
            programs.add(variant)
            draws.append(Draw(name, variant.key, False))
        passes.append(Pass("planar_shadow", index, draws=tuple(draws), depth_test=True,
                           stencil=PLANAR_SHADOW_STENCIL if shadow.stencil else None,
                           detail="; ".join([", ".join(how), *culled])))
    return passes


_PLANAR_TITLES = {"mark_mirror": "mark mirror", "reflection": "reflection", "mirror_surface": "mirror surface",
                  "planar_shadow": "planar shadow"}


def describe_planar_pass(step: Pass) -> str:
    what = ["depth test" if step.depth_test else "no depth test"]
    if step.kind == "mark_mirror":
        what.append("no colour or depth writes")
    if step.stencil is not None:
        what.append(f"stencil {step.stencil.describe()}")
    elif step.kind in ("reflection", "planar_shadow"):
        what.append("no stencil")
    if step.detail:
        what.append(step.detail)
    return f"{_PLANAR_TITLES[step.kind]} viewport {step.viewport} ({', '.join(what)}): {describe_draws(step)}"


# --- shadow maps (glsandbox.shadowmap) ----------------------------------------

#: The texture unit a receiver's shadow map is bound to (unit 0 is the material's texture).
SHADOW_MAP_UNIT = 1
#: Casters are drawn into the map with the flat program (a textured cut-out with
#: :data:`CUTOUT_SHADOW_PROGRAM`, a blended one not at all: :func:`caster_program`); only their depth is kept.
DEPTH_PROGRAM = ProgramVariant("basic", (("SOLID_COLOR", ""),))


def shadow_map_passes(scene: Scene, programs: set[ProgramVariant]) -> tuple[list[Pass], int | None]:
    """The depth-only pass of the shadow-casting light, before every viewport,
    and that light's index; none (and None) when no light casts a shadow map or
    no visible lit node receives it: the map would be drawn for nobody."""
    light = casting_light(scene)
    if light is None or not receivers(scene):
        return [], None
    shadow = scene.lights[light].shadow
    assert shadow is not None
    draws = []
    for node in casters(scene):
        variant = caster_program(node, DEPTH_PROGRAM)  # a cut-out's depth only where it is drawn
        if variant is not None:
            programs.add(variant)
            draws.append(Draw(node.name, variant.key, node.cull_back_faces))
    detail = f"{shadow.size}x{shadow.size} depth 24, perspective {shadow.fov:g}°"
    return [Pass("shadow_map", -1, clear_depth=True, draws=tuple(draws), depth_test=True, detail=detail,
                 target=f"shadow map {light}", camera=f"light {light}")], light


def describe_shadow_map_pass(step: Pass) -> str:
    return (f"shadow map from {step.camera} into {step.target} ({step.detail}, cleared, depth test, "
            f"no colour): {describe_draws(step)}")


#: One describer per pass kind; a new kind adds its entry here and its runner in
#: :data:`glsandbox.gl.executor.PASS_RUNNERS` (a test checks both registries agree).
PASS_DESCRIBERS: dict[str, Callable[[Pass], str]] = {
    "trace": describe_trace_pass,
    "shadow_map": describe_shadow_map_pass,
    "clear": describe_clear_pass,
    "draw": describe_draw_pass,
    **{kind: describe_planar_pass for kind in PLANAR_PASS_KINDS},
    "overlay": describe_overlay_pass,
}
#: Every pass kind, in frame order.
PASS_KINDS = tuple(PASS_DESCRIBERS)
