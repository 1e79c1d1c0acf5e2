"""The ``planar_shadow`` pass: the casters flattened onto the receiver's plane (course "The
stencil Test", ``XMMatrixShadow``), lifted, blended, without depth writes and without culling
(the flattened cube's front and back faces both cover the shadow). With the stencil each
pixel is darkened once: test "shadow bit clear", then set it."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant
from glsandbox.passes.planar_effects import (PLANAR_SHADOW_PROGRAM, PLANAR_SHADOW_STENCIL, caster_program,
                                             describe_planar)
from glsandbox.scene import Node, Scene


def planar_shadow_pass(scene: Scene, index: int, nodes: dict[str, Node], programs: set[ProgramVariant]) -> Pass:
    """Viewport ``index``'s planar shadow (``nodes``: the scene's by name), adding its variants to ``programs``."""
    shadow = scene.planar_shadow
    assert shadow is not None
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
    return Pass("planar_shadow", index, draws=tuple(draws), depth_test=True,
                stencil=PLANAR_SHADOW_STENCIL if shadow.stencil else None,
                detail="; ".join([", ".join(how), *culled]))


def describe(step: Pass) -> str:
    return describe_planar(step, "planar shadow")
