"""The shadow-epsilon knob (glsandbox/measure/knobs/shadow_epsilon.py): acne with no offset, the
contact shadow lost with a big one, the error bound neither."""

from __future__ import annotations

import numpy as np
from support import knob_counts

from glsandbox.measure.knobs import shadow_epsilon


def test_shadow_epsilon_shows_acne_and_lost_contact_shadows() -> None:
    counts = knob_counts(shadow_epsilon.KNOB, (96, 72))
    assert counts["error bound, at 1"].pixels == 0 and counts["error bound, at 1"].of > 1000
    assert counts["no offset, at 1"].share > 0.3  # acne: the floor shadows itself
    assert counts["2^-32*|P|, at 1"].pixels <= 2 and counts["2^-16*|P|, at 1"].pixels <= 2
    _, floor, shadow = shadow_epsilon.trace(1.0, "error bound", (96, 72))
    lost = counts["2^-16*|P|, at 100000"].pixels
    assert lost >= 0.9 * np.count_nonzero(shadow)  # the contact shadow is gone
    assert counts["2^-16*|P|, at 10000"].pixels < lost
    assert counts["error bound, at 100000"].pixels == 0 and counts["error bound, at 1e+06"].pixels == 0


def test_shadow_epsilon_reference_is_the_engines_shadow() -> None:
    from glsandbox.measure.knobs._far import contact_shadow
    from glsandbox.raytrace.render import render

    size = (64, 48)
    floor, shadow = shadow_epsilon.trace(1.0, "error bound", size)[1:]
    engine_floor, engine_shadow = contact_shadow(lambda s, sz, **o: render(s, sz, "numpy", **o), 0.0, size)
    assert np.count_nonzero(shadow) > 100
    assert np.count_nonzero(shadow != engine_shadow) <= 2 and np.count_nonzero(floor != engine_floor) <= 20
