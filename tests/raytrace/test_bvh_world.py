"""The top level over a World's nodes (the numpy engine's ``_top_level``, the one loop
renders use) through the mesh nodes' BVHs: the same nearest hit as testing every
triangle, and, on lesson scenes, the node the per-node scan finds.

These checks use a small grid of rays: the brute force they compare with tests every ray
against every triangle."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from glsandbox.lesson import find_lesson
from glsandbox.raytrace.bvh_traverse import closest_hit_brute_force
from glsandbox.raytrace.bvh_world import WorldBVH
from glsandbox.raytrace.numpy_engine import _nearest, _occluded
from glsandbox.raytrace.world import World, build_world, camera_rays

LESSONS = ("phong", "ray_phong", "ray_acceleration")
#: The camera's rays, as a grid of this size: 768 rays over the whole view (the brute force tests each
#: against every triangle: 6,662 of them in ray_phong).
RAYS = (32, 24)


@functools.cache
def world_of(lesson: str) -> tuple[World, np.ndarray, np.ndarray]:
    scene = find_lesson(lesson)().scene()
    world = build_world(scene, 0, analytic_spheres=False)  # every node a mesh
    eye, dirs = camera_rays(scene.viewports[0].camera or scene.camera, *RAYS)
    return world, eye, dirs


def brute_force(world: World, o: np.ndarray, d: np.ndarray, cull: bool | None) -> tuple[np.ndarray, np.ndarray]:
    """Every world triangle, each node one-sided or not as asked: ``(t, world triangle)``,
    ties to the lower world index (the course's min_indis over nodes, then triangles)."""
    one_sided = np.zeros(world.triangle_count, dtype=bool)
    for node in world.nodes:
        one_sided[node.start:node.start + node.count] = node.cull if cull is None else cull
    best_t = np.full(d.shape[0], np.inf)
    best_k = np.full(d.shape[0], -1)
    for side in (False, True):
        idx = np.flatnonzero(one_sided == side)
        if idx.size == 0:
            continue
        hits = closest_hit_brute_force(world.v0[idx], world.v1[idx], world.v2[idx], o, d, cull_backfaces=side)
        k = np.where(hits.triangle >= 0, idx[np.maximum(hits.triangle, 0)], -1)
        better = (hits.t < best_t) | ((hits.t == best_t) & (k >= 0) & ((best_k < 0) | (k < best_k)))
        best_t = np.where(better, hits.t, best_t)
        best_k = np.where(better, k, best_k)
    return best_t, best_k


@pytest.mark.parametrize("lesson", LESSONS)
@pytest.mark.parametrize("cull", [None, False, True])
def test_world_bvh_equals_testing_every_triangle(lesson: str, cull: bool | None) -> None:
    world, eye, dirs = world_of(lesson)
    hits = _nearest(world, eye, dirs, cull, True, None, WorldBVH.from_world(world))
    t, k = brute_force(world, eye, dirs, cull)
    np.testing.assert_array_equal(hits.tri, k)
    np.testing.assert_array_equal(hits.t, t)
    np.testing.assert_array_equal(hits.node, np.where(k >= 0, world.tri_node[np.maximum(k, 0)], -1))


@pytest.mark.parametrize("lesson", LESSONS)
def test_world_bvh_finds_the_node_the_engine_finds(lesson: str) -> None:
    # The scan and the BVH both use the watertight test: the same triangles, so the
    # same nodes and t (the BVH's order of tests may only change which of two
    # triangles at one t wins, never the node or t).
    world, eye, dirs = world_of(lesson)
    hits = _nearest(world, eye, dirs, None, True, None, WorldBVH.from_world(world))
    engine = _nearest(world, eye, dirs, None, True)  # the per-node scan (no BVH)
    np.testing.assert_array_equal(hits.node, engine.node)
    np.testing.assert_array_equal(hits.t, engine.t)


def test_shadow_rays_skip_the_lights_lamp() -> None:
    scene = find_lesson("ray_phong")().scene()
    world = build_world(scene, 0, analytic_spheres=False)
    top = WorldBVH.from_world(world)
    lamps = [n for n in top.nodes if n.lamp_of]
    assert lamps, "ray_phong's demo scene draws each light as a small lamp cube"
    light = int(np.log2(lamps[0].lamp_of & -lamps[0].lamp_of))
    target = world.light_positions[light]
    # A ray from just outside the lamp to the light: only the lamp is between.
    box = world.nodes[lamps[0].node]
    outside = np.array([[box.box_max[0] + 1e-3, target[1], target[2]]])
    for accel in (top, None):  # any hit through the BVHs, and the scan cut at t = 1
        assert _occluded(world, outside, target - outside, -1, None, True, None, accel)[0]  # no lamp skipped
        assert not _occluded(world, outside, target - outside, light, None, True, None, accel)[0]
