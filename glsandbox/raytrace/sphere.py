"""Işın-Küre kesim testi: ray-sphere intersection, two ways.

The course's geometric test (``method="geometric"``)
----------------------------------------------------
With a unit direction ``d``, centre ``C``, radius ``r`` and ray origin ``O``::

    l  = C − O                 vector from the origin to the centre
    s  = l·d                   where the ray passes closest to C (projection)
    m² = l·l − s²              squared distance from C to the ray (l² = m² + s²)
    m² > r²                  → miss
    q  = sqrt(r² − m²)         half the chord
    l·l > r² (dışta, outside): t = s − q   (and s < 0 means the sphere is behind)
    l·l ≤ r² (içte,  inside):  t = s + q   (the exit point)

Worked example #4: ``C = (0,0,100)``, ``r = 75``, ray ``(0,0,0)`` along
``(0, 0.6, 0.8)``: ``s = 80``, ``m² = 10000 − 6400 = 3600``,
``q = sqrt(5625 − 3600) = 45``, ``t = 35``, point ``(0, 21, 28)``.

Its weakness is ``m² = l·l − s²``: two huge, nearly equal numbers subtracted.
For a sphere of radius 1 at distance 1e8, ``l·l ≈ 1e16`` carries an absolute
rounding error of about 1, as big as ``r²`` itself, so ``q`` (and ``t``) lose
every digit below the units.

The stable form (``method="stable"``, the default)
--------------------------------------------------
Ray Tracing Gems, chapter 7 ("Precision Improvements for Ray/Sphere
Intersection", Haines, Günther, Akenine-Möller). Write the hit condition as the
quadratic ``a·t² − 2·b·t + c = 0`` with (for any, not necessarily unit, ``d``)::

    a = d·d,   b = l·d,   c = l·l − r² = (|l| − r)(|l| + r)

1. The discriminant ``b² − a·c`` is computed as ``a·(r² − |l − (b/a)·d|²)``.
   The vector ``h = l − (b/a)·d`` runs from the ray's closest point to the
   centre, so ``|h| = m`` is obtained from a *vector* difference, not from the
   difference of two squares: an error in ``b/a`` moves the closest point along
   ``d``, perpendicular to ``h``, and only adds to ``|h|²`` in quadrature.
2. The roots ``(b ± sqrt(disc))/a`` are formed without cancellation: with
   ``q = b + sign(b)·sqrt(disc)`` (the "q = −(b + sign(b)·sqrt(disc))/2" trick
   of the book, written for our half-``b`` with the opposite sign), the roots
   are ``q/a`` and ``c/q`` (their product is ``c/a``).
3. ``c = l·l − r²`` is factored as ``(|l| − r)(|l| + r)``: for an origin near
   the surface (shadow and reflection rays) the subtraction ``|l| − r`` is exact.

The nearest positive root is returned: the entry point from outside, the exit
point from inside (a ray starting inside a sphere returns the exit ``t``).
An origin on the surface (a shadow or reflected ray leaving it) is the root
``t = 0``: where ``c`` is within its rounding-error bound of 0 the root
``c/q`` is taken as 0, so such a ray never meets the surface it leaves again
and a ray into the sphere returns its far side (the bound is derived at the
line). The geometric test, the course's teaching form, has no such bound.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.constants import SPHERE_C_GAMMA, UNIT_F64, gamma
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays, finite_positive_or_none, shared_origin
from glsandbox.raytrace.vec import Vec3, as_vec3, dot, length, normalize

__all__ = ["Sphere", "SPHERE_METHODS"]

#: The names :meth:`Sphere.intersect` accepts.
SPHERE_METHODS: tuple[str, ...] = ("stable", "geometric")


class Sphere:
    """A sphere with ``center`` and ``radius > 0``."""

    __slots__ = ("center", "radius")

    center: Vec3
    radius: float

    def __init__(self, center: ArrayLike, radius: float) -> None:
        self.center = as_vec3(center, "sphere center")
        self.radius = float(radius)
        if not (np.isfinite(self.radius) and self.radius > 0.0):
            raise RayTraceError(f"sphere radius must be positive and finite, got {radius!r}")

    def normal_at(self, point: ArrayLike) -> Vec3:
        """Outward unit normal ``(P − C)/|P − C|`` (``= (P − C)/r`` on the surface).

        Worked example #5: ``((0,21,28) − (0,0,100))/75 = (0, 0.28, −0.96)``.
        """
        return normalize(as_vec3(point, "point") - self.center)

    def intersect(self, ray: Ray, method: str = "stable") -> float | None:
        """Nearest ``t > 0`` (entry from outside, exit from inside) or ``None``.

        ``method`` is ``"stable"`` (default) or ``"geometric"`` (the course's test).
        """
        if method == "stable":
            return finite_positive_or_none(self.intersect_many(ray.origin, ray.direction))
        if method == "geometric":
            return self._intersect_geometric(ray)
        raise RayTraceError(f"unknown sphere method {method!r}; choose one of {SPHERE_METHODS}")

    def _intersect_geometric(self, ray: Ray) -> float | None:
        """The course's test, step by step (see the module docstring)."""
        d_len = float(length(ray.direction))
        d = ray.direction / d_len  # the course's Rd is a unit vector
        l = self.center - ray.origin  # noqa: E741 (the course's l)
        s = float(dot(l, d))
        l2 = float(dot(l, l))
        r2 = self.radius * self.radius
        m2 = l2 - s * s
        if m2 > r2:
            return None  # the ray passes farther than r from the centre
        q = math.sqrt(r2 - m2)
        if l2 > r2:  # dışta: the origin is outside the sphere
            if s < 0.0:
                return None  # the sphere is behind the ray
            t = s - q
        else:  # içte (or on the surface): leave through the far side
            t = s + q
        if not t > 0.0:
            return None
        return t / d_len  # back to units of the direction as given

    def intersect_many(self, origins: ArrayLike, directions: ArrayLike) -> NDArray[np.float64]:
        """The stable test for ``N`` rays: a ``(N,)`` array of ``t``, ``inf`` for a miss."""
        o, d = broadcast_rays(origins, directions)
        r = self.radius
        origin = shared_origin(o)  # one (3,) vector for a shared origin
        l = self.center - origin  # noqa: E741 (the course's l)
        a = dot(d, d)
        b = dot(l, d)  # a·s in the course's terms (s = b/a along a non-unit d)
        ok = a > 0.0
        s = np.zeros_like(a)
        np.divide(b, a, out=s, where=ok)
        h = l - s[:, None] * d  # from the ray's closest point to the centre: |h| = m
        disc = a * (r * r - dot(h, h))  # = b² − a·c, without cancellation
        ok &= disc >= 0.0
        sq = np.sqrt(np.where(ok, disc, 0.0))
        q = b + np.copysign(sq, b)  # |q| = |b| + sqrt(disc): no cancellation
        l_len = np.sqrt(dot(l, l))
        c = (l_len - r) * (l_len + r)  # l·l − r², exact subtraction near the surface
        # The sphere's error bound. fl(l·l) is off by γ(3)·l·l (three squares, two sums of
        # non-negative terms) and its sqrt by u more: |l| is off by at most γ(3)·|l|, and
        # |l| − r by that plus u·||l| − r|; each of the two factors and their product round
        # once more: |c − c_exact| ≤ γ(5)·(|l| + r)². An origin given in floats is itself
        # known only to u·|O| per component, and the centre to u·|C|: their share of |l| − r
        # adds γ·(|C| + |O|). So |c| ≤ γ(5)·(|l| + r + |C| + |O|)·(|l| + r) means the origin
        # lies on the surface to within the arithmetic: the root c/q is 0 (the surface the
        # ray leaves), not a hit; the other root q/a (the far side, or behind) is the answer.
        reach = l_len + r + float(np.sqrt(dot(self.center, self.center))) + np.sqrt(dot(origin, origin))
        on_surface = np.abs(c) <= gamma(SPHERE_C_GAMMA, UNIT_F64) * reach * (l_len + r)
        c = np.where(on_surface, 0.0, c)
        ok &= q != 0.0  # q == 0 only for a tangent at t = 0: no positive root
        t1 = np.full_like(a, -np.inf)
        t0 = np.full_like(a, -np.inf)
        np.divide(q, a, out=t1, where=ok)
        np.divide(c, q, out=t0, where=ok)
        near = np.minimum(t0, t1)
        far = np.maximum(t0, t1)
        t = np.where(near > 0.0, near, np.where(far > 0.0, far, np.inf))
        return np.where(ok, t, np.inf)

    def __repr__(self) -> str:
        return f"Sphere(center={self.center.tolist()}, radius={self.radius!r})"
