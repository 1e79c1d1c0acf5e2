"""The ray tracer itself: the float32 GLSL engine against the float64 numpy
engine, with shadow rays on (the course's "Gölge testi"), at the origin and
with the scene moved far from it: world-space float32 against coordinates
taken relative to the scene's centre in float64 before the rounding."""

from __future__ import annotations

from glsandbox.measure.knob import Knob, Setting, register_knob
from glsandbox.measure.knobs._far import moved
from glsandbox.measure.knobs.lighting import lit
from glsandbox.measure.render_context import RenderContext


def world_space(c: RenderContext, at: float):  # type: ignore[no-untyped-def]
    """The gpu engine tracing world coordinates in float32 (``relative=False``)."""
    from glsandbox.raytrace.gpu import gpu_tracer

    return gpu_tracer(c.renderer.host.ctx).render_viewport(moved(lit("phong"), at), c.size, relative=False).copy()


KNOB = register_knob(Knob(
    name="ray_engine",
    title="Ray tracer engine",
    order=30,
    scene="phong at time 1.0, ray-traced with shadow rays; moved along (0.99, 0.7, -0.4) by the distance given",
    settings=(
        Setting("gpu (GLSL, float32)", lambda c: c.ray(lit("phong"), "gpu")),
        Setting("gpu, at 1e5", lambda c: c.ray(moved(lit("phong"), 1e5), "gpu"),
                "positions relative to the scene's centre, subtracted in float64 (the default)"),
        Setting("gpu, at 1e6", lambda c: c.ray(moved(lit("phong"), 1e6), "gpu")),
        Setting("gpu world-space float32, at 1e3", lambda c: world_space(c, 1e3)),
        Setting("gpu world-space float32, at 1e5", lambda c: world_space(c, 1e5),
                "float32 spacing is 0.0078 at 1e5: triangles, boxes and the eye move by that"),
    ),
    reference=Setting("numpy (float64)", lambda c: c.ray(lit("phong"), "numpy")),
    reference_note="the numpy engine in float64 at the origin, same algorithm and scene",
    quick=("gpu (GLSL, float32)", "gpu, at 1e5", "gpu world-space float32, at 1e5"),
))
