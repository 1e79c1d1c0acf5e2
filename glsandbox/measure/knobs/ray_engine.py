"""The ray tracer itself: the float32 GLSL engine against the float64 numpy
engine, with shadow rays on (the course's "Gölge testi"), at the origin and
with the scene moved far from it: world-space float32 against coordinates
taken relative to the scene's centre in float64 before the rounding."""

from __future__ import annotations

import weakref
from collections.abc import Callable

import numpy as np

from glsandbox.measure.knob import Knob, PixelCount, Setting, register_knob
from glsandbox.measure.knobs._far import moved
from glsandbox.measure.knobs.lighting import lit
from glsandbox.measure.render_context import RenderContext

#: A pixel is off when a channel differs from the reference's by more than this many levels.
OFF_LEVELS = 3
#: Per render context: the reference frame (rendered once per run).
_REFERENCE: weakref.WeakKeyDictionary[RenderContext, np.ndarray] = weakref.WeakKeyDictionary()


def world_space(c: RenderContext, at: float):  # type: ignore[no-untyped-def]
    """The gpu engine tracing world coordinates in float32 (``relative=False``)."""
    from glsandbox.raytrace.gpu import gpu_tracer

    return gpu_tracer(c.renderer.host.ctx).render_viewport(moved(lit("phong"), at), c.size, relative=False).copy()


def reference(c: RenderContext) -> np.ndarray:
    """The numpy engine's frame at the origin (float64)."""
    return np.asarray(c.ray(lit("phong"), "numpy"))


def pixels_off(render: Callable[[RenderContext], np.ndarray]) -> Callable[[RenderContext], PixelCount]:
    """Counts the pixels of ``render``'s frame more than :data:`OFF_LEVELS` away from the reference's."""

    def count(c: RenderContext) -> PixelCount:
        if c not in _REFERENCE:
            _REFERENCE[c] = reference(c)
        want = _REFERENCE[c][..., :3].astype(int)
        got = np.asarray(render(c))[..., :3].astype(int)
        off = np.abs(got - want).max(axis=-1) > OFF_LEVELS
        return PixelCount(int(np.count_nonzero(off)), off.size)

    return count


def setting(label: str, render: Callable[[RenderContext], np.ndarray], note: str = "") -> Setting:
    return Setting(label, render, note, pixels_off(render))


KNOB = register_knob(Knob(
    name="ray_engine",
    title="Ray tracer engine",
    order=30,
    scene="phong at time 1.0, ray-traced with shadow rays; moved along (0.99, 0.7, -0.4) by the distance given",
    settings=(
        setting("gpu (GLSL, float32)", lambda c: c.ray(lit("phong"), "gpu")),
        setting("gpu, at 1e5", lambda c: c.ray(moved(lit("phong"), 1e5), "gpu"),
                "positions relative to the scene's centre, subtracted in float64 (the default)"),
        setting("gpu, at 1e6", lambda c: c.ray(moved(lit("phong"), 1e6), "gpu")),
        setting("gpu world-space float32, at 1e3", lambda c: world_space(c, 1e3)),
        setting("gpu world-space float32, at 1e5", lambda c: world_space(c, 1e5),
                "float32 spacing is 0.0078 at 1e5: triangles, boxes and the eye move by that"),
        setting("numpy (float64), at 1e5", lambda c: c.ray(moved(lit("phong"), 1e5), "numpy")),
    ),
    reference=setting("numpy (float64)", reference),
    reference_note="the numpy engine in float64 at the origin, same algorithm and scene",
    quick=("gpu (GLSL, float32)", "gpu, at 1e5", "gpu world-space float32, at 1e5"),
    count_label="px off",
    count_of="px",
    notes=(
        f"px off: pixels whose colour differs from the reference's by more than {OFF_LEVELS} levels in a "
        "channel (the whole frame counts).",
        "Moved far from the origin, world-space float32 rounds every corner, box and the eye to float32's "
        "spacing there (0.0078 at 1e5): edges move and shadow rays start off their surface. The gpu "
        "engine's default takes positions relative to the scene's centre in float64 before rounding, "
        "and draws the same frame as at the origin.",
    ),
))
