"""Işın-Düzlem kesim testi: the first step of the ray-triangle test.

Sign convention (the course's, from ``Ax + By + Cz + D = 0``)
-------------------------------------------------------------
A plane is the set of points ``P`` with::

    N·P + D = 0,        so  D = −(N·V0)  for any point V0 on the plane.

This is the convention that reproduces the notes' numbers. Worked example #2:
``N = (0, 0.6, −0.8)`` through ``V0 = (30, −40, 60)`` gives
``D = −(0·30 + 0.6·(−40) + (−0.8)·60) = −(−72) = 72``. (Writing the plane as
``N·P = D`` instead would give ``D = −72``.) For a unit normal, ``D`` is the
signed distance of the world origin from the plane, positive when the origin is
on the side the normal points to.

Substituting the ray ``R0 + t·Rd`` into the plane equation::

    N·(R0 + t·Rd) + D = 0   =>   t = −(N·R0 + D) / (N·Rd)

- ``N·Rd = 0``: the ray is parallel to the plane (yüzeye paralel): no hit;
- ``t <= 0``: the plane is behind the ray's origin: no hit;
- otherwise the hit point is ``R0 + t·Rd``.

Worked example #2: ray ``(0,0,0)``, ``(0,0,1)``:
``t = −(0 + 72)/(−0.8) = 90``, point ``(0, 0, 90)``. Worked example #6: the
reflected ray ``(0,21,28) + t·(0, 0.936, −0.352)`` against ``N = (0,−1,0)``,
``D = 255`` (the plane ``y = 255``) gives ``t = 250``, point ``(0, 255, −60)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays, finite_positive_or_none
from glsandbox.raytrace.vec import Vec3, as_vec3, dot, length

__all__ = ["Plane"]


class Plane:
    """The plane ``N·P + D = 0`` (see the module docstring for the sign of ``D``).

    ``normal`` need not be unit length; it fixes the plane's front side, and
    :meth:`normal_at` returns it normalized. Use :meth:`through` to build a
    plane from a normal and a point on it.
    """

    __slots__ = ("normal", "d", "unit_normal")

    normal: Vec3
    d: float
    unit_normal: Vec3

    def __init__(self, normal: ArrayLike, d: float) -> None:
        self.normal = as_vec3(normal, "plane normal")
        n = float(length(self.normal))
        if n == 0.0:
            raise RayTraceError("plane normal must not be the zero vector")
        self.d = float(d)
        if not np.isfinite(self.d):
            raise RayTraceError(f"plane D must be finite, got {d!r}")
        self.unit_normal = self.normal / n

    @classmethod
    def through(cls, normal: ArrayLike, point: ArrayLike) -> Plane:
        """The plane with this normal through ``point``: ``D = −(N·point)``.

        Worked example #2: ``Plane.through((0, 0.6, −0.8), (30, −40, 60)).d == 72``;
        worked example #10: ``Plane.through((0, −0.6, 0.8), (0, 20, −34)).d == 39.2``.
        """
        n = as_vec3(normal, "plane normal")
        p = as_vec3(point, "point on the plane")
        return cls(n, -float(dot(n, p)))

    def signed_distance(self, point: ArrayLike) -> float:
        """``(N·P + D)/|N|``: positive on the side the normal points to."""
        p = as_vec3(point, "point")
        return float(dot(self.normal, p) + self.d) / float(length(self.normal))

    def normal_at(self, point: ArrayLike) -> Vec3:
        """The unit normal; the same everywhere on a plane."""
        return self.unit_normal.copy()

    def intersect(self, ray: Ray) -> float | None:
        """``t = −(N·R0 + D)/(N·Rd)`` if ``t > 0``; ``None`` when parallel or behind."""
        return finite_positive_or_none(self.intersect_many(ray.origin, ray.direction))

    def intersect_many(self, origins: ArrayLike, directions: ArrayLike) -> NDArray[np.float64]:
        """The plane test for ``N`` rays: a ``(N,)`` array of ``t``, ``inf`` for a miss."""
        o, rd = broadcast_rays(origins, directions)
        numerator = -(dot(self.normal, o) + self.d)
        denominator = dot(self.normal, rd)
        t = np.full(o.shape[0], np.inf)
        # Parallel rays (N·Rd == 0) are skipped, never divided: no warnings.
        np.divide(numerator, denominator, out=t, where=denominator != 0.0)
        t[~(t > 0.0)] = np.inf
        return t

    def __repr__(self) -> str:
        return f"Plane(normal={self.normal.tolist()}, d={self.d!r})"
