"""The unit sphere ``|p| = 1`` (course section "Işın-Küre kesim testi"), an ellipsoid under
its node's model matrix; the rasterizer draws :func:`glsandbox.geometry.sphere`."""

from __future__ import annotations

import numpy as np

from glsandbox import geometry
from glsandbox.raytrace.constants import UNIT_SHAPE_TOLERANCE
from glsandbox.raytrace.shape_kind import Array, ShapeKind
from glsandbox.raytrace.sphere import Sphere
from glsandbox.raytrace.vec import length

__all__ = ["SHAPE", "hit", "holds", "surface"]

_UNIT = Sphere((0.0, 0.0, 0.0), 1.0)


def hit(o: Array, d: Array, one_sided: bool) -> Array:
    """The stable quadratic (:meth:`glsandbox.raytrace.sphere.Sphere.intersect_many`)."""
    t = _UNIT.intersect_many(o, d)
    if one_sided:  # from inside, the sphere's front faces all face away
        t = np.where(np.einsum("...j,...j->...", o, o) < 1.0, np.inf, t)
    return t


def surface(q: Array) -> tuple[Array, Array]:
    """The normal is the point itself, on the unit sphere; uv as :func:`geometry.sphere` lays
    it out: ``u`` the azimuth/2π from +z towards +x, ``v`` the polar angle/π from +y."""
    n = q / length(q)[:, None]
    uv = np.stack([np.mod(np.arctan2(n[:, 0], n[:, 2]), 2 * np.pi) / (2 * np.pi),
                   np.arccos(np.clip(n[:, 1], -1.0, 1.0)) / np.pi], axis=1)
    return n, uv


def holds(positions: Array) -> bool:
    """Every point at distance 1 from the origin (to :data:`UNIT_SHAPE_TOLERANCE`)."""
    p = np.asarray(positions, dtype=np.float64)
    return bool(np.all(np.abs(np.linalg.norm(p, axis=1) - 1.0) < UNIT_SHAPE_TOLERANCE))


SHAPE = ShapeKind(name="sphere", hit=hit, surface=surface, holds=holds,
                  own_box=np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]),
                  record=("box_min", "box_max", "inverse", "normal"), mesh=geometry.sphere)
