"""The GLSL BVH traversal (shaders/common/bvh.glsl, float32) against the numpy one
(float64): the same hits but for rays within float32 of an edge, triangle indices past
65,535, and rays cut off by the loop bound reported rather than silently wrong."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from glsandbox import meshgen
from glsandbox.gl.shaders import compile_program, shader_root
from glsandbox.plan import ProgramVariant
from glsandbox.raytrace.bvh import build_bvh, mesh_world_triangles
from glsandbox.raytrace.bvh_traverse import any_hit, closest_hit
from glsandbox.raytrace.bvh_wide import collapse
from glsandbox.raytrace.gpu_bvh import WIDE_RECORD_TEXELS, GpuBVH, pack_bvh, pack_wide, texture_from_chunks, wide_stack
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.world import camera_rays
from glsandbox.scene import Camera


@pytest.fixture
def ctx(gl):
    return gl.host.ctx


def near_edge(u: np.ndarray, v: np.ndarray, tol: float = 2e-4) -> np.ndarray:
    """Whether barycentrics ``(u, v)`` lie within ``tol`` of the triangle's border."""
    return np.minimum(np.minimum(u, v), 1.0 - u - v) < tol


def test_gpu_and_numpy_agree_on_a_real_model_but_at_edges(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(4, seed=2))  # 5,120 triangles
    bvh = build_bvh(a, b, c)
    eye, dirs = camera_rays(Camera(eye=(0.4, 1.1, 3.2)), 160, 120)
    want = closest_hit(bvh, eye, dirs)
    gpu = GpuBVH(ctx, bvh)
    try:
        got = gpu.trace(eye, dirs)
    finally:
        gpu.release()
    assert not got.overflow.any()
    assert 0.2 < want.hit.mean() < 0.9
    differ = got.triangle != want.triangle
    # Every difference is a ray within float32 of an edge (as either side saw it).
    excused = (want.hit & near_edge(want.u, want.v)) | (got.hit & near_edge(got.u, got.v))
    assert np.all(excused[differ]), np.flatnonzero(differ & ~excused)[:10]
    assert differ.mean() < 0.005
    same = ~differ & want.hit
    np.testing.assert_allclose(got.t[same], want.t[same], rtol=2e-5)
    np.testing.assert_allclose(got.u[same], want.u[same], atol=2e-4)
    np.testing.assert_allclose(got.v[same], want.v[same], atol=2e-4)


def test_shadow_queries_agree(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(3, seed=9))
    bvh = build_bvh(a, b, c)
    rng = np.random.default_rng(4)
    o = rng.uniform(-2, 2, (3000, 3))
    d = rng.normal(size=(3000, 3))
    gpu = GpuBVH(ctx, bvh)
    try:
        blocked, overflow = gpu.any_hit(o, d, 1.5)
        near = gpu.trace(o, d, 1.5)
    finally:
        gpu.release()
    assert not overflow.any()
    want = any_hit(bvh, o, d, 1.5)
    nearest = closest_hit(bvh, o, d, 1.5)
    differ = blocked != want
    grazing = near_edge(nearest.u, nearest.v) | near_edge(near.u, near.v) | (np.abs(nearest.t - 1.5) < 1e-4)
    assert np.all(grazing[differ]) and differ.mean() < 0.005
    np.testing.assert_array_equal(blocked, near.hit)


def test_a_triangle_past_index_65535_is_found(ctx) -> None:
    # 70,000 triangles; the only one in front of the camera is the last. A loop
    # over all of them would stop at llvmpipe's 65,535 iterations and miss it.
    count = 70_000
    rng = np.random.default_rng(1)
    base = rng.uniform(-50, 50, (count, 3)) + np.array([0.0, 0.0, 200.0])  # far behind the camera
    a, b, c = base, base + [0.1, 0.0, 0.0], base + [0.0, 0.1, 0.0]
    a[-1], b[-1], c[-1] = (-1.0, -1.0, -5.0), (1.0, -1.0, -5.0), (0.0, 1.0, -5.0)
    bvh = build_bvh(a, b, c)
    eye, dirs = camera_rays(Camera(eye=(0.0, 0.0, 0.0), target=(0.0, 0.0, -1.0)), 48, 36)
    gpu = GpuBVH(ctx, bvh)
    try:
        got = gpu.trace(eye, dirs)
    finally:
        gpu.release()
    want = closest_hit(bvh, eye, dirs)
    assert want.hit.sum() > 50 and set(want.triangle[want.hit]) == {count - 1}
    assert set(got.triangle[got.hit]) == {count - 1}
    differ = got.hit != want.hit
    assert np.all(near_edge(want.u, want.v)[differ & want.hit]) and differ.mean() < 0.02
    np.testing.assert_allclose(got.t[got.hit & want.hit], 5.0, rtol=1e-6)


def test_rays_cut_off_by_the_loop_bound_are_reported_not_silently_wrong(ctx) -> None:
    # 20,000 copies of one triangle: every copy ties at the same t, so a ray
    # must test them all (the lowest index wins): far more than 8,192 steps.
    count = 20_000
    tri = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    a, b, c = (np.repeat(tri[i][None], count, axis=0) for i in range(3))
    bvh = build_bvh(a, b, c)
    o = np.array([[0.0, 0.0, 2.0], [5.0, 5.0, 2.0]])  # through all copies, and past them
    d = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    gpu = GpuBVH(ctx, bvh)
    try:
        with pytest.raises(RayTraceError, match=r"cut off 1 of 2 rays at its bound of 8,192"):
            gpu.trace(o, d)
        hits = gpu.trace(o, d, strict=False)
        assert hits.overflow.tolist() == [True, False]
        assert hits.steps[0] == 8192 and hits.triangle[1] == -1
        # A shadow ray stops at its first hit: no bound is reached.
        blocked, overflow = gpu.any_hit(o, d, 10.0)
        assert blocked.tolist() == [True, False] and not overflow.any()
    finally:
        gpu.release()
    # With a bound that suffices, the answer is the numpy one: the first copy.
    roomy = GpuBVH(ctx, bvh, max_steps=60_000)
    try:
        hits = roomy.trace(o, d)
        assert hits.triangle.tolist() == [0, -1] and hits.t[0] == 2.0 and hits.steps[0] > 20_000
        assert closest_hit(bvh, o, d).triangle.tolist() == [0, -1]
    finally:
        roomy.release()


def test_a_tight_bound_flags_exactly_the_unfinished_rays(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(4))
    bvh = build_bvh(a, b, c)
    eye, dirs = camera_rays(Camera(eye=(0.0, 0.5, 3.0)), 40, 30)
    want = closest_hit(bvh, eye, dirs)
    tight = GpuBVH(ctx, bvh, max_steps=12)
    try:
        hits = tight.trace(eye, dirs, strict=False)
    finally:
        tight.release()
    assert hits.overflow.any() and not hits.overflow.all()
    assert np.all(hits.steps[hits.overflow] == 12) and np.all(hits.steps[~hits.overflow] <= 12)
    done = ~hits.overflow & ~near_edge(want.u, want.v)
    np.testing.assert_array_equal(hits.triangle[done], want.triangle[done])


def test_ties_and_culling_follow_the_numpy_rules(ctx) -> None:
    tri = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    far = tri + [0.0, 0.0, -1.0]
    flipped = tri[[0, 2, 1]] + [0.0, 0.0, 0.5]  # faces -z: a back face for rays going -z
    a, b, c = (np.array([far[i], tri[i], tri[i], flipped[i]]) for i in range(3))
    bvh = build_bvh(a, b, c)
    o = np.array([0.0, 0.0, 3.0])
    d = np.array([[0.0, 0.0, -1.0], [0.1, 0.1, -1.0]])
    gpu = GpuBVH(ctx, bvh)
    try:
        front = gpu.trace(o, d, cull_backfaces=True)
        both = gpu.trace(o, d)
    finally:
        gpu.release()
    assert front.triangle.tolist() == [1, 1] and front.t[0] == 3.0  # 1 and 2 tie: the lower index
    assert both.triangle.tolist() == [3, 3] and both.t[0] == 2.5
    assert closest_hit(bvh, o, d, cull_backfaces=True).triangle.tolist() == [1, 1]


def test_from_inside_a_closed_mesh_float32_rays_at_vertices_and_edges_hit(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.icosphere(3))
    bvh = build_bvh(a, b, c)
    targets = np.concatenate([a, b, c, (a + b) / 2, (b + c) / 2, (c + a) / 2])
    gpu = GpuBVH(ctx, bvh)
    try:
        for inside in ([0.0, 0.0, 0.0], [0.013, -0.021, 0.017]):
            hits = gpu.trace(np.array(inside), targets - np.array(inside))
            assert hits.hit.all()
    finally:
        gpu.release()


def test_an_empty_bvh_is_missed_and_float32_boxes_contain_the_float64_ones(ctx) -> None:
    empty = build_bvh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    gpu = GpuBVH(ctx, empty)
    try:
        assert not gpu.trace(np.zeros(3), np.array([[0.0, 0.0, 1.0]])).hit.any()
    finally:
        gpu.release()
    a, b, c = mesh_world_triangles(meshgen.rock(3), np.diag([3.3, 1.7, 0.9, 1.0]))
    bvh = build_bvh(a, b, c)
    nodes, tris = pack_bvh(bvh)
    # Record 0 holds the root; record r >= 1 the two children of the r-th inner node.
    records = nodes.reshape(-1, 2, 2, 4)
    entries = np.concatenate([records[:1, 0], records[1:].reshape(-1, 2, 4)])
    inner = np.flatnonzero(bvh.node_count == 0)
    order = np.concatenate([[0], np.stack([bvh.node_first[inner], bvh.node_first[inner] + 1], axis=1).reshape(-1)])
    assert entries.shape[0] == bvh.node_total == order.size
    assert np.all(entries[:, 0, :3].astype(np.float64) <= bvh.node_min[order])
    assert np.all(entries[:, 1, :3].astype(np.float64) >= bvh.node_max[order])
    np.testing.assert_array_equal(entries[:, 1, 3], bvh.node_count[order])
    leaf = bvh.node_count[order] > 0
    np.testing.assert_array_equal(entries[leaf, 0, 3], bvh.node_first[order][leaf])
    record_of = np.zeros(bvh.node_total, dtype=np.int64)
    record_of[inner] = np.arange(1, inner.size + 1)
    np.testing.assert_array_equal(entries[~leaf, 0, 3], record_of[order[~leaf]])
    np.testing.assert_array_equal(tris[0::3, 3], bvh.tri_index)


def test_bvh_glsl_also_compiles_into_a_glsl_330_shader(ctx, tmp_path: Path) -> None:
    # A #version 330 shader has no doubles and no `precise`: bvh.glsl (and the
    # watertight test it includes) must still compile there.
    (tmp_path / "common").mkdir()
    shutil.copy(shader_root() / "common" / "bvh.glsl", tmp_path / "common" / "bvh.glsl")
    shutil.copy(shader_root() / "common" / "bvh_wide.glsl", tmp_path / "common" / "bvh_wide.glsl")
    shutil.copy(shader_root() / "common" / "watertight.glsl", tmp_path / "common" / "watertight.glsl")
    shutil.copy(shader_root() / "common" / "fullscreen_vertex.glsl", tmp_path / "common" / "fullscreen_vertex.glsl")
    (tmp_path / "probe330.glsl").write_text(
        "#version 330 core\n#if defined(VERTEX_SHADER)\n#include \"common/fullscreen_vertex.glsl\"\n"
        "#elif defined(FRAGMENT_SHADER)\n#include \"common/bvh.glsl\"\nout vec4 frag_color;\n"
        "void main() { BvhHit h = bvh_closest(vec3(0.0), vec3(0.0, 0.0, -1.0), 1e30, false);\n"
        "bool overflow; bool any = bvh_any(vec3(0.0), vec3(1.0), 1.0, true, overflow);\n"
        "frag_color = vec4(h.t, float(h.index), any ? 1.0 : 0.0, overflow ? 1.0 : 0.0); }\n#endif\n")
    for wide in ("0", "1"):  # the binary traversal and the 4-wide one
        program = compile_program(ctx, ProgramVariant("probe330", (("BVH_STACK", "24"), ("BVH_WIDE", wide))),
                                  root=tmp_path)
        program.release()


def test_bad_bounds_are_refused(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.icosphere(1))
    bvh = build_bvh(a, b, c)
    for bad in (0, 70_000, 2.5):
        with pytest.raises(RayTraceError, match="max_steps"):
            GpuBVH(ctx, bvh, max_steps=bad)


def test_camera_rays_made_in_the_shader_match_the_numpy_camera_rays(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.terrain(30))
    bvh = build_bvh(a, b, c)
    camera = Camera(eye=(0.3, 1.0, 2.0))
    eye, dirs = camera_rays(camera, 64, 48)
    want = closest_hit(bvh, eye, dirs)
    gpu = GpuBVH(ctx, bvh)
    try:
        got = gpu.trace_camera(camera, 64, 48)
    finally:
        gpu.release()
    assert not got.overflow.any() and 0.2 < want.hit.mean() < 0.9
    differ = got.triangle != want.triangle
    excused = (want.hit & near_edge(want.u, want.v)) | (got.hit & near_edge(got.u, got.v))
    assert np.all(excused[differ]) and differ.mean() < 0.01
    same = ~differ & want.hit
    np.testing.assert_allclose(got.t[same], want.t[same], rtol=2e-5)


def test_records_written_in_uneven_chunks_fill_the_texture_in_order(ctx) -> None:
    """texture_from_chunks: chunks that end mid-row (a row is carried to the next chunk),
    an empty chunk and a last partial row put texel i at (i % width, i // width)."""
    records = np.arange(4 * 23, dtype=np.float32).reshape(23, 4)
    chunks = (records[:3], records[3:3], records[3:12], records[12:21], records[21:])
    texture = texture_from_chunks(ctx, chunks, 23, 5)
    try:
        assert texture.size == (5, 5)
        texels = np.frombuffer(texture.read(), dtype=np.float32).reshape(-1, 4)
    finally:
        texture.release()
    assert np.array_equal(texels[:23], records)
    with pytest.raises(ValueError):
        texture_from_chunks(ctx, (records,), 24, 5)


# --- the 4-wide tree (glsandbox/raytrace/bvh_wide.py, shaders/common/bvh_wide.glsl) ---------


def test_the_wide_tree_finds_exactly_the_binary_trees_hits(ctx) -> None:
    """Nearest hits, shadow queries, ties and culling: bit for bit what the binary traversal finds
    (the same triangle test on the same float32 corners; the boxes only decide what is tested)."""
    a, b, c = mesh_world_triangles(meshgen.rock(4, seed=2))
    bvh = build_bvh(a, b, c, leaf_size=2)
    eye, dirs = camera_rays(Camera(eye=(0.4, 1.1, 3.2)), 160, 120)
    rng = np.random.default_rng(4)
    o, d = rng.uniform(-2, 2, (3000, 3)), rng.normal(size=(3000, 3))
    binary, wide = GpuBVH(ctx, bvh), GpuBVH(ctx, bvh, wide=True)
    try:
        want, got = binary.trace(eye, dirs), wide.trace(eye, dirs)
        for field in ("t", "triangle", "u", "v"):
            np.testing.assert_array_equal(getattr(got, field), getattr(want, field))
        assert 0.2 < got.hit.mean() < 0.9
        # About half the loop iterations a ray (half the levels to walk down).
        assert got.steps.mean() < 0.75 * want.steps.mean()
        for cull in (False, True):
            np.testing.assert_array_equal(wide.trace(o, d, 1.5, cull_backfaces=cull).triangle,
                                          binary.trace(o, d, 1.5, cull_backfaces=cull).triangle)
            blocked, overflow = wide.any_hit(o, d, 1.5, cull_backfaces=cull)
            np.testing.assert_array_equal(blocked, binary.any_hit(o, d, 1.5, cull_backfaces=cull)[0])
            assert not overflow.any() and 0.03 < blocked.mean() < 0.9
        camera = Camera(eye=(0.3, 1.0, 2.0))
        np.testing.assert_array_equal(wide.trace_camera(camera, 64, 48).triangle,
                                      binary.trace_camera(camera, 64, 48).triangle)
    finally:
        binary.release()
        wide.release()


def test_the_wide_tree_keeps_the_tie_rule_and_reports_cut_off_rays(ctx) -> None:
    tri = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    count = 300  # copies of one triangle: all tie, the lowest index wins
    a, b, c = (np.repeat(tri[i][None], count, axis=0) for i in range(3))
    bvh = build_bvh(a, b, c)
    o = np.array([[0.0, 0.0, 2.0], [5.0, 5.0, 2.0]])
    d = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    wide = GpuBVH(ctx, bvh, wide=True)
    tight = GpuBVH(ctx, bvh, wide=True, max_steps=40)
    try:
        hits = wide.trace(o, d)
        assert hits.triangle.tolist() == [0, -1] and hits.t[0] == 2.0 and hits.steps[0] >= count
        cut = tight.trace(o, d, strict=False)
        assert cut.overflow.tolist() == [True, False] and cut.steps[0] == 40
        with pytest.raises(RayTraceError, match="cut off 1 of 2 rays at its bound of 40"):
            tight.trace(o, d)
    finally:
        wide.release()
        tight.release()
    empty = GpuBVH(ctx, build_bvh(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3))), wide=True)
    try:
        assert not empty.trace(np.zeros(3), np.array([[0.0, 0.0, 1.0]])).hit.any()
        assert not empty.any_hit(np.zeros(3), np.array([[0.0, 0.0, 1.0]]))[0].any()
    finally:
        empty.release()


def test_wide_records_hold_four_boxes_a_plane_a_texel(ctx) -> None:
    a, b, c = mesh_world_triangles(meshgen.rock(3), np.diag([3.3, 1.7, 0.9, 1.0]))
    bvh = build_bvh(a, b, c, leaf_size=2)
    tree = collapse(bvh)
    nodes, tris = pack_wide(tree)
    records = nodes.reshape(-1, WIDE_RECORD_TEXELS, 4)  # record, texel, child slot
    assert records.shape[0] == tree.record_count
    used = tree.child >= 0
    node = np.where(used, tree.child, 0)
    lo = np.moveaxis(records[:, 0:3], 1, 2).astype(np.float64)  # (record, slot, xyz)
    hi = np.moveaxis(records[:, 3:6], 1, 2).astype(np.float64)
    assert np.all((lo <= bvh.node_min[node]) | ~used[..., None])  # rounded outwards
    assert np.all((hi >= bvh.node_max[node]) | ~used[..., None])
    assert np.all((bvh.node_min[node] - lo < 1e-6) | ~used[..., None])
    ref, count, _ = tree.slots()
    np.testing.assert_array_equal(records[:, 7], np.where(used, count, -1))
    np.testing.assert_array_equal(records[:, 6][used], ref[used])
    np.testing.assert_array_equal(tris, pack_bvh(bvh)[1])
    assert wide_stack(tree.depth) == 3 * tree.depth + 1
