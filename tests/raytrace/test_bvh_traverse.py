"""Traversing the BVH (glsandbox/raytrace/bvh_traverse.py, course "Hızlandırma: AABB" taken to its
conclusion): closest and any hits identical to testing every triangle with the watertight test,
the tests counted those of a level-by-level traversal, and rays aimed exactly at vertices and
edges never escape."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import assert_same_hits, random_rays, soup_and_rays, triangle_soup

from glsandbox import geometry, meshgen
from glsandbox.raytrace.bvh import BVH, build_bvh, mesh_world_triangles
from glsandbox.raytrace.bvh_traverse import BOX_PAD, TraversalCounts, any_hit, closest_hit, closest_hit_brute_force
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.triangle import Triangle, _watertight
from glsandbox.raytrace.watertight import ray_setup, watertight_pairs


# --- hits: the BVH against every triangle ----------------------------------------


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10**6), count=st.integers(1, 300), cull=st.booleans(), limited=st.booleans())
def test_closest_hit_equals_brute_force(seed: int, count: int, cull: bool, limited: bool) -> None:
    a, b, c, o, d, t_max = soup_and_rays(seed, count, limited)  # some rays straight at vertices
    bvh = build_bvh(a, b, c)
    want = closest_hit_brute_force(a, b, c, o, d, t_max, cull_backfaces=cull)
    assert_same_hits(closest_hit(bvh, o, d, t_max, cull_backfaces=cull), want)
    np.testing.assert_array_equal(any_hit(bvh, o, d, t_max, cull_backfaces=cull), want.hit)


def level_by_level(bvh: BVH, o: np.ndarray, d: np.ndarray, t_max: np.ndarray, cull: bool,
                   first_hit: bool) -> tuple[int, int]:
    """The (box, triangle) tests of the traversal's rule, one ray at a time in plain Python:
    a level's boxes are all tested, then its leaves' triangles (the ray's best hit, or with
    ``first_hit`` whether it hit at all, counting from then on), then the kept inner nodes'
    children make the next level. Boxes padded as the traversal pads them."""
    pad = BOX_PAD * np.maximum(np.abs(bvh.node_min), np.abs(bvh.node_max)).max(axis=1)
    lo, hi = bvh.node_min - pad[:, None], bvh.node_max + pad[:, None]
    boxes = triangles = 0
    for ray in range(len(d)):
        o_pad = BOX_PAD * np.abs(o[ray]).max()
        with np.errstate(divide="ignore"):
            inv = 1.0 / d[ray]
        setup = ray_setup(o[ray:ray + 1], d[ray:ray + 1])
        best, level, done = t_max[ray], [0], False
        while level and not done:
            kept = []
            for node in level:
                boxes += 1
                ta, tb = (lo[node] - (o[ray] + o_pad)) * inv, (hi[node] - (o[ray] - o_pad)) * inv
                near, far = np.minimum(ta, tb).max(), np.maximum(ta, tb).min()
                if near <= far and far >= 0.0 and (near < t_max[ray] if first_hit else near <= best):
                    kept.append(node)
            for node in (k for k in kept if bvh.node_count[k]):
                slots = np.arange(bvh.node_first[node], bvh.node_first[node] + bvh.node_count[node])
                triangles += slots.size
                t, _, _ = watertight_pairs(setup, np.zeros(slots.size, dtype=np.intp), bvh.v0, bvh.v1, bvh.v2,
                                           slots, cull)
                hit = t[t < t_max[ray]]
                done = first_hit and (done or hit.size > 0)
                best = min(best, hit.min(initial=np.inf))
            level = [bvh.node_first[k] + child for k in kept if not bvh.node_count[k] for child in (0, 1)]
    return boxes, triangles


@pytest.mark.parametrize("seed", [3, 4])
@pytest.mark.parametrize("cull", [False, True])
def test_the_tests_counted_are_those_of_a_level_by_level_traversal(seed: int, cull: bool) -> None:
    """What ``counts`` says (the ray_acceleration lesson prints it) is what the rule does,
    however the packet traversal batches its work: a level's boxes, then its leaves."""
    a, b, c = triangle_soup(seed, 250)
    o, d = random_rays(seed, 80)
    t_max = np.where(np.arange(80) % 3 == 0, np.random.default_rng(seed).uniform(0.5, 4.0, 80), np.inf)
    bvh = build_bvh(a, b, c)
    counts = TraversalCounts()
    hits = closest_hit(bvh, o, d, t_max, cull_backfaces=cull, counts=counts)
    boxes, triangles = level_by_level(bvh, o, d, t_max, cull, first_hit=False)
    assert (counts.boxes, counts.triangles) == (boxes, triangles + int(hits.hit.sum()))  # + the winners' uv test
    counts = TraversalCounts()
    any_hit(bvh, o, d, t_max, cull_backfaces=cull, counts=counts)
    assert (counts.boxes, counts.triangles) == level_by_level(bvh, o, d, t_max, cull, first_hit=True)
    assert 0 < hits.hit.sum() < 80 and counts.boxes > 3 * 80


def test_shared_origin_rays_of_a_camera_on_a_real_model() -> None:
    from glsandbox.raytrace.world import camera_rays
    from glsandbox.scene import Camera

    mesh = meshgen.terrain(24)
    a, b, c = mesh_world_triangles(mesh)
    eye, dirs = camera_rays(Camera(eye=(0.3, 1.0, 2.0)), 64, 48)
    want = closest_hit_brute_force(a, b, c, eye, dirs)
    got = closest_hit(build_bvh(a, b, c), eye, dirs)
    assert_same_hits(got, want)
    assert 0.2 < got.hit.mean() < 0.9


@pytest.mark.parametrize("moved", [True, False])
def test_shared_origin_rays_with_and_without_the_corners_moved_to_the_eye(moved: bool, monkeypatch) -> None:
    """Below ``MOVED_CORNERS`` triangles a BVH keeps its corners moved to the eye (``V − O``,
    the watertight test's first step, done once); above it each pair forms ``V − O``: the same numbers."""
    from glsandbox.raytrace import bvh_traverse

    monkeypatch.setattr(bvh_traverse, "MOVED_CORNERS", 1 << 18 if moved else 0)
    a, b, c = triangle_soup(21, 300)
    bvh = build_bvh(a, b, c)
    _, dirs = random_rays(22, 400)
    eye = np.array([0.5, 7.0, -1.0])
    assert_same_hits(closest_hit(bvh, eye, dirs), closest_hit_brute_force(a, b, c, eye, dirs))
    assert (bvh.__dict__["_kernel_moved"][3] is not None) == moved  # the path taken is the one meant


def test_brute_force_keeps_the_first_minimum_and_the_scalar_t() -> None:
    a, b, c = triangle_soup(11, 30)
    o, d = random_rays(11, 40)
    want = closest_hit_brute_force(a, b, c, o, d)
    for i in range(len(o)):
        ts = []
        for k in range(len(a)):
            tri = Triangle(a[k], b[k], c[k])
            hit = None if tri.is_degenerate else _watertight(tri, Ray(o[i], d[i]), False)
            ts.append(np.inf if hit is None else hit)
        k = int(np.argmin(ts))
        assert want.t[i] == ts[k] and want.triangle[i] == (k if np.isfinite(ts[k]) else -1)


def test_on_equal_t_the_lower_triangle_index_wins_wherever_the_bvh_stores_it() -> None:
    # A floor of 200 quads, then the same floor again in reverse order: every
    # ray meets two coincident triangles at the same t. The copy with the lower
    # index must win, as the course's min_indis loop keeps the first minimum.
    mesh = meshgen.terrain(10, height=0.0)
    a, b, c = mesh_world_triangles(mesh)
    m = len(a)
    a2, b2, c2 = (np.concatenate([x, x[::-1]]) for x in (a, b, c))
    o = np.array([0.0, 5.0, 0.0])
    xs = np.linspace(-0.9, 0.9, 23)
    d = np.stack(np.meshgrid(xs, [-5.0], xs), axis=-1).reshape(-1, 3)
    for first_half in (True, False):
        order = np.arange(2 * m) if first_half else np.r_[m:2 * m, 0:m]
        hits = closest_hit(build_bvh(a2[order], b2[order], c2[order]), o, d)
        want = closest_hit_brute_force(a2[order], b2[order], c2[order], o, d)
        assert_same_hits(hits, want)
        assert hits.hit.all()
        np.testing.assert_array_equal(hits.t, 1.0)
        # The winner is the lower of the two indices holding that triangle.
        original = order[hits.triangle]  # index in the floor, floor-reversed
        floor = np.where(original < m, original, 2 * m - 1 - original)
        position = np.argsort(order)  # where each of a2's triangles went
        np.testing.assert_array_equal(hits.triangle, np.minimum(position[floor], position[2 * m - 1 - floor]))


def test_backface_culling_skips_triangles_facing_away() -> None:
    a, b, c = (np.array([p]) for p in ((0.0, 0, 0), (1.0, 0, 0), (0.0, 1, 0)))  # normal +z
    bvh = build_bvh(a, b, c)
    front = closest_hit(bvh, (0.2, 0.2, 1.0), (0.0, 0.0, -1.0), cull_backfaces=True)
    back = closest_hit(bvh, (0.2, 0.2, -1.0), (0.0, 0.0, 1.0), cull_backfaces=True)
    both = closest_hit(bvh, (0.2, 0.2, -1.0), (0.0, 0.0, 1.0), cull_backfaces=False)
    assert front.triangle[0] == 0 and front.t[0] == 1.0
    assert back.triangle[0] == -1
    assert both.triangle[0] == 0 and both.t[0] == 1.0


def test_any_hit_counts_only_what_lies_strictly_between() -> None:
    a, b, c = (np.array([p]) for p in ((-1.0, -1, 0), (1.0, -1, 0), (0.0, 1, 0)))
    bvh = build_bvh(a, b, c)
    start = np.array([[0.0, 0.0, 2.0]] * 3)
    light = np.array([[0.0, 0.0, -2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # beyond, on, before the triangle
    blocked = any_hit(bvh, start, light - start, 1.0)
    assert blocked.tolist() == [True, False, False]


# --- watertight: rays aimed exactly at vertices and edges never escape ------------

CLOSED = {"icosphere3": lambda: meshgen.icosphere(3), "rock3": lambda: meshgen.rock(3, seed=5),
          "cube": geometry.cube}


def edge_midpoints(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    return np.concatenate([(a + b) / 2, (b + c) / 2, (c + a) / 2])


@pytest.mark.parametrize("name", CLOSED)
def test_from_inside_a_closed_mesh_every_ray_at_a_vertex_or_an_edge_hits(name: str) -> None:
    a, b, c = mesh_world_triangles(CLOSED[name]())
    bvh = build_bvh(a, b, c)
    targets = np.concatenate([a, b, c, edge_midpoints(a, b, c)])
    for inside in ([0.0, 0.0, 0.0], [0.013, -0.021, 0.017], [0.3, 0.2, -0.25]):
        o = np.array(inside)
        assert closest_hit(bvh, o, targets - o).hit.all()
        assert any_hit(bvh, o, 3.0 * (targets - o)).all()


@pytest.mark.parametrize("name", CLOSED)
def test_from_outside_rays_at_vertices_and_edges_inside_the_silhouette_hit(name: str) -> None:
    # A ray at a vertex on the silhouette only grazes it (rounding decides);
    # one at a vertex or edge whose faces all face the eye is inside the
    # projected mesh, and must hit: no crack between two triangles lets it through.
    a, b, c = mesh_world_triangles(CLOSED[name]())
    bvh = build_bvh(a, b, c)
    normal = np.cross(b - a, c - a)
    for eye in ([3.0, 2.0, 4.0], [-4.0, 0.5, -0.25], [0.0, 0.0, 6.0]):
        o = np.array(eye)
        facing = np.einsum("ij,ij->i", normal, (a + b + c) / 3 - o) < 0.0
        corners = np.concatenate([a, b, c])
        facing3 = np.tile(facing, 3)
        # A target counts when every face that touches it faces the eye.
        points, inverse = np.unique(corners, axis=0, return_inverse=True)
        all_front = np.ones(len(points), dtype=bool)
        np.logical_and.at(all_front, inverse.reshape(-1), facing3)
        mids = edge_midpoints(a, b, c)
        mid_points, mid_inverse = np.unique(mids, axis=0, return_inverse=True)
        mid_front = np.ones(len(mid_points), dtype=bool)
        np.logical_and.at(mid_front, mid_inverse.reshape(-1), facing3)
        targets = np.concatenate([points[all_front], mid_points[mid_front]])
        assert len(targets) > 0
        hits = closest_hit(bvh, o, targets - o)
        assert hits.hit.all()
        assert np.all(hits.t <= 1.0 + 1e-12)  # nothing behind the target point is taken
        # Culled, the front faces still answer.
        assert closest_hit(bvh, o, targets - o, cull_backfaces=True).hit.all()


def test_boxes_kept_between_calls_follow_the_shared_origin() -> None:
    """The padded boxes, and those moved to the last shared origin, are kept on the BVH
    between calls (an engine traces a frame in blocks): a new origin must move them again."""
    a, b, c = triangle_soup(11, 300)
    bvh = build_bvh(a, b, c)
    _, dirs = random_rays(12, 200)
    for origin in ([0.0, 0.0, 9.0], [5.0, -3.0, 1.0], [0.0, 0.0, 9.0], [0.5, 0.5, 0.5]):
        eye = np.array(origin)
        assert_same_hits(closest_hit(bvh, eye, dirs), closest_hit_brute_force(a, b, c, eye, dirs))
