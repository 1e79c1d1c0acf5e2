"""Işın: the ray ``R(t) = R0 + t·Rd``.

The course sends rays from the eye (bakış noktası) through the image plane;
everything the ray meets is reported by its parameter ``t`` along the ray. We
keep ``Rd`` exactly as given (it need not be a unit vector), so ``t`` is
measured *in units of the direction as given*: with a unit direction ``t`` is a
distance, with ``Rd = target - R0`` the target sits at ``t = 1``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.vec import Vec3, as_vec3

__all__ = ["Ray"]


class Ray:
    """A ray ``origin + t·direction`` (``R0 + t·Rd``), stored as float64 ``(3,)`` arrays.

    ``direction`` must be finite and non-zero; it is *not* normalized.
    """

    __slots__ = ("origin", "direction")

    origin: Vec3
    direction: Vec3

    def __init__(self, origin: ArrayLike, direction: ArrayLike) -> None:
        self.origin = as_vec3(origin, "ray origin")
        self.direction = as_vec3(direction, "ray direction")
        if not np.any(self.direction):
            raise RayTraceError("ray direction must not be the zero vector")

    def at(self, t: float) -> Vec3:
        """The point ``R0 + t·Rd`` (the course's ``R = R0 + t*Rd``)."""
        return self.origin + t * self.direction

    def __repr__(self) -> str:
        return f"Ray(origin={self.origin.tolist()}, direction={self.direction.tolist()})"
