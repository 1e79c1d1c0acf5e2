"""Lighting model (course sections "Phong boyama modeli", "Lighting"): per-vertex,
per-pixel Phong and Blinn-Phong in the rasterizer, against the course's formula
evaluated exactly per pixel by the float64 ray tracer."""

from __future__ import annotations

from glsandbox.measure.knob import Knob, Setting, lesson_scene, register_knob
from glsandbox.scene import Scene


def lit(shading: str) -> Scene:
    """The phong lesson at time 1 with the given shading (shared with the ray engine knob)."""
    return lesson_scene("phong", time=1.0, shading=shading)


KNOB = register_knob(Knob(
    name="lighting",
    title="Lighting model",
    order=20,
    scene="phong at time 1.0 (lit ground and ellipsoid, two orbiting lights)",
    settings=(
        Setting("per-vertex (Gouraud)", lambda c: c.raster(lit("gouraud"))),
        Setting("per-pixel Phong", lambda c: c.raster(lit("phong"))),
        Setting("Blinn-Phong", lambda c: c.raster(lit("blinn_phong"))),
    ),
    reference=Setting("ray tracer, float64", lambda c: c.ray(lit("phong"), "numpy", shadows=False)),
    reference_note=("the float64 numpy ray tracer (glsandbox.raytrace.render, engine=numpy), one ray per "
                    "pixel, shadow rays off (the rasterizer draws no shadows; this knob is about the "
                    "lighting model). Its shading is the course's formula evaluated exactly per pixel, "
                    "so per-pixel Phong's error is edge sampling and float32 only"),
))
