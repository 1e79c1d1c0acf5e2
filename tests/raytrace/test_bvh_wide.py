"""The 4-wide BVH (glsandbox/raytrace/bvh_wide.py): the binary SAH tree collapsed by surface area,
every triangle reachable exactly once, every child box inside its wide node's, the nearest hits the
binary tree's bit for bit, and the binary tree (the float64 reference) untouched by the collapse."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import assert_same_hits, soup_and_rays, triangle_soup

from glsandbox import meshgen
from glsandbox.raytrace.bvh import BVH, build_bvh, mesh_world_triangles
from glsandbox.raytrace.bvh_traverse import closest_hit
from glsandbox.raytrace.bvh_wide import WIDTH, WideBVH, closest_hit_wide, collapse


def area(bvh: BVH, node: np.ndarray) -> np.ndarray:
    e = np.maximum(bvh.node_max[node] - bvh.node_min[node], 0.0)
    return e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0]


def walk(wide: WideBVH) -> tuple[list[int], list[int]]:
    """Records reached from record 0 and the stored triangles of every leaf reached, in plain Python."""
    records, triangles, todo = [], [], [0]
    ref, count, used = wide.slots()
    while todo:
        r = todo.pop()
        records.append(r)
        for s in range(WIDTH):
            if not used[r, s]:
                continue
            if count[r, s] > 0:
                triangles.extend(range(ref[r, s], ref[r, s] + count[r, s]))
            else:
                todo.append(int(ref[r, s]))
    return records, triangles


def own_node(wide: WideBVH) -> np.ndarray:
    """The binary node each record was made from (record 0: the root)."""
    node = np.zeros(wide.record_count, dtype=np.int64)
    made = np.flatnonzero(wide.record_of >= 0)
    node[wide.record_of[made]] = made
    return node


def opened(bvh: BVH, top: int, kids: np.ndarray) -> list[int]:
    """The binary nodes between ``top`` and the record's children: those the collapse opened."""
    found, todo, leaves = [], [top], set(int(k) for k in kids if k >= 0)
    while todo:
        n = todo.pop()
        if n in leaves:
            continue
        found.append(n)
        left = int(bvh.node_first[n])
        todo += [left, left + 1]
    return found


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(1, 400), leaf_size=st.integers(1, 6))
def test_every_triangle_is_reached_once_and_every_box_holds_its_children(seed: int, count: int,
                                                                       leaf_size: int) -> None:
    bvh = build_bvh(*triangle_soup(seed, count), leaf_size=leaf_size)
    wide = collapse(bvh)
    records, triangles = walk(wide)
    assert sorted(records) == list(range(wide.record_count))  # each record once: a tree
    assert sorted(triangles) == list(range(bvh.triangle_count))  # each stored triangle once
    used = wide.child >= 0
    # Empty slots only after the used ones; a record holds 2..4 children (the root of a
    # one-leaf tree: that leaf alone).
    assert np.all(used[:, :-1] | ~used[:, 1:])
    lone_leaf = bvh.node_count[0] > 0
    assert np.all(used.sum(axis=1) >= (1 if lone_leaf else 2))
    node = own_node(wide)
    kids = np.where(used, wide.child, 0)
    lo, hi = bvh.node_min[kids], bvh.node_max[kids]
    inside = (lo >= bvh.node_min[node][:, None]) & (hi <= bvh.node_max[node][:, None])
    assert np.all(inside.all(axis=2) | ~used)
    assert wide.depth <= bvh.depth


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(8, 400))
def test_the_collapse_opens_the_largest_children_first(seed: int, count: int) -> None:
    """A record opened as many binary nodes as its slots allow (fewer than 4 children: none of
    them inner), and each opened node is at least as large as every inner child left closed:
    the greedy rule (the largest inner child opened next) in one checkable form."""
    bvh = build_bvh(*triangle_soup(seed, count), leaf_size=1)
    wide = collapse(bvh)
    node = own_node(wide)
    for r in range(wide.record_count):
        kids = wide.child[r][wide.child[r] >= 0]
        closed = [int(k) for k in kids if bvh.node_count[k] == 0]
        if kids.size < WIDTH:
            assert not closed
        opens = opened(bvh, int(node[r]), kids)
        assert len(opens) == kids.size - 1  # opening one node adds one slot
        if closed:
            assert area(bvh, np.array(opens)).min() >= area(bvh, np.array(closed)).max()


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(1, 300), cull=st.booleans(), limited=st.booleans())
def test_nearest_hits_equal_the_binary_trees(seed: int, count: int, cull: bool, limited: bool) -> None:
    a, b, c, o, d, t_max = soup_and_rays(seed, count, limited)  # some rays straight at vertices
    bvh = build_bvh(a, b, c, leaf_size=2)
    want = closest_hit(bvh, o, d, t_max, cull_backfaces=cull)
    assert_same_hits(closest_hit_wide(collapse(bvh), o, d, t_max, cull_backfaces=cull), want)


def test_a_real_model_hits_the_same_and_the_binary_tree_is_unchanged() -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(4, seed=2))  # 5,120 triangles
    bvh = build_bvh(a, b, c, leaf_size=2)
    rng = np.random.default_rng(3)
    o = rng.uniform(-0.3, 0.3, (2000, 3)) + [0.0, 0.0, 3.0]
    d = rng.normal(size=(2000, 3)) * 0.3 - [0.0, 0.0, 1.0]
    before = closest_hit(bvh, o, d)
    arrays = [x.copy() for x in (bvh.node_min, bvh.node_max, bvh.node_first, bvh.node_count, bvh.tri_index)]
    wide = collapse(bvh)
    assert 0.2 < before.hit.mean() < 0.9
    assert_same_hits(closest_hit_wide(wide, o, d), before)
    assert_same_hits(closest_hit(bvh, o, d), before)  # the float64 reference path: as before
    for was, now in zip(arrays, (bvh.node_min, bvh.node_max, bvh.node_first, bvh.node_count, bvh.tri_index)):
        np.testing.assert_array_equal(was, now)
    # Fewer, fuller nodes: about half the levels, most slots used.
    assert wide.depth <= (bvh.depth + 1) // 2 + 2
    assert (wide.child >= 0).sum() / wide.record_count > 2.5


def test_a_lone_leaf_and_no_triangles() -> None:
    one = build_bvh(np.zeros((1, 3)), [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    wide = collapse(one)
    assert wide.record_count == 1 and wide.depth == 1
    np.testing.assert_array_equal(wide.child[0], [0, -1, -1, -1])
    hits = closest_hit_wide(wide, [[0.2, 0.2, 1.0]], [[0.0, 0.0, -1.0]])
    assert hits.triangle.tolist() == [0] and hits.t.tolist() == [1.0]
    empty = build_bvh(np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)))  # degenerate: left out
    wide = collapse(empty)
    assert wide.record_count == 1 and not (wide.child >= 0).any()
    assert closest_hit_wide(wide, [[0.0, 0.0, 1.0]], [[0.0, 0.0, -1.0]]).triangle.tolist() == [-1]


def test_width_is_checked() -> None:
    bvh = build_bvh(*triangle_soup(1, 20))
    with pytest.raises(ValueError, match="width must be in 2..64"):
        collapse(bvh, width=1)
    binary = collapse(bvh, width=2)  # width 2: the binary tree itself, record for record
    assert binary.record_count == int((bvh.node_count == 0).sum())
