"""Işın-Üçgen kesim testi: ray-triangle intersection, six ways.

The course splits the test in two steps (iki aşama):

1. intersect the ray with the triangle's plane (Işın-Düzlem, see
   :mod:`glsandbox.raytrace.plane`), giving ``t`` and the point
   ``R = R0 + t·Rd``;
2. decide whether ``R`` lies inside the triangle. The notes give four ways
   (Yöntem I-IV), each available by name:

   - ``"area_sum"`` (I): ``S = S1 + S2 + S3``: the three sub-triangles ``R`` cuts
     the triangle into add up to the whole only when ``R`` is inside (outside,
     their sum is larger);
   - ``"edge_distance"`` (II): the signed distance from ``R`` to each edge line,
     ``((V_b − V_a) × (R − V_a))·n̂ / |V_b − V_a|``, is ``>= 0`` for all three;
   - ``"dot_barycentric"`` (III): solve ``R = V0 + u·e0 + v·e1`` for ``u, v`` with
     the dot products ``d00 = e0·e0, d01 = e0·e1, d11 = e1·e1, d20 = e2·e0,
     d21 = e2·e1`` (``e2 = R − V0``; the OCR'd notes write "×" but mean "·")::

         u = (d20·d11 − d21·d01) / (d00·d11 − d01·d01)
         v = (d00·d21 − d01·d20) / (d00·d11 − d01·d01)

     and test ``u >= 0, v >= 0, u + v <= 1``;
   - ``"area_ratio"`` (IV): the same ``u, v`` as ratios of areas, ``u = S1/S``,
     ``v = S2/S``, with the sub-areas *signed* (measured along the normal) so a
     point beyond an edge gets a negative ratio.

Two one-step tests that never build the plane are the modern standards:

- ``"moller_trumbore"`` (Möller & Trumbore 1997): Cramer's rule on
  ``O + t·d = V0 + u·e1 + v·e2``, sharing the cross products;
- ``"watertight"`` (Woop, Benthin & Wald 2013, the default): move the ray's
  origin to (0,0,0), permute the axes so the direction's largest component is
  z, shear so the ray becomes the +z axis, then test the 2D edge functions
  ``U, V, W`` of the projected triangle. The same edge shared by two triangles
  gives *exactly* opposite edge functions in both (the same floating-point
  products, subtracted in the opposite order), so no ray slips between them.
  When an edge function rounds to exactly 0 it is recomputed exactly (the
  paper's fall-back to double precision; we are in double already, so the
  fall-back is exact rational arithmetic) and zeros count as inside for both
  triangles: a ray through a shared edge hits at least one of them.

Conventions
-----------
- Normal and winding: ``N = (V1 − V0) × (V2 − V0)`` (worked example #1). A
  triangle is *front-facing* for a ray when ``N·Rd < 0`` (its normal points back
  at the viewer, the course's "z bileşeni negatifse frontface");
  ``cull_backfaces=True`` (Hızlandırma 1: Backface Culling) skips the others.
- Barycentrics: ``t(u, v) = V0 + u·(V1 − V0) + v·(V2 − V0)``, ``u, v >= 0``,
  ``u + v <= 1``.
- Degenerate triangles (zero area: ``|e1 × e2| <= 64·eps·|e1|·|e2|``, the sine
  of the angle at ``V0`` below rounding noise) are rejected by every method:
  ``None``, no division by zero, no warning.
- Rays closer to parallel with the plane than ``sin(angle) <= PARALLEL_EPS``
  miss in the plane-based and Möller-Trumbore tests (the watertight test needs
  no epsilon: an edge-on triangle has ``det = 0``).
- Inside tolerances are relative to the triangle's size, never absolute:
  distances are compared against ``INSIDE_REL_TOL · L_max`` (``L_max`` the
  longest edge), areas against ``INSIDE_REL_TOL · L_max²``, barycentrics
  (dimensionless) against ``INSIDE_REL_TOL``. Scaling a scene therefore never
  changes a hit into a miss.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.constants import UNIT_F64, gamma
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays, finite_positive_or_none, shared_origin
from glsandbox.raytrace.vec import Vec3, as_vec3, as_vec3_batch, cross, dot, length

__all__ = [
    "DEFAULT_METHOD",
    "DEGENERATE_SIN",
    "INSIDE_REL_TOL",
    "INSIDE_TESTS",
    "PARALLEL_EPS",
    "POINT_IN_TRIANGLE",
    "Triangle",
    "TriangleBatch",
    "TriangleTest",
    "moller_trumbore_many",
]

#: Relative tolerance of the course's inside tests (I-IV), see the module docstring.
INSIDE_REL_TOL: float = 1e-9
#: A triangle is degenerate when ``|e1 × e2| <= DEGENERATE_SIN·|e1|·|e2|``.
DEGENERATE_SIN: float = 64.0 * float(np.finfo(np.float64).eps)
#: A ray is parallel to a plane when ``|N·d| <= PARALLEL_EPS·|N|·|d|``.
PARALLEL_EPS: float = 1e-12
#: The method :meth:`Triangle.intersect` uses unless told otherwise.
DEFAULT_METHOD: str = "watertight"

TriangleTest = Callable[["Triangle", Ray, bool], "float | None"]
"""A ray-triangle test: ``(triangle, ray, cull_backfaces) -> t or None``."""

PointTest = Callable[["Triangle", Vec3], bool]
"""A point-in-triangle test for a point already on the triangle's plane."""


class Triangle:
    """The triangle ``V0, V1, V2`` with optional per-vertex texture coordinates.

    ``uvs`` is a ``(3, 2)`` array of texture coordinates at ``V0, V1, V2``;
    :meth:`uv_at` interpolates them with the barycentrics. ``method`` and
    ``cull_backfaces`` are the defaults of :meth:`intersect` (so a scene can fix
    them per triangle and :func:`nearest_hit` honours them).
    """

    __slots__ = (
        "v0",
        "v1",
        "v2",
        "e1",
        "e2",
        "n",
        "uvs",
        "method",
        "cull_backfaces",
        "_n_len",
        "_l_max",
        "_degenerate",
    )

    v0: Vec3
    v1: Vec3
    v2: Vec3
    e1: Vec3
    e2: Vec3
    n: Vec3
    uvs: NDArray[np.float64] | None
    method: str
    cull_backfaces: bool

    def __init__(
        self,
        v0: ArrayLike,
        v1: ArrayLike,
        v2: ArrayLike,
        uvs: ArrayLike | None = None,
        *,
        method: str = DEFAULT_METHOD,
        cull_backfaces: bool = False,
    ) -> None:
        self.v0 = as_vec3(v0, "triangle v0")
        self.v1 = as_vec3(v1, "triangle v1")
        self.v2 = as_vec3(v2, "triangle v2")
        _check_method(method)
        self.method = method
        self.cull_backfaces = bool(cull_backfaces)
        if uvs is None:
            self.uvs = None
        else:
            arr = np.array(uvs, dtype=np.float64)
            if arr.shape != (3, 2) or not np.all(np.isfinite(arr)):
                raise RayTraceError(f"triangle uvs must be 3 finite (u, v) pairs, got shape {arr.shape}")
            self.uvs = arr
        # Kenarlar (edges) and the unnormalized normal N = e1 × e2 (|N| = 2·area).
        self.e1 = self.v1 - self.v0
        self.e2 = self.v2 - self.v0
        self.n = cross(self.e1, self.e2)
        self._n_len = float(length(self.n))
        e3 = self.v2 - self.v1
        self._l_max = math.sqrt(max(float(dot(e, e)) for e in (self.e1, self.e2, e3)))
        self._degenerate = not (self._n_len > DEGENERATE_SIN * float(length(self.e1)) * float(length(self.e2)))

    # --- geometry ---------------------------------------------------------

    @property
    def is_degenerate(self) -> bool:
        """Whether the triangle has (numerically) zero area; such triangles are never hit."""
        return self._degenerate

    @property
    def area(self) -> float:
        """``|e1 × e2| / 2``."""
        return 0.5 * self._n_len

    @property
    def normal(self) -> Vec3:
        """The unit normal ``N/|N|`` with ``N = (V1 − V0) × (V2 − V0)``."""
        if self._degenerate:
            raise RayTraceError("a degenerate (zero-area) triangle has no normal")
        return self.n / self._n_len

    def normal_at(self, point: ArrayLike) -> Vec3:
        """The unit geometric normal (the same at every point of a flat triangle)."""
        return self.normal

    def barycentric(self, point: ArrayLike) -> tuple[float, float]:
        """``(u, v)`` with ``point = V0 + u·(V1 − V0) + v·(V2 − V0)``.

        Computed as signed area ratios (Yöntem IV):
        ``u = ((P − V0) × e2)·N / N·N`` and ``v = (e1 × (P − V0))·N / N·N``.
        A point off the plane is first projected onto it along the normal.
        """
        if self._degenerate:
            raise RayTraceError("barycentric coordinates are undefined on a degenerate triangle")
        w = as_vec3(point, "point") - self.v0
        nn = float(dot(self.n, self.n))
        u = float(dot(cross(w, self.e2), self.n)) / nn
        v = float(dot(cross(self.e1, w), self.n)) / nn
        return u, v

    def interpolate(self, values: ArrayLike, point: ArrayLike) -> NDArray[np.float64]:
        """Interpolate per-vertex ``values`` (shape ``(3, ...)``) at ``point``.

        ``(1 − u − v)·values[0] + u·values[1] + v·values[2]``.
        """
        vals = np.asarray(values, dtype=np.float64)
        if vals.shape[:1] != (3,):
            raise RayTraceError(f"need one value per vertex (3 rows), got shape {vals.shape}")
        u, v = self.barycentric(point)
        result: NDArray[np.float64] = (1.0 - u - v) * vals[0] + u * vals[1] + v * vals[2]
        return result

    def uv_at(self, point: ArrayLike) -> NDArray[np.float64]:
        """Texture coordinates at ``point``, interpolated from the per-vertex ``uvs``."""
        if self.uvs is None:
            raise RayTraceError("this triangle carries no per-vertex uvs")
        return self.interpolate(self.uvs, point)

    def contains(self, point: ArrayLike, method: str = "area_sum") -> bool:
        """The course's second step alone: is ``point`` (on the plane) inside?

        ``method`` is one of the four point tests in :data:`POINT_IN_TRIANGLE`.
        """
        if method not in POINT_IN_TRIANGLE:
            raise RayTraceError(f"unknown point-in-triangle test {method!r}; choose one of {sorted(POINT_IN_TRIANGLE)}")
        if self._degenerate:
            return False
        return POINT_IN_TRIANGLE[method](self, as_vec3(point, "point"))

    # --- intersection -----------------------------------------------------

    def intersect(self, ray: Ray, method: str | None = None, cull_backfaces: bool | None = None) -> float | None:
        """Nearest ``t > 0`` where ``ray`` meets the triangle, or ``None``.

        ``method`` names a test in :data:`INSIDE_TESTS` (default: the triangle's
        ``method``, normally ``"watertight"``); ``cull_backfaces=True`` skips the
        triangle when it faces away from the ray (``N·Rd >= 0``).
        """
        name = self.method if method is None else method
        _check_method(name)
        cull = self.cull_backfaces if cull_backfaces is None else bool(cull_backfaces)
        if self._degenerate:
            return None
        return INSIDE_TESTS[name](self, ray, cull)

    def intersect_many(
        self, origins: ArrayLike, directions: ArrayLike, cull_backfaces: bool | None = None
    ) -> NDArray[np.float64]:
        """Möller-Trumbore for ``N`` rays: a ``(N,)`` array of ``t``, ``inf`` for a miss."""
        cull = self.cull_backfaces if cull_backfaces is None else bool(cull_backfaces)
        o, d = broadcast_rays(origins, directions)
        t = moller_trumbore_many(o, d, self.v0[None], self.v1[None], self.v2[None], cull_backfaces=cull)
        return t[:, 0]

    def __repr__(self) -> str:
        return (
            f"Triangle({self.v0.tolist()}, {self.v1.tolist()}, {self.v2.tolist()}"
            f"{'' if self.uvs is None else ', uvs=' + repr(self.uvs.tolist())})"
        )


def _check_method(name: str) -> None:
    if name not in INSIDE_TESTS:
        raise RayTraceError(f"unknown triangle test {name!r}; choose one of {sorted(INSIDE_TESTS)}")


# --- step 1: Işın-Düzlem (the plane of the triangle) -------------------------


def _ray_plane(tri: Triangle, ray: Ray, cull: bool) -> float | None:
    """``t`` where the ray meets the triangle's plane, honouring culling.

    ``t = −(N·R0 + D)/(N·Rd)`` with ``D = −(N·V0)``, written as
    ``N·(V0 − R0)/(N·Rd)``: the same value, but ``V0 − R0`` is formed before
    the dot product, which keeps digits when both points are far from (0,0,0).
    """
    d = ray.direction
    den = float(dot(tri.n, d))
    if abs(den) <= PARALLEL_EPS * tri._n_len * float(length(d)):
        return None  # yüzeye paralel: the ray runs along the plane
    if cull and den > 0.0:
        return None  # backface: the normal looks away from the viewer
    t = float(dot(tri.n, tri.v0 - ray.origin)) / den
    return t if t > 0.0 else None


# --- step 2: the course's four inside tests --------------------------------


def _inside_area_sum(tri: Triangle, p: Vec3) -> bool:
    """Yöntem I: ``S1 + S2 + S3 == S`` (up to a tolerance scaled by the size).

    ``S1 = |(R − V0) × (V2 − V0)|``, ``S2 = |(V1 − V0) × (R − V0)|``,
    ``S3 = |(V1 − R) × (V2 − R)|``, ``S = |(V1 − V0) × (V2 − V0)|``
    (parallelogram areas, twice the triangle areas: the factor cancels).
    A point a distance ``h`` outside an edge of length ``L`` raises the sum by
    ``2·L·h``; we accept ``h`` up to ``INSIDE_REL_TOL·L_max``.
    """
    w = p - tri.v0
    s1 = float(length(cross(w, tri.e2)))
    s2 = float(length(cross(tri.e1, w)))
    s3 = float(length(cross(tri.v1 - p, tri.v2 - p)))
    tol = 2.0 * INSIDE_REL_TOL * tri._l_max * tri._l_max
    return s1 + s2 + s3 <= tri._n_len + tol


def _inside_edge_distance(tri: Triangle, p: Vec3) -> bool:
    """Yöntem II: the signed distance to each edge line is not negative.

    For the edge ``a → b`` (counter-clockwise about ``n̂``)
    ``dist = ((b − a) × (R − a))·n̂ / |b − a|`` is positive on the inner side.
    """
    n_hat = tri.n / tri._n_len
    tol = INSIDE_REL_TOL * tri._l_max
    for a, b in ((tri.v0, tri.v1), (tri.v1, tri.v2), (tri.v2, tri.v0)):
        edge = b - a
        edge_len = float(length(edge))
        if edge_len == 0.0:  # impossible for a non-degenerate triangle; never divide by 0
            return False
        if float(dot(cross(edge, p - a), n_hat)) / edge_len < -tol:
            return False
    return True


def _inside_dot_barycentric(tri: Triangle, p: Vec3) -> bool:
    """Yöntem III: ``u, v`` from dot products only (the notes' ``d00 ... d21``)."""
    e0, e1, e2 = tri.e1, tri.e2, p - tri.v0  # the notes' e0 = B − A, e1 = C − A, e2 = P − A
    d00 = float(dot(e0, e0))
    d01 = float(dot(e0, e1))
    d11 = float(dot(e1, e1))
    d20 = float(dot(e2, e0))
    d21 = float(dot(e2, e1))
    denom = d00 * d11 - d01 * d01  # = |e0 × e1|², by Lagrange's identity
    if not denom > 0.0:  # cancellation on an extreme needle: no division by zero
        return False
    u = (d20 * d11 - d21 * d01) / denom
    v = (d00 * d21 - d01 * d20) / denom
    tol = INSIDE_REL_TOL
    return u >= -tol and v >= -tol and u + v <= 1.0 + tol


def _inside_area_ratio(tri: Triangle, p: Vec3) -> bool:
    """Yöntem IV: ``u = S1/S``, ``v = S2/S`` with signed sub-areas.

    ``S1 = ((R − V0) × (V2 − V0))·N``, ``S2 = ((V1 − V0) × (R − V0))·N``,
    ``S = N·N``: the projection on ``N`` gives the areas a sign, negative when
    ``R`` is beyond the corresponding edge (with plain magnitudes, as the notes
    write them, ``u, v >= 0`` would always hold and test nothing).
    """
    w = p - tri.v0
    s = float(dot(tri.n, tri.n))
    u = float(dot(cross(w, tri.e2), tri.n)) / s
    v = float(dot(cross(tri.e1, w), tri.n)) / s
    tol = INSIDE_REL_TOL
    return u >= -tol and v >= -tol and u + v <= 1.0 + tol


def _plane_then(inside: PointTest) -> TriangleTest:
    """The course's two-step test: the plane first, then ``inside`` on the point."""

    def test(tri: Triangle, ray: Ray, cull: bool) -> float | None:
        t = _ray_plane(tri, ray, cull)
        if t is None:
            return None
        return t if inside(tri, ray.at(t)) else None

    test.__doc__ = f"Ray-plane, then {inside.__doc__}"
    return test


# --- one-step tests ----------------------------------------------------------


def _moller_trumbore(tri: Triangle, ray: Ray, cull: bool) -> float | None:
    """Möller-Trumbore, through the same kernel as the vectorized version (bit-identical)."""
    t = _moller_trumbore_kernel(
        ray.origin[None],
        ray.direction[None],
        tri.v0[None],
        tri.e1[None],
        tri.e2[None],
        np.array([tri._n_len]),
        np.array([not tri._degenerate]),
        cull,
    )
    return finite_positive_or_none(t)


def _edge_function(px: float, py: float, qx: float, qy: float) -> float:
    """``px·qy − py·qx``, recomputed exactly when it rounds to 0.

    Only the sign of a zero matters to the inside decision; exact rational
    arithmetic gives the true sign of the edge function of the (already
    sheared, float) coordinates, and it is exactly antisymmetric, so two
    triangles sharing the edge still see opposite signs.
    """
    e = px * qy - py * qx
    if e != 0.0:
        return e
    exact = Fraction(px) * Fraction(qy) - Fraction(py) * Fraction(qx)
    if exact == 0:
        return 0.0
    f = float(exact)
    if f == 0.0:  # below the smallest subnormal: keep the sign
        f = 5e-324 if exact > 0 else -5e-324
    return f


def _watertight(tri: Triangle, ray: Ray, cull: bool) -> float | None:
    """Woop, Benthin & Wald (2013), "Watertight Ray/Triangle Intersection"."""
    d = ray.direction
    # 1. Permute: kz is the axis where the direction is largest; keep the
    #    winding (a right-handed kx, ky, kz) by swapping kx and ky if d[kz] < 0.
    kz = int(np.argmax(np.abs(d)))
    kx = (kz + 1) % 3
    ky = (kx + 1) % 3
    if d[kz] < 0.0:
        kx, ky = ky, kx
    dx, dy, dz = float(d[kx]), float(d[ky]), float(d[kz])
    # 2. Shear constants: after (x − sx·z, y − sy·z) the ray is the z axis.
    sx = dx / dz
    sy = dy / dz
    sz = 1.0 / dz
    # 3. Translate the vertices so the ray starts at (0,0,0), then shear.
    a = tri.v0 - ray.origin
    b = tri.v1 - ray.origin
    c = tri.v2 - ray.origin
    ax, ay, az = float(a[kx]), float(a[ky]), float(a[kz])
    bx, by, bz = float(b[kx]), float(b[ky]), float(b[kz])
    cx, cy, cz = float(c[kx]), float(c[ky]), float(c[kz])
    ax, ay = ax - sx * az, ay - sy * az
    bx, by = bx - sx * bz, by - sy * bz
    cx, cy = cx - sx * cz, cy - sy * cz
    # 4. 2D edge functions (scaled barycentrics of V0, V1, V2).
    u = _edge_function(cx, cy, bx, by)  # edge V1-V2
    v = _edge_function(ax, ay, cx, cy)  # edge V2-V0
    w = _edge_function(bx, by, ax, ay)  # edge V0-V1
    # 5. Inside when all three share a sign (zeros count on both sides).
    #    U, V, W >= 0 is a front face (N·Rd < 0); backface culling keeps only it.
    if cull:
        if u < 0.0 or v < 0.0 or w < 0.0:
            return None
    elif (u < 0.0 or v < 0.0 or w < 0.0) and (u > 0.0 or v > 0.0 or w > 0.0):
        return None
    det = u + v + w
    if det == 0.0:
        return None  # the triangle is seen edge-on
    # 6. Interpolate the (scaled) z of the vertices: that is t along d.
    t = (u * (sz * az) + v * (sz * bz) + w * (sz * cz)) / det
    # 7. Only a t above its own rounding-error bound counts (pbrt-v4): a shadow ray
    #    leaving its surface by the hit point's error bound never meets it again.
    bound = watertight_t_bound((ax, bx, cx), (ay, by, cy), (sz * az, sz * bz, sz * cz), (u, v, w), det)
    return t if t > bound else None


def watertight_t_bound(x, y, z, e, det):  # type: ignore[no-untyped-def]
    """pbrt-v4's bound on the rounding error of the watertight test's ``t``
    (float64): ``x, y`` the three sheared corners' coordinates, ``z`` their scaled
    ``sz·z``, ``e`` the edge functions ``U, V, W``, ``det`` their sum. Floats or
    numpy arrays alike (the scalar and the vectorized test share it, operation for
    operation). The error of each step, in ``γ(n)`` (:func:`~glsandbox.raytrace.constants.gamma`):
    the corners' ``z`` ``γ(3)·max|z|``, their sheared ``x, y`` ``γ(5)·(max|x| + max|z|)``,
    the edge functions ``2·(γ(2)·max|x|·max|y| + δy·max|x| + δx·max|y|)``, and ``t``
    three times the error of ``Σ e_i·z_i`` over ``|det|``."""
    g2, g3, g5 = (gamma(n, UNIT_F64) for n in (2, 3, 5))
    with np.errstate(over="ignore", invalid="ignore"):  # coordinates near 1e154 and up: an inf bound, a miss
        return _t_bound(x, y, z, e, det, g2, g3, g5)


def _t_bound(x, y, z, e, det, g2, g3, g5):  # type: ignore[no-untyped-def]
    max_x = np.maximum(np.maximum(np.abs(x[0]), np.abs(x[1])), np.abs(x[2]))
    max_y = np.maximum(np.maximum(np.abs(y[0]), np.abs(y[1])), np.abs(y[2]))
    max_z = np.maximum(np.maximum(np.abs(z[0]), np.abs(z[1])), np.abs(z[2]))
    max_e = np.maximum(np.maximum(np.abs(e[0]), np.abs(e[1])), np.abs(e[2]))
    delta_z = g3 * max_z
    delta_x = g5 * (max_x + max_z)
    delta_y = g5 * (max_y + max_z)
    delta_e = 2.0 * (g2 * max_x * max_y + delta_y * max_x + delta_x * max_y)
    return 3.0 * (g3 * max_e * max_z + delta_e * max_z + delta_z * max_e) / np.abs(det)


#: The four point-in-triangle tests of the course (step 2 of Işın-Üçgen kesim testi).
POINT_IN_TRIANGLE: dict[str, PointTest] = {
    "area_sum": _inside_area_sum,
    "edge_distance": _inside_edge_distance,
    "dot_barycentric": _inside_dot_barycentric,
    "area_ratio": _inside_area_ratio,
}

#: Every ray-triangle test by name: the course's four (ray-plane, then the point
#: test) and Möller-Trumbore and the watertight test.
INSIDE_TESTS: dict[str, TriangleTest] = {
    **{name: _plane_then(test) for name, test in POINT_IN_TRIANGLE.items()},
    "moller_trumbore": _moller_trumbore,
    "watertight": _watertight,
}


# --- vectorized Möller-Trumbore ----------------------------------------------


def moller_trumbore_many(
    origins: ArrayLike,
    directions: ArrayLike,
    v0: ArrayLike,
    v1: ArrayLike,
    v2: ArrayLike,
    *,
    cull_backfaces: bool = False,
) -> NDArray[np.float64]:
    """Möller-Trumbore for ``N`` rays against ``M`` triangles: a ``(N, M)`` array of ``t``.

    ``origins``/``directions`` are ``(N, 3)`` (or one shared ``(3,)``); ``v0, v1,
    v2`` are ``(M, 3)``. Misses, parallel rays, culled and degenerate triangles
    give ``inf``; nothing divides by zero and nothing warns.

    Solving ``O + t·d = V0 + u·e1 + v·e2`` by Cramer's rule with
    ``p = d × e2``, ``det = e1·p`` (``= −N·d``: positive for a front face),
    ``s = O − V0``, ``q = s × e1``::

        u = s·p / det,   v = d·q / det,   t = e2·q / det
    """
    o, d = broadcast_rays(origins, directions)
    a = as_vec3_batch(v0, "v0")
    b = as_vec3_batch(v1, "v1")
    c = as_vec3_batch(v2, "v2")
    if not (a.shape == b.shape == c.shape):
        raise RayTraceError(f"v0, v1, v2 must have the same shape, got {a.shape}, {b.shape}, {c.shape}")
    return _moller_trumbore_kernel(o, d, a, *_triangle_terms(a, b, c), cull_backfaces)


def _triangle_terms(a: Vec3, b: Vec3, c: Vec3
                    ) -> tuple[Vec3, Vec3, NDArray[np.float64], NDArray[np.bool_]]:
    """Möller-Trumbore's per-triangle terms of ``(M, 3)`` corners: the edges ``e1, e2``,
    ``|e1 × e2|`` and whether the triangle is not degenerate (``(M,)`` each)."""
    e1 = b - a
    e2 = c - a
    n_len = length(cross(e1, e2))
    return e1, e2, n_len, n_len > DEGENERATE_SIN * length(e1) * length(e2)


def _moller_trumbore_kernel(
    o: Vec3,
    d: Vec3,
    a: Vec3,
    e1: Vec3,
    e2: Vec3,
    n_len: NDArray[np.float64],
    ok_tri: NDArray[np.bool_],
    cull_backfaces: bool,
) -> NDArray[np.float64]:
    """The arithmetic of :func:`moller_trumbore_many` on validated ``(N, 3)``/``(M, 3)`` arrays.

    Every ``(N, M)`` quantity is kept as three component arrays (``p_x, p_y,
    p_z``...), never as an ``(N, M, 3)`` stack, with the products summed in
    the order :func:`~glsandbox.raytrace.vec.dot` and
    :func:`~glsandbox.raytrace.vec.cross` use: the same numbers, bit for bit.

    Rays that share one origin (the eye, for every primary ray of Bakış
    noktası; ``o`` is then a stride-0 broadcast of it or a ``(3,)`` vector)
    make ``s = O − V0`` and ``q = s × e1`` depend on the triangle alone: they
    are formed once per triangle, ``(M, 3)``, instead of once per ray and
    triangle. Only ``p = d × e2`` and the three dot products with the ray's
    direction are left per pair.
    """
    o = shared_origin(o)
    d = np.asarray(d, dtype=np.float64)
    dx, dy, dz = d[:, 0, None], d[:, 1, None], d[:, 2, None]  # (N, 1) against (M,) -> (N, M)
    px, py, pz = _cross_parts(dx, dy, dz, e2[:, 0], e2[:, 1], e2[:, 2])  # p = d × e2
    det = e1[:, 0] * px + e1[:, 1] * py + e1[:, 2] * pz  # e1·p = −N·d
    threshold = PARALLEL_EPS * length(d)[:, None] * n_len[None, :]
    ok = (det > threshold) if cull_backfaces else (np.abs(det) > threshold)
    ok &= ok_tri[None, :]
    if o.ndim == 1:  # one origin: s and q per triangle, (M,)
        s = o - a
        sx, sy, sz = s[:, 0], s[:, 1], s[:, 2]
    else:  # an origin per ray: (N, M)
        sx, sy, sz = (o[:, i, None] - a[:, i] for i in range(3))
    qx, qy, qz = _cross_parts(sx, sy, sz, e1[:, 0], e1[:, 1], e1[:, 2])  # q = s × e1
    u = _divide(sx * px + sy * py + sz * pz, det, ok)  # s·p / det
    v = _divide(dx * qx + dy * qy + dz * qz, det, ok)  # d·q / det
    t = _divide(e2[:, 0] * qx + e2[:, 1] * qy + e2[:, 2] * qz, det, ok)  # e2·q / det
    hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > 0.0)
    return np.where(hit, t, np.inf)


def _cross_parts(ax: NDArray[np.float64], ay: NDArray[np.float64], az: NDArray[np.float64], bx: NDArray[np.float64],
                 by: NDArray[np.float64], bz: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The components of ``a × b`` (:func:`~glsandbox.raytrace.vec.cross`'s formula), unstacked."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


def _divide(num: NDArray[np.float64], den: NDArray[np.float64], where: NDArray[np.bool_]) -> NDArray[np.float64]:
    out = np.zeros(np.broadcast_shapes(num.shape, den.shape))
    np.divide(num, den, out=out, where=where)
    return out


class TriangleBatch:
    """``M`` triangles as three ``(M, 3)`` arrays, for the vectorized renderer.

    Build from arrays, from an indexed mesh (:meth:`from_indexed`) or from
    :class:`Triangle` objects (:meth:`from_triangles`).
    """

    __slots__ = ("v0", "v1", "v2", "_e1", "_e2", "_n_len", "_ok")

    v0: NDArray[np.float64]
    v1: NDArray[np.float64]
    v2: NDArray[np.float64]

    def __init__(self, v0: ArrayLike, v1: ArrayLike, v2: ArrayLike) -> None:
        self.v0 = np.array(as_vec3_batch(v0, "v0"))
        self.v1 = np.array(as_vec3_batch(v1, "v1"))
        self.v2 = np.array(as_vec3_batch(v2, "v2"))
        if not (self.v0.shape == self.v1.shape == self.v2.shape):
            raise RayTraceError("v0, v1, v2 must have the same shape (M, 3)")
        if not (np.all(np.isfinite(self.v0)) and np.all(np.isfinite(self.v1)) and np.all(np.isfinite(self.v2))):
            raise RayTraceError("triangle vertices must be finite")
        # Möller-Trumbore's per-triangle terms, formed once for every ray cast at the batch.
        self._e1, self._e2, self._n_len, self._ok = _triangle_terms(self.v0, self.v1, self.v2)

    @classmethod
    def from_indexed(cls, vertices: ArrayLike, indices: ArrayLike) -> TriangleBatch:
        """From a vertex array ``(V, 3)`` and indices, three per triangle (flat or ``(M, 3)``)."""
        verts = as_vec3_batch(vertices, "vertices")
        idx = np.asarray(indices)
        if idx.size % 3 != 0 or not np.issubdtype(idx.dtype, np.integer):
            raise RayTraceError(f"indices must be integers, three per triangle; got {idx.size} of {idx.dtype}")
        idx = idx.reshape(-1, 3)
        if idx.size and (idx.min() < 0 or idx.max() >= len(verts)):
            raise RayTraceError(f"indices must lie in [0, {len(verts)}), got {idx.min()}..{idx.max()}")
        return cls(verts[idx[:, 0]], verts[idx[:, 1]], verts[idx[:, 2]])

    @classmethod
    def from_triangles(cls, triangles: list[Triangle]) -> TriangleBatch:
        return cls(
            np.array([t.v0 for t in triangles]).reshape(-1, 3),
            np.array([t.v1 for t in triangles]).reshape(-1, 3),
            np.array([t.v2 for t in triangles]).reshape(-1, 3),
        )

    def __len__(self) -> int:
        return int(self.v0.shape[0])

    def intersect_many(
        self, origins: ArrayLike, directions: ArrayLike, cull_backfaces: bool = False
    ) -> NDArray[np.float64]:
        """``(N, M)`` array of ``t`` for every ray against every triangle (``inf`` = miss)."""
        return moller_trumbore_many(origins, directions, self.v0, self.v1, self.v2, cull_backfaces=cull_backfaces)

    def nearest_many(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        cull_backfaces: bool = False,
        chunk_elements: int = 1 << 13,
    ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        """Nearest hit per ray: ``(t, index)``, ``t = inf`` and ``index = −1`` for a miss.

        Rays and triangles are processed in blocks of at most about
        ``chunk_elements`` ray-triangle pairs: blocks of rays against every
        triangle while the triangles are few (the default keeps a block's
        dozen ``(rays, M)`` temporaries in a core's cache, far faster than
        streaming ``(N, M)`` arrays through memory), blocks of triangles too
        when they are many. Ties go to the lower index (the course's
        ``min_indis`` loop keeps the first minimum).
        """
        o, d = broadcast_rays(origins, directions)
        n_rays = d.shape[0]
        best_t = np.full(n_rays, np.inf)
        best_i = np.full(n_rays, -1, dtype=np.intp)
        chunk = max(1, int(chunk_elements))
        m = len(self)
        ray_step = max(min(n_rays, 64), min(n_rays, chunk // max(1, m)), 1)
        tri_step = max(1, chunk // ray_step)
        for first in range(0, m, tri_step):
            tris = slice(first, min(m, first + tri_step))
            for lo in range(0, n_rays, ray_step):
                rays = slice(lo, min(n_rays, lo + ray_step))
                t = _moller_trumbore_kernel(o[rays], d[rays], self.v0[tris], self._e1[tris], self._e2[tris],
                                            self._n_len[tris], self._ok[tris], cull_backfaces)
                j = np.argmin(t, axis=1)  # the first minimum: the lowest index on a tie
                tj = t[np.arange(t.shape[0]), j]
                better = tj < best_t[rays]  # strictly: an earlier block keeps a tie
                best_t[rays] = np.where(better, tj, best_t[rays])
                best_i[rays] = np.where(better, j + first, best_i[rays])
        return best_t, best_i

    def __repr__(self) -> str:
        return f"TriangleBatch({len(self)} triangles)"
