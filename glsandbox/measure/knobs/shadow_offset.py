"""Shadow-ray offsets (course section "Gölge testi"): a fixed share of
``|P|`` against a bound on the hit point's rounding error, with a cube standing
on a floor moved from the origin to 1e6. The error counted is the floor's
shadow pixels that come out wrong: contact shadow lost (an offset too big
lifts the shadow ray over the cube's base) or acne (too small, a surface
shadows itself)."""

from __future__ import annotations

import numpy as np

from glsandbox.measure.knob import Knob, PixelCount, Setting, register_knob
from glsandbox.measure.knobs._far import contact_shadow, cube_on_floor, grown
from glsandbox.measure.render_context import RenderContext


def _trace(c: RenderContext):  # type: ignore[no-untyped-def]
    return lambda scene, size, **options: c.ray(scene, "numpy", **options)


def setting(offset: str, at: float) -> Setting:
    """The scene at ``at`` from the origin, shadow rays leaving by ``offset``; its
    wrong shadow pixels counted against the reference's shadow."""
    label = {"simple": "simple 2^-16*|P|", "bound": "error bound"}[offset] + f", at {at:g}"

    def count(c: RenderContext) -> PixelCount:
        _, want = contact_shadow(_trace(c), 0.0, c.size)
        _, got = contact_shadow(_trace(c), at, c.size, offset=offset)
        lost = np.count_nonzero(want & ~got)
        false = np.count_nonzero(got & ~grown(want))
        return PixelCount(int(lost + false), int(np.count_nonzero(want)))

    return Setting(label, lambda c: c.ray(cube_on_floor(at), "numpy", offset=offset, max_depth=0), "", count)


KNOB = register_knob(Knob(
    name="shadow_offset",
    title="Shadow-ray offset: a share of |P| against the hit point's error bound",
    order=35,
    scene="a unit cube resting on a floor, lit from the side, moved from the origin along (0.99, 0.7, -0.4)",
    settings=(
        setting("simple", 1.0), setting("simple", 1e4), setting("simple", 1e5), setting("simple", 1e6),
        setting("bound", 1e5), setting("bound", 1e6),
    ),
    reference=setting("bound", 1.0),
    reference_note=("the numpy engine (float64) at the origin, shadow rays offset by the hit point's "
                    "rounding-error bound (pbrt-v4): the cube's shadow as exact arithmetic draws it"),
    quick=("simple 2^-16*|P|, at 1", "simple 2^-16*|P|, at 100000", "error bound, at 100000"),
    count_label="wrong shadow px",
    count_of="shadow px",
    notes=(
        "The simple offset moves a shadow ray 2^-16*max(1, |P|) along the normal: 1.5 units at 1e5, "
        "above the cube's base, so the contact shadow is gone; at the origin it is 1.5e-5 and holds.",
        "The error bound is gamma(7)*sum|b_i*V_i| for a triangle's barycentric point (a few 1e-15 "
        "relative in float64): the shadow is kept at every distance and no surface shadows itself "
        "(the watertight test accepts t only above its own error bound).",
    ),
))
