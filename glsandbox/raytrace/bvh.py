"""A bounding volume hierarchy: the course's "Hızlandırma: AABB" taken to its conclusion.

The course puts one axis-aligned box around each object: a ray that misses
the box skips every triangle inside. A BVH does the same *recursively*: the
box of a model holds two boxes, each holding two more, down to leaves of a
few triangles. A ray that misses a box skips its whole subtree, so a ray
visits a number of boxes that grows with the *logarithm* of the triangle
count instead of testing every triangle: a million triangles cost a few
dozen box tests and a handful of triangle tests per ray.

Building: binned SAH
--------------------
Where to cut a box in two? The surface area heuristic (SAH, Goldsmith &
Salmon 1987; MacDonald & Booth 1990) estimates the cost of a split as

    cost = N_left · A(left) + N_right · A(right)

because a random ray that hits a box hits a child box with a probability
proportional to the child's surface area ``A`` (for convex boxes, Cauchy's
formula), and then tests its ``N`` triangles. Among the candidate cuts the
cheapest wins. The candidates are those of *binned* SAH (Wald 2007): along
each axis the node's box is cut into :data:`BINS` equal slabs; every triangle
falls into the slab of its centroid; the bins' counts and boxes are
summed from the left and from the right, and the ``BINS − 1`` cuts between
bins are scored at once.

The build runs breadth first, one level of the tree per step: every node of
a level is binned and split by the same few numpy operations over all of
its triangles (``bincount`` for the counts, ``np.minimum.at`` for the bin
boxes), so the Python loop runs once per *level*, never per triangle or per
node. A node of at most ``leaf_size`` triangles becomes a leaf; a node whose
triangles all fall into one bin (all centroids in one point) is cut in half
by count. The boxes used for binning are the heuristic's; the stored node
boxes are recomputed exactly from the triangles at the end, leaves first.

Parts and threads
-----------------
Every choice above is made per node, from the node's own triangles, so the
nodes of a level can be split in separate calls and give the same tree. A
node of at least :data:`PART_MIN` triangles is split level by level only
until :data:`PARTS` nodes are open below it; each of their subtrees is then a
*part* built on its own (and cut in parts again while it is that big), the
small nodes made on the way one more (``_split_part``). A part's arrays are a
fraction of the model's, so they stay in the CPU's caches (about 10% less CPU
time on a million triangles), and the top's parts are built in threads
(:func:`build_threads`: the CPUs no other thread is running on, up to
:data:`THREADS`; numpy lets go of the GIL in its loops over arrays). A part
numbers its nodes from 0 and is grafted into the tree in a fixed order, so the
arrays are the same for any number of threads.

Small nodes: the full sweep
---------------------------
Bins pay off on big nodes. On a node of a few dozen triangles sixteen bins
per axis cost as much as the triangles and still see only sixteen cuts, so
nodes of at most :data:`SMALL` triangles are finished differently
(``_split_small``): along each axis the node's triangles are sorted by
centroid and *every* cut between them is scored, the boxes of the first
``i`` triangles and of the rest being running minima and maxima of the
sorted boxes (the "full sweep" SAH, MacDonald & Booth's original). The small
nodes lie one per column of a padded ``(width, nodes)`` array, so each step
of the running boxes is one numpy call over all of them. Where no cut gains
(slivers sharing one box), the cut is a multiple of ``leaf_size`` near the
middle: the subtree then ends in full leaves, the fewest boxes.

Layout (flat arrays, what :mod:`glsandbox.raytrace.gpu_bvh` uploads)
------------------------------------------------------------------
Node ``i`` has the box ``node_min[i] .. node_max[i]`` (float64, exact: the
min and max of its triangles' vertices) and

- ``node_count[i] == 0``: an inner node; its children are ``node_first[i]``
  and ``node_first[i] + 1`` (children are always made in pairs);
- ``node_count[i] > 0``: a leaf of triangles ``node_first[i] ..
  node_first[i] + node_count[i] − 1`` in the BVH's own triangle order.

Node 0 is the root. The triangles are stored reordered (``v0, v1, v2``,
leaf after leaf); ``tri_index[k]`` is the caller's index of stored triangle
``k``, the one the tie rule and the results use. Degenerate (zero-area)
triangles, which no ray can hit (the course's
:data:`~glsandbox.raytrace.triangle.DEGENERATE_SIN` rule), are left out.

Caching
-------
:func:`bvh_for_triangles` and :func:`bvh_for_mesh` keep the last few BVHs
(:data:`CACHE_SIZE`) by a blake2b digest of what they were built from: the
triangles' bytes, or a :class:`~glsandbox.geometry.Mesh`'s positions and
indices with the model matrix. Rendering the same model again (another
frame, another camera) builds nothing.
"""

from __future__ import annotations

import hashlib
import os
import time
import weakref
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox import transforms
from glsandbox.geometry import Mesh
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.watertight import nondegenerate

__all__ = [
    "BINS",
    "BVH",
    "CACHE_SIZE",
    "LEAF_SIZE",
    "build_bvh",
    "build_threads",
    "bvh_for_mesh",
    "bvh_for_triangles",
    "clear_cache",
    "mesh_digest",
    "mesh_world_triangles",
    "sah_cost",
]

#: Most triangles in a leaf.
LEAF_SIZE: int = 4
#: Bins per axis of the binned SAH.
BINS: int = 16
#: Triangles of a node whose boxes the SAH bins (a big node's are sampled, see ``_split_levels``).
SAMPLE: int = 1024
#: Nodes of at least this many triangles are binned from their sample alone, counts too (``_split_levels``):
#: the big top levels of a large model (below it, counts are exact and only the boxes sampled).
SAMPLED_ONLY: int = 8 * SAMPLE
#: An axis whose triangle centroids span less than this share of the node's binning range is
#: binned over the centroids' own range instead (``_split_levels``).
CENTROID_RANGE: float = 0.5
#: A node whose best SAH cut costs at least this share of ``N·A(node)`` is cut evenly by count instead.
NO_GAIN: float = 0.99
#: Nodes of at most this many triangles are split by the full SAH sweep (``_split_small``), not binned.
SMALL: int = 64
#: Padded slots (nodes × width) that ``_split_small`` scores in one batch: about a few MB of boxes each.
SMALL_CHUNK: int = 1 << 16
#: The widths ``_split_small`` pads nodes to (powers of two and halfway between: at most a third wasted),
#: up to 64: SMALL and leaf_size (1..64) at most.
WIDTHS = np.array([2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64])
#: Open nodes of at least this many triangles are split in parts (``_split_part``): the parts'
#: smaller working sets stay in the CPU's caches (about 10% less CPU time on 1M triangles; smaller
#: parts cost more in numpy calls than they save), and a build with parts runs them in threads.
PART_MIN: int = 1 << 17
#: The parts: the subtrees of the first level with this many open nodes, and the small nodes so far.
PARTS: int = 4
#: Most threads a build uses by default (fewer where the process may use fewer CPUs).
THREADS: int = 4
#: BVHs kept by :func:`bvh_for_triangles` / :func:`bvh_for_mesh`.
CACHE_SIZE: int = 16


@dataclass(frozen=True, eq=False)
class BVH:
    """A built hierarchy over ``M`` triangles (layout in the module docstring)."""

    node_min: NDArray[np.float64]  # (N, 3)
    node_max: NDArray[np.float64]  # (N, 3)
    node_first: NDArray[np.int64]  # (N,) left child (inner) or first stored triangle (leaf)
    node_count: NDArray[np.int64]  # (N,) 0 for inner nodes, triangles in a leaf otherwise
    v0: NDArray[np.float64]  # (M, 3) the stored triangles, leaf after leaf
    v1: NDArray[np.float64]
    v2: NDArray[np.float64]
    tri_index: NDArray[np.int64]  # (M,) the caller's index of each stored triangle
    depth: int  # levels: 1 for a lone leaf
    input_count: int  # triangles given, degenerate ones included
    build_seconds: float = 0.0  # the time build_bvh took (a cached BVH keeps its first build's)

    def __post_init__(self) -> None:
        for array in (self.node_min, self.node_max, self.node_first, self.node_count, self.v0, self.v1, self.v2,
                      self.tri_index):
            array.flags.writeable = False

    @property
    def node_total(self) -> int:
        return int(self.node_count.shape[0])

    @property
    def triangle_count(self) -> int:
        """Triangles stored (the non-degenerate ones)."""
        return int(self.tri_index.shape[0])

    @property
    def leaf_count(self) -> int:
        return int(np.count_nonzero(self.node_count))

    @property
    def empty(self) -> bool:
        return self.triangle_count == 0

    def __repr__(self) -> str:
        return (f"BVH({self.triangle_count} triangles of {self.input_count}, {self.node_total} nodes, "
                f"{self.leaf_count} leaves, depth {self.depth})")


def _triangle_arrays(v0: ArrayLike, v1: ArrayLike, v2: ArrayLike
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The corners as contiguous float64 ``(M, 3)`` arrays (their finiteness: :func:`_check_finite`)."""
    arrays = tuple(np.ascontiguousarray(np.asarray(v, dtype=np.float64)) for v in (v0, v1, v2))
    a, b, c = arrays
    if a.ndim != 2 or a.shape[1:] != (3,) or a.shape != b.shape or a.shape != c.shape:
        raise RayTraceError(f"triangle corners must be three (M, 3) arrays, got {a.shape}, {b.shape}, {c.shape}")
    return a, b, c


def _check_finite(lo: NDArray[np.float64], hi: NDArray[np.float64]) -> None:
    """Raise unless every corner is finite, from the triangles' boxes ``lo = min(a, b, c)`` and
    ``hi = max(a, b, c)`` (two reductions, no mask): a NaN corner makes both NaN (np.minimum and
    np.maximum pass NaN on), −inf makes ``lo`` −inf and +inf makes ``hi`` +inf; ``lo`` is +inf only
    where ``hi`` is too. So all corners are finite exactly when ``lo.min()`` and ``hi.max()`` are."""
    if lo.size and not (np.isfinite(lo.min()) and np.isfinite(hi.max())):
        raise RayTraceError("triangle vertices must be finite (a NaN or infinite coordinate)")


def _empty_bvh(count: int) -> BVH:
    """A root with no triangles: an inverted box that every ray misses."""
    zeros3 = np.zeros((0, 3))
    return BVH(np.full((1, 3), np.inf), np.full((1, 3), -np.inf), np.zeros(1, dtype=np.int64),
               np.zeros(1, dtype=np.int64), zeros3, zeros3.copy(), zeros3.copy(), np.zeros(0, dtype=np.int64), 1, count)


def _sweep(lo: NDArray[np.float32], hi: NDArray[np.float32], forward: bool
           ) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Running boxes over the bins of ``(3, B, n)`` arrays: bins ``0..s`` (forward)
    or ``s..B−1`` (backward), one numpy call per bin on contiguous ``(3, n)`` slices,
    or for few nodes (the levels of a part's top) one ``accumulate`` per bound."""
    if lo.shape[2] < 64:  # a call per bin costs more than the bins' work here
        if forward:
            return np.minimum.accumulate(lo, axis=1), np.maximum.accumulate(hi, axis=1)
        return (np.minimum.accumulate(lo[:, ::-1], axis=1)[:, ::-1],
                np.maximum.accumulate(hi[:, ::-1], axis=1)[:, ::-1])
    run_lo = lo.copy()
    run_hi = hi.copy()
    count = lo.shape[1]
    steps = range(1, count) if forward else range(count - 2, -1, -1)
    for s in steps:
        prev = s - 1 if forward else s + 1
        np.minimum(run_lo[:, prev], lo[:, s], out=run_lo[:, s])
        np.maximum(run_hi[:, prev], hi[:, s], out=run_hi[:, s])
    return run_lo, run_hi


def _half_area(lo: NDArray[np.float32], hi: NDArray[np.float32]) -> NDArray[np.float32]:
    """Half the surface area ``ex·ey + ey·ez + ez·ex`` of boxes stored one component
    per row (``(3, ...)``); an empty box (``lo = inf, hi = −inf``) has 0."""
    e = np.maximum(hi - lo, np.float32(0.0))
    result: NDArray[np.float32] = e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    return result


def build_bvh(v0: ArrayLike, v1: ArrayLike, v2: ArrayLike, *, leaf_size: int = LEAF_SIZE, bins: int = BINS,
              threads: int | None = None) -> BVH:
    """:func:`_build_bvh`, its time kept in :attr:`BVH.build_seconds`. ``threads``: at most this many
    threads (default: the usable CPUs, at most :data:`THREADS`); the tree is the same for any count."""
    start = time.perf_counter()
    result = _build_bvh(v0, v1, v2, leaf_size=leaf_size, bins=bins, threads=threads)
    object.__setattr__(result, "build_seconds", time.perf_counter() - start)  # frozen: set once, here
    return result


def _build_bvh(v0: ArrayLike, v1: ArrayLike, v2: ArrayLike, *, leaf_size: int = LEAF_SIZE, bins: int = BINS,
               threads: int | None = None) -> BVH:
    """Build a BVH over the triangles ``v0[k], v1[k], v2[k]`` (``(M, 3)`` arrays) by binned SAH.

    Degenerate triangles are left out (no ray hits them); the others are
    each in exactly one leaf of at most ``leaf_size`` triangles.
    """
    if not 1 <= int(leaf_size) <= 64 or not 2 <= int(bins) <= 64:
        raise RayTraceError(f"leaf_size must be in 1..64 and bins in 2..64, got {leaf_size} and {bins}")
    a, b, c = _triangle_arrays(v0, v1, v2)
    threads = build_threads(threads)
    if threads > 1 and a.shape[0] >= PART_MIN:
        with ThreadPoolExecutor(max_workers=threads) as pool:
            return _build(a, b, c, int(leaf_size), int(bins), pool)
    return _build(a, b, c, int(leaf_size), int(bins), None)


def _run(pool: ThreadPoolExecutor | None, jobs: list[Callable[[], Any]]) -> list[Any]:
    """The jobs' results in order, the jobs run in ``pool``'s threads (None: here, one after another)."""
    if pool is None:
        return [job() for job in jobs]
    return [done.result() for done in [pool.submit(job) for job in jobs]]


def _build(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64], leaf_size: int, bins: int,
           pool: ThreadPoolExecutor | None) -> BVH:
    """:func:`_build_bvh` of contiguous ``(M, 3)`` corners, big steps run in ``pool`` (None: none)."""
    total = a.shape[0]
    # The degenerate test (elementwise), the second half of the triangles in a thread of its own.
    half = total // 2 if pool else total
    second = pool.submit(nondegenerate, a[half:], b[half:], c[half:]) if pool else None
    lo = np.minimum(np.minimum(a, b), c)
    hi = np.maximum(np.maximum(a, b), c)
    _check_finite(lo, hi)
    kept = nondegenerate(a[:half], b[:half], c[:half])
    keep = np.flatnonzero(kept if second is None else np.concatenate([kept, second.result()]))
    if keep.size == 0:
        return _empty_bvh(total)
    if keep.size < total:
        a, b, c, lo, hi = _run(pool, [lambda x=x: np.take(x, keep, axis=0) for x in (a, b, c, lo, hi)])
    # The splitting works on float32 copies of the triangles' boxes, one row
    # per quantity (box min, box max; x, y, z each): the SAH is a heuristic,
    # and half the bytes make its scattered reads faster. The stored boxes
    # are exact float64, computed from the triangles at the end.
    rows = np.empty((6, keep.size), dtype=np.float32)
    rows[0:3] = lo.T
    rows[3:6] = hi.T
    tree = _split_tree(rows, leaf_size, bins, pool)
    del rows
    first, count = tree.arrays()
    # The triangles leaf after leaf: a leaf's first slot plus the place within it.
    leaves = np.flatnonzero(count)
    offsets = np.zeros(count.shape[0], dtype=np.int64)
    offsets[leaves[1:]] = np.cumsum(count[leaves][:-1])
    first[leaves] = offsets[leaves]
    order = np.empty(keep.size, dtype=np.int64)
    order[offsets[tree.leaf_of] + tree.leaf_rank] = np.arange(keep.size)
    # np.take: several times faster than x[order] here; the triangles' exact boxes are lo and hi
    # reordered, a leaf's box the min and max of its run of them.
    starts = first[leaves]
    a, b, c, leaf_min, leaf_max = _run(pool, [
        lambda: np.take(a, order, axis=0), lambda: np.take(b, order, axis=0), lambda: np.take(c, order, axis=0),
        lambda: np.minimum.reduceat(np.take(lo, order, axis=0), starts, axis=0),
        lambda: np.maximum.reduceat(np.take(hi, order, axis=0), starts, axis=0)])
    node_min, node_max = _exact_boxes(leaf_min, leaf_max, count, first, leaves, tree.levels)
    return BVH(node_min, node_max, first, count, a, b, c, np.take(keep, order), tree.depth, total)


class _Tree:
    """The nodes made so far, level after level (children always in pairs, numbered in order):
    ``first`` and ``count`` per level, each triangle's leaf and its place in it.

    A *part* (:meth:`part`) numbers the nodes below some of the tree's nodes on its own (its
    roots are its ids ``0 .. R − 1``), so that parts can be built at once in threads; each is then
    :meth:`graft`-ed back, in a fixed order: the numbering does not depend on which thread ends first."""

    def __init__(self, triangles: int, roots: int = 0) -> None:
        self.leaf_of = np.zeros(triangles, dtype=np.int64)
        self.leaf_rank = np.arange(triangles)  # each triangle's place within its leaf
        self.levels: list[NDArray[np.int64]] = []  # the nodes made at each step
        self.firsts: list[NDArray[np.int64]] = []
        self.counts: list[NDArray[np.int64]] = []
        if not roots:  # the whole tree: its root, node 0
            self.levels.append(np.zeros(1, dtype=np.int64))
            self.firsts.append(np.zeros(1, dtype=np.int64))
            self.counts.append(np.array([triangles], dtype=np.int64))
        self.next_id = max(1, roots)
        self.depth = 1  # nodes on the longest path from the root to a leaf
        self._parents: list[NDArray[np.int64]] = []  # inner nodes made after the level arrays were written
        self._lefts: list[NDArray[np.int64]] = []

    def part(self, roots: int) -> _Tree:
        """An empty part below ``roots`` nodes of this tree (the triangles' leaf and rank arrays
        shared: parts write disjoint triangles)."""
        sub = _Tree(0, roots)
        sub.leaf_of, sub.leaf_rank = self.leaf_of, self.leaf_rank
        return sub

    def graft(self, sub: _Tree, roots: NDArray[np.int64], tris: NDArray[np.int64]) -> None:
        """Number the nodes of part ``sub`` after this tree's (its roots are ``roots``); ``tris``:
        the triangles below them, whose leaves ``sub`` numbered on its own."""
        r = roots.size
        shift = self.next_id - r  # part node j >= r becomes node j + shift
        self.next_id += sub.next_id - r
        self.depth = max(self.depth, sub.depth)
        self.levels += [ids + shift for ids in sub.levels]
        self.firsts += sub.firsts
        self.counts += sub.counts
        self._lefts += [ids + shift for ids in sub._lefts]
        self._parents += [np.where(p < r, roots[np.minimum(p, r - 1)], p + shift) for p in sub._parents]
        self.leaf_of[tris] += shift  # a leaf is never a root (roots are nodes still to split)

    def children(self, parents: NDArray[np.int64], child_count: NDArray[np.int64], leaf_size: int
                 ) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
        """Number the pairs of children of ``parents`` (``child_count``: left, right, left, ...):
        the children's ids and which of them are leaves."""
        ids = self.next_id + np.arange(child_count.size, dtype=np.int64)
        self.next_id += child_count.size
        is_leaf = child_count <= leaf_size
        level_count = np.where(is_leaf, child_count, 0)
        self._parents.append(parents)
        self._lefts.append(ids[0::2])
        self.levels.append(ids)
        self.firsts.append(np.zeros(ids.size, dtype=np.int64))
        self.counts.append(level_count)
        return ids, is_leaf

    def arrays(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``first`` (an inner node's left child) and ``count`` (a leaf's triangles, 0 for inner nodes)."""
        first = np.concatenate(self.firsts)
        count = np.concatenate(self.counts)
        if self._parents:
            parents = np.concatenate(self._parents)
            first[parents] = np.concatenate(self._lefts)
            count[parents] = 0
        return first, count


def build_threads(threads: int | None = None) -> int:
    """Threads for a build: ``threads``; by default the CPUs this process may use (at most
    :data:`THREADS`) that no other thread is running on now. On a busy machine a second thread
    costs more than it gains: each numpy call hands Python's GIL over, and a thread waiting for it
    waits for a CPU too (the 1.27M-triangle build at load 6 on 2 cores: 5.7 s in two threads,
    4.9 s in one). The tree is the same for any count."""
    if threads is not None:
        return max(1, int(threads))
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count() or 1
    limit = max(1, min(THREADS, usable))
    try:
        with open("/proc/loadavg") as f:  # Linux: "1.0 0.9 0.8 R/T ...", R threads runnable now (this one too)
            running = int(f.read().split()[3].split("/")[0])
    except (OSError, ValueError, IndexError):
        return limit
    return max(1, min(limit, usable - running + 1))


def _split_tree(rows: NDArray[np.float32], leaf_size: int, bins: int, pool: ThreadPoolExecutor | None) -> _Tree:
    """The tree over the triangles whose boxes are ``rows`` (``(6, K)``: min, max; used as a buffer).

    Big nodes are binned level by level (:func:`_split_levels`), small ones
    swept (:func:`_split_small`). A node of :data:`PART_MIN` triangles or more
    is cut into parts once a level below it has :data:`PARTS` open nodes
    (:func:`_split_part`): each open node's subtree is one part, the small
    nodes made so far another. Every choice of the splitting is per node, so
    the parts build the same tree as one pass would; the top's parts are built
    in ``pool``'s threads (numpy releases the GIL in its loops over arrays)
    and numbered in a fixed order (:meth:`_Tree.graft`), so the result is the
    same for any thread count.
    """
    k = rows.shape[1]
    tree = _Tree(k)
    small = max(SMALL, leaf_size)
    if k <= leaf_size:
        return tree
    if k <= small:
        tree.counts[0][0] = 0
        one = np.ones(1, dtype=np.int64)
        _split_small(tree, (np.arange(k), one - 1, one * k, one, rows), leaf_size)
        return tree
    start = _Open(np.arange(k), rows, np.array([k], dtype=np.int64),  # rows: overwritten from here on
                  rows[0:3].min(axis=1)[None, :].astype(np.float64), rows[3:6].max(axis=1)[None, :].astype(np.float64),
                  np.zeros(1, dtype=np.int64), 1)
    _split_part(start, tree, leaf_size, bins, pool)
    return tree


def _split_part(start: _Open, tree: _Tree, leaf_size: int, bins: int, pool: ThreadPoolExecutor | None) -> None:
    """Split the open nodes ``start`` down to leaves, recording them in ``tree``: in one pass
    below :data:`PART_MIN` triangles; above, until a level has :data:`PARTS` open nodes, then
    each of their subtrees as a part of its own (split the same way), and the small nodes made
    so far as one more, the parts run in ``pool``'s threads (None: one after another)."""
    if start.tris.size < PART_MIN:
        smalls, _ = _split_levels(start, tree, leaf_size, bins)
        _split_small(tree, smalls, leaf_size)
        return
    smalls, rest = _split_levels(start, tree, leaf_size, bins, stop=PARTS)
    del start
    parts: list[tuple[NDArray[np.int64], NDArray[np.int64], int, Callable[[_Tree], None]]] = []
    if rest is not None:
        ends = np.cumsum(rest.counts)
        for i in range(rest.counts.size):
            def subtree(sub: _Tree, i: int = i) -> None:
                _split_part(rest.part(slice(i, i + 1)), sub, leaf_size, bins, None)
            node_tris = rest.tris[int(ends[i] - rest.counts[i]):int(ends[i])]
            parts.append((rest.ids[i:i + 1], node_tris, node_tris.size, subtree))
    if smalls[1].size:
        caller, ids, counts, depths, boxes = smalls
        parts.append((ids, caller, caller.size, lambda sub: _split_small(
            sub, (caller, np.arange(ids.size), counts, depths, boxes), leaf_size)))
    subs = [tree.part(roots.size) for roots, _, _, _ in parts]
    biggest_first = sorted(range(len(parts)), key=lambda j: -parts[j][2])  # the longest first: the threads end together
    _run(pool, [lambda j=j: parts[j][3](subs[j]) for j in biggest_first])
    for (roots, tris, _, _), sub in zip(parts, subs):
        tree.graft(sub, roots, tris)


class _Open(NamedTuple):
    """Nodes still to bin (more than :data:`SMALL` triangles), their triangles grouped by node."""

    tris: NDArray[np.int64]  # the caller's triangle of each column
    cols: NDArray[np.float32]  # (6, width): the columns' boxes, min and max (contiguous)
    counts: NDArray[np.int64]  # columns per node, in column order
    box_lo: NDArray[np.float64]  # (n, 3): the nodes' binning boxes
    box_hi: NDArray[np.float64]
    ids: NDArray[np.int64]  # the nodes' ids
    level: int  # the nodes' depth (1: the root)

    def part(self, nodes: slice) -> _Open:
        """Nodes ``nodes`` (a range) alone, numbered ``0 ..`` as the roots of a :meth:`_Tree.part`."""
        starts = np.cumsum(self.counts) - self.counts
        first = int(starts[nodes.start])
        last = first + int(self.counts[nodes].sum())
        counts = self.counts[nodes]
        return _Open(self.tris[first:last], np.ascontiguousarray(self.cols[:, first:last]), counts,
                     self.box_lo[nodes], self.box_hi[nodes], np.arange(counts.size), self.level)


_Small = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.float32]]


class _Buffers:
    """Flat buffers a level's per-column arrays are viewed from, made once per
    :func:`_split_levels` (fresh pages each level cost more than the work on them)."""

    def __init__(self, cols: NDArray[np.float32]) -> None:
        k = cols.shape[1]
        # The columns move between two flat buffers level after level: a fresh 24 bytes per
        # triangle each level would be fresh pages for the kernel to zero and map each time.
        self.spare = np.empty(cols.size, dtype=np.float32)
        # Viewed as contiguous (3, width) arrays each level: np.take copies a strided array whole first.
        self.centre = np.empty(3 * k, dtype=np.float32)
        # int32 keys (a level's n·B bins are fewer than its columns): np.minimum.at reads them faster than int64.
        self.bin_keys = np.empty(3 * k, dtype=np.int32)
        self.bin_rows = np.empty(3 * k, dtype=np.uint8)  # each column's bin on each axis (the key less i·B)


class _Found:
    """The nodes of at most :data:`SMALL` triangles the levels made, for :func:`_split_small`."""

    def __init__(self) -> None:
        self.tris: list[NDArray[np.int64]] = []
        self.ids: list[NDArray[np.int64]] = []
        self.counts: list[NDArray[np.int64]] = []
        self.depth: list[NDArray[np.int64]] = []
        self.boxes: list[NDArray[np.float32]] = []

    def arrays(self, cols: NDArray[np.float32]) -> _Small:
        if not self.ids:
            none = np.zeros(0, dtype=np.int64)
            return none, none, none, none, cols[:, :0]
        return (np.concatenate(self.tris), np.concatenate(self.ids), np.concatenate(self.counts),
                np.concatenate(self.depth), np.concatenate(self.boxes, axis=1))


def _split_levels(start: _Open, tree: _Tree, leaf_size: int, max_bins: int, stop: int = 0
                  ) -> tuple[_Small, _Open | None]:
    """The breadth-first binned-SAH splitting of the nodes of more than :data:`SMALL` triangles
    (see the module docstring), from the open nodes ``start`` down, or only until a level has
    ``stop`` open nodes or more (0: to the end).

    Records the nodes in ``tree``; returns the nodes of at most :data:`SMALL`
    triangles still to split (:func:`_split_small`): their triangles (grouped
    by node), their ids, triangle counts and depths, and the triangles' boxes
    (``(6, …)``, in the same order); and the nodes still open at ``stop`` (None at the end).

    The triangles still to split are kept grouped by node (``cols`` columns
    in node order, ``counts`` per node), so per-node values reach their
    triangles by ``np.repeat`` and the scattered bin updates stay local in
    memory; each level partitions every node's columns into its two
    children's in one pass (a counting sort: no ``argsort`` per level).
    Every choice is per node (the bins per node are ``max_bins`` at every
    level: open nodes hold more than SMALL ≥ 64 triangles), so the nodes of a
    level may be split in separate calls with the same result. One level is
    four steps: bin (:func:`_bin_level`), score the cuts (:func:`_score_cuts`),
    put each column on its side (:func:`_sides`), partition (:func:`_partition`).
    """
    small = max(SMALL, leaf_size)
    found = _Found()
    buffers = _Buffers(start.cols)
    level: _Open | None = start
    while level is not None and level.counts.size:
        if stop and level.counts.size >= stop:
            return found.arrays(level.cols), level
        binned = _bin_level(level, buffers, max_bins)
        cuts = _score_cuts(binned, level.counts)
        right, node_of = _sides(binned, cuts, level.counts)
        cols = level.cols
        level = _partition(level, binned, cuts, right, node_of, tree, leaf_size, small, found, buffers)
    return found.arrays(cols if level is None else level.cols), None


class _Binned(NamedTuple):
    """One level's nodes binned (:func:`_bin_level`)."""

    n: int  # open nodes
    width: int  # their columns
    bins: int  # bins per node and axis
    starts: NDArray[np.int64]  # each node's first column
    cen: NDArray[np.float32]  # (3, width): twice the columns' centroids
    box_lo: NDArray[np.float64]  # (n, 3): the binning ranges
    box_hi: NDArray[np.float64]
    scale: NDArray[np.float64]  # (n, 3): bins per unit length
    sampled: bool  # some node binned from a sample of its columns only
    taken: NDArray[np.int64]  # binned columns per node
    bin_key: NDArray[np.int32]  # (3, binned): node i's bins are i·B .. i·B + B − 1
    bin_row: NDArray[np.uint8]  # (3, binned): the bin within the node
    box_rows: NDArray[np.float32]  # (6, boxed): the boxes the bins' boxes are made of
    box_keys: NDArray[np.int32]  # (3, boxed): their bins


def _bin_level(level: _Open, buffers: _Buffers, max_bins: int) -> _Binned:
    """Every open node's binning range and each of its (sampled) columns' bin on each axis."""
    tris, cols, counts, box_lo, box_hi = level.tris, level.cols, level.counts, level.box_lo, level.box_hi
    n = counts.size
    width = tris.size
    cen = buffers.centre[:3 * width].reshape(3, width)
    np.add(cols[0:3], cols[3:6], out=cen)  # twice the centroids (halving them would be one more pass)
    # Bins per node: max_bins, fewer once nodes are small (about one per
    # triangle), so the per-bin work never exceeds the per-triangle work.
    bins = int(min(max_bins, max(4, 1 << int(np.log2(max(1, width // n))))))
    # Binning range per node and axis: the node's box (from its parent's
    # sweep), cut into `bins` equal slabs; a flat axis puts all in bin 0.
    # Where the triangles' centroids span less than CENTROID_RANGE of it on
    # an axis, the centroids' own range instead (Wald 2007): slivers meeting
    # at one point (a fan) have their centroids bunched in one slab of their
    # box, and only the stragglers could be cut off, one level each (a fan
    # of 1M triangles was 5,470 levels deep).
    starts = np.cumsum(counts) - counts
    centre_lo = 0.5 * np.minimum.reduceat(cen, starts, axis=1).T.astype(np.float64)
    centre_hi = 0.5 * np.maximum.reduceat(cen, starts, axis=1).T.astype(np.float64)
    bunched = (centre_hi - centre_lo) < CENTROID_RANGE * (box_hi - box_lo)
    box_lo = np.where(bunched, centre_lo, box_lo)
    box_hi = np.where(bunched, centre_hi, box_hi)
    extent = box_hi - box_lo
    scale = np.where(extent > 0.0, bins * (1.0 - 1e-6) / np.where(extent > 0.0, extent, 1.0), 0.0)
    # A node of SAMPLED_ONLY triangles or more is binned from every stride-th
    # of its triangles (about SAMPLE of them): its bins' counts (scaled by
    # stride) and boxes are the heuristic's estimate of the children's sizes
    # and areas, which picks the axis; the exact counts on that axis then
    # pick the cut (:func:`_sides`). Smaller nodes bin all their triangles (exact
    # counts) and, over 2·SAMPLE of them, take the bins' boxes from every
    # stride-th (the boxes are only the estimate of the children's areas).
    stride = np.maximum(1, counts // SAMPLE)
    sampled = bool(counts.max() >= SAMPLED_ONLY)
    if sampled:
        bin_stride = np.where(counts >= SAMPLED_ONLY, stride, 1)
        taken = -(-counts // bin_stride)
        sample = _every(starts, taken, bin_stride)
        box_rows = np.take(cols, sample, axis=1)
        bin_cen = np.take(cen, sample, axis=1)
        del sample
    else:
        taken = counts
        box_rows, bin_cen = cols, cen
    bin_key, bin_row = _bin_keys(bin_cen, taken, box_lo, scale, bins, buffers)
    box_stride = np.where(counts >= SAMPLED_ONLY, 1, stride)
    box_keys = bin_key
    if box_stride.max() > 1:
        box_sample = _every(np.cumsum(taken) - taken, -(-taken // box_stride), box_stride)
        box_rows = np.take(box_rows, box_sample, axis=1)
        box_keys = np.take(bin_key, box_sample, axis=1)
    return _Binned(n, width, bins, starts, cen, box_lo, box_hi, scale, sampled, taken, bin_key, bin_row,
                   box_rows, box_keys)


def _bin_keys(bin_cen: NDArray[np.float32], taken: NDArray[np.int64], box_lo: NDArray[np.float64],
              scale: NDArray[np.float64], bins: int, buffers: _Buffers
              ) -> tuple[NDArray[np.int32], NDArray[np.uint8]]:
    """Each binned column's bin on each axis, ``⌊(c − lo)·scale⌋`` clipped to the node's bins, and
    as a key node-major over the level (node i's bins are i·B .. i·B + B − 1)."""
    binned = bin_cen.shape[1]
    node_key = np.repeat(np.arange(taken.size, dtype=np.int32) * np.int32(bins), taken)
    bin_key = buffers.bin_keys[:3 * binned].reshape(3, binned)
    bin_row = buffers.bin_rows[:3 * binned].reshape(3, binned)
    rel = np.empty(binned, dtype=np.float32)
    for axis in range(3):  # one row at a time: np.repeat of a 1-D array is a plain copy loop
        # (2c − 2·lo)·(scale / 2): the same float32 value as (c − lo)·scale (halving and
        # doubling are exact), from the doubled centroids.
        np.subtract(bin_cen[axis], np.repeat((2.0 * box_lo[:, axis]).astype(np.float32), taken), out=rel)
        rel *= np.repeat((0.5 * scale[:, axis]).astype(np.float32), taken)
        np.clip(rel, 0, bins - 1, out=rel)
        bin_row[axis] = rel
        np.add(bin_row[axis], node_key, out=bin_key[axis])
    return bin_key, bin_row


class _Cuts:
    """Each node's cheapest cut so far (axis, first bin on the right, the children's boxes) and its
    most even cut by count (where no SAH cut gains), over the axes scored (:func:`_score_cuts`)."""

    def __init__(self, n: int) -> None:
        self.cost = np.full(n, np.inf)
        self.axis = np.zeros(n, dtype=np.int64)
        self.cut = np.ones(n, dtype=np.int64)
        self.lo = np.empty((n, 2, 3))
        self.hi = np.empty((n, 2, 3))
        self.even_gap = np.full(n, np.inf)
        self.even_axis = np.zeros(n, dtype=np.int64)
        self.even_cut = np.ones(n, dtype=np.int64)
        self.even_lo = np.empty((n, 2, 3))
        self.even_hi = np.empty((n, 2, 3))
        self.no_gain = np.zeros(0, dtype=np.int64)
        #: Per axis (sampled levels): the running boxes and the cuts' half areas (left, right).
        self.sweeps: list[tuple[NDArray[np.float32], ...]] = []
        self.areas: list[tuple[NDArray[np.float32], NDArray[np.float32]]] = []

    def keep(self, which: NDArray[np.int64], axis: int, cut: NDArray[np.int64],
             sweep: tuple[NDArray[np.float32], ...], even: bool = False) -> None:
        """Nodes ``which`` take the cut before bin ``cut + 1`` on ``axis``: its axis, cut and the
        children's boxes from the running boxes ``sweep`` (left lo, hi, right lo, hi)."""
        llo, lhi, rlo, rhi = sweep
        lo, hi = (self.even_lo, self.even_hi) if even else (self.lo, self.hi)
        (self.even_axis if even else self.axis)[which] = axis
        (self.even_cut if even else self.cut)[which] = cut + 1  # bins below the cut go left
        lo[which, 0] = llo[:, cut, which].T
        hi[which, 0] = lhi[:, cut, which].T
        lo[which, 1] = rlo[:, cut + 1, which].T
        hi[which, 1] = rhi[:, cut + 1, which].T


def _score_cuts(binned: _Binned, counts: NDArray[np.int64]) -> _Cuts:
    """The SAH cost ``N_left·A_left + N_right·A_right`` of every cut between bins on every axis,
    each node's cheapest kept; where it gains nothing, the most even cut by count instead."""
    n, bins = binned.n, binned.bins
    cuts = _Cuts(n)
    nodes = np.arange(n)
    to_counts = (counts / binned.taken)[:, None] if binned.sampled else None  # a sampled bin's count: stride × its own
    node_lo = node_hi = None
    for axis in range(3):
        cnt, sweep = _axis_bins(binned, axis)
        llo, lhi, rlo, rhi = sweep
        if node_lo is None:  # all the bins: the node's (sampled) box
            node_lo, node_hi = llo[:, -1], lhi[:, -1]
        n_left = np.cumsum(cnt.T[:-1], axis=0)
        # Both sides something, from the binned columns' own (integer) counts: scaled ones
        # round, and a side of none could look like a sliver of one.
        both = (n_left > 0) & (n_left < binned.taken)
        if to_counts is not None:
            n_left = n_left * to_counts.T
        n_right = counts - n_left
        area_left, area_right = _half_area(llo[:, :-1], lhi[:, :-1]), _half_area(rlo[:, 1:], rhi[:, 1:])
        if binned.sampled:
            cuts.sweeps.append(sweep)
            cuts.areas.append((area_left, area_right))
        sah = n_left * area_left + n_right * area_right
        sah = np.where(both, sah, np.inf)  # a cut must leave both sides something
        cut = np.argmin(sah, axis=0)  # the best cut on this axis, minus one
        cost = sah[cut, nodes]
        gap = np.where(both, np.abs(2 * n_left - counts), np.inf)
        even = np.argmin(gap, axis=0)
        evener = np.flatnonzero(gap[even, nodes] < cuts.even_gap)
        if evener.size:
            cuts.even_gap[evener] = gap[even[evener], evener]
            cuts.keep(evener, axis, even[evener], sweep, even=True)
        better = np.flatnonzero(cost < cuts.cost)
        if better.size:
            cuts.cost[better] = cost[better]
            cuts.keep(better, axis, cut[better], sweep)
    # No gain: when the best cut costs about what the node itself does (N·A: every child box
    # as big as the parent's), the SAH would peel a few triangles off per level and the tree
    # grow as deep as the node is large. The most even cut by count keeps the depth logarithmic.
    parent_cost = counts * _half_area(node_lo, node_hi).astype(np.float64)
    cuts.no_gain = np.flatnonzero(np.isfinite(cuts.cost) & (cuts.cost >= NO_GAIN * parent_cost)
                                  & np.isfinite(cuts.even_gap))
    if cuts.no_gain.size:
        g = cuts.no_gain
        cuts.axis[g], cuts.cut[g], cuts.lo[g], cuts.hi[g] = cuts.even_axis[g], cuts.even_cut[g], cuts.even_lo[g], \
            cuts.even_hi[g]
    return cuts


def _axis_bins(binned: _Binned, axis: int) -> tuple[NDArray[np.int64], tuple[NDArray[np.float32], ...]]:
    """On one axis: every node's bin counts ``(n, B)`` and the sweep, the boxes of bins ``[0, s]``
    and ``[s, B)`` for every ``s`` (left lo, hi, right lo, hi; ``(3, B, n)`` each)."""
    n, bins = binned.n, binned.bins
    cnt = np.bincount(binned.bin_key[axis], minlength=n * bins).reshape(n, bins)
    blo = np.full((3, n * bins), np.inf, dtype=np.float32)
    bhi = np.full((3, n * bins), -np.inf, dtype=np.float32)
    key = binned.box_keys[axis]
    for j in range(3):
        np.minimum.at(blo[j], key, binned.box_rows[j])
        np.maximum.at(bhi[j], key, binned.box_rows[3 + j])
    # Bin-major copies, (3, B, n): the sweep then runs over contiguous rows.
    blo3 = np.ascontiguousarray(blo.reshape(3, n, bins).transpose(0, 2, 1))
    bhi3 = np.ascontiguousarray(bhi.reshape(3, n, bins).transpose(0, 2, 1))
    llo, lhi = _sweep(blo3, bhi3, forward=True)
    rlo, rhi = _sweep(blo3, bhi3, forward=False)
    return cnt, (llo, lhi, rlo, rhi)


def _sides(binned: _Binned, cuts: _Cuts, counts: NDArray[np.int64]) -> tuple[NDArray[np.bool_], NDArray[np.int64]]:
    """Each column's side (True: the right child) on its node's chosen axis, and its node.

    On a sampled level the sample chose the axis; the exact counts of every column's bin on
    it then pick the cut there (:func:`_exact_cut`), and the children's boxes follow it. A
    child that got no box (none of the sampled columns were its own) is binned over its
    parent's range; a node no cut separates (every centroid in one bin on every axis) is
    split in half by count, in column order."""
    n, bins, cen = binned.n, binned.bins, binned.cen
    nodes = np.arange(n)
    # (Byte rows: the column's bin on each axis, its node's axis and cut repeated per column.)
    axis_of = np.repeat(cuts.axis.astype(np.uint8), counts)
    cut_of = np.repeat(cuts.cut.astype(np.uint8), counts)
    node_of = np.repeat(nodes, counts)  # each column's node
    if binned.sampled:
        # Only the chosen axis's bin of every column, by the same float32 steps as _bin_keys.
        if (cuts.axis == cuts.axis[0]).all():  # one axis for all (the top levels: one or two nodes)
            rel = cen[cuts.axis[0]].copy()
        else:
            rel = np.where(axis_of == 0, cen[0], np.where(axis_of == 1, cen[1], cen[2]))
        rel -= np.repeat((2.0 * binned.box_lo[nodes, cuts.axis]).astype(np.float32), counts)
        rel *= np.repeat((0.5 * binned.scale[nodes, cuts.axis]).astype(np.float32), counts)
        np.clip(rel, 0, bins - 1, out=rel)
        chosen_bin = rel.astype(np.uint8)
        del rel
        exact = np.bincount(node_of * bins + chosen_bin, minlength=n * bins).reshape(n, bins)
        cuts.cut = _exact_cut(exact, counts, cuts.axis, cuts.cut, cuts.no_gain, cuts.areas)
        cut_of = np.repeat(cuts.cut.astype(np.uint8), counts)
        right = np.greater_equal(chosen_bin, cut_of)
        del chosen_bin
        moved_cut = np.flatnonzero(np.isfinite(cuts.cost))
        if moved_cut.size:
            ax = cuts.axis[moved_cut]
            for j, sweep in enumerate(cuts.sweeps):  # the children's boxes at the new cut
                cuts.keep(moved_cut[ax == j], j, cuts.cut[moved_cut][ax == j] - 1, sweep)
    else:
        bin_row = binned.bin_row
        right = np.greater_equal(bin_row[2], cut_of)
        np.copyto(right, np.greater_equal(bin_row[1], cut_of), where=axis_of == 1)
        np.copyto(right, np.greater_equal(bin_row[0], cut_of), where=axis_of == 0)
    del axis_of, cut_of
    empty = np.logical_not(np.logical_and(np.isfinite(cuts.lo).all(axis=2), np.isfinite(cuts.hi).all(axis=2)))
    if empty.any():
        cuts.lo = np.where(empty[:, :, None], binned.box_lo[:, None, :], cuts.lo)
        cuts.hi = np.where(empty[:, :, None], binned.box_hi[:, None, :], cuts.hi)
    stuck = np.flatnonzero(~np.isfinite(cuts.cost))
    if stuck.size:
        where = np.repeat(~np.isfinite(cuts.cost), counts)
        rank = np.arange(binned.width) - np.repeat(binned.starts, counts)
        right[where] = (rank >= np.repeat(counts // 2, counts))[where]
        cuts.lo[stuck] = binned.box_lo[stuck][:, None, :]
        cuts.hi[stuck] = binned.box_hi[stuck][:, None, :]
    return right, node_of


def _partition(level: _Open, binned: _Binned, cuts: _Cuts, right: NDArray[np.bool_], node_of: NDArray[np.int64],
               tree: _Tree, leaf_size: int, small: int, found: _Found, buffers: _Buffers) -> _Open | None:
    """Number the children (in pairs: open node i's are 2i, left, and 2i + 1), record the leaves'
    triangles in ``tree`` and the small children in ``found``, and move the columns of the
    children still open into node order: the next level (None when none is open).

    One stable counting sort of all the columns by child, the children in three runs: those
    that stay open, then the small ones (SMALL triangles at most: on to _split_small, node
    after node), then the leaves (whose triangles get their places here)."""
    tris, cols, n, width, starts = level.tris, level.cols, binned.n, binned.width, binned.starts
    child = node_of
    child *= 2
    child += right
    # Each column's rank within its child (lefts keep their order, rights
    # too): with the child's start, its place in the partition below.
    # A right column's rank is the rights before it less the rights before its node's first
    # column; a left's, the lefts before it less the lefts before its node: one gather per
    # column of a per-child offset, no per-column repeat of per-node values.
    rights_before = right.astype(np.int64)
    np.cumsum(rights_before, out=rights_before)
    rights_before -= right  # rights in columns [0, i)
    at_start = rights_before[starts]
    child_count = np.empty(2 * n, dtype=np.int64)  # a node's rights: those before the next node's less its own
    child_count[1::2] = np.append(at_start[1:], rights_before[-1] + right[-1]) - at_start
    np.subtract(level.counts, child_count[1::2], out=child_count[0::2])
    child_ids, is_leaf = tree.children(level.ids, child_count, leaf_size)
    depth = level.level + 1
    tree.depth = max(tree.depth, depth)
    offset = np.empty(2 * n, dtype=np.int64)
    offset[0::2] = starts - at_start  # lefts before each node's first column
    offset[1::2] = at_start
    rank = np.arange(width)
    rank -= rights_before  # lefts in columns [0, i)
    np.copyto(rank, rights_before, where=right)
    is_small = ~is_leaf & (child_count <= small)
    group = is_leaf.astype(np.int8) * 2 + is_small  # 0 open, 1 small, 2 leaf
    runs = np.argsort(group, kind="stable")
    child_start = np.empty(2 * n, dtype=np.int64)
    run_counts = child_count[runs]
    child_start[runs] = np.cumsum(run_counts) - run_counts
    offset -= child_start
    rank -= offset[child]  # each column's place in the sorted order: the child's start plus its rank in it
    source = np.empty(width, dtype=np.int64)
    source[rank] = np.arange(width)
    n_open = int(child_count[group == 0].sum())
    n_small = int(child_count[is_small].sum())
    leaf_cols = source[n_open + n_small:]
    leaf_tris = tris[leaf_cols]
    leaf_child = child[leaf_cols]
    tree.leaf_of[leaf_tris] = child_ids[leaf_child]
    # A leaf column's place in its leaf: its place in the sorted order less the leaf's start.
    tree.leaf_rank[leaf_tris] = np.arange(n_open + n_small, width) - child_start[leaf_child]
    if n_small:
        smalls = np.flatnonzero(is_small)
        found.ids.append(child_ids[smalls])
        found.counts.append(child_count[smalls])
        found.depth.append(np.full(smalls.size, depth, dtype=np.int64))
        grouped = source[n_open:n_open + n_small]  # their columns, node after node
        found.tris.append(tris[grouped])
        found.boxes.append(np.take(cols, grouped, axis=1))
    if n_open == 0:
        return None
    kept = np.flatnonzero(group == 0)
    source = source[:n_open]
    moved = buffers.spare[:6 * n_open].reshape(6, n_open)
    np.take(cols, source, axis=1, out=moved, mode="clip")  # "clip": unbuffered (all in range)
    buffers.spare = cols.base if cols.base is not None and cols.base.ndim == 1 else cols.reshape(-1)
    return _Open(np.take(tris, source), moved, child_count[kept], cuts.lo.reshape(2 * n, 3)[kept],
                 cuts.hi.reshape(2 * n, 3)[kept], child_ids[kept], depth)


def _every(starts: NDArray[np.int64], taken: NDArray[np.int64], stride: NDArray[np.int64]) -> NDArray[np.int64]:
    """Column indices: node i's ``starts[i] + stride[i]·q`` for ``q = 0 .. taken[i] − 1``, node after node."""
    q = np.arange(taken.sum()) - np.repeat(np.cumsum(taken) - taken, taken)
    q *= np.repeat(stride, taken)
    q += np.repeat(starts, taken)
    return q


def _exact_cut(exact: NDArray[np.int64], counts: NDArray[np.int64], axis: NDArray[np.int64], cut: NDArray[np.int64],
               no_gain: NDArray[np.int64], areas: list[tuple[NDArray[np.float32], NDArray[np.float32]]]
               ) -> NDArray[np.int64]:
    """The cut (first bin on the right) of each node on its chosen ``axis`` from its exact bin
    counts there (``exact``, ``(n, B)``): the cheapest by the SAH with the sampled bins' areas,
    or the most even by count for the ``no_gain`` nodes; ``cut`` where no cut leaves both
    sides something."""
    nodes = np.arange(counts.size)
    area_left = np.stack([a[0] for a in areas])[axis, :, nodes].T  # (B − 1, n)
    area_right = np.stack([a[1] for a in areas])[axis, :, nodes].T
    n_left = np.cumsum(exact.T[:-1], axis=0)
    n_right = counts - n_left
    both = (n_left > 0) & (n_right > 0)
    sah = np.where(both, n_left * area_left + n_right * area_right, np.inf)
    best = np.argmin(sah, axis=0) + 1
    if no_gain.size:
        gap = np.where(both, np.abs(2 * n_left - counts), np.iinfo(np.int64).max)
        best[no_gain] = np.argmin(gap[:, no_gain], axis=0) + 1
    result: NDArray[np.int64] = np.where(both.any(axis=0), best, cut)
    return result


def _box_half_area(box: NDArray[np.float32], empty: bool = True) -> NDArray[np.float32]:
    """Half the surface area of boxes stored as ``(6, ...)``: ``min x, y, z, −max x, y, z``
    (an empty box, all ``inf``, has 0; ``empty=False``: there is none, min − max is never above 0)."""
    e = box[0:3] + box[3:6]  # min − max: minus the extent
    if empty:
        np.minimum(e, np.float32(0.0), out=e)
    result: NDArray[np.float32] = e[0] * e[1]
    result += e[1] * e[2]
    result += e[2] * e[0]
    return result


def _split_small(tree: _Tree, small: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
                                           NDArray[np.int64], NDArray[np.float32]], leaf_size: int) -> None:
    """Split the nodes of at most :data:`SMALL` triangles down to leaves by the *full* SAH sweep.

    Binning pays off on big nodes; on a node of a few dozen triangles the
    bins cost as much as the triangles and see less. Here every cut of a
    node is scored: along each axis its triangles are sorted by centroid
    (``argsort`` of short rows), and the boxes of the first ``i`` and of the
    rest, for every ``i``, are running minima and maxima of the sorted
    boxes. The nodes are laid out one per column of a ``(w, n)`` array,
    padded to a power of two ``w`` (nodes of similar size together), so each
    step of the running boxes is one numpy call over all the nodes.
    """
    caller, ids, counts, depths, boxes = small
    if ids.size == 0:
        return
    # (6, K + 1) float32: min x, y, z and minus max x, y, z of each triangle (running boxes are then
    # running minima only), and last an empty box (all inf) that pads the nodes' columns.
    tris = np.arange(caller.size)  # indices into table, node after node
    table = np.empty((6, caller.size + 1), dtype=np.float32)
    table[0:3, :-1] = boxes[0:3]
    np.negative(boxes[3:6], out=table[3:6, :-1])
    table[:, -1] = np.inf
    # The sort keys of the triangles (and the padding): twice the centroid, its float32 bits made
    # an int32 of the same order (a negative float's magnitude bits flipped); padding sorts last.
    with np.errstate(invalid="ignore"):
        keys = table[0:3] - table[3:6]  # min + max; padding: NaN
    order_bits = keys.view(np.int32)
    order_bits ^= (order_bits >> 31) & np.int32(0x7FFFFFFF)
    order_bits[:, -1] = np.iinfo(np.int32).max
    while ids.size:
        starts = np.cumsum(counts) - counts
        width_class = WIDTHS[np.searchsorted(WIDTHS, counts)]  # the narrowest padding that holds the node
        out_tris, out_cuts, order_nodes = [], [], []
        for w in np.unique(width_class):
            members = np.flatnonzero(width_class == w)
            for part in range(0, members.size, max(1, SMALL_CHUNK // int(w))):
                sel = members[part:part + max(1, SMALL_CHUNK // int(w))]
                sorted_tris, cut = _small_cuts(table, order_bits, tris, starts[sel], counts[sel], int(w), leaf_size)
                out_tris.append(sorted_tris)
                out_cuts.append(cut)
                order_nodes.append(sel)
        sel = np.concatenate(order_nodes)
        cut = np.concatenate(out_cuts)
        tris = np.concatenate(out_tris)
        m = counts[sel]
        child_count = np.empty(2 * sel.size, dtype=np.int64)
        child_count[0::2] = cut
        child_count[1::2] = m - cut
        child_ids, is_leaf = tree.children(ids[sel], child_count, leaf_size)
        child_depth = np.repeat(depths[sel] + 1, 2)
        tree.depth = max(tree.depth, int(child_depth.max()))
        child = np.repeat(np.arange(child_count.size), child_count)
        rank = np.arange(tris.size) - np.repeat(np.cumsum(child_count) - child_count, child_count)
        tri_leaf = is_leaf[child]
        leaf_tris = caller[tris[tri_leaf]]
        tree.leaf_of[leaf_tris] = child_ids[child[tri_leaf]]
        tree.leaf_rank[leaf_tris] = rank[tri_leaf]
        tris = tris[~tri_leaf]
        ids = child_ids[~is_leaf]
        counts = child_count[~is_leaf]
        depths = child_depth[~is_leaf]


def _small_cuts(table: NDArray[np.float32], order_bits: NDArray[np.int32], tris: NDArray[np.int64],
                starts: NDArray[np.int64], counts: NDArray[np.int64], w: int, leaf_size: int
                ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The best cut of each of ``r`` nodes (triangles ``tris[starts[j] : starts[j] + counts[j]]``,
    at most ``w`` each; boxes in ``table``, sort keys in ``order_bits``): their triangles in the
    chosen order (left child first, node after node) and the left child's triangle count."""
    r = counts.size
    slot = np.arange(w)[:, None]
    valid = slot < counts  # (w, r): slot i of node j holds a triangle
    tri = np.where(valid, tris[np.minimum(starts + slot, tris.size - 1)], table.shape[1] - 1)  # (w, r)
    # Sort keys: the centroid's order bits, then the slot in the low bits: np.sort of int64 keys is
    # several times faster than np.argsort of floats, and the slot is read back from the key.
    bits = np.take(order_bits, tri, axis=1)  # (3, w, r); padding sorts last
    shift = int(w - 1).bit_length()
    flat_tri = tri.reshape(-1)
    cuts = np.arange(1, w, dtype=np.float32)[:, None]  # cut i: sorted triangles [0, i) go left
    no_cut = np.where(cuts >= counts, np.float32(np.inf), np.float32(0.0))  # (w − 1, r): added to the costs
    rest = counts.astype(np.float32) - cuts  # the right side's triangles
    columns = np.arange(r)
    orders = []
    costs = np.empty((3, r), dtype=np.float32)
    best = np.empty((3, r), dtype=np.int64)
    middle = np.empty((3, r), dtype=np.float32)
    # The even cut of a node with no SAH gain: a multiple of leaf_size near the middle, so that its
    # subtree ends in full leaves (ceil(N / leaf_size) of them, the fewest boxes).
    half = np.clip(leaf_size * np.rint(counts / (2 * leaf_size)).astype(np.int64), 1, counts - 1)
    size = counts.astype(np.float32)
    parent = None
    for axis in range(3):
        keys = bits[axis].T.astype(np.int64)  # (r, w)
        keys <<= shift
        keys |= slot.T
        keys.sort(axis=1)
        order = keys & ((1 << shift) - 1)  # (r, w): node j's slots by centroid
        orders.append(order)
        # (6, w, r): the boxes in that order, padding the empty box (no effect on running minima).
        sweep = np.take(table, flat_tri[order.T * r + columns], axis=1)
        back = np.empty_like(sweep)
        back[:, w - 1] = sweep[:, w - 1]
        for i in range(w - 2, -1, -1):  # boxes of slots i ..
            np.minimum(back[:, i + 1], sweep[:, i], out=back[:, i])
        for i in range(1, w):  # boxes of the first i + 1
            np.minimum(sweep[:, i - 1], sweep[:, i], out=sweep[:, i])
        if parent is None:
            parent = size * _box_half_area(sweep[:, w - 1], empty=False)
        sah = _box_half_area(sweep[:, :-1], empty=False)  # the first i + 1 slots: slot 0 is never padding
        sah *= cuts
        right = _box_half_area(back[:, 1:])
        right *= rest
        sah += right
        sah += no_cut  # inf where the cut leaves the right side nothing
        pick = np.argmin(sah, axis=0)
        best[axis] = pick + 1
        costs[axis] = sah[pick, columns]
        middle[axis] = sah[half - 1, columns]
    axis = np.argmin(costs, axis=0)
    cut = best[axis, columns]
    # No gain (the best cut costs about N·A: slivers sharing one box): the most even cut by count,
    # on the axis where it costs least, keeps the depth logarithmic (as in _split_levels).
    no_gain = costs[axis, columns] >= NO_GAIN * parent
    if no_gain.any():
        even_axis = np.argmin(middle, axis=0)
        axis = np.where(no_gain, even_axis, axis)
        cut = np.where(no_gain, half, cut)
    chosen = np.where(axis[:, None] == 0, orders[0], np.where(axis[:, None] == 1, orders[1], orders[2]))  # (r, w)
    sorted_tri = tri.T.reshape(-1)[chosen + columns[:, None] * w]  # (r, w)
    return sorted_tri[valid.T], cut


def sah_cost(bvh: BVH) -> float:
    """The tree's expected cost by the surface area heuristic, relative to its root box:
    ``Σ_inner A(n)/A(root) + Σ_leaf A(l)/A(root)·N(l)`` (one unit per box test and per
    triangle test). Lower is better; a single leaf of ``M`` triangles costs ``M``."""
    e = np.maximum(bvh.node_max - bvh.node_min, 0.0)
    area = e[:, 0] * e[:, 1] + e[:, 1] * e[:, 2] + e[:, 2] * e[:, 0]
    if bvh.empty or area[0] <= 0.0:
        return float(bvh.triangle_count)
    return float((area * np.where(bvh.node_count == 0, 1, bvh.node_count)).sum() / area[0])


def _exact_boxes(leaf_min: NDArray[np.float64], leaf_max: NDArray[np.float64], count: NDArray[np.int64],
                 first: NDArray[np.int64], leaves: NDArray[np.int64], levels: list[NDArray[np.int64]]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Exact float64 node boxes: the leaves' (``leaf_min``, ``leaf_max``: the min and max of their
    triangles' corners), then each level's inner nodes from their two children, deepest first."""
    total = count.shape[0]
    node_min = np.empty((total, 3))
    node_max = np.empty((total, 3))
    node_min[leaves] = leaf_min
    node_max[leaves] = leaf_max
    for ids in reversed(levels):
        inner = ids[count[ids] == 0]
        if inner.size:
            left = first[inner]
            node_min[inner] = np.minimum(node_min[left], node_min[left + 1])
            node_max[inner] = np.maximum(node_max[left], node_max[left + 1])
    return node_min, node_max


# --- the cache ---------------------------------------------------------------

_CACHE: OrderedDict[bytes, BVH] = OrderedDict()
_MESH_DIGESTS: weakref.WeakKeyDictionary[Mesh, bytes] = weakref.WeakKeyDictionary()


def clear_cache() -> None:
    """Forget every cached BVH."""
    _CACHE.clear()


def _cached(key: bytes, build: object) -> BVH:
    found = _CACHE.get(key)
    if found is not None:
        _CACHE.move_to_end(key)
        return found
    assert callable(build)
    result: BVH = build()
    _CACHE[key] = result
    while len(_CACHE) > CACHE_SIZE:
        _CACHE.popitem(last=False)
    return result


def _digest(*parts: bytes) -> bytes:
    h = hashlib.blake2b(digest_size=20)
    for part in parts:
        h.update(len(part).to_bytes(8, "little"))
        h.update(part)
    return h.digest()


def bvh_for_triangles(v0: ArrayLike, v1: ArrayLike, v2: ArrayLike, *, leaf_size: int = LEAF_SIZE,
                      bins: int = BINS) -> BVH:
    """:func:`build_bvh`, cached by a digest of the triangles' float64 bytes."""
    a, b, c = _triangle_arrays(v0, v1, v2)
    key = _digest(b"triangles", a.tobytes(), b.tobytes(), c.tobytes(), f"{leaf_size},{bins}".encode())
    return _cached(key, lambda: build_bvh(a, b, c, leaf_size=leaf_size, bins=bins))


def mesh_digest(mesh: Mesh) -> bytes:
    """A blake2b digest of a mesh's triangles: mode, positions and indices (kept per Mesh object:
    meshes are immutable)."""
    found = _MESH_DIGESTS.get(mesh)
    if found is None:
        positions = np.ascontiguousarray(np.asarray(mesh.positions, dtype=np.float64))
        indices = b"" if mesh.indices is None else np.ascontiguousarray(np.asarray(mesh.indices, dtype=np.int64)).tobytes()
        found = _digest(b"mesh", mesh.mode.encode(), positions.tobytes(), indices)
        _MESH_DIGESTS[mesh] = found
    return found


def mesh_world_triangles(mesh: Mesh, model: ArrayLike | None = None
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """A mesh's triangles in world space, ``(M, 3)`` corners each: positions moved by
    ``model`` exactly as :func:`glsandbox.raytrace.world.build_world` moves them (strips
    unrolled with their winding, :meth:`~glsandbox.geometry.Mesh.triangles`; a line mesh
    has none)."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    if model is not None:
        positions = transforms.transform_points(np.asarray(model, dtype=np.float64), positions)
    tris = Mesh(mesh.name, positions, mesh.indices, mode=mesh.mode).triangles().reshape(-1, 3, 3)
    return (np.ascontiguousarray(tris[:, 0]), np.ascontiguousarray(tris[:, 1]), np.ascontiguousarray(tris[:, 2]))


def bvh_for_mesh(mesh: Mesh, model: ArrayLike | None = None, *, leaf_size: int = LEAF_SIZE, bins: int = BINS) -> BVH:
    """The BVH of ``mesh`` moved to world space by ``model`` (identity when None),
    cached by (mesh digest, model bytes): the same model in another frame builds nothing.
    Triangle indices are the mesh's own (triangle ``k`` is indices ``3k .. 3k+2``)."""
    m = np.eye(4) if model is None else np.asarray(model, dtype=np.float64)
    if m.shape != (4, 4):
        raise RayTraceError(f"a model matrix is 4x4, got shape {m.shape}")
    key = _digest(b"mesh-bvh", mesh_digest(mesh), np.ascontiguousarray(m).tobytes(), f"{leaf_size},{bins}".encode())
    return _cached(key, lambda: build_bvh(*mesh_world_triangles(mesh, None if model is None else m),
                                          leaf_size=leaf_size, bins=bins))
