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
both ways: too big near the origin, too small for hit points at 1e6.

The simple fix a first ray tracer uses is a *relative* epsilon (the teaching
variant, ``epsilon=SHADOW_EPSILON``)::

    offset = SHADOW_EPSILON · max(1, max_i |P_i|),  SHADOW_EPSILON = 2⁻³²

It fails where ``P``'s error does not scale with ``P``: ``P = R0 + t·Rd`` is
off by about ``u·(|R0| + |t·Rd|)`` (``u = 2⁻⁵³``), so an eye 1e7 away from a
unit sphere at the origin makes ``P`` off by 1e-9 while the offset is 2e-10:
91 of 400 lit points shadow themselves.

So by default the offset comes from a *bound* on ``P``'s rounding error
(pbrt-v4, "Managing Rounding Error"): :func:`first_hit` records it in
:attr:`Hit.error`, ``γ(16)·(|R0| + |t·Rd|)`` per component
(:data:`~glsandbox.raytrace.constants.RAY_POINT_GAMMA`), and the origin moves
along the normal by that bound's reach along it, ``Σ|N_i|·error_i``, then one
float further in each moved coordinate, flipped to the light's side of the
surface (so a point facing away from the light starts just *inside* a closed
shape and is correctly shadowed by it). Without a normal it steps that far
along the shadow ray itself. A bare point with no ``error`` gets the teaching
variant (``|P|`` is then the only scale known). The bound is as small as the
arithmetic allows, so a contact shadow a millionth of a unit deep survives:
pass the :class:`Hit` (``in_shadow(hit, light, shapes)``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.constants import RAY_POINT_GAMMA, UNIT_F64, gamma
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.shape_protocol import Shape, broadcast_rays
from glsandbox.raytrace.vec import Vec3, as_vec3, dot, length, moved_off, normalize

__all__ = [
    "SHADOW_EPSILON",
    "Hit",
    "first_hit",
    "in_shadow",
    "nearest_hit",
    "nearest_hit_many",
    "shadow_ray",
]

#: The teaching variant's relative offset of shadow-ray origins (see the module
#: docstring): ``in_shadow(..., epsilon=SHADOW_EPSILON)``.
SHADOW_EPSILON: float = 2.0**-32


@dataclass(frozen=True, eq=False)
class Hit:
    """Where a ray first meets the scene.

    ``t`` along the ray (units of its direction), ``index`` of the shape in
    the list given, the ``point`` ``R0 + t·Rd``, the shape's unit ``normal``
    there, the ``shape`` itself, and ``error``: a bound on the point's rounding
    error per component (see the module docstring), what :func:`shadow_ray`
    offsets by.
    """

    t: float
    index: int
    point: Vec3
    normal: Vec3
    shape: Shape
    error: Vec3 | None = None


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
    error = gamma(RAY_POINT_GAMMA, UNIT_F64) * (np.abs(ray.origin) + np.abs(t * ray.direction))
    return Hit(t=t, index=i, point=point, normal=shapes[i].normal_at(point), shape=shapes[i], error=error)


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
    point: ArrayLike | Hit,
    light_position: ArrayLike,
    normal: ArrayLike | None = None,
    epsilon: float | None = None,
    *,
    error: ArrayLike | None = None,
) -> tuple[Ray, float]:
    """The shadow ray from ``point`` to the light and the distance to the light.

    The ray's direction is a unit vector (so ``t`` is a distance) and its
    origin is ``point`` moved off the surface by the bound ``error`` on its
    rounding error, as the module docstring explains. ``point`` may be a
    :class:`Hit` (from :func:`first_hit`): its point, normal and error bound
    are used. A bare point with no ``error`` gets the teaching variant's
    relative offset ``epsilon·max(1, max|P|)`` (``epsilon`` defaults to
    :data:`SHADOW_EPSILON`): without knowing how ``P`` was computed, ``|P|`` is
    the only scale there is. Worked example #9: from ``(72, 21, 0)`` to
    ``L = (100, 117, 0)`` the direction is ``(0.28, 0.96, 0)`` and the distance
    100 (up to the offset). Raises :class:`RayTraceError` when the light sits on the point.
    """
    if isinstance(point, Hit):
        normal = point.normal if normal is None else normal
        error = point.error if error is None else error
        point = point.point
    if epsilon is None and error is None:
        epsilon = SHADOW_EPSILON
    p = as_vec3(point, "point")
    light = as_vec3(light_position, "light position")
    if normal is not None:
        n = normalize(as_vec3(normal, "normal"))
        if float(dot(n, light - p)) < 0.0:
            n = -n  # offset towards the light's side of the surface
    else:
        n = normalize(light - p)
    if epsilon is not None:
        step = float(epsilon) * max(1.0, float(np.max(np.abs(p)))) * n
    else:
        step = float(np.dot(np.abs(n), np.abs(as_vec3(error, "error")))) * n
    origin = moved_off(p, step)  # one float further in each moved coordinate
    to_light = light - origin
    distance = float(length(to_light))
    return Ray(origin, to_light / distance), distance


def in_shadow(
    point: ArrayLike | Hit,
    light_position: ArrayLike,
    shapes: Sequence[Shape],
    normal: ArrayLike | None = None,
    *,
    epsilon: float | None = None,
    error: ArrayLike | None = None,
) -> bool:
    """Gölge testi: is something between ``point`` and the light?

    Blocked iff some shape is hit at ``0 < t < distance to the light`` (not the
    notes' erratum of #10, see the module docstring). ``normal``, the surface
    normal at ``point``, makes the self-intersection offset robust, and
    ``error`` (a :class:`Hit`'s; or pass the :class:`Hit` itself as ``point``)
    makes it as small as the arithmetic allows; without it, the teaching
    variant's relative ``epsilon`` (:data:`SHADOW_EPSILON`). The shape the point
    lies on may (and should) be among ``shapes``.
    """
    ray, distance = shadow_ray(point, light_position, normal, epsilon, error=error)
    for shape in shapes:
        t = shape.intersect(ray)
        if t is not None and 0.0 < t < distance:
            return True
    return False
