"""The ray tracer itself: the float32 GLSL engine against the float64 numpy
engine, with shadow rays on (the course's "Gölge testi")."""

from __future__ import annotations

from glsandbox.measure.knob import Knob, Setting, register_knob
from glsandbox.measure.knobs.lighting import lit

KNOB = register_knob(Knob(
    name="ray_engine",
    title="Ray tracer engine",
    order=30,
    scene="phong at time 1.0, ray-traced with shadow rays",
    settings=(Setting("gpu (GLSL, float32)", lambda c: c.ray(lit("phong"), "gpu")),),
    reference=Setting("numpy (float64)", lambda c: c.ray(lit("phong"), "numpy")),
    reference_note="the numpy engine in float64, same algorithm and scene",
))
