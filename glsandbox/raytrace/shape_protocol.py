"""What every shape offers, and the plumbing shared by the vectorized tests.

A shape answers three questions (the course asks the first two of every object
in the scene):

- ``intersect(ray)``: the nearest ``t > 0`` where the ray meets it, or ``None``;
- ``normal_at(point)``: the unit surface normal there (for shading, reflection
  and shadow rays);
- ``intersect_many(origins, directions)``: the same test for ``N`` rays at once,
  a ``(N,)`` float64 array of ``t`` with ``inf`` for a miss (so ``np.argmin``
  over shapes picks the nearest hit, as the course's ``min_indis`` loop does).

``t`` is always in units of the ray's direction as given (directions are never
normalized behind the caller's back).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.vec import Vec3, as_vec3_batch

__all__ = ["Shape", "broadcast_rays", "finite_positive_or_none", "shared_origin"]


@runtime_checkable
class Shape(Protocol):
    """The interface of :class:`Plane`, :class:`Sphere`, :class:`Triangle` and :class:`AABB`."""

    def intersect(self, ray: Ray) -> float | None:
        """Nearest ``t > 0`` along ``ray`` (units of ``ray.direction``), or ``None``."""
        ...

    def normal_at(self, point: ArrayLike) -> Vec3:
        """Unit outward (or, for open surfaces, the stored-side) normal at ``point``."""
        ...

    def intersect_many(self, origins: ArrayLike, directions: ArrayLike) -> NDArray[np.float64]:
        """``t`` for each of ``N`` rays, ``inf`` where a ray misses."""
        ...


def broadcast_rays(origins: ArrayLike, directions: ArrayLike) -> tuple[Vec3, Vec3]:
    """Origins and directions as two float64 ``(N, 3)`` arrays.

    Either may be a single ``(3,)`` vector shared by all rays (one eye point and
    many directions is the primary-ray case). Zero directions are allowed here:
    they simply miss everything (``t = inf``), without warnings.
    """
    o = as_vec3_batch(origins, "origins")
    d = as_vec3_batch(directions, "directions")
    if o.shape[0] != d.shape[0]:
        if o.shape[0] == 1:
            o = np.broadcast_to(o, d.shape)
        elif d.shape[0] == 1:
            d = np.broadcast_to(d, o.shape)
        else:
            raise RayTraceError(f"origins and directions must have the same length, got {o.shape[0]} and {d.shape[0]}")
    return o, d


def shared_origin(origins: Vec3) -> Vec3:
    """``(3,)`` when every row of ``(N, 3)`` ``origins`` is one origin, else ``origins``.

    :func:`broadcast_rays` turns a single origin (the eye of all primary rays)
    into a stride-0 view; the kernels recognise it here and form what depends
    on the origin alone (``O − C``, ``O − V0``...) once instead of per ray:
    the same numbers, computed fewer times.
    """
    if origins.ndim == 2 and origins.shape[0] > 0 and origins.strides[0] == 0:
        return origins[0]
    return origins


def finite_positive_or_none(t: NDArray[np.float64] | float) -> float | None:
    """Turn the ``inf``-for-miss convention of the kernels into ``float | None``."""
    value = float(np.asarray(t).reshape(-1)[0])
    if np.isfinite(value) and value > 0.0:
        return value
    return None
