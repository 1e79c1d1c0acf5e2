"""The third node kind, the capped unit cylinder (``NodeKind.CYLINDER``): its hit test against
exact points and against a dense triangle mesh of the same cylinder, its surface, and the
gpu engine against the numpy engine (unrolled and general programs)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.geometry import Mesh
from glsandbox.raytrace import render
from glsandbox.raytrace.numpy_engine import _Hits, _nearest, _surface
from glsandbox.raytrace.shapes.cylinder import unit_cylinder_t
from glsandbox.raytrace.world import NodeKind, build_world
from glsandbox.scene import Camera, Light, Material, Node, Scene

MODEL = transforms.translate(0.3, -0.2, 0.1) @ transforms.rotate_y(0.7) @ transforms.rotate_x(0.5) \
    @ transforms.scale(0.8, 1.3, 0.6)


def cylinder_scene(mesh: Mesh, model: np.ndarray = MODEL, **material) -> Scene:
    node = Node("cylinder", mesh, model, Material(color=(0.8, 0.5, 0.3, 1.0), shading="phong", **material))
    return Scene("cylinder", nodes=(node,), camera=Camera(eye=(0.5, 1.5, 5.0), target=(0.0, 0.0, 0.0)),
                 lights=(Light((3.0, 4.0, 3.0)),))


def surface_points(count: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Points on the unit cylinder (half on the side, a quarter on each cap) and their normals."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0.0, 2.0 * math.pi, count)
    side = np.stack([np.sin(phi), rng.uniform(-0.99, 0.99, count), np.cos(phi)], axis=1)
    r = np.sqrt(rng.uniform(0.0, 0.98, count))
    y = np.where(np.arange(count) % 2 == 0, 1.0, -1.0)
    cap = np.stack([r * np.sin(phi), y, r * np.cos(phi)], axis=1)
    points = np.concatenate([side, cap])
    normals = np.concatenate([side * [1.0, 0.0, 1.0], np.stack([0 * y, y, 0 * y], axis=1)])
    return points, normals


def test_rays_aimed_at_surface_points_hit_them_first() -> None:
    points, normals = surface_points(2000)
    rng = np.random.default_rng(1)
    # From outside, along a direction that leaves the surface outwards: the point is the entry.
    away = normals + 0.8 * rng.normal(size=normals.shape)
    away[np.einsum("ij,ij->i", away, normals) <= 0.1] = normals[np.einsum("ij,ij->i", away, normals) <= 0.1]
    origins = points + 3.0 * away / np.linalg.norm(away, axis=1, keepdims=True)
    t = unit_cylinder_t(origins, points - origins)
    np.testing.assert_allclose(t, 1.0, rtol=0, atol=1e-12)
    # From the centre every ray leaves through the point it is aimed at.
    t = unit_cylinder_t(np.zeros_like(points), points)
    np.testing.assert_allclose(t, 1.0, rtol=0, atol=1e-12)


def test_rays_along_the_axis_meet_the_caps_and_rays_across_it_the_side() -> None:
    o = np.array([[0.5, 5.0, 0.0], [0.5, -5.0, 0.0], [1.5, 5.0, 0.0], [5.0, 0.5, 0.0], [5.0, 1.5, 0.0]])
    d = np.array([[0.0, -1.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(unit_cylinder_t(o, d), [4.0, 4.0, np.inf, 4.0, np.inf])


def test_a_cylinder_mesh_is_traced_as_the_cylinder_it_says_it_is() -> None:
    world = build_world(cylinder_scene(geometry.cylinder()))
    node = world.nodes[0]
    assert node.kind is NodeKind.CYLINDER and node.count == 0 and world.triangle_count == 0
    mesh_world = build_world(cylinder_scene(geometry.cylinder()), analytic_spheres=False)
    assert mesh_world.nodes[0].kind is NodeKind.MESH
    # The analytic box holds the tessellation's and is no larger than the exact cylinder's.
    assert np.all(node.box_min <= mesh_world.nodes[0].box_min + 1e-12)
    assert np.all(node.box_max >= mesh_world.nodes[0].box_max - 1e-12)
    # A mesh that only claims to be the cylinder (a vertex off it) keeps its triangles.
    mesh = geometry.cylinder()
    moved = mesh.positions.copy()
    moved[0] *= 1.01
    liar = Mesh("liar", moved, mesh.indices, mesh.normals, mesh.uvs, analytic="cylinder")
    assert build_world(cylinder_scene(liar)).nodes[0].kind is NodeKind.MESH


@pytest.mark.parametrize("cull", [False, True])
def test_hits_match_a_dense_triangle_mesh_of_the_same_cylinder(cull: bool) -> None:
    """Rays from all around at the cylinder: the analytic test and the 512-slice mesh
    (its chords within 1.9e-5 of the circle) agree on hit or miss except where a ray
    passes within that of the outline, and on ``t`` to within the chords' reach."""
    mesh = geometry.cylinder(512)
    exact = build_world(cylinder_scene(mesh))
    tessellated = build_world(cylinder_scene(mesh), analytic_spheres=False)
    rng = np.random.default_rng(7)
    origins = rng.normal(size=(4000, 3))
    origins *= (4.0 / np.linalg.norm(origins, axis=1))[:, None]
    targets = transforms.transform_points(MODEL, rng.uniform(-1.2, 1.2, size=(4000, 3)))
    d = targets - origins
    a = _nearest(exact, origins, d, cull, True)
    b = _nearest(tessellated, origins, d, cull, True)
    hit_a, hit_b = a.node >= 0, b.node >= 0
    assert 500 < hit_a.sum() < 3500  # both hits and misses are tested
    assert np.count_nonzero(hit_a != hit_b) <= 4  # grazing the outline only
    both = hit_a & hit_b
    dt = np.abs(a.t[both] - b.t[both]) * np.linalg.norm(d[both], axis=1)  # in world units
    sag = 1.0 - math.cos(math.pi / 512)  # how far a chord's middle lies inside the circle: 1.9e-5
    assert np.median(dt) < sag and np.quantile(dt, 0.99) < 50 * sag


def test_the_surface_is_the_meshs_surface() -> None:
    """Normals and uv at the hits: the analytic ones against the mesh's interpolated ones
    (the same layout as :func:`glsandbox.geometry.cylinder`)."""
    scene = cylinder_scene(geometry.cylinder(512), np.eye(4))
    exact, tessellated = build_world(scene), build_world(scene, analytic_spheres=False)
    points, normals = surface_points(400, seed=3)
    points *= [0.97, 0.999, 0.97]  # inside the 512-gon too: both hit
    origins = points + 2.0 * normals
    d = points - origins
    surfaces = []
    for world in (exact, tessellated):
        hits = _nearest(world, origins, d, None, True)
        assert (hits.node == 0).all()
        _, n, _, _, _ = _surface(world, _Hits(hits.t, hits.node, hits.tri), origins, d, need_spawn=False)
        surfaces.append(n)
    np.testing.assert_allclose(surfaces[0], normals, atol=1e-12)
    np.testing.assert_allclose(surfaces[1], normals, atol=1e-4)


def test_a_textured_cylinder_looks_the_same_traced_exactly_or_as_triangles() -> None:
    from glsandbox.scene import Texture

    scene = cylinder_scene(geometry.cylinder(256), texture=Texture("checker"))
    exact = render(scene, (96, 72)).astype(int)
    mesh = render(scene, (96, 72), analytic_spheres=False).astype(int)
    differ = np.abs(exact - mesh).max(axis=-1) > 8
    assert differ.mean() < 0.01
    assert len(np.unique(exact.reshape(-1, 4), axis=0)) > 20  # the checker shows


def test_the_gpu_engine_traces_the_cylinder_as_the_numpy_engine(gl, monkeypatch) -> None:
    from glsandbox.raytrace import gpu as gpu_engine

    scene = cylinder_scene(geometry.cylinder(), reflectivity=0.0)
    ref = render(scene, (96, 72))
    covered = np.any(ref != ref[0, 0], axis=-1).mean()
    assert covered > 0.1
    tracer = gpu_engine.gpu_tracer(gl.host.ctx)
    images = []
    for unroll in (gpu_engine.UNROLL_NODES, 0):  # the unrolled program and the general one
        tracer.forget_scenes()
        with monkeypatch.context() as patch:
            patch.setattr(gpu_engine, "UNROLL_NODES", unroll)
            images.append(np.array(render(scene, (96, 72), "gpu", ctx=gl.host.ctx)))
            assert tracer._scenes[0].unrolled == (unroll > 0)
    tracer.forget_scenes()
    for image in images:
        diff = np.abs(image.astype(int) - ref.astype(int)).max(axis=-1)
        assert np.count_nonzero(diff > 2) <= 3 and diff.mean() < 0.5


def test_a_scene_file_cylinder_is_traced_as_the_cylinder(tmp_path) -> None:
    from glsandbox.scene_file import load_scene

    path = tmp_path / "scene.toml"
    path.write_text('[camera]\neye = [0, 2, 6]\n\n[[nodes]]\nname = "post"\nmesh = "cylinder"\n'
                    'scale = [0.5, 1.5, 0.5]\nshading = "phong"\n\n[[lights]]\nposition = [2, 3, 2]\n')
    scene = load_scene(path)
    world = build_world(scene)
    assert [node.kind for node in world.nodes] == [NodeKind.CYLINDER]
    np.testing.assert_allclose(world.nodes[0].box_max, [0.5, 1.5, 0.5])
    image = render(scene, (48, 36))
    assert np.any(image != image[0, 0], axis=-1).mean() > 0.05
