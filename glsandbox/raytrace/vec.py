"""Vektörel işlemler: the course's vector basics, in float64.

Every helper works on one vector of shape ``(3,)`` or on a batch of shape
``(..., 3)`` (the last axis is x, y, z), so the same code serves one ray and a
whole image of rays.

The sums are written out component by component, in a fixed order
(x, then y, then z), instead of ``np.dot``/``np.sum``: a scalar call and a
batched call then round identically, bit for bit. The vectorized intersection
kernels rely on that (one ray through :meth:`Sphere.intersect` gives exactly the
same ``t`` as the same ray inside :meth:`Sphere.intersect_many`).

Worked example #1: ``R1 = (30, -80, -60)``, ``R2 = (-30, -80, -60)``;
``cross(R1, R2) = (0, 3600, -4800)``, ``length = 6000``,
``normalize = (0, 0.6, -0.8)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.raytrace_error import RayTraceError

Vec3 = NDArray[np.float64]
"""A float64 array whose last axis has length 3 (one vector or a batch)."""

__all__ = [
    "moved_off",
    "Vec3",
    "as_vec3",
    "as_vec3_batch",
    "cross",
    "dot",
    "length",
    "normalize",
]


def as_vec3(value: ArrayLike, name: str = "vector") -> Vec3:
    """``value`` as a finite float64 array of shape ``(3,)``.

    Raises :class:`RayTraceError` (a ``ValueError``) naming ``name`` otherwise.
    """
    try:
        arr = np.array(value, dtype=np.float64)  # a copy: callers may not mutate ours
    except (TypeError, ValueError) as exc:
        raise RayTraceError(f"{name} must be 3 numbers, got {value!r}") from exc
    if arr.shape != (3,):
        raise RayTraceError(f"{name} must have shape (3,), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise RayTraceError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def as_vec3_batch(value: ArrayLike, name: str = "vectors") -> Vec3:
    """``value`` as a float64 array of shape ``(N, 3)`` (a single ``(3,)`` becomes ``(1, 3)``)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise RayTraceError(f"{name} must be an array of 3-vectors, got {value!r}") from exc
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise RayTraceError(f"{name} must have shape (N, 3), got shape {arr.shape}")
    return arr


def dot(a: ArrayLike, b: ArrayLike) -> Any:
    """Skaler çarpım: ``a·b = ax·bx + ay·by + az·bz = |a||b|cos(β)``.

    Returns a float64 scalar for two vectors, an array for batches (broadcasting).
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def cross(a: ArrayLike, b: ArrayLike) -> Vec3:
    """Vektörel çarpım, exactly as the notes write it::

        R1 × R2 = (R1y·R2z − R1z·R2y,  R1z·R2x − R1x·R2z,  R1x·R2y − R1y·R2x)

    The result is perpendicular to both, with length ``|a||b|sin(β)`` (twice the
    area of the triangle the two edges span). Right-handed.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    bx, by, bz = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=-1)


def length(v: ArrayLike) -> Any:
    """``|R| = sqrt(x² + y² + z²)``; a scalar for one vector, an array for a batch."""
    v = np.asarray(v, dtype=np.float64)
    return np.sqrt(dot(v, v))


def normalize(v: ArrayLike) -> Vec3:
    """Normalizasyon: ``v / |v|``, the unit vector (birim vektör) along ``v``.

    Raises :class:`RayTraceError` for a zero (or non-finite) vector, which has no
    direction; in a batch, for any such row.
    """
    v = np.asarray(v, dtype=np.float64)
    n = length(v)
    if np.any(~np.isfinite(n)) or np.any(n == 0.0):
        raise RayTraceError(f"cannot normalize a zero or non-finite vector: {v.tolist()}")
    unit: Vec3 = v / np.asarray(n)[..., None]
    return unit


def moved_off(point: ArrayLike, step: ArrayLike) -> NDArray[np.float64]:
    """``point + step``, each coordinate the step moves then rounded one float further
    the same way (pbrt-v4's robust spawned origins): the sum's own rounding can then
    never put the point back within the bound the step was sized for."""
    moved = np.asarray(point, dtype=np.float64) + step
    step = np.broadcast_to(step, moved.shape)
    result: NDArray[np.float64] = np.where(step > 0.0, np.nextafter(moved, np.inf),
                                           np.where(step < 0.0, np.nextafter(moved, -np.inf), moved))
    return result
