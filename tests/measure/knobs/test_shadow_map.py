"""The shadow-map knob of ``glsandbox tradeoffs`` (glsandbox/measure/knobs/shadow_map.py):
its settings and its wrong-state count, measured at a small size against the ray tracer (far
away and at small scale on both headless backends: support.on_backend)."""

from __future__ import annotations

from support import on_backend, shadow_knob_counts

from glsandbox.frame import LazyRenderer
from glsandbox.measure.knob import all_knobs
from glsandbox.measure.render_context import RenderContext


def knob():
    return next(k for k in all_knobs() if k.name == "shadow_map")


def test_the_knob_lists_planar_and_every_map_size_with_and_without_pcf():
    labels = [s.label for s in knob().settings]
    assert labels[0] == "planar shadow (stencil)"
    assert labels[1:9] == [f"shadow map {size}, PCF {pcf}" for size in (256, 512, 1024, 2048) for pcf in (1, 3)]
    assert labels[9:] == [f"shadow map 1024, PCF 3, {where}" for where in ("at 1e5", "at 9e5", "x1e-4 at 1e3")]
    assert set(knob().quick) <= set(labels) and knob().count_label == "wrong-state px"


def test_wrong_state_pixels_fall_with_the_map_size_and_the_planar_shadow_misses_most(gl):
    context = RenderContext((192, 144))
    context.gl = LazyRenderer(renderer=gl)  # the session's renderer, shared (not closed here)
    settings = {s.label: s for s in knob().settings}
    counts = {label: settings[label].count(context) for label in
              ("planar shadow (stencil)", "shadow map 256, PCF 1", "shadow map 2048, PCF 1")}
    planar, coarse, fine = (counts[k].pixels for k in counts)
    # The planar shadow misses the sphere's shadow on the cube; a small map's stairs
    # stray further from the exact edge than a large map's.
    assert planar > coarse > fine > 0, counts
    assert all(c.of == 192 * 144 for c in counts.values())


def test_the_default_map_gives_the_origin_s_states_far_away_and_at_small_scale(backend, gl):
    default = "shadow map 1024, PCF 3"
    labels = (default, *(f"{default}, {where}" for where in ("at 1e5", "at 9e5", "x1e-4 at 1e3")))
    [counts] = on_backend(backend, gl, [(shadow_knob_counts, ((192, 144), labels))])
    here = counts[default].pixels
    for label in labels[1:]:
        there = counts[label].pixels
        assert abs(there - here) <= 0.1 * here + 5, (backend, label, there, here)
