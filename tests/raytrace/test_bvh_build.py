"""Building the BVH on hard real-world shapes: a fan of slivers meeting at one point stays
logarithmically deep and cheap by the SAH; the build's work grows linearly with the fan; sah_cost()."""

from __future__ import annotations

import hashlib
import math
import time
from pathlib import Path

import numpy as np
import pytest

from glsandbox import meshgen
from glsandbox.mesh.load import load_mesh
from glsandbox.raytrace import bvh as bvh_module
from glsandbox.raytrace.bvh import LEAF_SIZE, SMALL, build_bvh, build_threads, mesh_world_triangles, sah_cost


def fan(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` slivers around the origin, three quarters of a disc, corners as three (n, 3) arrays."""
    angle = np.linspace(0.0, 1.5 * np.pi, n + 1)
    rim = np.c_[np.cos(angle), np.sin(angle), np.zeros(n + 1)]
    return np.zeros((n, 3)), rim[:-1].copy(), rim[1:].copy()


def leaves_hold_every_triangle_once(bvh) -> bool:
    leaves = np.flatnonzero(bvh.node_count)
    slots = np.concatenate([np.arange(bvh.node_first[i], bvh.node_first[i] + bvh.node_count[i]) for i in leaves])
    return bool(np.array_equal(np.sort(slots), np.arange(bvh.triangle_count)))


def test_a_fan_is_as_deep_as_a_balanced_tree() -> None:
    # Binning a node over its own box put a sliver fan's centroids in one slab: only the stragglers
    # could be cut off, one per level (32,000 slivers were 901 levels deep, SAH cost 4,577). Binned
    # down to the leaves the tree cost 3,507.7; small nodes cut at multiples of the leaf size where
    # no cut gains (_small_cuts) end in full leaves: 3,217.7.
    n = 32_000
    bvh = build_bvh(*fan(n))
    assert bvh.depth <= 2 * math.ceil(math.log2(n / LEAF_SIZE)), bvh
    assert leaves_hold_every_triangle_once(bvh) and bvh.triangle_count == n
    assert sah_cost(bvh) < 3_300.0


def test_the_fan_build_grows_linearly() -> None:
    def seconds(n: int) -> float:
        tris = fan(n)
        best = math.inf
        for _ in range(3):
            start = time.process_time()
            build_bvh(*tris)
            best = min(best, time.process_time() - start)
        return best

    seconds(5_000)  # warm
    ratio = seconds(80_000) / max(seconds(20_000), 1e-4)
    assert ratio < 9.0, f"4x the slivers took {ratio:.1f}x the time (linear: about 4x, square: 16x)"


def test_a_rock_keeps_a_good_tree() -> None:
    # A lumpy closed surface (what a scan looks like): the SAH cost of its tree against the builder
    # before the fan fix (32.142 for rock(4), 5,120 triangles; 32.139 after it, binned down to the
    # leaves; 32.093 with small nodes split by the full sweep); a split rule that builds a worse
    # tree shows here as a higher cost.
    bvh = build_bvh(*mesh_world_triangles(meshgen.rock(4)))
    assert leaves_hold_every_triangle_once(bvh) and bvh.depth <= 20
    assert sah_cost(bvh) <= 32.139, sah_cost(bvh)


def test_a_terrain_keeps_a_good_tree() -> None:
    # A height field (the bvh benchmark's model): 18.921 binned down to the leaves, and now.
    bvh = build_bvh(*mesh_world_triangles(meshgen.terrain(meshgen.terrain_cells_for(20_000))))
    assert leaves_hold_every_triangle_once(bvh)
    assert sah_cost(bvh) <= 18.922, sah_cost(bvh)


def test_a_small_node_is_cut_where_the_sah_is_least() -> None:
    # 40 triangles (fewer than SMALL): the root is cut by the full sweep, the cheapest of every cut
    # of the triangles sorted by centroid on each axis (float32 inside: equal to a few ulps).
    rng = np.random.default_rng(3)
    a = rng.uniform(-1.0, 1.0, (40, 3))
    b, c = a + rng.normal(0.0, 0.2, (40, 3)), a + rng.normal(0.0, 0.2, (40, 3))
    assert 40 <= SMALL
    bvh = build_bvh(a, b, c)
    lo = np.minimum(np.minimum(a, b), c)
    hi = np.maximum(np.maximum(a, b), c)

    def half_area(lo: np.ndarray, hi: np.ndarray) -> float:
        e = hi - lo
        return float(e[0] * e[1] + e[1] * e[2] + e[2] * e[0])

    best = math.inf
    for axis in range(3):
        order = np.argsort((lo + hi)[:, axis], kind="stable")
        for i in range(1, 40):
            left, right = order[:i], order[i:]
            cost = i * half_area(lo[left].min(axis=0), hi[left].max(axis=0)) + \
                (40 - i) * half_area(lo[right].min(axis=0), hi[right].max(axis=0))
            best = min(best, cost)
    left = bvh.node_first[0]
    sizes = []
    for child in (left, left + 1):
        stack, count = [child], 0
        while stack:
            k = stack.pop()
            count += bvh.node_count[k]
            if bvh.node_count[k] == 0:
                stack += [bvh.node_first[k], bvh.node_first[k] + 1]
        sizes.append(count)
    got = sum(n * half_area(bvh.node_min[k], bvh.node_max[k]) for n, k in zip(sizes, (left, left + 1)))
    assert got <= best * (1.0 + 1e-5), (got, best)


def test_sah_cost_of_a_single_leaf_is_its_triangle_count() -> None:
    a, b, c = fan(3)
    assert sah_cost(build_bvh(a, b, c)) == 3.0


def leaf_sets(bvh) -> list[tuple[int, ...]]:
    """The tree's leaves as sorted tuples of the caller's triangle indices, sorted: the tree without its numbering."""
    leaves = np.flatnonzero(bvh.node_count)
    return sorted(tuple(sorted(bvh.tri_index[bvh.node_first[i]:bvh.node_first[i] + bvh.node_count[i]].tolist()))
                  for i in leaves)


def test_a_build_in_parts_and_threads_is_the_tree_of_one_pass(monkeypatch) -> None:
    # A big build is cut into parts (the subtrees of the first level with PARTS open nodes, and the
    # small nodes made above it), built in threads and numbered in a fixed order: the same leaves and
    # boxes as one pass, and the same arrays for any thread count. Degenerate triangles are left out.
    a, b, c = mesh_world_triangles(meshgen.terrain(meshgen.terrain_cells_for(20_000)))
    c = c.copy()
    c[::9] = a[::9]  # degenerate: no area
    one_pass = build_bvh(a, b, c)
    monkeypatch.setattr(bvh_module, "PART_MIN", 1_000)
    built = [build_bvh(a, b, c, threads=n) for n in (1, 2, 3)]
    assert leaf_sets(built[0]) == leaf_sets(one_pass)
    assert built[0].node_total == one_pass.node_total and built[0].depth == one_pass.depth
    assert not np.array_equal(built[0].node_first, one_pass.node_first)  # numbered part after part
    assert sah_cost(built[0]) == pytest.approx(sah_cost(one_pass), rel=1e-12)
    for field in ("node_min", "node_max", "node_first", "node_count", "v0", "v1", "v2", "tri_index"):
        assert all(np.array_equal(getattr(built[0], field), getattr(other, field)) for other in built[1:]), field
    assert leaves_hold_every_triangle_once(built[1]) and built[1].triangle_count == one_pass.triangle_count


def test_build_threads_are_the_idle_usable_cpus_at_most_threads() -> None:
    assert build_threads(3) == 3 and build_threads(0) == 1
    assert 1 <= build_threads() <= bvh_module.THREADS


def random_triangles(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` small triangles scattered in a flattened cloud (random centres, random corners about them)."""
    rng = np.random.default_rng(seed)
    centre = rng.normal(size=(n, 3)) * [1.0, 3.0, 0.2]
    a, b, c = (centre + 0.05 * rng.normal(size=(n, 3)) for _ in range(3))
    return a, b, c


#: The trees the builder makes, by their SAH figure (the float sah_cost() returns, to 1e-12), node
#: count and depth: binned levels, sampled levels (nodes of SAMPLED_ONLY triangles and more), the
#: no-gain and all-in-one-bin cuts (the fan), the full sweep of small nodes, and leaf sizes 1 and 8.
#: Any change to how the builder chooses its cuts changes these; a change to how it is written must not.
TREES = [
    ("rock3", lambda: mesh_world_triangles(meshgen.rock(3)), 4, 817, 11, 27.703694650059145),
    ("rock5", lambda: mesh_world_triangles(meshgen.rock(5)), 4, 12999, 17, 36.361955016563705),
    ("rock5 leaf 1", lambda: mesh_world_triangles(meshgen.rock(5)), 1, 40959, 19, 35.662178720185395),
    ("rock5 leaf 8", lambda: mesh_world_triangles(meshgen.rock(5)), 8, 6927, 15, 41.26220161005427),
    ("terrain64", lambda: mesh_world_triangles(meshgen.terrain(64)), 4, 4455, 14, 17.39876613019888),
    ("random1000", lambda: random_triangles(1000, 2), 4, 659, 12, 9.803011896223921),
    ("random20000", lambda: random_triangles(20000, 3), 4, 13341, 18, 28.801946919275053),
]


@pytest.mark.parametrize(("make", "leaf_size", "nodes", "depth", "sah"), [t[1:] for t in TREES],
                         ids=[t[0] for t in TREES])
def test_the_builder_makes_the_same_trees(make, leaf_size: int, nodes: int, depth: int, sah: float) -> None:
    bvh = build_bvh(*make(), leaf_size=leaf_size)
    # The SAH figure to 1e-12: numpy's releases add in different orders (1.26, the floor below
    # Python 3.13, differs from 2.x in the last bit), while another cut moves it far more.
    assert (bvh.node_total, bvh.depth) == (nodes, depth) and sah_cost(bvh) == pytest.approx(sah, rel=1e-12, abs=0)
    assert leaves_hold_every_triangle_once(bvh)


def node_digest(bvh) -> str:
    """A blake2b digest of the tree's node arrays (boxes, children or triangle runs, the stored
    triangles' order): two trees have the same one when they are the same arrays, byte for byte."""
    h = hashlib.blake2b(digest_size=12)
    for field in ("node_min", "node_max", "node_first", "node_count", "tri_index"):
        h.update(np.ascontiguousarray(getattr(bvh, field)).tobytes())
    return h.hexdigest()


BOULDER = Path(__file__).resolve().parents[2] / "glsandbox" / "models" / "boulder.obj"

#: The node arrays the builder makes (their digest) on the shipped model and generated meshes:
#: the full sweep (rock, terrain), a cloud, a terrain big enough for sampled levels (nodes of
#: SAMPLED_ONLY triangles and more), and the same built in parts (PART_MIN lowered: the parts'
#: numbering). A faster builder must make these same arrays; one that chooses other cuts changes
#: them (and TREES says whether its SAH is better).
NODE_ARRAYS = [
    ("boulder", lambda: mesh_world_triangles(load_mesh(BOULDER)), None, "97a8c9288e8d550f1ffc3eab"),
    ("rock5", lambda: mesh_world_triangles(meshgen.rock(5)), None, "8d6e8b95b0a7259fe6f387c9"),
    ("terrain64", lambda: mesh_world_triangles(meshgen.terrain(64)), None, "8c749f25213d0cffb7fd09b4"),
    ("random20000", lambda: random_triangles(20000, 3), None, "4bb1cee14ed0ae22181e7912"),
    ("terrain40k", lambda: mesh_world_triangles(meshgen.terrain(meshgen.terrain_cells_for(40_000))), None,
     "75eea07613a50594ff6a4134"),
    ("terrain40k parts", lambda: mesh_world_triangles(meshgen.terrain(meshgen.terrain_cells_for(40_000))), 4096,
     "4ab62ea96f0984bb27a0b9fa"),
]


@pytest.mark.parametrize(("make", "part_min", "digest"), [t[1:] for t in NODE_ARRAYS], ids=[t[0] for t in NODE_ARRAYS])
def test_the_builder_makes_the_same_node_arrays(make, part_min: int | None, digest: str, monkeypatch) -> None:
    if part_min is not None:
        monkeypatch.setattr(bvh_module, "PART_MIN", part_min)
    bvh = build_bvh(*make(), threads=1)
    assert node_digest(bvh) == digest
    if part_min is not None:  # parts built in threads: the same arrays
        assert node_digest(build_bvh(*make(), threads=2)) == digest
