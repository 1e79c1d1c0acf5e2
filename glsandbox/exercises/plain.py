"""Vector arithmetic on plain sequences, as a student writes it: what the named mistakes use.

The named mistakes are wrong versions of the student's function written the
way a student would write them (lists and loops, no numpy), so that they go
wrong exactly where a student's would; these are their shared steps.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["cross", "dot", "sub", "unit"]

Vector = Sequence[float]


def sub(a: Vector, b: Vector) -> list[float]:
    """``a - b``."""
    return [x - y for x, y in zip(a, b, strict=True)]


def dot(a: Vector, b: Vector) -> float:
    """``a·b``."""
    return sum(x * y for x, y in zip(a, b, strict=True))


def cross(a: Vector, b: Vector) -> list[float]:
    """``a x b = (a.y·b.z - a.z·b.y, a.z·b.x - a.x·b.z, a.x·b.y - a.y·b.x)``."""
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(v: Vector) -> list[float] | None:
    """``v / |v|``; None for the zero vector."""
    size = math.sqrt(dot(v, v))
    return None if size == 0 else [x / size for x in v]
