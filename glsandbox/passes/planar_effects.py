"""What the planar passes share: the stencil mirror and the planar shadow (course "The stencil Test").

The mirror is three pass kinds (``mark_mirror``, ``reflection``, ``mirror_surface``),
the shadow one (``planar_shadow``); here are their stencil states, the programs
casters are drawn with, and the line their describers print.
"""

from __future__ import annotations

import math
from typing import Any

from glsandbox.passes.plan_parts import Pass, ProgramVariant, StencilState, describe_draws
from glsandbox.scene import Color, Material, Node, Scene

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


def has_planar_effects(scene: Scene) -> bool:
    return scene.mirror is not None or scene.planar_shadow is not None


def needs_stencil(scene: Scene) -> bool:
    """The stencil buffer exists only for a stencil mirror or a stencil shadow."""
    return bool((scene.mirror is not None and scene.mirror.stencil)
                or (scene.planar_shadow is not None and scene.planar_shadow.stencil))



def describe_planar(step: Pass, title: str) -> str:
    """A planar pass's line: ``title``, its depth test, its stencil state and its detail."""
    what = ["depth test" if step.depth_test else "no depth test"]
    if step.kind == "mark_mirror":
        what.append("no colour or depth writes")
    if step.stencil is not None:
        what.append(f"stencil {step.stencil.describe()}")
    elif step.kind in ("reflection", "planar_shadow"):
        what.append("no stencil")
    if step.detail:
        what.append(step.detail)
    return f"{title} viewport {step.viewport} ({', '.join(what)}): {describe_draws(step)}"
