"""The ray-engine knob (glsandbox/measure/knobs/ray_engine.py): world-space float32 differs from
float64 at 1e5, and anchored coordinates do not."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from glsandbox.measure import metrics
from glsandbox.measure.knobs import ray_engine
from glsandbox.measure.render_context import RenderContext


def test_world_space_float32_differs_far_away_and_anchored_does_not(gl) -> None:
    context = SimpleNamespace(renderer=gl, size=(160, 120))
    context.ray = lambda scene, engine="numpy", **kw: RenderContext.ray(context, scene, engine, **kw)
    settings = {s.label: s for s in ray_engine.KNOB.settings}
    reference = ray_engine.KNOB.reference.render(context)
    far = np.asarray(settings["gpu world-space float32, at 1e5"].render(context))
    anchored = np.asarray(settings["gpu, at 1e5"].render(context))
    assert metrics.rmse(reference, anchored) < 0.2 * metrics.rmse(reference, far)
    assert np.count_nonzero(np.abs(far.astype(int) - reference.astype(int)).max(axis=-1) > 3) > 20


def test_ray_engine_counts_the_pixels_off_far_from_the_origin(gl) -> None:
    from glsandbox.frame import LazyRenderer

    context = RenderContext((96, 72))
    context.gl = LazyRenderer(renderer=gl)  # the session's context: never a second one in this process
    settings = {s.label: s for s in ray_engine.KNOB.settings}
    off = {label: settings[label].count(context) for label in
           ("gpu, at 1e5", "gpu world-space float32, at 1e5", "numpy (float64), at 1e5")}
    assert ray_engine.KNOB.reference.count(context).pixels == 0
    assert off["gpu world-space float32, at 1e5"].pixels > 10 and off["gpu world-space float32, at 1e5"].of == 96 * 72
    assert off["numpy (float64), at 1e5"].pixels <= 2
    assert off["gpu, at 1e5"].pixels < 0.2 * off["gpu world-space float32, at 1e5"].pixels
