"""The gpu engine traces large mesh nodes through their BVHs (general program): a
triangle past llvmpipe's 65,535 loop iterations appears (tests/raytrace/test_render.py,
with the numpy engine), a ~20k-triangle rock agrees
with the numpy engine pixel for pixel but for float32 edge grazes, and a ray that runs
out of its step bound raises instead of drawing a wrong picture; a sampler object another
user left bound on the shared context changes nothing."""

from __future__ import annotations

import moderngl
import numpy as np
import pytest

from glsandbox import Camera, Light, Material, Node, Scene, meshgen
from glsandbox.raytrace import RayTraceError, render
from glsandbox.raytrace import gpu as gpu_engine
from glsandbox.raytrace.world import build_world


def rock_scene(subdivisions: int = 5) -> Scene:
    mesh = meshgen.rock(subdivisions, seed=4, roughness=0.3)
    material = Material(color=(0.8, 0.7, 0.6, 1.0))
    return Scene("rock", nodes=(Node("rock", mesh, np.eye(4), material),),
                 camera=Camera(eye=(0.0, 0.5, 3.0), target=(0.0, 0.0, 0.0)), lights=(Light((3.0, 3.0, 3.0)),),
                 clear_color=(0.0, 0.0, 0.0, 1.0))


def test_a_large_rock_hits_where_the_numpy_engine_hits(gl) -> None:
    scene = rock_scene()
    assert build_world(scene, 0).triangle_count == 20_480  # past gpu.BVH_TRIANGLES: the BVH program
    size = (160, 120)
    cpu = render(scene, size)
    gpu = render(scene, size, "gpu", ctx=gl.host.ctx)
    hit_cpu = cpu[..., :3].any(axis=-1)
    hit_gpu = gpu[..., :3].any(axis=-1)
    assert 0.2 < hit_cpu.mean() < 0.9
    differing = np.count_nonzero(hit_cpu != hit_gpu)
    assert differing < 0.01 * hit_cpu.size, differing
    both = hit_cpu & hit_gpu
    close = np.abs(cpu[..., :3].astype(int) - gpu[..., :3].astype(int)).max(axis=-1) <= 3
    assert close[both].mean() > 0.97


def test_a_ray_out_of_steps_raises(gl, monkeypatch) -> None:
    monkeypatch.setattr(gpu_engine, "BVH_STEP_CAP", 4)
    with pytest.raises(RayTraceError) as info:
        render(rock_scene(), (40, 30), "gpu", ctx=gl.host.ctx)
    message = str(info.value)
    assert "\n" not in message and "4 steps" in message and "renderer=ray_numpy" in message


def test_a_sampler_object_left_bound_on_the_context_changes_nothing(gl) -> None:
    """The rasterizer binds a sampler object per material filter. One left on the units the
    engine uses (here a mipmapped filter on units 0-3, what a frame that raised half-way
    left before the executor unbound it) overrides the records' NEAREST state: they are
    incomplete without mip levels and texelFetch reads zeros (wrong hits, rays cut off)."""
    from glsandbox.raytrace.bvh import build_bvh, mesh_world_triangles
    from glsandbox.raytrace.gpu_bvh import GpuBVH
    from glsandbox.raytrace.world import camera_rays

    ctx, scene, size = gl.host.ctx, rock_scene(3), (64, 48)  # 1,280 triangles: the BVH program
    bvh = GpuBVH(ctx, build_bvh(*mesh_world_triangles(scene.nodes[0].mesh)))
    eye, dirs = camera_rays(scene.camera, *size)

    def both() -> tuple[np.ndarray, np.ndarray]:
        gpu_engine.gpu_tracer(ctx).forget_scenes()  # uploaded again, then drawn
        return render(scene, size, "gpu", ctx=ctx).copy(), bvh.trace(eye, dirs).triangle

    sampler = ctx.sampler(filter=(moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR))
    try:
        clean_image, clean_hits = both()
        assert 0.2 < np.mean(clean_hits >= 0) < 0.9
        for unit in range(gpu_engine.MAX_TEXTURES):
            sampler.use(unit)
        image, hits = both()
        np.testing.assert_array_equal(image, clean_image)
        np.testing.assert_array_equal(hits, clean_hits)
    finally:
        ctx.clear_samplers(0, gpu_engine.MAX_TEXTURES)
        sampler.release()
        bvh.release()


def row_of_cubes_scene() -> Scene:
    """A floor quad (two triangles sharing two corners: the scan's PAIR) and three cubes
    in a row (consecutive looped nodes: one RUN), the middle one the light's lamp, the
    last one a mirror."""
    from glsandbox import geometry

    def at(x: float, y: float, scale: float) -> np.ndarray:
        m = np.diag([scale, scale, scale, 1.0])
        m[:3, 3] = (x, y, 0.0)
        return m

    floor = np.diag([4.0, 1.0, 4.0, 1.0])
    floor[1, 3] = -0.5
    lit = Material(color=(0.8, 0.6, 0.4, 1.0), shading="phong")
    nodes = (Node("floor", geometry.plane(), floor, lit),
             Node("left", geometry.cube(), at(-1.2, 0.0, 0.5), lit),
             Node("lamp", geometry.cube(), at(0.0, 1.2, 0.2), Material(color=(1.0, 1.0, 0.9, 1.0), shading="solid")),
             Node("right", geometry.cube(), at(1.2, 0.0, 0.5), Material(color=(0.5, 0.7, 0.9, 1.0), shading="phong",
                                                                       reflectivity=0.5)))
    return Scene("row", nodes=nodes, camera=Camera(eye=(0.5, 1.5, 4.0), target=(0.0, 0.0, 0.0)),
                 lights=(Light((0.0, 1.2, 0.0)),), clear_color=(0.1, 0.1, 0.1, 1.0))


def test_the_unrolled_scan_draws_what_the_node_loops_draw(gl, monkeypatch) -> None:
    """The small-scene program merges consecutive cubes into one triangle loop (a lamp
    among them left out of its light's shadow rays) and shares a quad's corners; the
    general program loops over every node and triangle. Same float32 tests: the same
    pixels, shadows and a mirror bounce included."""
    scene = row_of_cubes_scene()
    world = build_world(scene, 0)
    assert [node.lamp_of for node in world.nodes] == [0, 0, 1, 0]
    size = (160, 120)
    options = dict(shadows=True, max_depth=1)
    tracer = gpu_engine.gpu_tracer(gl.host.ctx)
    tracer.forget_scenes()
    unrolled = render(scene, size, "gpu", ctx=gl.host.ctx, **options)
    assert all(upload.unrolled for upload in tracer._scenes)
    tracer.forget_scenes()
    monkeypatch.setattr(gpu_engine, "UNROLL_NODES", 0)  # the general program
    looped = render(scene, size, "gpu", ctx=gl.host.ctx, **options)
    assert not any(upload.unrolled for upload in tracer._scenes)
    tracer.forget_scenes()
    shadowed = (unrolled[..., :3].astype(int).sum(axis=-1) < 120) & (unrolled[..., :3] != 25).any(axis=-1)
    assert shadowed.sum() > 50  # the cubes cast shadows on the floor
    assert np.array_equal(unrolled, looped)


def test_the_wide_bvh_draws_exactly_what_the_binary_one_draws(gl, monkeypatch) -> None:
    """Two mesh nodes (their trees side by side in one texture pair, refs offset), one shiny
    (bounces), shadows between them: the 4-wide trees draw the same pixels, byte for byte, and a
    ray out of its steps still raises. ``gpu.BVH_WIDE`` is the default a tracer takes."""
    rock = meshgen.rock(4, seed=4, roughness=0.3)
    shiny = Material(color=(0.6, 0.7, 0.8, 1.0), shading="phong", reflectivity=0.4)
    scene = Scene("rocks", nodes=(Node("a", rock, np.eye(4), shiny),
                                  Node("b", meshgen.terrain(20), np.diag([3.0, 0.5, 3.0, 1.0]) @ np.eye(4))),
                  camera=Camera(eye=(0.0, 1.5, 3.0), target=(0.0, 0.0, 0.0)), lights=(Light((3.0, 3.0, 1.0)),),
                  clear_color=(0.0, 0.0, 0.0, 1.0))
    size = (160, 120)
    binary, wide = gpu_engine.GpuTracer(gl.host.ctx, wide_bvh=False), gpu_engine.GpuTracer(gl.host.ctx, wide_bvh=True)
    try:
        for options in (dict(shadows=False, max_depth=0), dict(shadows=True, max_depth=2)):
            want = binary.render_viewport(scene, size, **options).copy()
            assert 0.3 < want[..., :3].any(axis=-1).mean() < 0.99
            np.testing.assert_array_equal(wide.render_viewport(scene, size, **options), want)
        assert wide._scenes[0].wide and not binary._scenes[0].wide
        monkeypatch.setattr(gpu_engine, "BVH_STEP_CAP", 4)
        with pytest.raises(RayTraceError, match="4 steps"):
            wide.render_viewport(rock_scene(), (40, 30))
    finally:
        binary.release()
        wide.release()
    monkeypatch.setattr(gpu_engine, "BVH_WIDE", True)
    assert gpu_engine.GpuTracer(gl.host.ctx).wide_bvh


def test_a_model_packed_in_chunks_draws_what_one_pack_draws_and_is_recognised_again(gl, monkeypatch) -> None:
    """A model's triangle records are packed and written to their texture a chunk at a time
    (never whole on the host). Chunks of 1,000 triangles (9,000 texels: rows of 1,024 split
    across chunks) draw exactly what one chunk draws, and a rebuilt Scene with the same data
    is recognised by its chunked digest (no second upload), one with other data is not."""
    scene = rock_scene()
    size = (160, 120)
    options = dict(shadows=True, max_depth=1)
    tracer = gpu_engine.GpuTracer(gl.host.ctx)
    try:
        whole = tracer.render_viewport(scene, size, **options).copy()
        tracer.forget_scenes()
        monkeypatch.setattr(gpu_engine, "PACK_CHUNK", 1000)
        chunked = tracer.render_viewport(scene, size, **options).copy()
        assert np.array_equal(whole, chunked)
        assert tracer.uploads == 2
        rebuilt = Scene("rock", nodes=(Node("rock", scene.nodes[0].mesh, np.eye(4), scene.nodes[0].material),),
                        camera=scene.camera, lights=scene.lights, clear_color=scene.clear_color)
        assert np.array_equal(tracer.render_viewport(rebuilt, size, **options), whole)
        assert (tracer.uploads, tracer.reuses) == (2, 1)
        tracer.render_viewport(rock_scene(4), size, **options)  # another rock: uploaded
        assert tracer.uploads == 3
    finally:
        tracer.release()


def test_a_model_upload_holds_no_second_copy_of_its_records(gl, monkeypatch) -> None:
    """Host memory (numpy's arrays, tracemalloc) of building a one-node model's World and
    uploading it to the BVH program, in bytes a triangle of a ~60k-triangle terrain: the
    World's arrays are the node's own (no concatenated copy; absent vertex colours a view,
    not 72 bytes of ones): 200 held, 248 at its peak (272 and 592 before). When the BVH
    build starts the upload holds the World's corners (moved to the anchor in place, not
    copied) and float32 normals (no uv without a texture): 110 (152 before, corners copied);
    outside the build (bvh.py's own working arrays) it never holds the triangle records
    whole (packed a chunk at a time): 418 at most."""
    import tracemalloc

    from glsandbox.raytrace import bvh as bvh_module

    mesh = meshgen.terrain(meshgen.terrain_cells_for(60_000))
    scene = Scene("terrain", nodes=(Node("terrain", mesh, np.eye(4), Material(color=(0.7, 0.7, 0.7, 1.0))),),
                  camera=Camera(eye=(0.0, 1.2, 2.2)), lights=(Light((1.0, 3.0, 1.5)),))
    mesh.triangle_indices()
    seen: dict[str, int] = {}
    build = bvh_module.build_bvh

    def measured_build(*args, **kwargs):
        held, peak = tracemalloc.get_traced_memory()
        seen["held at the build"], seen["peak before the build"] = held - seen["start"], peak - seen["start"]
        result = build(*args, **kwargs)
        tracemalloc.reset_peak()  # the build's own peak is bvh.py's
        return result

    monkeypatch.setattr(bvh_module, "build_bvh", measured_build)
    tracer = gpu_engine.GpuTracer(gl.host.ctx)
    tracemalloc.start()
    try:
        world = build_world(scene, 0)
        count = world.triangle_count
        held, world_peak = tracemalloc.get_traced_memory()
        del world
        seen["start"] = tracemalloc.get_traced_memory()[0]
        tracer.render_viewport(scene, (40, 30), shadows=False, max_depth=0)
        peak_after = tracemalloc.get_traced_memory()[1] - seen["start"]
    finally:
        tracemalloc.stop()
        tracer.release()
    assert held <= 205 * count  # corners, normals, uvs (float64) and the node of each triangle
    assert world_peak <= 300 * count, world_peak / count
    assert seen["held at the build"] <= 120 * count, seen["held at the build"] / count
    assert max(seen["peak before the build"], peak_after) <= 450 * count, (seen, peak_after / count)
