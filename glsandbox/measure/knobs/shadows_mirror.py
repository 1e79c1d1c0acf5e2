"""The planar shadow matrix and the stencil mirror (course section "The stencil
Test") against the ray tracer's shadows and reflections."""

from __future__ import annotations

from typing import Any

from glsandbox.measure.knob import Knob, Setting, lesson_scene, register_knob
from glsandbox.scene import Scene


def room(**values: Any) -> Scene:
    return lesson_scene("mirror", time=1.0, **values)


KNOB = register_knob(Knob(
    name="shadows_mirror",
    title="Planar shadow and stencil mirror vs the ray tracer",
    order=60,
    scene="mirror at time 1.0 (the room, the stencil mirror in the back wall, the cube's planar shadow)",
    settings=(
        Setting("raster: stencil mirror + planar shadow", lambda c: c.raster(room()),
                "the lesson's default: reflection matrix + stencil, shadow matrix + stencil"),
        Setting("raster: stencil mirror, no shadow", lambda c: c.raster(room(shadow="off"))),
        Setting("raster: opaque glass, planar shadow", lambda c: c.raster(room(mirror="off"))),
        Setting("raster: mirror without stencil (leaks)", lambda c: c.raster(room(mirror="no_stencil"))),
        Setting("raster: shadow blended twice", lambda c: c.raster(room(shadow="double_blend"))),
        Setting("ray tracer, gpu (GLSL, float32)", lambda c: c.ray(room(), "gpu")),
    ),
    reference=Setting("ray tracer, numpy (float64)", lambda c: c.ray(room(), "numpy")),
    reference_note=("the float64 numpy ray tracer on the same scene: shadow rays towards the light from "
                    "every hit, the glass reflecting 1 - alpha = 0.75 of a traced reflected ray (up to 2 "
                    "bounces), one ray per pixel"),
    quick=("raster: stencil mirror + planar shadow", "raster: stencil mirror, no shadow",
           "raster: opaque glass, planar shadow", "ray tracer, gpu (GLSL, float32)"),
    notes=(
        "The two renderers model different things, so part of the raster error is not a fault of the "
        "matrices: the planar shadow is the cube alone flattened onto the floor's plane (not onto the "
        "walls, and nothing else casts one), drawn black at alpha 0.5 over the lit floor, so a shadowed "
        "pixel keeps half its diffuse and specular light and half its ambient; the ray tracer's shadow "
        "comes from every object onto every surface and keeps the ambient term only.",
        "The stencil mirror reflects the floor, the left wall, the cube and the light, without their "
        "shadow (the shadow pass draws on the real floor only) and with one bounce; the traced glass "
        "reflects everything in front of it, shadows included, up to 2 bounces.",
        "So the double-blended shadow (a mistake: overlapping triangles darken twice) scores a lower FLIP "
        "than the stencil's: darker, it comes nearer the traced ambient-only shadow.",
        "Both shade per pixel with the same formula and draw the same triangles, so the rest is edge "
        "sampling and float32; the gpu engine's row is that alone.",
    ),
))
