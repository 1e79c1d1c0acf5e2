"""Hızlandırma: the AABB slab test, where a ray enters an axis-aligned box."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid

DOC = """AABB (axis-aligned bounding box), course section "Hızlandırma: backface culling, AABB".

The box is the space between `box_min` and `box_max`: three slabs
min_i <= x_i <= max_i. Along the ray R0 + t·Rd, slab i is crossed between

    t_a = (min_i - R0_i) / Rd_i,   t_b = (max_i - R0_i) / Rd_i   (swap them when Rd_i < 0)

The ray is in the box from t_enter = max of the three entries to t_exit =
min of the three exits. No hit when t_enter > t_exit or t_exit < 0. Return
t_enter when it is > 0, t_exit when the origin is inside (t_enter <= 0), or
None. A ray parallel to a slab (Rd_i = 0) never crosses it: it is inside
the slab for every t when min_i <= R0_i <= max_i, and misses otherwise.
Boundaries count (a ray along a face or through an edge hits).

Worked example: the notes write AABB(-25, -20, 70, 15, 20, 30), the centre
(-25, -20, 70) and half-sizes (15, 20, 30): box_min = (-40, -40, 40),
box_max = (-10, 0, 100). The ray from (0, 0, 0) along (-25, -20, 70)
(towards the centre) enters through z = 40 at t = 4/7.
"""


def reference(origin, direction, box_min, box_max):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :meth:`AABB.intersect`."""
    from glsandbox.raytrace.aabb import AABB
    from glsandbox.raytrace.ray import Ray

    return AABB(box_min, box_max).intersect(Ray(origin, direction))


def _reference_many(inputs: list[tuple]) -> list:
    from glsandbox.raytrace.aabb import AABB

    (_, _, box_min, box_max) = inputs[0]
    o = np.array([i[0] for i in inputs], dtype=np.float64)
    d = np.array([i[1] for i in inputs], dtype=np.float64)
    t = AABB(box_min, box_max).intersect_many(o, d).tolist()
    return [v if math.isfinite(v) else None for v in t]


def _slabs(origin, direction, box_min, box_max, swap=True):  # noqa: ANN001, ANN202
    enter, leave = -math.inf, math.inf
    for o, d, lo, hi in zip(origin, direction, box_min, box_max, strict=True):
        if d == 0:
            if not lo <= o <= hi:
                return math.inf, -math.inf
            continue
        a, b = (lo - o) / d, (hi - o) / d
        if swap and a > b:
            a, b = b, a
        enter, leave = max(enter, a), min(leave, b)
    return enter, leave


def no_swap(origin, direction, box_min, box_max):  # noqa: ANN001, ANN201
    enter, leave = _slabs(origin, direction, box_min, box_max, swap=False)
    if enter > leave or leave < 0:
        return None
    return enter if enter > 0 else (leave if leave > 0 else None)


def no_miss_test(origin, direction, box_min, box_max):  # noqa: ANN001, ANN201
    enter, leave = _slabs(origin, direction, box_min, box_max)
    if math.isinf(enter) and enter > 0:
        return None
    return enter if enter > 0 else (leave if leave > 0 else None)


def behind_accepted(origin, direction, box_min, box_max):  # noqa: ANN001, ANN201
    enter, leave = _slabs(origin, direction, box_min, box_max)
    if enter > leave:
        return None
    return enter if enter > 0 else leave


def entry_from_inside(origin, direction, box_min, box_max):  # noqa: ANN001, ANN201
    enter, leave = _slabs(origin, direction, box_min, box_max)
    if enter > leave or leave < 0:
        return None
    return enter


MISTAKES = (
    Mistake("no_swap", "when Rd_i < 0 the ray meets max_i before min_i: swap t_a and t_b so that each slab's "
            "entry is the smaller one.", no_swap),
    Mistake("no_miss_test", "the ray misses the box when the largest entry comes after the smallest exit "
            "(t_enter > t_exit): your function reports a hit there.", no_miss_test),
    Mistake("behind_accepted", "a box behind the ray's origin (t_exit < 0) is no hit: return None instead of a "
            "negative t.", behind_accepted),
    Mistake("entry_from_inside", "from inside the box t_enter is behind the origin: the ray leaves the box at "
            "t_exit, which is the hit.", entry_from_inside),
)

BOX_MIN, BOX_MAX = (-40.0, -40.0, 40.0), (-10.0, 0.0, 100.0)
ORIGIN = (0.0, 0.0, 0.0)

VISIBLE = (
    Case("the notes' AABB(-25, -20, 70, 15, 20, 30), towards its centre: t = 4/7",
         (ORIGIN, (-25.0, -20.0, 70.0), BOX_MIN, BOX_MAX), 4.0 / 7.0),
    Case("the notes' box, a ray along +z beside it (x = 0 is outside -40..-10)",
         (ORIGIN, (0.0, 0.0, 1.0), BOX_MIN, BOX_MAX), None),
)


def hidden() -> list[Case]:
    """Parallel slabs inside and out, from inside, behind, an edge and a face (boundaries count),
    negative directions, far and tiny boxes."""
    lo, hi = (-1.0, -1.0, -1.0), (1.0, 1.0, 1.0)
    return [
        Case("parallel to two slabs, inside them", ((-5.0, 0.0, 0.0), (1.0, 0.0, 0.0), lo, hi), 4.0,
             group="parallel"),
        Case("parallel to a slab, outside it", ((-5.0, 2.0, 0.0), (1.0, 0.0, 0.0), lo, hi), None,
             group="parallel"),
        Case("along a face (on the boundary)", ((-5.0, 1.0, 0.0), (1.0, 0.0, 0.0), lo, hi), 4.0, also=(None,),
             margin="the ray runs in the plane of a face: the boundary counts, within rounding",
             group="parallel"),
        Case("from inside: the exit", ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), lo, hi), 1.0, group="inside"),
        Case("from inside, a negative direction", ((0.5, 0.0, 0.0), (-1.0, -0.5, 0.0), lo, hi), 1.5,
             group="inside"),
        Case("the box behind the origin", ((0.0, 0.0, 5.0), (0.0, 0.0, 1.0), lo, hi), None, group="behind"),
        Case("a negative direction, from the far side", ((5.0, 0.5, 0.0), (-1.0, 0.0, 0.0), lo, hi), 4.0,
             group="negative"),
        Case("diagonal, missing the corner", ((-3.0, 0.0, 0.0), (1.0, 1.0, 0.0), lo, hi), None,
             group="negative"),
        Case("through an edge exactly", ((-3.0, -1.0, 0.0), (1.0, 1.0, 0.0), lo, hi), 2.0, also=(None,),
             margin="the ray passes through the box's edge: the boundary decision is within rounding",
             group="negative"),
        Case("far from the world's origin (1e5)", ((1e5 - 5.0, 1e5, 1e5), (1.0, 0.0, 0.0),
                                                   (1e5 - 1.0,) * 3, (1e5 + 1.0,) * 3), 4.0, rel=1e-9,
             group="scale"),
        Case("a tiny box (1e-4)", ((-5e-4, 0.0, 0.0), (1.0, 0.0, 0.0), (-1e-4,) * 3, (1e-4,) * 3), 4e-4,
             abs=1e-15, group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """Rays along (-1, -0.4, 0.05) from each point of the plane z = 0 around the box [-1, 1]³."""
    direction, lo, hi = (-1.0, -0.4, 0.05), (-1.0, -1.0, -1.0), (1.0, 1.0, 1.0)
    return [((float(u), float(v), 0.0), direction, lo, hi) for u, v in grid(n, -3.0, 3.0).tolist()]


EXERCISE = Exercise(
    name="aabb", function="intersect_aabb", params=("origin", "direction", "box_min", "box_max"),
    section="Hızlandırma: backface culling, AABB", term="eksene hizalı sınırlayıcı kutu",
    summary="the slab test: nearest t > 0 where a ray meets a box (the exit from inside), or None",
    doc=DOC, example="abs(intersect_aabb((0, 0, 0), (-25, -20, 70), (-40, -40, 40), (-10, 0, 100)) - 4 / 7) < 1e-12",
    returns="t", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("rays along (-1, -0.4, 0.05) from each point of the plane z = 0 around the box [-1, 1]³",
                _probe_inputs, _reference_many, shade=lambda t: 1.0 - t / 6.0),
    mistakes=MISTAKES, order=100,
)
