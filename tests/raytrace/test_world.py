"""The Scene as the ray tracer sees it (glsandbox/raytrace/world.py): one viewport's nodes in world
space, a sphere mesh traced as the exact sphere, the viewport's clear colour behind, how much of a
surface covers what lies behind it, and the primary rays of the course's camera and image plane."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.world import (ALPHA_CODES, NodeKind, analytic_kind, build_world, camera_rays, coverage,
                                      course_image_plane)
from glsandbox.scene import Camera, Material, Node, Scene, Viewport

LIT = Material(color=(1.0, 1.0, 1.0, 1.0), shading="phong")
HALVES = (Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0), clear_color=(0.0, 1.0, 0.0, 1.0)))


def test_a_viewport_holds_its_own_nodes_in_world_space_in_front_of_its_clear_colour() -> None:
    moved = Node("moved", geometry.triangle(), transforms.translate(10.0, 0.0, 0.0))
    scene = Scene("s", viewports=HALVES, clear_color=(0.0, 0.0, 1.0, 1.0),
                  nodes=(moved, Node("right_only", geometry.cube(), viewports=(1,))))
    left = build_world(scene, 0)
    assert [n.name for n in left.nodes] == ["moved"] and np.allclose(left.background, (0.0, 0.0, 1.0))
    positions = geometry.triangle().positions
    assert np.allclose(left.v0[0], positions[0] + (10.0, 0.0, 0.0))
    right = build_world(scene, 1)
    assert [n.name for n in right.nodes] == ["moved", "right_only"] and np.allclose(right.background, (0.0, 1.0, 0.0))
    assert right.nodes[1].start == right.nodes[0].count  # each node's triangles follow the one before's
    with pytest.raises(RayTraceError, match="viewport 2 does not exist"):
        build_world(scene, 2)


def test_sphere_mesh_is_traced_as_exact_sphere():
    scene = Scene("s", nodes=(Node("ball", geometry.sphere(), transforms.translate(1, 2, 3) @ transforms.scale(2, 2, 2), LIT),))
    world = build_world(scene)
    assert world.nodes[0].kind == "sphere" and world.triangle_count == 0
    assert np.allclose(world.nodes[0].box_min, (-1, 0, 1)) and np.allclose(world.nodes[0].box_max, (3, 4, 5))
    triangles = build_world(scene, analytic_spheres=False)
    assert triangles.nodes[0].kind == "mesh" and triangles.triangle_count > 1000


def test_a_sphere_mesh_whose_vertices_moved_off_the_sphere_is_its_triangles() -> None:
    ball = geometry.sphere()
    assert analytic_kind(ball) is NodeKind.SPHERE
    bumped = ball.positions.copy()
    bumped[0] *= 1.1
    assert analytic_kind(replace(ball, name="bumpy", positions=bumped)) is None


def test_coverage_is_one_for_opaque_the_cutoff_for_a_cut_out_and_alpha_when_blended() -> None:
    modes = np.array([ALPHA_CODES["opaque"], ALPHA_CODES["mask"], ALPHA_CODES["mask"], ALPHA_CODES["blend"]])
    alpha = np.array([0.2, 0.6, 0.4, 0.3])
    assert coverage(modes, alpha, np.full(4, 0.5)).tolist() == [1.0, 1.0, 0.0, 0.3]


def test_course_image_plane_gd_mapping():
    """GD(x, y) of an 800x450 image: (16x/799 - 8, 4.5 - 9y/449, 10)."""
    corners = course_image_plane(np.array([0, 799, 400]), np.array([0, 449, 225]))
    assert np.allclose(corners[0], (-8, 4.5, 10), atol=1e-12)
    assert np.allclose(corners[1], (8, -4.5, 10), atol=1e-12)
    assert np.allclose(corners[2], (16 * 400 / 799 - 8, 4.5 - 9 * 225 / 449, 10), atol=1e-12)


def test_primary_ray_t_is_depth():
    """Directions have a view-axis component of 1: t of a hit is its distance along the view."""
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0))
    eye, dirs = camera_rays(camera, 9, 7)
    assert np.allclose(eye, (0, 0, 5))
    assert np.allclose(dirs[:, 2], -1.0)
    assert np.allclose(dirs[4 + 3 * 9], (0, 0, -1))  # the centre pixel looks straight ahead
    assert dirs[0, 0] < 0 < dirs[0, 1]  # row 0 is the top, column 0 the left
