"""The nearest hit over a scene, and the shadow test (Gölge testi).

Nearest hit
-----------
The notes collect every positive ``t`` in ``tDistances`` with the shape's index
in ``tIndices`` and keep the smallest (``min_distances`` starts at
``FLT_MAX``, ``min_indis`` at −1): the nearest object is the one seen.
:func:`nearest_hit` does exactly that and returns ``(t, index)``, or
``(inf, −1)`` when nothing is hit; :func:`first_hit` also builds the
:class:`Hit` record (point and normal) for shading.

Shadow rays
-----------
A point ``P`` is in shadow when something lies *between* it and the light: a
ray from ``P`` towards the light ``L`` hits an occluder at ``0 < t < |L − P|``
(with a unit direction, so ``t`` is a distance). An occluder *beyond* the light
does not count.

Erratum (Gölge testi, worked example #10, the 2012 exam): the notes find the
plane at ``t = 40`` with the light at distance 30 and conclude "t_light < t,
so it is in shadow". The plane is crossed beyond the light, so nothing blocks
it: ``P`` is **lit**. The notes' own 2013 answer (#9: blue sphere at
``t = 75 < 100``, in shadow) uses the right rule, which is the one used here.

Self-intersection (shadow acne) and the offset we chose
-------------------------------------------------------
``P`` was computed by an earlier intersection and is only approximately on its
surface; a shadow ray starting exactly at ``P`` may hit that same surface at a
tiny ``t`` (or a tiny negative one, and then, for a closed shape, the far
side), and the point shadows itself. An absolute epsilon (``t > 1e-4``) fails
both ways: too big near the origin, too small for hit points at 1e6, where the
rounding error of ``P`` alone is about 1e-10·1e6.

We move the origin off the surface by a *relative* amount
(cf. Ray Tracing Gems, ch. 6, "A Fast and Robust Method for Avoiding
Self-Intersection", which offsets by a fixed number of ulps of each coordinate;
a relative epsilon is the same idea in one line)::

    offset = SHADOW_EPSILON · max(1, max_i |P_i|),  SHADOW_EPSILON = 2⁻³²

that is about 2²⁰ ulps of the point's largest coordinate: far above the few
ulps of error in ``P`` and in the intersection arithmetic, far below any
feature of a scene at that scale. With the surface normal we offset along it,
flipped to the light's side of the surface (so a point facing away from the
light starts just *inside* a closed shape and is correctly shadowed by it);
without a normal we step that far along the shadow ray itself. Give the
normal when you have it: it is the robust choice for grazing light.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.base import Shape, broadcast_rays
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.vec import Vec3, as_vec3, dot, length, normalize

__all__ = [
    "SHADOW_EPSILON",
    "Hit",
    "first_hit",
    "in_shadow",
    "nearest_hit",
    "nearest_hit_many",
    "shadow_ray",
]

#: Relative offset of shadow-ray origins (see the module docstring).
SHADOW_EPSILON: float = 2.0**-32


@dataclass(frozen=True, eq=False)
class Hit:
    """Where a ray first meets the scene.

    ``t`` along the ray (units of its direction), ``index`` of the shape in
    the list given, the ``point`` ``R0 + t·Rd``, the shape's unit ``normal``
    there and the ``shape`` itself.
    """

    t: float
    index: int
    point: Vec3
    normal: Vec3
    shape: Shape


def nearest_hit(ray: Ray, shapes: Sequence[Shape]) -> tuple[float, int]:
    """``(t, index)`` of the nearest positive ``t`` over ``shapes``; ``(inf, −1)`` if none.

    The course's ``tDistances``/``min_indis`` loop: ties keep the first shape.
    """
    min_distance = math.inf  # the notes' FLT_MAX
    min_index = -1
    for i, shape in enumerate(shapes):
        t = shape.intersect(ray)
        if t is not None and t < min_distance:
            min_distance, min_index = t, i
    return min_distance, min_index


def first_hit(ray: Ray, shapes: Sequence[Shape]) -> Hit | None:
    """The :class:`Hit` record of the nearest hit, or ``None``."""
    t, i = nearest_hit(ray, shapes)
    if i < 0:
        return None
    point = ray.at(t)
    return Hit(t=t, index=i, point=point, normal=shapes[i].normal_at(point), shape=shapes[i])


def nearest_hit_many(
    origins: ArrayLike, directions: ArrayLike, shapes: Sequence[Shape]
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Vectorized :func:`nearest_hit`: ``(t, index)`` arrays of shape ``(N,)``.

    Uses each shape's ``intersect_many``; misses are ``t = inf``, ``index = −1``.
    """
    o, d = broadcast_rays(origins, directions)
    best_t = np.full(o.shape[0], np.inf)
    best_i = np.full(o.shape[0], -1, dtype=np.intp)
    for i, shape in enumerate(shapes):
        t = shape.intersect_many(o, d)
        better = t < best_t
        best_t = np.where(better, t, best_t)
        best_i = np.where(better, i, best_i)
    return best_t, best_i


def shadow_ray(
    point: ArrayLike,
    light_position: ArrayLike,
    normal: ArrayLike | None = None,
    epsilon: float = SHADOW_EPSILON,
) -> tuple[Ray, float]:
    """The shadow ray from ``point`` to the light and the distance to the light.

    The ray's direction is a unit vector (so ``t`` is a distance) and its
    origin is ``point`` moved off the surface as the module docstring explains.
    Worked example #9: from ``(72, 21, 0)`` to ``L = (100, 117, 0)`` the
    direction is ``(0.28, 0.96, 0)`` and the distance 100 (up to the offset).
    Raises :class:`RayTraceError` when the light sits on the point.
    """
    p = as_vec3(point, "point")
    light = as_vec3(light_position, "light position")
    offset = float(epsilon) * max(1.0, float(np.max(np.abs(p))))
    if normal is not None:
        n = normalize(as_vec3(normal, "normal"))
        if float(dot(n, light - p)) < 0.0:
            n = -n  # offset towards the light's side of the surface
        origin = p + offset * n
    else:
        origin = p + offset * normalize(light - p)
    to_light = light - origin
    distance = float(length(to_light))
    return Ray(origin, to_light / distance), distance


def in_shadow(
    point: ArrayLike,
    light_position: ArrayLike,
    shapes: Sequence[Shape],
    normal: ArrayLike | None = None,
    *,
    epsilon: float = SHADOW_EPSILON,
) -> bool:
    """Gölge testi: is something between ``point`` and the light?

    Blocked iff some shape is hit at ``0 < t < distance to the light`` (not the
    notes' erratum of #10, see the module docstring). ``normal``, the surface
    normal at ``point``, makes the self-intersection offset robust; the shape
    the point lies on may (and should) be among ``shapes``.
    """
    ray, distance = shadow_ray(point, light_position, normal, epsilon)
    for shape in shapes:
        t = shape.intersect(ray)
        if t is not None and 0.0 < t < distance:
            return True
    return False
