"""The BVH (glsandbox/raytrace/bvh.py, course "Hızlandırma: AABB" taken to its conclusion): its
structure, the watertight kernel its leaves use, and the cache (traversal: test_bvh_traverse.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import random_rays, triangle_soup

from glsandbox import meshgen
from glsandbox.raytrace.bvh import (
    BVH,
    CACHE_SIZE,
    build_bvh,
    bvh_for_mesh,
    bvh_for_triangles,
    clear_cache,
    mesh_world_triangles,
)
from glsandbox.raytrace.bvh_traverse import any_hit, closest_hit
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.triangle import Triangle, _watertight
from glsandbox.raytrace.watertight import nondegenerate, ray_setup, watertight_pairs


# --- structure ------------------------------------------------------------------


def check_structure(bvh: BVH, a: np.ndarray, b: np.ndarray, c: np.ndarray, leaf_size: int = 4) -> None:
    ok = nondegenerate(a, b, c)
    leaves = np.flatnonzero(bvh.node_count)
    inner = np.flatnonzero(bvh.node_count == 0)
    # Every non-degenerate triangle in exactly one leaf, no degenerate one anywhere.
    slots = np.concatenate([np.arange(bvh.node_first[k], bvh.node_first[k] + bvh.node_count[k]) for k in leaves])
    assert np.array_equal(np.sort(slots), np.arange(bvh.triangle_count))
    assert np.array_equal(np.sort(bvh.tri_index), np.flatnonzero(ok))
    assert bvh.node_count.max() <= leaf_size
    np.testing.assert_array_equal(bvh.v0, a[bvh.tri_index])
    np.testing.assert_array_equal(bvh.v1, b[bvh.tri_index])
    np.testing.assert_array_equal(bvh.v2, c[bvh.tri_index])
    # Leaf boxes are exactly their triangles' boxes.
    for k in leaves:
        part = slice(bvh.node_first[k], bvh.node_first[k] + bvh.node_count[k])
        corners = np.concatenate([bvh.v0[part], bvh.v1[part], bvh.v2[part]])
        np.testing.assert_array_equal(bvh.node_min[k], corners.min(axis=0))
        np.testing.assert_array_equal(bvh.node_max[k], corners.max(axis=0))
    # Inner nodes: two children after them, boxes inside, each node reached once.
    left = bvh.node_first[inner]
    assert np.all(left > inner) and np.all(left + 1 < bvh.node_total)
    for child in (left, left + 1):
        assert np.all(bvh.node_min[child] >= bvh.node_min[inner])
        assert np.all(bvh.node_max[child] <= bvh.node_max[inner])
    reached = np.concatenate([[0], left, left + 1])
    assert np.array_equal(np.sort(reached), np.arange(bvh.node_total))
    # depth: the nodes on the longest path from the root (the GPU traversal's stack is sized by it).
    level = np.ones(bvh.node_total, dtype=np.int64)
    for k in inner:  # in id order: a parent before its children
        level[bvh.node_first[k]] = level[bvh.node_first[k] + 1] = level[k] + 1
    assert bvh.depth == level.max()
    if ok.any():
        np.testing.assert_array_equal(bvh.node_min[0], np.minimum(np.minimum(a[ok], b[ok]), c[ok]).min(axis=0))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(1, 400), leaf_size=st.integers(1, 6))
def test_every_triangle_is_in_exactly_one_leaf_and_children_lie_inside_parents(seed: int, count: int,
                                                                               leaf_size: int) -> None:
    a, b, c = triangle_soup(seed, count)
    bvh = build_bvh(a, b, c, leaf_size=leaf_size)
    assert bvh.input_count == count
    check_structure(bvh, a, b, c, leaf_size)


@pytest.mark.parametrize("leaf_size", [33, 64])
def test_leaves_as_big_as_the_small_node_limit(leaf_size: int) -> None:
    # Nodes of up to bvh.SMALL triangles are split by the full sweep; a leaf size at or above it
    # leaves that phase nothing (or everything) to do.
    a, b, c = triangle_soup(7, 1500)
    check_structure(build_bvh(a, b, c, leaf_size=leaf_size), a, b, c, leaf_size)


def test_triangles_that_no_cut_separates_are_split_by_count() -> None:
    # 50 copies of one triangle: every centroid in one point, no bin boundary between them.
    tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    a, b, c = (np.repeat(tri[i][None], 50, axis=0) for i in range(3))
    bvh = build_bvh(a, b, c)
    check_structure(bvh, a, b, c)
    hits = closest_hit(bvh, (0.2, 0.2, 1.0), (0.0, 0.0, -1.0))
    assert hits.triangle[0] == 0 and hits.t[0] == 1.0  # all 50 tie: the first wins


def test_a_real_model_builds_a_shallow_tree_with_full_leaves() -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(5))
    bvh = build_bvh(a, b, c)
    check_structure(bvh, a, b, c)
    assert bvh.triangle_count == 20480
    assert bvh.depth <= 24
    assert bvh.triangle_count / bvh.leaf_count > 2.5  # leaves mostly filled


def test_no_triangles_or_only_degenerate_ones_give_an_empty_bvh_that_every_ray_misses() -> None:
    for a, b, c in [(np.zeros((0, 3)),) * 3, (np.zeros((3, 3)), np.ones((3, 3)), np.ones((3, 3)))]:
        bvh = build_bvh(a, b, c)
        assert bvh.empty and bvh.triangle_count == 0
        hits = closest_hit(bvh, np.zeros(3), np.array([[1.0, 1.0, 1.0]]))
        assert hits.triangle[0] == -1 and hits.t[0] == np.inf
        assert not any_hit(bvh, np.zeros(3), np.array([[1.0, 1.0, 1.0]]))[0]


def test_bad_triangles_are_refused() -> None:
    from glsandbox.errors import SandboxError

    with pytest.raises(SandboxError, match="finite"):
        build_bvh(np.array([[np.nan, 0, 0]]), np.ones((1, 3)), np.zeros((1, 3)))
    with pytest.raises(SandboxError, match=r"\(M, 3\)"):
        build_bvh(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)))


# --- the watertight kernel ------------------------------------------------------


def test_the_vectorised_watertight_test_is_the_scalar_test_bit_for_bit() -> None:
    a, b, c = triangle_soup(7, 40)
    o, d = random_rays(7, 120)
    d[:60] = a[np.arange(60) % 40] - o[:60]  # aimed at vertices: edge functions of exactly 0
    d[60:80] = (b[np.arange(20)] + c[np.arange(20)]) / 2 - o[60:80]  # aimed at edge midpoints
    setup = ray_setup(o, d)
    rr = np.repeat(np.arange(len(o)), len(a))
    tt = np.tile(np.arange(len(a)), len(o))
    for cull in (False, True):
        t, _, _ = watertight_pairs(setup, rr, a, b, c, tt, cull)
        want = []
        for r, k in zip(rr, tt):
            hit = _watertight(Triangle(a[k], b[k], c[k]), Ray(o[r], d[r]), cull)
            want.append(np.inf if hit is None else hit)
        np.testing.assert_array_equal(t, np.array(want))


def test_barycentrics_rebuild_the_hit_point() -> None:
    a, b, c = triangle_soup(3, 200)
    o, d = random_rays(3, 2000)
    hits = closest_hit(build_bvh(a, b, c), o, d)
    k = hits.triangle[hits.hit]
    p = o[hits.hit] + hits.t[hits.hit, None] * d[hits.hit]
    q = a[k] + hits.u[hits.hit, None] * (b[k] - a[k]) + hits.v[hits.hit, None] * (c[k] - a[k])
    np.testing.assert_allclose(p, q, atol=1e-9)
    assert np.all(hits.u[hits.hit] >= -1e-12) and np.all(hits.v[hits.hit] >= -1e-12)


# --- the cache -----------------------------------------------------------------


def test_the_cache_returns_the_same_bvh_for_the_same_content() -> None:
    clear_cache()
    mesh = meshgen.icosphere(2)
    model = np.diag([2.0, 2.0, 2.0, 1.0])
    first = bvh_for_mesh(mesh, model)
    assert bvh_for_mesh(mesh, model.copy()) is first  # same mesh, same matrix values
    assert bvh_for_mesh(mesh, np.eye(4)) is not first
    a, b, c = mesh_world_triangles(mesh, model)
    np.testing.assert_array_equal(first.v0, a[first.tri_index])
    assert bvh_for_triangles(a, b, c) is bvh_for_triangles(a.copy(), b.copy(), c.copy())
    for k in range(CACHE_SIZE + 2):  # older entries leave the LRU
        bvh_for_mesh(mesh, np.diag([1.0 + k, 1.0, 1.0, 1.0]))
    assert bvh_for_mesh(mesh, model) is not first
