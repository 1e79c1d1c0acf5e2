"""The precision knobs of ``glsandbox tradeoffs`` (issue 21) measure what they say:
the simple shadow offset loses the contact shadow far from the origin and the
error bound does not; world-space float32 differs from float64 at 1e5 and
anchored coordinates do not; cheap settings' medians are judged stable."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from glsandbox.measure import metrics
from glsandbox.measure.knob import all_knobs, median_spread
from glsandbox.measure.knobs import ray_engine, shadow_offset
from glsandbox.measure.render_context import RenderContext


def test_the_precision_knobs_are_registered() -> None:
    names = [knob.name for knob in all_knobs()]
    assert "shadow_offset" in names and "ray_engine" in names


def test_shadow_offset_counts_the_lost_contact_shadow() -> None:
    context = RenderContext((96, 72))
    counts = {s.label: s.count(context) for s in (*shadow_offset.KNOB.settings, shadow_offset.KNOB.reference)}
    reference = counts["error bound, at 1"]
    assert reference.pixels == 0 and reference.of > 150
    assert counts["simple 2^-16*|P|, at 1"].pixels <= 0.05 * reference.of
    assert counts["simple 2^-16*|P|, at 100000"].share > 0.9  # the shadow is gone
    assert counts["error bound, at 100000"].pixels == 0 and counts["error bound, at 1e+06"].pixels == 0


def test_world_space_float32_differs_far_away_and_anchored_does_not(gl) -> None:
    context = SimpleNamespace(renderer=gl, size=(160, 120))
    context.ray = lambda scene, engine="numpy", **kw: RenderContext.ray(context, scene, engine, **kw)
    settings = {s.label: s for s in ray_engine.KNOB.settings}
    reference = ray_engine.KNOB.reference.render(context)
    far = np.asarray(settings["gpu world-space float32, at 1e5"].render(context))
    anchored = np.asarray(settings["gpu, at 1e5"].render(context))
    assert metrics.rmse(reference, anchored) < 0.2 * metrics.rmse(reference, far)
    assert np.count_nonzero(np.abs(far.astype(int) - reference.astype(int)).max(axis=-1) > 3) > 20


@pytest.mark.parametrize("times, stable", [([1.0, 1.0, 1.02, 0.99, 1.0, 1.01], True),
                                           ([0.5, 3.0, 0.5, 3.1, 0.6, 2.9], False)])
def test_median_spread_tells_a_stable_median(times, stable) -> None:
    assert (median_spread(times) < 0.05) is stable
