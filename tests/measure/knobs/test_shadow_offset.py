"""The shadow-offset knob (glsandbox/measure/knobs/shadow_offset.py): the simple offset loses the
contact shadow far from the origin, and the error bound does not."""

from __future__ import annotations

from glsandbox.measure.knobs import shadow_offset
from glsandbox.measure.render_context import RenderContext


def test_shadow_offset_counts_the_lost_contact_shadow() -> None:
    context = RenderContext((96, 72))
    counts = {s.label: s.count(context) for s in (*shadow_offset.KNOB.settings, shadow_offset.KNOB.reference)}
    reference = counts["error bound, at 1"]
    assert reference.pixels == 0 and reference.of > 150
    assert counts["simple 2^-16*|P|, at 1"].pixels <= 0.05 * reference.of
    assert counts["simple 2^-16*|P|, at 100000"].share > 0.9  # the shadow is gone
    assert counts["error bound, at 100000"].pixels == 0 and counts["error bound, at 1e+06"].pixels == 0
