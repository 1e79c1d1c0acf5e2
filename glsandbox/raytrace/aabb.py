"""Axis Aligned Bounding Box: the course's second acceleration method.

The notes' ``AABB(R0, R1, B, u, v, w)`` takes the box's centre ``B`` and its
half-sizes ``u, v, w`` (``AABB(-25, -20, 70, 15, 20, 30)``); here the box is
stored by its two corners and :meth:`AABB.from_center` builds it the course's way.

The slab test
-------------
The box is the intersection of three slabs ``min_i <= x_i <= max_i``. Along
the ray, slab ``i`` is crossed between::

    t_a = (min_i − O_i) / d_i,   t_b = (max_i − O_i) / d_i

(swapped when ``d_i < 0``). The ray is inside the box on
``[max of the entries, min of the exits]``; it hits when that interval is not
empty and ends after ``t = 0``.

IEEE arithmetic does the special cases for us, deliberately:

- ``d_i = +0.0`` gives ``1/d_i = +inf`` and ``d_i = −0.0`` gives ``−inf``; a ray
  parallel to a slab then gets ``t = ±inf`` for both planes: ``(−inf, +inf)`` if
  the origin is between them (the slab never ends), an empty interval otherwise.
  The sign bit, not ``d_i < 0``, picks which plane is the entry, so ``−0.0``
  behaves as the negative direction it is.
- An origin exactly *on* a slab plane with ``d_i = ±0`` gives ``0 · inf = NaN``.
  The ray then runs inside the plane of a face; we count the boundary as part of
  the box, so a NaN entry becomes ``−inf`` and a NaN exit ``+inf``.

Boundaries are inclusive throughout (a ray through an edge or a corner hits).
An origin inside the box (or on a face, heading in) returns the exit ``t``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays, finite_positive_or_none, shared_origin
from glsandbox.raytrace.vec import Vec3, as_vec3

__all__ = ["AABB", "reciprocals"]


def reciprocals(directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """``1/d`` of ``(N, 3)`` directions as a ``(3, N)`` array, one contiguous row an axis
    (what :meth:`AABB.slabs_reciprocal` takes). Deliberately ``1/(+0) = +inf``
    and ``1/(−0) = −inf``, without a warning."""
    with np.errstate(divide="ignore"):
        return 1.0 / np.ascontiguousarray(np.asarray(directions, dtype=np.float64).T)


class AABB:
    """An axis-aligned box between corners ``min`` and ``max`` (``min <= max``)."""

    __slots__ = ("min", "max")

    min: Vec3
    max: Vec3

    def __init__(self, min: ArrayLike, max: ArrayLike) -> None:  # noqa: A002 (the course's words)
        self.min = as_vec3(min, "AABB min")
        self.max = as_vec3(max, "AABB max")
        if np.any(self.min > self.max):
            raise RayTraceError(f"AABB min must not exceed max, got min={self.min.tolist()} max={self.max.tolist()}")

    @classmethod
    def from_center(cls, center: ArrayLike, half_size: ArrayLike) -> AABB:
        """The course's form: centre ``B`` and half-sizes ``(u, v, w)``."""
        c = as_vec3(center, "AABB center")
        h = as_vec3(half_size, "AABB half size")
        if np.any(h < 0.0):
            raise RayTraceError(f"AABB half sizes must be >= 0, got {h.tolist()}")
        return cls(c - h, c + h)

    @property
    def center(self) -> Vec3:
        return (self.min + self.max) * 0.5

    def contains(self, point: ArrayLike) -> bool:
        """Whether ``point`` is in the box (boundary included)."""
        p = as_vec3(point, "point")
        return bool(np.all(self.min <= p) and np.all(p <= self.max))

    def normal_at(self, point: ArrayLike) -> Vec3:
        """Unit outward normal of the face nearest to ``point``.

        The face is the axis where ``point`` sticks out most relative to the
        box's half-size (ties go to the lowest axis).
        """
        p = as_vec3(point, "point")
        half = (self.max - self.min) * 0.5
        rel = np.abs(p - self.center) - half  # signed distance outside each slab
        axis = int(np.argmax(rel))
        n = np.zeros(3)
        n[axis] = 1.0 if p[axis] >= self.center[axis] else -1.0
        return n

    def intersect(self, ray: Ray) -> float | None:
        """Nearest ``t > 0``: the entry, or the exit for an origin inside; else ``None``."""
        return finite_positive_or_none(self.intersect_many(ray.origin, ray.direction))

    def slabs(self, origins: ArrayLike, directions: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(t_near, t_far)`` for ``N`` rays: the ray is in the box on ``[t_near, t_far]``.

        Empty when ``t_near > t_far``. See the module docstring for ±0 and NaN.
        """
        o, d = broadcast_rays(origins, directions)
        return self.slabs_reciprocal(shared_origin(o), reciprocals(d))

    def slabs_reciprocal(self, origin: Vec3, inverse: NDArray[np.float64]
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`slabs` with the directions' reciprocals already formed: ``inverse``
        is :func:`reciprocals` of the ``(N, 3)`` directions, ``(3, N)``, one row an
        axis; ``origin`` is ``(N, 3)``, or ``(3,)`` for one origin shared by all.

        A renderer tests every ray against many boxes, so it forms ``1/d`` once.
        Per axis, the entry is the smaller of ``t_a, t_b`` and the exit the larger:
        for ``d_i > 0`` that is ``t_a`` then ``t_b``, for ``d_i < 0`` (or ``−0.0``,
        whose reciprocal is ``−inf``) the other way round, the same pair the sign
        bit picks. ``np.minimum``/``np.maximum`` keep a NaN (the origin on a slab
        plane with ``d_i = ±0``); ``np.fmax``/``np.fmin`` then skip it, so that
        slab neither starts nor ends, as the module docstring says.
        """
        origin = np.asarray(origin, dtype=np.float64)
        near = np.full(inverse.shape[1], -np.inf)
        far = np.full(inverse.shape[1], np.inf)
        with np.errstate(invalid="ignore"):  # 0·inf = NaN when O lies on a slab plane
            for axis in range(3):
                o = origin[..., axis]
                ta = (self.min[axis] - o) * inverse[axis]
                tb = (self.max[axis] - o) * inverse[axis]
                np.fmax(near, np.minimum(ta, tb), out=near)
                np.fmin(far, np.maximum(ta, tb, out=tb), out=far)
        return near, far

    def intersect_many(self, origins: ArrayLike, directions: ArrayLike) -> NDArray[np.float64]:
        """The slab test for ``N`` rays: a ``(N,)`` array of ``t``, ``inf`` for a miss."""
        t_near, t_far = self.slabs(origins, directions)
        t = np.where(t_near > 0.0, t_near, t_far)
        return np.where((t_near <= t_far) & (t > 0.0), t, np.inf)

    def __repr__(self) -> str:
        return f"AABB(min={self.min.tolist()}, max={self.max.tolist()})"
