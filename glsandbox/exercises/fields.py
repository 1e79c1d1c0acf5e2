"""Fields of inputs for probe pictures: the pixel grid, mapped to the exercise's space.

Every probe's pixel ``(row, column)`` of an ``n x n`` picture is the point
``(u, v)`` of a square, ``u`` growing to the right and ``v`` upwards (so
the picture reads like a plot), sampled at the pixels' centres.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["grid", "hemisphere", "plain"]


def grid(n: int, low: float, high: float) -> NDArray[np.float64]:
    """``(n·n, 2)`` points ``(u, v)`` of the square ``[low, high]²``, row by row from the top."""
    centres = low + (np.arange(n) + 0.5) * (high - low) / n
    u, v = np.meshgrid(centres, centres[::-1])
    return np.stack([u.ravel(), v.ravel()], axis=1)


def hemisphere(n: int) -> NDArray[np.float64]:
    """``(n·n, 3)`` unit vectors of the upper (z >= 0) hemisphere seen from above: pixel
    ``(u, v)`` of the unit disc is the normal ``(u, v, sqrt(1 − u² − v²))``; outside the
    disc, the horizon's vector in that direction."""
    uv = grid(n, -1.0, 1.0)
    r2 = np.sum(uv * uv, axis=1)
    scale = np.where(r2 > 1.0, 1.0 / np.sqrt(np.maximum(r2, 1e-300)), 1.0)
    uv = uv * scale[:, None]
    z = np.sqrt(np.maximum(0.0, 1.0 - np.sum(uv * uv, axis=1)))
    return np.column_stack([uv, z])


def plain(values: NDArray[np.float64]) -> list[tuple[float, ...]]:
    """Rows of an array as tuples of Python floats (what a student's function is given)."""
    return [tuple(float(x) for x in row) for row in values.tolist()] if values.ndim > 1 else \
        [float(x) for x in values.tolist()]  # type: ignore[return-value]


def unit(v: tuple[float, float, float]) -> tuple[float, float, float]:
    """``v / |v|`` as plain floats."""
    length = math.sqrt(sum(x * x for x in v))
    return (v[0] / length, v[1] / length, v[2] / length)
