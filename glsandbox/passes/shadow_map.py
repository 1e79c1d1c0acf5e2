"""The ``shadow_map`` pass: the casters' depth as the shadow-casting light sees it
(course "The stencil Test", then shadow maps: :mod:`glsandbox.shadowmap`)."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant, describe_draws
from glsandbox.passes.planar_effects import caster_program
from glsandbox.scene import Scene
from glsandbox.shadowmap import casters, casting_light, receivers

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


def describe(step: Pass) -> str:
    return (f"shadow map from {step.camera} into {step.target} ({step.detail}, cleared, depth test, "
            f"no colour): {describe_draws(step)}")


