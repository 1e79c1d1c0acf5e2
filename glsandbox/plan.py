"""Scene -> Plan: only the passes, shader variants and buffers a scene needs.

This is how "simulate only the effects a scene calls for" stays honest: the
plan is a pure function of the Scene, printed by ``glsandbox plan LESSON`` and
pinned per lesson by a test. Nothing in here touches GL; the executor in
:mod:`glsandbox.gl.executor` runs a plan as written, and allocates only the
buffers the plan lists. Each pass kind's planner and describer is its module
of :mod:`glsandbox.passes`; the shader variants are :mod:`glsandbox.plan_variants`'s,
the notes :mod:`glsandbox.plan_notes`'s.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from glsandbox.geometry import Mesh
from glsandbox.overlay import Overlay
from glsandbox.passes import PASS_KINDS
from glsandbox.passes.clear import clear_pass
from glsandbox.passes.draw import draw_pass
from glsandbox.passes.mark_mirror import mark_mirror_pass
from glsandbox.passes.mirror_surface import mirror_surface_pass
from glsandbox.passes.order import farthest_first, mirrored_eye
from glsandbox.passes.overlay import OVERLAY_PROGRAM, overlay_passes
from glsandbox.passes.plan_parts import SHADOW_MAP_UNIT, Draw, Pass, ProgramVariant, StencilState, describe_draws
from glsandbox.passes.planar_effects import (CUTOUT_SHADOW_PROGRAM, MARK_MIRROR_STENCIL, MIRROR_STENCIL_BIT,
                                             PLANAR_SHADOW_PROGRAM, PLANAR_SHADOW_STENCIL,
                                             PLANAR_SHADOW_STENCIL_BIT, REFLECTION_STENCIL, caster_program,
                                             cutout_caster_material, cutout_shadow, has_planar_effects,
                                             needs_stencil)
from glsandbox.passes.planar_shadow import planar_shadow_pass
from glsandbox.passes.reflection import reflection_pass
from glsandbox.passes.shadow_map import DEPTH_PROGRAM, shadow_map_passes
from glsandbox.passes.trace import (TRACE_OPTIONS, TRACED_SHADING, TRACERS, trace_pass, traced_image_name,
                                    traced_reflectivity, traced_scene)
from glsandbox.plan_notes import ignored_settings_notes, renderer_notes, user_shader_note, user_shader_notes
from glsandbox.plan_variants import lit_program_for, program_for
from glsandbox.scene import Node, Scene, _copy_with

#: The names other modules, lessons and tests import from here (defined in the modules above).
__all__ = ["Buffers", "Plan", "plan", "motion_decisions", "mesh_warnings", "planar_passes", "PASS_KINDS",
           "SHADOW_MAP_UNIT", "Draw", "Pass", "ProgramVariant", "StencilState", "describe_draws",
           "OVERLAY_PROGRAM", "overlay_passes", "CUTOUT_SHADOW_PROGRAM", "MARK_MIRROR_STENCIL",
           "MIRROR_STENCIL_BIT", "PLANAR_SHADOW_PROGRAM", "PLANAR_SHADOW_STENCIL", "PLANAR_SHADOW_STENCIL_BIT",
           "REFLECTION_STENCIL", "caster_program", "cutout_caster_material", "cutout_shadow", "DEPTH_PROGRAM",
           "shadow_map_passes", "TRACE_OPTIONS", "TRACED_SHADING", "TRACERS", "traced_image_name",
           "traced_reflectivity", "traced_scene", "ignored_settings_notes", "renderer_notes", "user_shader_note",
           "user_shader_notes", "lit_program_for", "program_for"]


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



def motion_decisions(scene: Scene, models: Mapping[str, Any] | None = None) -> tuple:
    """What of :func:`plan`'s answer depends on where nodes, lights and cameras are: the order
    of each viewport's blended draws (:func:`glsandbox.passes.order.distance`) and which casters the planar shadow
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
        decisions.append(tuple(node.name for node, _ in farthest_first(pairs, viewports[index].camera or scene.camera)))
    for index, shown in reflected:  # the blended nodes the mirror reflects, in their order seen in it
        eye = mirrored_eye(scene.mirror, viewports[index].camera or scene.camera)
        pairs = [(nodes[i], None) for i in shown]
        decisions.append(("mirror", tuple(node.name for node, _ in farthest_first(pairs, eye))))
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



_PLACEHOLDER = np.zeros((1, 1, 4), dtype=np.uint8)


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
        return _traced_plan(scene, ray)
    # plan_mode "all": the everything-on baseline. Depth and stencil are allocated
    # and cleared in every viewport, and the depth test runs in every draw pass
    # (unless the scene turned depth testing off, which would change the picture).
    force = scene.plan_mode == "all"
    uses_depth = _needs_depth(scene) or (force and scene.depth_test) or has_planar_effects(scene)
    programs: set[ProgramVariant] = set()
    passes, shadow_light = shadow_map_passes(scene, programs)
    shadow_pcf = scene.lights[shadow_light].shadow.pcf if shadow_light is not None else 1  # type: ignore[union-attr]
    for index in range(len(scene.viewports)):
        passes.append(clear_pass(scene, index, uses_depth, force or needs_stencil(scene)))
        drawn = draw_pass(scene, index, uses_depth, programs, shadow_light, shadow_pcf)
        if drawn is not None:
            passes.append(drawn)
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
        meshes=mesh_notes(scene),
        notes=user_shader_notes(scene),
        warnings=mesh_warnings(scene),
    )


def _traced_plan(scene: Scene, ray: list[int]) -> Plan:
    """The plan of a scene with ray-traced viewports ``ray``: their ``trace`` passes, then
    the plan of the frame the rasterizer draws with their pictures as overlays."""
    images = {i: Overlay(traced_image_name(i), _PLACEHOLDER, viewport=i, position=(0, 0), scalable=False) for i in ray}
    drawn = plan(traced_scene(scene, images))
    return replace(drawn, passes=(*(trace_pass(scene, i) for i in ray), *drawn.passes),
                   meshes=mesh_notes(scene), notes=renderer_notes(scene), warnings=mesh_warnings(scene))


def mesh_notes(scene: Scene) -> tuple[str, ...]:
    """``node: notes`` for each node whose mesh has notes (:attr:`Plan.meshes`)."""
    return tuple(f"{node.name}: {', '.join(node.mesh.notes)}" for node in scene.nodes if node.mesh.notes)


def mesh_warnings(scene: Scene) -> tuple[str, ...]:
    """What the scene's model files hold that is not drawn, each line once."""
    return tuple(dict.fromkeys(line for node in scene.nodes for line in node.mesh.warnings))


def planar_passes(scene: Scene, index: int, programs: set[ProgramVariant]) -> list[Pass]:
    """The mirror's and the shadow's passes for viewport ``index``, after its draw pass
    (course "The stencil Test"): with a stencil mirror ``mark_mirror``, then ``reflection``
    and ``mirror_surface``; then ``planar_shadow``. Each shown only where its glass or
    receiver is shown; their variants are added to ``programs``."""
    if not has_planar_effects(scene):
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
            passes.append(mark_mirror_pass(index, glass_draw))
        passes.append(reflection_pass(scene, index, nodes, programs))
        passes.append(mirror_surface_pass(index, glass_draw))
    shadow = scene.planar_shadow
    if shadow is not None and shadow.receiver in nodes and nodes[shadow.receiver].shown_in(index):
        passes.append(planar_shadow_pass(scene, index, nodes, programs))
    return passes
