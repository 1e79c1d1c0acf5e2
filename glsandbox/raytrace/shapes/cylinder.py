"""The capped unit cylinder ``x² + z² ≤ 1, |y| ≤ 1`` (axis +y) under its node's model matrix;
the rasterizer draws :func:`glsandbox.geometry.cylinder`."""

from __future__ import annotations

import numpy as np

from glsandbox import geometry
from glsandbox.raytrace.constants import LENGTH_TINY, UNIT_SHAPE_TOLERANCE
from glsandbox.raytrace.shape_kind import Array, ShapeKind

__all__ = ["SHAPE", "hit", "holds", "surface", "unit_cylinder_t"]


def hit(o: Array, d: Array, one_sided: bool) -> Array:
    """:func:`unit_cylinder_t`, an origin inside culled when ``one_sided``."""
    t = unit_cylinder_t(np.broadcast_to(o, d.shape), d)
    if one_sided:  # from inside, every front face faces away
        inside = (o[..., 0] ** 2 + o[..., 2] ** 2 < 1.0) & (np.abs(o[..., 1]) < 1.0)
        t = np.where(inside, np.inf, t)
    return t


def unit_cylinder_t(o: Array, d: Array) -> Array:
    """The nearest ``t > 0`` where rays ``o + t·d`` (``(N, 3)`` each) meet the capped unit
    cylinder ``x² + z² ≤ 1, |y| ≤ 1``; inf for a miss.

    The side is the circle ``x² + z² = 1`` in the xz-plane: the sphere's stable
    quadratic (Ray Tracing Gems ch. 7) in two dimensions, its roots kept where
    ``|y| ≤ 1``; each cap is the plane ``y = ±1`` (course "Işın-Düzlem kesim
    testi"), kept where ``x² + z² ≤ 1``. A ray along the axis (``d_x = d_z =
    0``) meets only the caps, one parallel to them only the side."""
    ox, oy, oz = o[:, 0], o[:, 1], o[:, 2]
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    best = np.full(d.shape[0], np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = dx * dx + dz * dz
        b = -(ox * dx + oz * dz)  # l·d with l = −o, in the xz-plane
        hx = -ox - (b / a) * dx
        hz = -oz - (b / a) * dz
        disc = a * (1.0 - (hx * hx + hz * hz))
        root = np.sqrt(np.maximum(disc, 0.0))
        q = b + np.where(b >= 0.0, root, -root)
        ell = np.hypot(ox, oz)
        c = (ell - 1.0) * (ell + 1.0)
        side = (a > 0.0) & (disc >= 0.0) & (q != 0.0)
        for t in (c / q, q / a):
            ok = side & (t > 0.0) & (t < best) & (np.abs(oy + t * dy) <= 1.0)
            best = np.where(ok, t, best)
        for y in (-1.0, 1.0):
            t = (y - oy) / dy
            px, pz = ox + t * dx, oz + t * dz
            ok = (dy != 0.0) & (t > 0.0) & (t < best) & (px * px + pz * pz <= 1.0)
            best = np.where(ok, t, best)
    return best


def surface(q: Array) -> tuple[Array, Array]:
    """As :func:`geometry.cylinder` lays them out: on a cap (the hit nearer ``|y| = 1`` than
    ``x² + z² = 1``) the cap's normal and ``(½ + x/2, ½ + z/2)``, on the side the radial
    normal and ``(azimuth/2π, (1 − y)/2)``."""
    r = np.hypot(q[:, 0], q[:, 2])
    cap = np.abs(np.abs(q[:, 1]) - 1.0) < np.abs(r - 1.0)
    n = np.where(cap[:, None], np.stack([np.zeros_like(r), np.sign(q[:, 1]), np.zeros_like(r)], axis=1),
                 q * np.array([1.0, 0.0, 1.0]) / np.maximum(r, LENGTH_TINY)[:, None])
    uv = np.where(cap[:, None], np.stack([0.5 + 0.5 * q[:, 0], 0.5 + 0.5 * q[:, 2]], axis=1),
                  np.stack([np.mod(np.arctan2(q[:, 0], q[:, 2]), 2 * np.pi) / (2 * np.pi), 0.5 * (1.0 - q[:, 1])],
                           axis=1))
    return n, uv


def holds(positions: Array) -> bool:
    """Every point on the side (``x² + z² = 1``, ``|y| ≤ 1``) or a cap (``|y| = 1``, ``x² + z² ≤ 1``)."""
    p = np.asarray(positions, dtype=np.float64)
    tol = UNIT_SHAPE_TOLERANCE
    r = np.hypot(p[:, 0], p[:, 2])
    side = (np.abs(r - 1.0) < tol) & (np.abs(p[:, 1]) <= 1.0 + tol)
    cap = (np.abs(np.abs(p[:, 1]) - 1.0) < tol) & (r <= 1.0 + tol)
    return bool(np.all(side | cap))


SHAPE = ShapeKind(name="cylinder", hit=hit, surface=surface, holds=holds,
                  own_box=np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]),
                  record=("box_min", "box_max", "inverse", "normal"), mesh=geometry.cylinder)
