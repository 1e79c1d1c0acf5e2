"""Numbers both ray tracing engines read, so they trace the same picture.

The numpy engine (:mod:`glsandbox.raytrace.numpy_engine`, float64) and the
GLSL engine (:mod:`glsandbox.raytrace.gpu`, float32, which hands them to
``shaders/raytrace.glsl`` and ``shaders/common/*.glsl`` as ``#define``s, see
:func:`glsl_defines`) import them from here and from nowhere else; this
module imports nothing. Each number carries its one-line argument.

Rounding-error bounds (pbrt-v4, "Managing Rounding Error")
----------------------------------------------------------
One float operation is off by at most a relative ``u`` (half an ulp: 2⁻⁵³ in
float64, 2⁻²⁴ in float32); ``n`` of them in a row by at most
``γ(n) = n·u / (1 − n·u)`` (:func:`gamma`). A hit point computed as
``P = b0·V0 + b1·V1 + b2·V2`` from its barycentrics is off its triangle's
plane by at most ``γ(7)·(|b0·V0| + |b1·V1| + |b2·V2|)`` per component; the
shadow and reflected rays start that far along the normal, towards the side
they leave on (:data:`TRIANGLE_POINT_GAMMA`), instead of a fixed fraction of
``|P|``: the bound is what the arithmetic can actually be off, so a contact
shadow a millionth of a unit deep survives, at the origin and at 1e6 alike.
"""

from __future__ import annotations

__all__ = [
    "BVH_BOX_PAD",
    "BVH_BOX_PAD_F64",
    "DIRECTION_TINY",
    "FLOAT32_MIN_NORMAL",
    "LENGTH_TINY",
    "NO_HIT_F32",
    "SQUARES_UNDERFLOW",
    "UNIT_SHAPE_TOLERANCE",
    "NODE_BOX_PAD",
    "OFFSETS",
    "SIMPLE_OFFSET",
    "RAY_POINT_GAMMA",
    "SPHERE_C_GAMMA",
    "SPHERE_C_GAMMA_GLSL",
    "TRIANGLE_POINT_GAMMA",
    "UNIT_F32",
    "UNIT_F64",
    "gamma",
    "glsl_defines",
]

#: Unit roundoff of float64: half an ulp of 1.
UNIT_F64: float = 2.0**-53
#: Unit roundoff of float32 (what the GLSL engine computes in).
UNIT_F32: float = 2.0**-24

#: Operations behind a barycentric hit point, ``b0·V0 + b1·V1 + b2·V2``
#: (three products, two sums, and ``b_i`` itself a quotient off by two more):
#: pbrt-v4's bound for its watertight triangle, ``γ(7)·Σ|b_i·V_i|``.
TRIANGLE_POINT_GAMMA: int = 7
#: Operations behind a point ``O + t·D`` (a sphere hit in the engines, any hit in
#: the course API's :class:`~glsandbox.raytrace.trace.Hit`): the stable quadratic's ``t`` is
#: off by a few ulps (Ray Tracing Gems ch. 7), and the point by that times
#: ``|t·D|`` plus the two operations of the sum; 16 covers it with room
#: (the bound is ``γ(16)·(|O| + |t·D|)`` per component).
RAY_POINT_GAMMA: int = 16
#: Roundings behind the stable sphere test's ``c = (|l| − r)(|l| + r)``
#: (Işın-Küre kesim testi; the derivation is at the line, in
#: :meth:`glsandbox.raytrace.sphere.Sphere.intersect_many`): ``|l|`` is a sqrt
#: of a 3-term dot product of squares (γ(3) relative), ``|l| − r`` and
#: ``|l| + r`` one more each, their product one more: 5 in float64. The GLSL
#: engine's sqrt and division are only within 2.5 ulps (GLSL 4.00 §4.7.1),
#: 5 roundings each: :data:`SPHERE_C_GAMMA_GLSL`.
SPHERE_C_GAMMA: int = 5
SPHERE_C_GAMMA_GLSL: int = 12
#: How secondary rays leave a surface, as the engines' ``offset`` option names
#: it (the value: whether it is the simple relative offset).
#: ``"bound"``: by the hit point's rounding-error bound (the default, above);
#: ``"simple"``: the teaching variant, :data:`SIMPLE_OFFSET`.
OFFSETS: dict[str, bool] = {"bound": False, "simple": True}
#: The simple offset, the one a first ray tracer writes:
#: ``SIMPLE_OFFSET·max(1, max|P_i|)`` along the normal, ``P`` the world position
#: in both engines (the gpu engine adds its anchor back). 2⁻¹⁶ is about 256
#: float32 ulps of the point's largest coordinate: no acne, but a fixed share
#: of ``|P|`` is 1.5 units at 1e5, and a cube's contact shadow on a floor
#: there is gone (what the ``shadow_offset`` tradeoff knob shows).
SIMPLE_OFFSET: float = 2.0**-16
#: Relative pad of a node's world box in the float32 slab test (gpu scan
#: path): a box edge and ``1/d`` each round, and the slab test must never
#: reject a ray the triangle test would accept at the box's face.
NODE_BOX_PAD: float = 2.0**-17
#: Relative pad of BVH boxes (both engines, ``shaders/common/bvh.glsl``'s
#: ``BVH_PAD`` for float32; the numpy traversal uses :data:`BVH_BOX_PAD_F64`):
#: a few ulps of the largest coordinate the slab test sees.
BVH_BOX_PAD: float = 2.0**-18
#: The float64 BVH's relative box pad (numpy engine and :mod:`glsandbox.raytrace.bvh_world`).
BVH_BOX_PAD_F64: float = 2.0**-30
#: Direction components below this are made ±this before ``1/d`` (a slab
#: test with ``0·inf`` would give NaN); far below any direction a scene uses.
DIRECTION_TINY: float = 1e-30
#: A vector is divided by ``max(|v|, LENGTH_TINY)`` when normalised (float64): a
#: zero vector (a degenerate triangle's normal) stays zero instead of 0/0 = NaN,
#: and any length float64 can square without underflow is far above it.
LENGTH_TINY: float = 1e-300
#: Rows shorter than this are rescaled by their largest component before their
#: length is taken: their squares (below 1e-300) would underflow towards 0.
SQUARES_UNDERFLOW: float = 1e-150
#: How far (relative) a mesh's vertices may lie off the analytic shape its
#: ``Mesh.analytic`` names for the node to be traced as that shape: a vertex
#: computed with ``cos``/``sin`` in float64 is within a few ulps of it.
UNIT_SHAPE_TOLERANCE: float = 1e-9
#: The GLSL engine's "no hit" ``t`` (``INF``): float32 has no literal infinity in
#: GLSL 4.0, and no ray a scene casts reaches 1e30.
NO_HIT_F32: float = 1e30
#: The smallest normal float32, 2⁻¹²⁶: the first float away from 0 in the GLSL
#: engine's ``next_float`` (rounding a spawned origin off the surface).
FLOAT32_MIN_NORMAL: float = 2.0**-126


def gamma(n: int, unit: float) -> float:
    """``γ(n) = n·u/(1 − n·u)``: the relative error bound of ``n`` roundings of unit ``u``."""
    return n * unit / (1.0 - n * unit)


def glsl_defines() -> tuple[tuple[str, str], ...]:
    """The numbers above as the shaders' ``#define``s (float32 values)."""
    return (
        ("TRIANGLE_POINT_ERROR", repr(gamma(TRIANGLE_POINT_GAMMA, UNIT_F32))),
        ("SPHERE_POINT_ERROR", repr(gamma(RAY_POINT_GAMMA, UNIT_F32))),
        ("SPHERE_C_ERROR", repr(gamma(SPHERE_C_GAMMA_GLSL, UNIT_F32))),
        ("GAMMA2", repr(gamma(2, UNIT_F32))),
        ("GAMMA3", repr(gamma(3, UNIT_F32))),
        ("GAMMA5", repr(gamma(5, UNIT_F32))),
        ("BVH_PAD", repr(BVH_BOX_PAD)),
        ("DIRECTION_TINY", repr(DIRECTION_TINY)),
        ("INF", repr(NO_HIT_F32)),
        ("FLT_MIN_NORMAL", repr(FLOAT32_MIN_NORMAL)),
    )
