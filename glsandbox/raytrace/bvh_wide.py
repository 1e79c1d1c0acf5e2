"""A wide BVH: the binary SAH tree of :mod:`glsandbox.raytrace.bvh` collapsed to 4 children a node.

Why wider? A traversal step of the binary tree tests two boxes and then
decides where to go; a step of a 4-wide tree tests four boxes with the same
decision, so a ray needs about half the steps to reach its leaves (the tree
is half as deep) and its four box tests can run side by side (SIMD lanes,
one ``vec4`` per plane in GLSL). The boxes are the binary tree's own: a wide
node's children are its binary grandchildren (or deeper), so nothing is
rebuilt and every box is still exact.

The collapse (the standard one, e.g. Wald et al. 2008 "Getting rid of
packets", Pinto 2010): a wide node starts as its binary node; while it has
fewer than :data:`WIDTH` children and one of them is an inner binary node,
the inner child with the *largest surface area* is opened (replaced by its
two children). By the SAH argument (a random ray hits a box with a
probability proportional to its area) the largest child is the one a ray is
most likely to enter, so opening it saves the most box tests of a level
below. Every inner child left at the end becomes a wide node of its own.
Leaves are not touched: a wide leaf is a binary leaf (the same triangles).

Layout: record ``r`` holds :data:`WIDTH` child slots, ``child[r, s]`` the
binary node (``-1``: an empty slot, always after the used ones). Record 0
is the root's: the binary root opened (or, for a tree that is one leaf,
that leaf alone). ``record_of[n]`` is the record of binary inner node ``n``
(``-1`` where ``n`` is no wide node: a leaf, or a node opened into its
parent). Everything is made level by level with numpy (one Python loop step
per wide level and per opening), never per node.

:func:`closest_hit_wide` traverses it with numpy, for the tests: the same
padded slab test and tie rule as :func:`~glsandbox.raytrace.bvh_traverse.closest_hit`
(which stays the float64 reference), so the two agree bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.bvh import BVH
from glsandbox.raytrace.bvh_traverse import BOX_PAD, Hits, _rays
from glsandbox.raytrace.watertight import ray_setup, watertight_pairs

__all__ = ["WIDTH", "WideBVH", "closest_hit_wide", "collapse"]

#: Children a wide node holds at most.
WIDTH: int = 4


@dataclass(frozen=True, eq=False)
class WideBVH:
    """A binary :class:`~glsandbox.raytrace.bvh.BVH` seen as a :data:`WIDTH`-wide tree (module docstring)."""

    bvh: BVH
    child: NDArray[np.int64]  # (R, WIDTH) binary node of each slot, -1 empty
    record_of: NDArray[np.int64]  # (N,) record of a binary node that is a wide node, else -1
    depth: int  # wide levels: 1 for a root whose children are all leaves

    @property
    def record_count(self) -> int:
        return int(self.child.shape[0])

    def slots(self) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
        """Per slot ``(ref, count, used)``: an inner child's record and count 0, a leaf's
        first stored triangle and its triangle count, an empty slot ``(0, 0, False)``."""
        used = self.child >= 0
        node = np.where(used, self.child, 0)
        count = np.where(used, self.bvh.node_count[node], 0)
        ref = np.where(count > 0, self.bvh.node_first[node], self.record_of[node])
        return np.where(used, ref, 0), count, used


def _half_areas(bvh: BVH) -> NDArray[np.float64]:
    """Half the surface area of every binary node's box (0 for an empty one)."""
    e = np.maximum(bvh.node_max - bvh.node_min, 0.0)
    result: NDArray[np.float64] = e[:, 0] * e[:, 1] + e[:, 1] * e[:, 2] + e[:, 2] * e[:, 0]
    return result


def _open_level(bvh: BVH, nodes: NDArray[np.int64], area: NDArray[np.float64], width: int) -> NDArray[np.int64]:
    """The child slots ``(len(nodes), width)`` of the wide nodes made from binary ``nodes``:
    each starts as its own node and opens its largest inner child, ``width − 1`` times at most.
    All rows open together: a row with no inner child left has none at the next opening either
    (opening only turns an inner node into its children), so its empty slots stay at the end."""
    kids = np.full((nodes.size, width), -1, dtype=np.int64)
    kids[:, 0] = nodes
    inner = bvh.node_count == 0
    for used in range(1, width):
        safe = np.where(kids >= 0, kids, 0)
        openable = (kids >= 0) & inner[safe]
        rows = np.flatnonzero(openable.any(axis=1))
        if rows.size == 0:
            break
        # The largest openable child (an equal area: the first slot, np.argmax's rule).
        score = np.where(openable[rows], area[safe[rows]], -np.inf)
        slot = np.argmax(score, axis=1)
        left = bvh.node_first[kids[rows, slot]]
        kids[rows, slot] = left
        kids[rows, used] = left + 1
    return kids


def collapse(bvh: BVH, width: int = WIDTH) -> WideBVH:
    """The ``width``-wide tree of ``bvh`` (module docstring), level by level from the root."""
    if not 2 <= width <= 64:
        raise ValueError(f"collapse: width must be in 2..64, got {width!r}")
    record_of = np.full(bvh.node_total, -1, dtype=np.int64)
    record_of[0] = 0
    if bvh.empty:  # the root of no triangles (an inverted box, count 0): a record with no child
        return WideBVH(bvh, np.full((1, width), -1, dtype=np.int64), record_of, 1)
    area = _half_areas(bvh)
    levels: list[NDArray[np.int64]] = []
    nodes = np.zeros(1, dtype=np.int64)
    made = 1
    while nodes.size:
        kids = _open_level(bvh, nodes, area, width)
        levels.append(kids)
        flat = kids.reshape(-1)
        nodes = flat[(flat >= 0) & (bvh.node_count[np.where(flat >= 0, flat, 0)] == 0)]  # the next wide nodes
        record_of[nodes] = np.arange(made, made + nodes.size)
        made += nodes.size
    return WideBVH(bvh, np.concatenate(levels), record_of, len(levels))


def _padded(wide: WideBVH) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Every slot's box padded as the binary traversal pads it (``BOX_PAD·|box|``; the ray's part
    is added per ray), ``(R, WIDTH, 3)``; an empty slot gets an inverted box (never entered)."""
    bvh = wide.bvh
    node = np.where(wide.child >= 0, wide.child, 0)
    pad = BOX_PAD * np.maximum(np.abs(bvh.node_min), np.abs(bvh.node_max)).max(axis=1)
    lo = bvh.node_min[node] - pad[node][..., None]
    hi = bvh.node_max[node] + pad[node][..., None]
    lo[wide.child < 0] = np.inf
    hi[wide.child < 0] = -np.inf
    return lo, hi


def _keep_nearest(rr: NDArray[np.intp], tris: NDArray[np.intp], t: NDArray[np.float64], limit: NDArray[np.float64],
                  best_t: NDArray[np.float64], best_tri: NDArray[np.int64], best_slot: NDArray[np.int64],
                  tri_index: NDArray[np.int64]) -> None:
    """Fold (ray, stored triangle, t) hits into each ray's best so far (in place), by the course's
    ``min_indis``: the smallest ``t < t_max`` wins, an equal ``t`` goes to the lower caller's index."""
    ok = np.flatnonzero((t < limit[rr]) & (t <= best_t[rr]))
    if not ok.size:
        return
    rr, tris, t = rr[ok], tris[ok], t[ok]
    before = best_t[rr]
    np.minimum.at(best_t, rr, t)
    after = best_t[rr]
    best_tri[rr[after < before]] = np.iinfo(np.int64).max  # a nearer t: the old winner is out
    at_best = t == after
    rr, tris = rr[at_best], tris[at_best]
    index = tri_index[tris]
    np.minimum.at(best_tri, rr, index)
    won = index == best_tri[rr]
    best_slot[rr[won]] = tris[won]


def closest_hit_wide(wide: WideBVH, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = np.inf, *,
                     cull_backfaces: bool = False) -> Hits:
    """The nearest hit of each ray through the wide tree (float64): a frontier of (ray, record)
    pairs advanced one wide level a step, all four slots of a pair slab-tested at once, leaf
    slots' triangles tested with the watertight test; the tie rule of ``closest_hit``."""
    o, d, limit = _rays(origins, directions, t_max)
    n = d.shape[0]
    out = Hits.misses(n)
    bvh = wide.bvh
    if bvh.empty or n == 0:
        return out
    lo, hi = _padded(wide)
    ref, count, _ = wide.slots()
    setup = ray_setup(o, d)
    o_pad = BOX_PAD * np.abs(o).max(axis=1)
    with np.errstate(divide="ignore"):
        inv = 1.0 / d
    best_t, best_tri, best_slot = limit.copy(), np.full(n, np.iinfo(np.int64).max), np.full(n, -1, dtype=np.int64)
    rays, recs = np.arange(n), np.zeros(n, dtype=np.int64)
    with np.errstate(invalid="ignore"):
        while rays.size:
            oo, ii = o[rays][:, None, :], inv[rays][:, None, :]
            pp = o_pad[rays][:, None, None]
            ta = (lo[recs] - pp - oo) * ii
            tb = (hi[recs] + pp - oo) * ii
            near = np.fmax.reduce(np.minimum(ta, tb), axis=2)
            far = np.fmin.reduce(np.maximum(ta, tb), axis=2)
            keep = (near <= far) & (far >= 0.0) & (near <= best_t[rays][:, None])
            pair, slot = np.nonzero(keep & (count[recs] > 0))
            if pair.size:  # leaves: every triangle of every kept leaf slot
                first, many = ref[recs[pair], slot], count[recs[pair], slot]
                rr = np.repeat(rays[pair], many)
                tris = np.repeat(first - np.cumsum(many) + many, many) + np.arange(int(many.sum()))
                t, _, _ = watertight_pairs(setup, rr, bvh.v0, bvh.v1, bvh.v2, tris, cull_backfaces,
                                           barycentrics=False)
                _keep_nearest(rr, tris, t, limit, best_t, best_tri, best_slot, bvh.tri_index)
            pair, slot = np.nonzero(keep & (count[recs] == 0) & (wide.child[recs] >= 0))
            rays, recs = rays[pair], ref[recs[pair], slot]
    hit = np.flatnonzero(best_slot >= 0)
    if hit.size:
        t, u, v = watertight_pairs(setup, hit, bvh.v0, bvh.v1, bvh.v2, best_slot[hit], cull_backfaces)
        out.t[hit], out.triangle[hit], out.u[hit], out.v[hit] = t, best_tri[hit], u, v
    return out
