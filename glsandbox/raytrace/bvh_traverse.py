"""Tracing whole packets of rays through a :class:`~glsandbox.raytrace.bvh.BVH` with numpy.

The course's AABB acceleration asks one question per box: does the ray hit
it (the slab test, :mod:`glsandbox.raytrace.aabb`)? A BVH asks it again for
the two boxes inside, and so on down to the leaves, where the triangles are
tested with the watertight test (:mod:`glsandbox.raytrace.watertight`).

No Python loop runs per ray. The traversal keeps a *frontier* of (ray, node)
pairs and advances all of them one tree level per step:

1. the slab test for every pair at once (three component arrays), dropping
   pairs whose ray misses the box, or enters it only beyond the ray's best
   hit so far;
2. leaf pairs become (ray, triangle) pairs, tested all at once; each ray
   keeps its nearest hit;
3. inner pairs become two pairs, one per child, for the next step.

Rays are traced in blocks (:data:`RAY_BLOCK`) so a block's frontier stays
small. Shadow rays (:func:`any_hit`) leave the frontier at their first hit.

The nearest hit keeps the course's ``min_indis`` rule exactly as
:func:`glsandbox.raytrace.numpy_engine._nearest` does: the smallest ``t`` with
``0 < t < t_max`` wins, and on an equal ``t`` the lower triangle index (the
caller's index, not the BVH's storage order) wins. The result is the same,
bit for bit, as testing every triangle (:func:`closest_hit_brute_force`).

Robust boxes
------------
A box test rounded the wrong way must not lose a hit the watertight test
would find (a ray aimed exactly at a vertex sits on the corner of every box
around it). Each box is therefore widened by ``BOX_PAD·(|box| + |origin|)``
(largest coordinates): the watertight test's rounding moves a hit by a few
``2⁻⁵²`` of those magnitudes at most, and ``BOX_PAD = 2⁻⁴⁰`` is over a
thousand times that (the idea of Ize 2013, "Robust BVH ray traversal",
applied to the box rather than to ``t``). Boxes entered only at ``t`` beyond
the best hit are skipped with ``near <= best`` (not ``<``): a tie with a
lower triangle index elsewhere must still be found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.base import broadcast_rays, shared_origin
from glsandbox.raytrace.bvh import BVH
from glsandbox.raytrace.errors import RayTraceError
from glsandbox.raytrace.watertight import RaySetup, nondegenerate, ray_setup, watertight_pairs

__all__ = ["BOX_PAD", "RAY_BLOCK", "Hits", "TraversalCounts", "any_hit", "closest_hit", "closest_hit_brute_force"]

#: Relative widening of every box in the slab test (see the module docstring).
BOX_PAD: float = 2.0**-40
#: Rays traced together.
RAY_BLOCK: int = 1 << 14
_NO_TRIANGLE = np.iinfo(np.int64).max


@dataclass
class TraversalCounts:
    """What a traversal did, added up over calls: ray-box slab tests and ray-triangle tests
    (the engine's :class:`~glsandbox.raytrace.numpy_engine.RenderStats` reads them)."""

    boxes: int = 0
    triangles: int = 0


@dataclass
class Hits:
    """The nearest hit of each of ``N`` rays.

    ``t`` is ``inf`` and ``triangle`` is −1 for a miss; ``(u, v)`` are the
    barycentrics of the hit, ``P = V0 + u·(V1 − V0) + v·(V2 − V0)`` (0 for a miss).
    """

    t: NDArray[np.float64]
    triangle: NDArray[np.int64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]

    @property
    def hit(self) -> NDArray[np.bool_]:
        result: NDArray[np.bool_] = self.triangle >= 0
        return result

    @classmethod
    def misses(cls, n: int) -> Hits:
        return cls(np.full(n, np.inf), np.full(n, -1, dtype=np.int64), np.zeros(n), np.zeros(n))


def _rays(origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike
          ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    o, d = broadcast_rays(origins, directions)
    limit = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (d.shape[0],)).copy()
    if np.isnan(limit).any():
        raise RayTraceError("t_max must not be NaN")
    return o, np.ascontiguousarray(d), limit  # o stays a stride-0 view when one origin is shared


class _Boxes:
    """The nodes' padded boxes as contiguous rows, one per axis.

    Rays that share one origin (primary rays from the eye) get the boxes
    already moved to that origin, ``(plane − pad) − O``: the slab test is then
    a gather and a product per plane. Both are kept on the BVH (the padded
    boxes, and those moved to the last shared origin): an engine traces a
    frame in blocks of rays, and remaking them per block cost O(nodes) each
    time, 2.3 of 5.4 s for a 1M-triangle terrain at 800x600.
    """

    def __init__(self, bvh: BVH, o: NDArray[np.float64]) -> None:
        padded = bvh.__dict__.get("_padded_boxes")
        if padded is None:
            pad = _node_pad(bvh)[None, :]
            padded = (np.ascontiguousarray(bvh.node_min.T - pad), np.ascontiguousarray(bvh.node_max.T + pad))
            object.__setattr__(bvh, "_padded_boxes", padded)  # frozen: a cache of what it holds
        self.lo, self.hi = padded
        origin = shared_origin(o)
        self.shared = origin.ndim == 1
        if self.shared:
            key = origin.tobytes()
            moved = bvh.__dict__.get("_moved_boxes")
            if moved is None or moved[0] != key:
                o_pad = BOX_PAD * float(np.abs(origin).max(initial=0.0))
                moved = (key, np.ascontiguousarray(self.lo - o_pad - origin[:, None]),
                         np.ascontiguousarray(self.hi + o_pad - origin[:, None]))
                object.__setattr__(bvh, "_moved_boxes", moved)
            self.lo, self.hi = moved[1], moved[2]


class _Block:
    """One block of rays: what the slab test needs per ray, and the best hits so far."""

    def __init__(self, boxes: _Boxes, o: NDArray[np.float64], d: NDArray[np.float64],
                 limit: NDArray[np.float64]) -> None:
        self.n = d.shape[0]
        self.boxes = boxes
        with np.errstate(divide="ignore"):
            self.inv = np.ascontiguousarray(1.0 / d.T)  # 1/(+0) = +inf, 1/(−0) = −inf: the slab test's special cases
        self.setup: RaySetup = ray_setup(o, d)
        if not boxes.shared:  # the ray's part of the padding goes with its origin
            o_pad = BOX_PAD * np.abs(o).max(axis=1)
            self.o_lo = np.ascontiguousarray((o + o_pad[:, None]).T)
            self.o_hi = np.ascontiguousarray((o - o_pad[:, None]).T)
        self.limit = limit
        self.best_t = limit.copy()
        self.best_tri = np.full(self.n, _NO_TRIANGLE, dtype=np.int64)
        self.best_slot = np.full(self.n, -1, dtype=np.int64)

    def slab(self, bvh: BVH, rays: NDArray[np.intp], nodes: NDArray[np.intp]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(near, far)`` of each pair's ray through its node's (padded) box.

        Per axis ``t = (plane − O)·(1/d)``, as :meth:`~glsandbox.raytrace.aabb.AABB.slabs_reciprocal`:
        ``minimum``/``maximum`` keep the NaN of ``0·inf`` (an origin on a plane
        the ray runs along) and ``fmax``/``fmin`` then skip it: inside the slab.
        """
        near = np.full(rays.size, -np.inf)
        far = np.full(rays.size, np.inf)
        boxes = self.boxes
        with np.errstate(invalid="ignore"):
            for axis in range(3):
                inv = self.inv[axis, rays]
                if boxes.shared:
                    ta = boxes.lo[axis, nodes] * inv
                    tb = boxes.hi[axis, nodes] * inv
                else:
                    ta = (boxes.lo[axis, nodes] - self.o_lo[axis, rays]) * inv
                    tb = (boxes.hi[axis, nodes] - self.o_hi[axis, rays]) * inv
                np.fmax(near, np.minimum(ta, tb), out=near)
                np.fmin(far, np.maximum(ta, tb, out=tb), out=far)
        return near, far


def _node_pad(bvh: BVH) -> NDArray[np.float64]:
    """``BOX_PAD·|box|`` per node: the box's part of its padding."""
    size = np.maximum(np.abs(bvh.node_min), np.abs(bvh.node_max)).max(axis=1)
    result: NDArray[np.float64] = BOX_PAD * size
    return result


def _leaf_pairs(bvh: BVH, rays: NDArray[np.intp], nodes: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """(ray, stored triangle) pairs for (ray, leaf) pairs: each leaf's triangles in turn."""
    count = bvh.node_count[nodes]
    total = int(count.sum())
    rr = np.repeat(rays, count)
    starts = np.cumsum(count) - count
    slots = np.repeat(bvh.node_first[nodes], count) + (np.arange(total) - np.repeat(starts, count))
    return rr, slots


def _closest_block(bvh: BVH, block: _Block, cull: bool, counts: TraversalCounts | None = None) -> None:
    rays = np.arange(block.n)
    nodes = np.zeros(block.n, dtype=np.int64)
    while rays.size:
        near, far = block.slab(bvh, rays, nodes)
        if counts is not None:
            counts.boxes += rays.size
        keep = (near <= far) & (far >= 0.0) & (near <= block.best_t[rays])
        rays, nodes = rays[keep], nodes[keep]
        leaf = bvh.node_count[nodes] > 0
        if leaf.any():
            rr, slots = _leaf_pairs(bvh, rays[leaf], nodes[leaf])
            t, _, _ = watertight_pairs(block.setup, rr, bvh.v0, bvh.v1, bvh.v2, slots, cull)
            if counts is not None:
                counts.triangles += rr.size
            ok = t < block.limit[rr]
            if ok.any():
                rr, slots, t = rr[ok], slots[ok], t[ok]
                # The nearest t per ray; where it improved, forget the old triangle.
                new_t = block.best_t.copy()
                np.minimum.at(new_t, rr, t)
                block.best_tri[new_t < block.best_t] = _NO_TRIANGLE
                block.best_t = new_t
                # Among the pairs at that t, the lowest triangle index (ties: min_indis).
                at_best = t == new_t[rr]
                rr, slots = rr[at_best], slots[at_best]
                index = bvh.tri_index[slots]
                np.minimum.at(block.best_tri, rr, index)
                won = index == block.best_tri[rr]
                block.best_slot[rr[won]] = slots[won]
        inner = ~leaf
        rays, nodes = rays[inner], nodes[inner]
        left = bvh.node_first[nodes]
        rays = np.concatenate([rays, rays])
        nodes = np.concatenate([left, left + 1])


def closest_hit(bvh: BVH, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = np.inf, *,
                cull_backfaces: bool = False, counts: TraversalCounts | None = None) -> Hits:
    """The nearest hit with ``0 < t < t_max`` of each ray (``origins`` may be one shared point).

    ``t_max`` is one number or one per ray. ``cull_backfaces=True`` skips
    triangles facing away from the ray (course "Hızlandırma: backface
    culling"). Results are float64 and identical to :func:`closest_hit_brute_force`.
    ``counts`` adds up the box and triangle tests done (the winners' second
    test, for their barycentrics, included).
    """
    o, d, limit = _rays(origins, directions, t_max)
    n = d.shape[0]
    out = Hits.misses(n)
    if bvh.empty or n == 0:
        return out
    boxes = _Boxes(bvh, o)
    for lo in range(0, n, RAY_BLOCK):
        part = slice(lo, min(n, lo + RAY_BLOCK))
        block = _Block(boxes, o[part], d[part], limit[part])
        _closest_block(bvh, block, bool(cull_backfaces), counts)
        hit = np.flatnonzero(block.best_slot >= 0)
        if hit.size:
            if counts is not None:
                counts.triangles += hit.size
            # The winners' barycentrics, from the same test (so the same t).
            t, u, v = watertight_pairs(block.setup, hit, bvh.v0, bvh.v1, bvh.v2, block.best_slot[hit],
                                       bool(cull_backfaces))
            rows = hit + lo
            out.t[rows] = t
            out.triangle[rows] = block.best_tri[hit]
            out.u[rows] = u
            out.v[rows] = v
    return out


def any_hit(bvh: BVH, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = 1.0, *,
            cull_backfaces: bool = False, counts: TraversalCounts | None = None) -> NDArray[np.bool_]:
    """Whether anything is hit with ``0 < t < t_max`` (the course's Gölge testi: a shadow
    ray from ``P`` towards the light ``L`` with ``d = L − P`` and ``t_max = 1``).
    A ray stops at its first hit, in whatever order the tree gives. ``counts``
    adds up the box and triangle tests done."""
    o, d, limit = _rays(origins, directions, t_max)
    n = d.shape[0]
    found = np.zeros(n, dtype=bool)
    if bvh.empty or n == 0:
        return found
    cull = bool(cull_backfaces)
    boxes = _Boxes(bvh, o)
    for lo in range(0, n, RAY_BLOCK):
        part = slice(lo, min(n, lo + RAY_BLOCK))
        block = _Block(boxes, o[part], d[part], limit[part])
        done = np.zeros(block.n, dtype=bool)
        rays = np.arange(block.n)
        nodes = np.zeros(block.n, dtype=np.int64)
        while rays.size:
            near, far = block.slab(bvh, rays, nodes)
            if counts is not None:
                counts.boxes += rays.size
            keep = (near <= far) & (far >= 0.0) & (near < block.limit[rays])
            rays, nodes = rays[keep], nodes[keep]
            leaf = bvh.node_count[nodes] > 0
            if leaf.any():
                rr, slots = _leaf_pairs(bvh, rays[leaf], nodes[leaf])
                t, _, _ = watertight_pairs(block.setup, rr, bvh.v0, bvh.v1, bvh.v2, slots, cull)
                if counts is not None:
                    counts.triangles += rr.size
                done[rr[t < block.limit[rr]]] = True
            inner = ~leaf & ~done[rays]
            rays, nodes = rays[inner], nodes[inner]
            left = bvh.node_first[nodes]
            rays = np.concatenate([rays, rays])
            nodes = np.concatenate([left, left + 1])
        found[part] = done
    return found


def closest_hit_brute_force(v0: ArrayLike, v1: ArrayLike, v2: ArrayLike, origins: ArrayLike, directions: ArrayLike,
                            t_max: ArrayLike = np.inf, *, cull_backfaces: bool = False,
                            chunk_pairs: int = 1 << 20) -> Hits:
    """The reference: every ray against every (non-degenerate) triangle, the same
    watertight test and tie rule as :func:`closest_hit`. ``O(rays × triangles)``: for tests."""
    a, b, c = (np.ascontiguousarray(np.asarray(x, dtype=np.float64)).reshape(-1, 3) for x in (v0, v1, v2))
    o, d, limit = _rays(origins, directions, t_max)
    n, m = d.shape[0], a.shape[0]
    out = Hits.misses(n)
    tris = np.flatnonzero(nondegenerate(a, b, c))
    if n == 0 or tris.size == 0:
        return out
    setup = ray_setup(o, d)
    ray_step = max(1, chunk_pairs // tris.size)
    for lo in range(0, n, ray_step):
        rays = np.arange(lo, min(n, lo + ray_step))
        rr = np.repeat(rays, tris.size)
        tt = np.tile(tris, rays.size)
        t, u, v = watertight_pairs(setup, rr, a, b, c, tt, cull_backfaces)
        t = np.where(t < limit[rr], t, np.inf).reshape(rays.size, tris.size)
        j = np.argmin(t, axis=1)  # the first minimum: the lowest index on a tie
        best = t[np.arange(rays.size), j]
        hit = np.isfinite(best)
        sel = rays[hit]
        pick = np.arange(rays.size)[hit] * tris.size + j[hit]
        out.t[sel] = best[hit]
        out.triangle[sel] = tris[j[hit]]
        out.u[sel] = u[pick]
        out.v[sel] = v[pick]
    del m
    return out
