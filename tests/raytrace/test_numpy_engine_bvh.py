"""The numpy engine traced through the BVH: rays aimed exactly at a closed mesh's vertices
never slip between its triangles (the watertight test), and the BVH changes no picture
of a lesson scene but for rays grazing an edge."""

from __future__ import annotations

import numpy as np
import pytest

from support import far_triangle_scene

from glsandbox import Camera, Light, Material, Node, Scene, meshgen, transforms
from glsandbox.raytrace import RenderStats, render
from glsandbox.raytrace.bvh_world import WorldBVH
from glsandbox.raytrace.numpy_engine import _nearest, _occluded
from glsandbox.raytrace.world import build_world

MESHES = {
    "icosphere": lambda: meshgen.icosphere(3),
    "rock": lambda: meshgen.rock(3, seed=4, roughness=0.3),
}


def closed_mesh_world(name: str, model: np.ndarray):
    mesh = MESHES[name]()
    scene = Scene("vertices", nodes=(Node("mesh", mesh, model, Material(color=(0.8, 0.8, 0.8, 1.0))),),
                  camera=Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0)), lights=(Light((3.0, 3.0, 3.0)),))
    world = build_world(scene, 0)
    vertices = np.unique(np.concatenate([world.v0, world.v1, world.v2]), axis=0)
    assert world.nodes[0].kind == "mesh" and vertices.shape[0] > 100
    return scene, world, vertices


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("cull", [None, False, True])
def test_rays_at_every_vertex_never_escape(name: str, cull: bool | None) -> None:
    model = transforms.translate(0.3, -0.2, 0.1) @ transforms.rotate_y(0.7) @ transforms.scale(1.3, 0.9, 1.1)
    _, world, vertices = closed_mesh_world(name, model)
    bvh = WorldBVH.from_world(world)
    centre = vertices.mean(axis=0)
    # From outside: from a far point on the line through the centre, and from a skew
    # point, aimed exactly at the vertex (d = V - O).
    for eye in (centre + (vertices - centre) * 3.0, np.array([7.0, 5.5, -6.25])):
        d = vertices - eye
        hits = _nearest(world, eye, d, cull, True, RenderStats(), bvh)
        assert (hits.node >= 0).all(), f"{np.count_nonzero(hits.node < 0)} rays from outside escaped"
        assert (hits.t <= 1.0 + 1e-9).all()  # nothing beyond the vertex it was aimed at
        # The same rays as shadow rays past the vertex: always occluded.
        blocked = _occluded(world, eye if eye.ndim == 2 else np.broadcast_to(eye, d.shape), 2.0 * d, 0, cull,
                            True, RenderStats(), bvh)
        assert blocked.all()
    # From inside (the centre): every ray leaves through a triangle (back faces, so not when culling).
    if cull is not True:
        hits = _nearest(world, centre, vertices - centre, False, True, RenderStats(), bvh)
        assert (hits.node >= 0).all(), f"{np.count_nonzero(hits.node < 0)} rays from inside escaped"
        np.testing.assert_allclose(hits.t, 1.0, rtol=1e-9)


def test_render_through_the_bvh_counts_its_tests_and_matches_the_scan() -> None:
    _, world, _ = closed_mesh_world("rock", np.eye(4))
    scene, _, _ = closed_mesh_world("rock", np.eye(4))
    with_bvh, scan = RenderStats(), RenderStats()
    a = render(scene, (48, 36), stats=with_bvh)
    b = render(scene, (48, 36), bvh=False, stats=scan)
    differ = np.abs(a.astype(int) - b.astype(int)).max(axis=-1) > 0
    assert differ.mean() < 0.01  # only where a ray grazes an edge
    assert with_bvh.primary == scan.primary and with_bvh.shadow == scan.shadow
    assert 0 < with_bvh.tests < scan.tests / 10 and with_bvh.box_tests > scan.box_tests > 0


def test_the_model_lesson_shows_the_bvh_figures() -> None:
    from glsandbox.lessons.model import bvh_figures, generated

    line = bvh_figures(generated("rock"))
    assert line.startswith("BVH: ") and " nodes, " in line and line.endswith(" leaves") and "not built" not in line


def test_the_gpu_engine_refuses_where_its_bvh_budget_is_too_small(gl, monkeypatch) -> None:
    """This test used to expect the gpu engine to refuse the 70,000-triangle node outright;
    the engine now traces it through a BVH (tests/raytrace/test_render.py checks it
    appears). What is left of the refusal: when the loop budget leaves a ray too few
    traversal steps, one line naming the cause and the numpy engine."""
    from glsandbox.raytrace import RayTraceError
    from glsandbox.raytrace import gpu as gpu_engine

    monkeypatch.setattr(gpu_engine, "BVH_MIN_STEPS", 10**6)
    with pytest.raises(RayTraceError) as info:
        render(far_triangle_scene(), (32, 24), "gpu", ctx=gl.host.ctx)
    message = str(info.value)
    assert "\n" not in message and "65,535" in message and "1 mesh nodes" in message
    assert "renderer=ray_numpy" in message


def test_the_numpy_engine_keeps_a_scenes_world_while_the_scene_lives(monkeypatch) -> None:
    """A Scene is immutable, so the same Scene object rendered again reuses its World and BVHs
    (built once); a new Scene object, even with equal content, builds its own."""
    from glsandbox.raytrace import numpy_engine

    built = []
    real = numpy_engine.build_world
    monkeypatch.setattr(numpy_engine, "build_world", lambda *a, **k: built.append(1) or real(*a, **k))
    scene = Scene("rock", nodes=(Node("rock", meshgen.rock(2), material=Material(shading="phong")),),
                  camera=Camera(eye=(0.0, 0.5, 3.0)), lights=(Light((1.0, 3.0, 2.0)),))
    first = render(scene, (32, 24))
    again = render(scene, (32, 24))
    assert len(built) == 1 and np.array_equal(first, again)
    render(scene, (32, 24), analytic_spheres=False)  # another World of the same scene
    copy = Scene("rock", nodes=scene.nodes, camera=scene.camera, lights=scene.lights)
    assert np.array_equal(render(copy, (32, 24)), first)
    assert len(built) == 3
