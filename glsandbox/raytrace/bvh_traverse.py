"""Tracing whole packets of rays through a :class:`~glsandbox.raytrace.bvh.BVH` with numpy.

The course's AABB acceleration asks one question per box: does the ray hit
it (the slab test, :mod:`glsandbox.raytrace.aabb`)? A BVH asks it again for
the two boxes inside, and so on down to the leaves, where the triangles are
tested with the watertight test (:mod:`glsandbox.raytrace.watertight`).

No Python loop runs per ray. The traversal tests the root's box for every
ray, then keeps a *frontier* of (ray, inner node) pairs whose box the ray
entered and advances all of them one tree level per step:

1. the slab test of both children of every pair at once: the children's
   twelve planes are one column of a table kept per node (:class:`_Boxes`),
   gathered in one call, and the arithmetic runs on ``(2, 2, 3, pairs)``
   arrays (side, child, axis), dropping children the ray misses or enters
   only beyond its best hit so far;
2. kept leaf children become (ray, triangle) pairs, tested all at once; each
   ray keeps its nearest hit (before the next level's boxes are tested);
3. kept inner children are the next frontier.

Every ray does exactly the tests of a level-by-level walk of its own (a
level's boxes, then its leaves): how the pairs are batched changes the time,
never what is tested or counted. Rays are traced in blocks
(:data:`RAY_BLOCK`) so a step's temporaries stay in cache. Shadow rays
(:func:`any_hit`) leave the frontier at their first hit.

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

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.bvh import BVH
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays, shared_origin
from glsandbox.raytrace.watertight import RaySetup, nondegenerate, ray_setup, watertight_pairs

#: An any-hit filter: ``(rays, triangles, t) -> which hits count`` (bool per hit).
Accept = Callable[[NDArray[np.intp], NDArray[np.intp], NDArray[np.float64]], NDArray[np.bool_]]

__all__ = ["BOX_PAD", "RAY_BLOCK", "Accept", "Hits", "TraversalCounts", "any_hit", "closest_hit",
           "closest_hit_brute_force"]

#: Relative widening of every box in the slab test (see the module docstring).
BOX_PAD: float = 2.0**-40
#: Rays traced together. A step's temporaries (a dozen planes per pair) then stay
#: in a core's cache: 4,096 rays measured 15% faster than 16,384 on a 10k-triangle
#: model, and 1,024 slower again (numpy's per-call cost).
RAY_BLOCK: int = 1 << 12
#: Rays that share an origin test triangles moved to it (``V − O`` kept per BVH for the
#: last origin) up to this many triangles: a few percent faster, 72 bytes a triangle.
MOVED_CORNERS: int = 1 << 18
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
    """The nodes' padded boxes laid out for the traversal, kept on the BVH.

    The traversal tests the two children of an inner node together, so each
    inner node ``p`` holds its children's padded planes as one column of a
    ``(12, N)`` table, rows ``[side][child][axis]`` (side 0 the low planes,
    1 the high ones): a step gathers all twelve planes of its pairs in one
    call. ``root`` is the root's own padded box ``(2, 1, 3, 1)``.

    Rays that share one origin (primary rays from the eye) get the planes
    already moved to that origin, ``(plane − pad) − O``: the slab test is then
    a gather and a product per plane; and the triangles' corners ``V − O``
    (``corners``, the watertight test's first step). Both are kept on the BVH (the padded
    planes, and those moved to the last shared origin): an engine traces a
    frame in blocks of rays, and remaking them per block cost O(nodes) each
    time, 2.3 of 5.4 s for a 1M-triangle terrain at 800x600.
    """

    def __init__(self, bvh: BVH, o: NDArray[np.float64]) -> None:
        layout = bvh.__dict__.get("_kernel_layout")
        if layout is None:
            layout = _layout(bvh)
            object.__setattr__(bvh, "_kernel_layout", layout)  # frozen: a cache of what it holds
        self.kids, self.root, self.kid_leaf, self.left, self.root_leaf = layout
        origin = shared_origin(o)
        self.shared = origin.ndim == 1
        corners = None
        if self.shared:
            key = origin.tobytes()
            moved = bvh.__dict__.get("_kernel_moved")
            if moved is None or moved[0] != key:
                o_pad = BOX_PAD * float(np.abs(origin).max(initial=0.0))
                # The triangles too: V − O, the watertight test's first step, once per origin
                # (up to MOVED_CORNERS triangles: 72 bytes each).
                corners = tuple(np.subtract(v, origin) for v in (bvh.v0, bvh.v1, bvh.v2)) \
                    if bvh.triangle_count <= MOVED_CORNERS else None
                moved = (key, _moved(self.kids, o_pad, origin), _moved(self.root, o_pad, origin), corners)
                object.__setattr__(bvh, "_kernel_moved", moved)
            self.kids, self.root, corners = moved[1], moved[2], moved[3]
        #: The corners the watertight test reads, and whether they are already ``V − O``.
        self.relative = self.shared and corners is not None
        self.corners = corners if self.relative else (bvh.v0, bvh.v1, bvh.v2)


def _layout(bvh: BVH) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.intp], bool]:
    """``(kids, root, kid_leaf, left, root_leaf)`` of :class:`_Boxes`: the children's padded
    planes per inner node, the root's, whether each child is a leaf, the left child."""
    pad = _node_pad(bvh)[None, :]
    lo = bvh.node_min.T - pad  # (3, N) padded planes of every node
    hi = bvh.node_max.T + pad
    n = bvh.node_total
    inner = np.flatnonzero(bvh.node_count == 0)
    left = np.ascontiguousarray(bvh.node_first, dtype=np.intp)
    kids = np.zeros((2, 2, 3, n))
    kid_leaf = np.zeros((2, n), dtype=bool)
    for child in (0, 1):
        index = left[inner] + child
        kids[0, child][:, inner] = lo[:, index]
        kids[1, child][:, inner] = hi[:, index]
        kid_leaf[child, inner] = bvh.node_count[index] > 0
    root = np.stack([lo[:, 0], hi[:, 0]]).reshape(2, 1, 3, 1)
    return kids.reshape(12, n), root, kid_leaf, left, bool(bvh.node_count[0] > 0)


def _moved(planes: NDArray[np.float64], o_pad: float, origin: NDArray[np.float64]) -> NDArray[np.float64]:
    """Planes ``[side][child][axis]`` moved to ``origin``: ``(lo − o_pad) − O``, ``(hi + o_pad) − O``."""
    rows = planes.reshape(2, -1, 3, planes.shape[-1])
    moved = np.empty_like(rows)
    np.subtract(rows[0], o_pad, out=moved[0])
    np.add(rows[1], o_pad, out=moved[1])
    moved -= origin[:, None]
    return moved.reshape(planes.shape)


class _Block:
    """One block of rays: what the slab test needs per ray, and the best hits so far."""

    def __init__(self, boxes: _Boxes, o: NDArray[np.float64], d: NDArray[np.float64],
                 limit: NDArray[np.float64]) -> None:
        self.n = d.shape[0]
        self.boxes = boxes
        with np.errstate(divide="ignore"):
            self.inv = np.divide(1.0, d.T, out=np.empty((3, self.n)))  # 1/(+0) = +inf, 1/(−0) = −inf: the slab test's special cases
        self.setup: RaySetup = ray_setup(o, d)
        if not boxes.shared:  # the ray's part of the padding goes with its origin: (2 sides, 3, N)
            o_pad = BOX_PAD * np.abs(o).max(axis=1)
            self.o_sides = np.stack([(o + o_pad[:, None]).T, (o - o_pad[:, None]).T])
        self.limit = limit
        self.best_t = limit.copy()
        self.best_tri = np.full(self.n, _NO_TRIANGLE, dtype=np.int64)
        self.best_slot = np.full(self.n, -1, dtype=np.int64)

    def slab(self, planes: NDArray[np.float64], rays: NDArray[np.intp] | None
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(near, far)``, ``(K, P)``, of each pair's ray through ``K`` (padded) boxes.

        ``planes`` is ``(2, K, 3, P)`` (low and high planes of ``K`` boxes per pair,
        or ``P = 1`` for one box every ray meets); ``rays`` the pairs' rays (None: all).
        Per axis ``t = (plane − O)·(1/d)``, as :meth:`~glsandbox.raytrace.aabb.AABB.slabs_reciprocal`:
        ``minimum``/``maximum`` keep the NaN of ``0·inf`` (an origin on a plane
        the ray runs along) and ``fmax``/``fmin`` then skip it: inside the slab.
        The caller holds ``errstate(invalid="ignore")``.
        """
        if rays is None:  # the root: planes shared by every ray
            inv = self.inv
            t = planes * inv if self.boxes.shared else (planes - self.o_sides[:, None]) * inv
        else:  # planes gathered for these pairs: worked on in place
            inv = self.inv.take(rays, axis=1)
            t = planes
            if not self.boxes.shared:
                t -= self.o_sides.take(rays, axis=2)[:, None]
            t *= inv
        low, high = t[0], t[1]
        first = np.minimum(low, high)
        np.maximum(low, high, out=high)
        return np.fmax.reduce(first, axis=1, initial=-np.inf), np.fmin.reduce(high, axis=1, initial=np.inf)


def _node_pad(bvh: BVH) -> NDArray[np.float64]:
    """``BOX_PAD·|box|`` per node: the box's part of its padding."""
    size = np.maximum(np.abs(bvh.node_min), np.abs(bvh.node_max)).max(axis=1)
    result: NDArray[np.float64] = BOX_PAD * size
    return result


def _leaf_pairs(bvh: BVH, rays: NDArray[np.intp], nodes: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """(ray, stored triangle) pairs for (ray, leaf) pairs: each leaf's triangles in turn
    (slot ``first + i`` for the ``i``-th pair of a leaf: ``arange`` minus the leaf's start)."""
    count = bvh.node_count.take(nodes)
    rr = np.repeat(rays, count)
    starts = np.cumsum(count)
    total = int(starts[-1])
    starts -= count
    slots = np.repeat(bvh.node_first.take(nodes) - starts, count)
    slots += np.arange(total)
    return rr, slots


def _traverse(bvh: BVH, block: _Block, counts: TraversalCounts | None, bound: NDArray[np.float64], strict: bool,
              leaves: Callable[[NDArray[np.intp], NDArray[np.intp]], None],
              done: NDArray[np.bool_] | None = None) -> None:
    """Walk the tree one level a step for every ray of ``block`` at once.

    A pair (ray, node) is kept when its ray meets the node's box at ``far >= 0``
    and enters it at ``near <= bound`` (``< bound`` when ``strict``); ``bound``
    is read afresh at every step (the nearest hit so far shrinks it). The two
    children of every kept inner pair are tested together at the next step;
    kept leaf pairs go to ``leaves(rays, leaf nodes)`` before that, so the next
    step sees their hits. Rays set in ``done`` leave (any-hit).
    """
    boxes = block.boxes
    less = np.less if strict else np.less_equal
    with np.errstate(invalid="ignore"):
        near, far = block.slab(boxes.root, None)
        if counts is not None:
            counts.boxes += block.n
        keep = _kept(near[0], far[0], bound, less)
        rays = np.flatnonzero(keep)
        if boxes.root_leaf:
            if rays.size:
                leaves(rays, np.zeros(rays.size, dtype=np.intp))
            return
        parents = np.zeros(rays.size, dtype=np.intp)
        while rays.size:
            m = rays.size
            near, far = block.slab(boxes.kids.take(parents, axis=1).reshape(2, 2, 3, m), rays)
            if counts is not None:
                counts.boxes += 2 * m
            keep = _kept(near, far, bound.take(rays), less)
            leaf = boxes.kid_leaf.take(parents, axis=1)
            leaf &= keep
            # (child, pair) of a (2, m) mask's set entries in np.nonzero's order, from their flat
            # positions: np.nonzero of a 2-D mask costs several times as much.
            found = np.flatnonzero(leaf)
            if found.size:
                child, pair = np.divmod(found, m)
                leaves(rays[pair], boxes.left[parents[pair]] + child)
                keep &= ~leaf
            if done is not None:
                keep &= ~done.take(rays)
            child, pair = np.divmod(np.flatnonzero(keep), m)
            rays = rays[pair]
            parents = boxes.left[parents[pair]]
            parents += child


def _kept(near: NDArray[np.float64], far: NDArray[np.float64], bound: NDArray[np.float64],
          less: Callable[..., NDArray[np.bool_]]) -> NDArray[np.bool_]:
    """``near <= far``, ``far >= 0`` and ``near`` before ``bound`` (``less``: ``<`` or ``<=``)."""
    keep = near <= far
    keep &= far >= 0.0
    keep &= less(near, bound)
    return keep


def _closest_block(bvh: BVH, block: _Block, cull: bool, counts: TraversalCounts | None = None) -> None:
    best_t = block.best_t  # updated in place: the traversal reads it as its bound at every step

    def leaves(rays: NDArray[np.intp], nodes: NDArray[np.intp]) -> None:
        rr, slots = _leaf_pairs(bvh, rays, nodes)
        t, _, _ = watertight_pairs(block.setup, rr, *block.boxes.corners, slots, cull, barycentrics=False,
                                   relative=block.boxes.relative)
        if counts is not None:
            counts.triangles += rr.size
        # Only pairs at or before their ray's best so far (and before its t_max) can change
        # it: a tie may still win on its lower triangle index.
        ok = np.flatnonzero(t <= best_t.take(rr))
        ok = ok[t[ok] < block.limit[rr[ok]]]
        if ok.size:
            rr, slots, t = rr[ok], slots[ok], t[ok]
            # The nearest t per ray; where it improved, forget the old triangle.
            before = best_t[rr]
            np.minimum.at(best_t, rr, t)
            after = best_t[rr]
            block.best_tri[rr[after < before]] = _NO_TRIANGLE
            # Among the pairs at that t, the lowest triangle index (ties: min_indis).
            at_best = t == after
            rr, slots = rr[at_best], slots[at_best]
            index = bvh.tri_index[slots]
            np.minimum.at(block.best_tri, rr, index)
            won = index == block.best_tri[rr]
            block.best_slot[rr[won]] = slots[won]

    _traverse(bvh, block, counts, best_t, False, leaves)


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
            t, u, v = watertight_pairs(block.setup, hit, *block.boxes.corners, block.best_slot[hit],
                                       bool(cull_backfaces), relative=boxes.relative)
            rows = hit + lo
            out.t[rows] = t
            out.triangle[rows] = block.best_tri[hit]
            out.u[rows] = u
            out.v[rows] = v
    return out


def any_hit(bvh: BVH, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = 1.0, *,
            cull_backfaces: bool = False, counts: TraversalCounts | None = None,
            accept: Accept | None = None) -> NDArray[np.bool_]:
    """Whether anything is hit with ``0 < t < t_max`` (the course's Gölge testi: a shadow
    ray from ``P`` towards the light ``L`` with ``d = L − P`` and ``t_max = 1``).
    A ray stops at its first hit, in whatever order the tree gives. ``counts``
    adds up the box and triangle tests done.

    ``accept(rays, triangles, t)`` (an any-hit filter, as Embree's): which of the
    hits found (rays' indices, the caller's triangle indices, their ``t``) count; a
    ray whose hits are all refused walks on (a cut-out's transparent texels)."""
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

        def leaves(rays: NDArray[np.intp], nodes: NDArray[np.intp], block: _Block = block,
                   done: NDArray[np.bool_] = done, lo: int = lo) -> None:
            rr, slots = _leaf_pairs(bvh, rays, nodes)
            t, _, _ = watertight_pairs(block.setup, rr, *block.boxes.corners, slots, cull, barycentrics=False,
                                   relative=block.boxes.relative)
            if counts is not None:
                counts.triangles += rr.size
            hit = np.flatnonzero(t < block.limit[rr])
            if accept is not None and hit.size:
                hit = hit[accept(rr[hit] + lo, bvh.tri_index[slots[hit]], t[hit])]
            done[rr[hit]] = True

        _traverse(bvh, block, counts, block.limit, True, leaves, done)
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
