"""Texture filtering (course section "Texture Mapping"): the checkered ground at
a grazing angle, from nearest to anisotropic, against anisotropic at 8x8
supersampling."""

from __future__ import annotations

from glsandbox.measure.knob import Knob, Setting, lesson_scene, register_knob
from glsandbox.measure.render_context import REFERENCE_FACTOR as REF
from glsandbox.scene import Scene


def textured(filter_name: str) -> Scene:
    return lesson_scene("texture", time=0.0, filter=filter_name)


KNOB = register_knob(Knob(
    name="texture_filter",
    title="Texture filtering",
    order=40,
    scene="texture at time 0 (checkered ground at a grazing angle, labelled cube)",
    settings=(
        Setting("nearest", lambda c: c.raster(textured("nearest"))),
        Setting("linear", lambda c: c.raster(textured("linear"))),
        Setting("mipmapped (nearest level)", lambda c: c.raster(textured("mip_nearest"))),
        Setting("mipmapped (trilinear)", lambda c: c.raster(textured("mip_linear"))),
        Setting("anisotropic 16x", lambda c: c.raster(textured("anisotropic"))),
    ),
    reference=Setting(f"anisotropic, SSAA {REF}x", lambda c: c.raster(textured("anisotropic"), factor=REF)),
    reference_note=f"anisotropic 16x filtering at {REF}x supersampling",
    quick=("nearest", "linear", "mipmapped (trilinear)", "anisotropic 16x"),
    monotone=("nearest", "mipmapped (trilinear)", "anisotropic 16x"),
))
