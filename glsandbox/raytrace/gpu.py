"""The GLSL ray tracing engine: ``render(scene, size, engine="gpu", ctx=...)``.

``shaders/raytrace.glsl`` is a fragment shader drawn over one full-viewport
quad: one fragment is one pixel and one primary ray, with its shadow rays
and reflection bounces. It runs the algorithm of
:mod:`glsandbox.raytrace.render`, the one the float64 numpy engine
(:mod:`glsandbox.raytrace.numpy_engine`) runs, in float32. A fragment shader
rather than a compute shader: on llvmpipe the same ray cast measured about
10 Mrays/s against 1.9.

The scene on the context
------------------------
:func:`~glsandbox.raytrace.world.build_world` gives the
:class:`~glsandbox.raytrace.world.World` (world-space triangles; nodes with
their boxes and materials); :func:`pack_triangles` and :func:`pack_nodes`
flatten it into ``vec4`` records, :data:`TRI_RECORDS` per triangle and
:data:`NODE_RECORDS` per node, mesh nodes first (the layout is in the
shader). A small scene (see the program variants below) has its records in
one uniform block, the shader's ``SceneData``; a larger one in two RGBA32F
textures :data:`TEX_WIDTH` wide, read with ``texelFetch``. The materials'
images become RGBA8 textures (at most :data:`MAX_TEXTURES` a viewport),
sampled by hand, bilinear in the base level with the wrap mode done in the
shader, exactly as the numpy engine samples them; the nodes of any more
textures (a model file with many materials) are traced with their colour
alone, and a ``warning:`` line says so. Uploads are kept (the
last :attr:`GpuTracer.KEEP_SCENES`): a render of the same node objects,
lights and viewport, or of new objects that pack to the same records, only
moves the camera.

Program variants
----------------
One program per set of defines, compiled on first use and kept (the last
:attr:`GpuTracer.KEEP_PROGRAMS`). llvmpipe runs 8 pixels at once under
execution masks: a branch no pixel takes still costs, only a loop can end
early, and a record read at an index that varies per pixel costs 8 loads.
So what a scene cannot reach is compiled out rather than branched around:
``NUM_LIGHTS`` and ``NUM_TEXTURES`` size the light loop and the samplers;
``SHADOWS`` (shadow rays), ``REFLECT`` (the bounce loop: some node reflects
and ``max_depth > 0``), ``HAS_MESHES``, ``HAS_SHAPES`` (analytic nodes), one
``HAS_<KIND>`` per analytic :class:`~glsandbox.raytrace.world.NodeKind` and
``VERTEX_COLORS``, ``TWO_SIDED`` (a node lit on both sides), ``SEE_THROUGH``
(a cut-out or blended node) and ``SIMPLE_OFFSET`` (the teaching variant of
the secondary rays' offset) switch code on.

A small scene, at most :data:`UNROLL_NODES` nodes of which at most
:data:`UNROLL_LOOPS` have more than :data:`UNROLL_TRIS` triangles, its
records within the uniform block (:data:`BLOCK_RECORDS`, or less where the
context's ``GL_MAX_UNIFORM_BLOCK_SIZE`` is smaller), also gets its node list
unrolled into the program: ``SCENE_NODES`` (:meth:`_Uploaded.scene_nodes`,
with ``NODE_COUNT`` and ``TRI_COUNT``) lists every node in scene order as
``MESH`` (a loop over its triangles that runs as many times as the node's
AABB test allows: none when the ray misses the box), ``TRI`` (each triangle
of a node of at most :data:`UNROLL_TRIS`, tested without a loop) or
``SHAPE`` (an analytic node, its ``KIND_<NAME>`` a literal), with its
record slot, triangle range, one-sidedness and lamp bits as literals, so
its records are read at constant indices. Any larger scene gets the
general program: a loop over the node records and, inside it, over each
node's triangles; its node counts come as literals (``MESH_NODES``,
``SHAPE_NODES``), so a model's one mesh node runs as straight code (a loop
bounded by a uniform measured about 15% of a 1,000-triangle model's primary
frame). Unrolling is paid in compile time (Mesa's shader cache
is off): it grows exponentially with the number of triangle
loops, which the bounds keep near a second; a lesson's first render, which
compiles its variant, takes 0.4 to 0.9 s. In both programs shadow rays stop
at their first hit, and the shading reuses the triangle test's barycentrics.

llvmpipe's loop limit
---------------------
llvmpipe ends a shader invocation's loops after 65,535 iterations, all
loops counted together (Mesa gallivm's ``LP_MAX_TGSI_LOOP_ITERATIONS``),
silently. A render whose scan could pass it (:func:`check_loop_budget`:
every ray of a pixel testing every triangle and node record) gets the BVH
program below; an unrolled scene that could (none known) is refused
(:class:`RayTraceError`, naming the largest node and suggesting
``renderer=ray_numpy``), rather than drawing a wrong picture. Every
triangle a ray tests in a loop is an iteration, for the primary ray, each shadow ray and each
bounce (in the general program every node record too), and a pixel that
runs past the limit keeps whatever it had found: one node of about 65,000
triangles that the primary ray's box test lets in is enough, and fewer
when shadow rays and bounces enter it too. The lesson scenes stay far
below it: the largest, ``ray_acceleration`` (2,018 triangles, the general
program, one light), runs at most about 4,100 iterations a pixel.

The BVH program
---------------
A scene too large for that scan, or with a mesh node of more than
:data:`BVH_TRIANGLES` triangles, gets the general program with ``BVH``
defined (never the unrolled one): each mesh node's triangles are traced through
its BVH (:func:`~glsandbox.raytrace.bvh.bvh_for_triangles` on the World's
triangles, cached; ``shaders/common/bvh.glsl``: the watertight test, nearest
hit for primary and reflected rays, any hit for shadow rays), all nodes'
BVHs packed into one node/triangle texture pair with their indices offset
(``u_bvh_roots`` holds each mesh node's root). Each traversal is one loop
bounded by ``BVH_MAX_STEPS`` (:func:`bvh_step_cap`: what the loop limit
leaves after the other loops, shared by every ray of a pixel and every mesh
node). A ray that reaches the bound writes alpha 0, and the render raises
:class:`RayTraceError` instead of returning the picture. A scene with such a
mesh node builds its BVHs when it is uploaded and then keeps of its World only
the nodes, lights and textures (the textures hold what the shader reads of
the triangles): a 1M-triangle model's frame keeps about 170 MiB over the model
(resident, measured), not 820. The upload builds the BVHs first, then packs the
triangle records a chunk at a time straight into their texture (never whole on
the host), and hands the freed heap back: its peak is what the build meets of
the World (the corners and float32 normals, about 105 MiB for 1M triangles)
plus the BVH build's own working arrays. Scenes whose mesh
nodes all have at most :data:`BVH_TRIANGLES` triangles (the cubes, quads and
floors of most lessons) keep the scan, which tests its triangles with the
same watertight test (``shaders/common/watertight.glsl``; the triangle
records hold the three corners, so a corner shared by two triangles is the
same three floats in both).

Precision far from the origin
-----------------------------
Every position is uploaded relative to :func:`world_anchor`, the scene's
centre, the difference taken in float64 before the float32 rounding: the
picture, and the BVH's steps per ray, do not depend on where the scene
sits (``tests/raytrace/test_engine_far_from_origin.py``). Shadow and
reflected rays leave a surface by a bound on the hit point's rounding
error (``shaders/raytrace.glsl``'s ``offset_point``, the bounds in
:mod:`glsandbox.raytrace.constants`), and the triangle test accepts ``t``
only above its own error bound, so no surface shadows itself and contact
shadows stay.

Float32 differs from float64 in the last bits of ``t`` and of the shading;
the image agrees with the numpy engine's to within a couple of 8-bit levels
except on a few pixels where a ray grazes an edge or a shadow boundary
(``tests/raytrace/test_render.py`` states the tolerance).
"""

from __future__ import annotations

import ctypes
import hashlib
import sys
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING

import moderngl
import numpy as np
from numpy.typing import NDArray

from glsandbox.gl.shaders import compile_program
from glsandbox.plan import ProgramVariant
from glsandbox.raytrace.constants import NODE_BOX_PAD, OFFSETS, SIMPLE_OFFSET, glsl_defines
from glsandbox.raytrace.gpu_records import NODE, TRI, layout_defines
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.watertight import nondegenerate
from glsandbox.raytrace.shapes import glsl_dispatch
from glsandbox.raytrace.world import MODES, NodeKind, World, build_world, camera_basis, kind_defines
from glsandbox.scene import Scene

if TYPE_CHECKING:
    from glsandbox.raytrace.bvh import BVH

__all__ = ["LOOP_LIMIT", "GpuTracer", "MAX_TEXTURES", "check_loop_budget", "gpu_tracer"]

#: Width of the record textures (must match TEX_WIDTH in the shader).
TEX_WIDTH = 1024
#: ``vec4`` records per triangle and per node (the layouts: :mod:`glsandbox.raytrace.gpu_records`).
TRI_RECORDS = TRI.records
NODE_RECORDS = NODE.records
#: Samplers the shader declares at most.
MAX_TEXTURES = 4
#: llvmpipe's loop iterations per shader invocation, all loops together (see the module docstring).
LOOP_LIMIT = 65_535
#: The alpha byte of a pixel whose ray met a node kind the shader's dispatch has no case for
#: (``g_bad_kind``: alpha 0.25, stored as round(0.25·255)).
BAD_KIND_ALPHA = 64


def check_loop_budget(world: World, lights: int, shadows: bool, reflect: bool, max_depth: int) -> int:
    """The most loop iterations one pixel could run: every ray it casts (the primary ray,
    a shadow ray per light, and as much again per bounce) testing every triangle and every
    node record. Raises :class:`RayTraceError` when that could pass :data:`LOOP_LIMIT`,
    where llvmpipe would silently stop testing (a wrong picture): a conservative bound,
    never a guess."""
    rays = (1 + (lights if shadows else 0)) * (1 + (max_depth if reflect else 0))
    meshes = [node for node in world.nodes if node.kind.triangles]
    worst = rays * (sum(node.count for node in meshes) + len(world.nodes))
    if worst > LOOP_LIMIT:
        largest = max(meshes, key=lambda node: node.count)
        raise RayTraceError(
            f"the gpu engine could run {worst:,} loop iterations a pixel, past llvmpipe's {LOOP_LIMIT:,} "
            f"(node {largest.name!r} has {largest.count:,} triangles, {rays} rays a pixel): "
            "use renderer=ray_numpy (engine='numpy'), which traces meshes through a BVH")
    return worst


#: The most steps (node visits plus triangle tests) one ray's traversal of one
#: mesh node's BVH may take; None: as many as the loop budget allows
#: (:func:`bvh_step_cap`). Tests set it small to see the overflow raise.
BVH_STEP_CAP: int | None = None
#: The program traces mesh nodes through BVHs when some mesh node has more
#: triangles than this (or the scan could pass the loop limit); smaller scenes scan.
#: Measured crossover (terrain meshes, 800x600, llvmpipe, warm renders, primary /
#: shadow+bounce): 32 triangles scan 0.033/0.045 s vs BVH 0.054/0.087 s; 72: 0.060/0.114
#: vs 0.058/0.093; 128: 0.098/0.148 vs 0.063/0.098; 1,058: 1.43/2.22 vs 0.082/0.179.
BVH_TRIANGLES = 64
#: Triangles per leaf of the gpu engine's BVHs (bvh.py's default is 4): each walk
#: iteration tests one triangle while the walk moves one node, so smaller leaves
#: keep the two in step. Measured (CPU time, 800x600, primary / shadow+bounce,
#: against 4): 2 took 0.96/0.94x on the 1k terrain, 0.99/1.00x on the bunny,
#: 0.97/0.97x on 100k; 1 took 1.04-1.09x of 2's, 3 0.98-1.03x, 8 1.07-1.15x of 4's.
BVH_LEAF_SIZE = 2
#: Whether a :class:`GpuTracer` traces its meshes through the 4-wide tree
#: (:mod:`glsandbox.raytrace.bvh_wide`, ``BVH_WIDE`` in ``shaders/common/bvh.glsl``)
#: rather than the binary one; the same pictures either way. ``GpuTracer(ctx, wide_bvh=...)``
#: chooses per tracer (what benchmarks/models.py compares side by side).
BVH_WIDE = False
#: A BVH render is refused when the budget leaves a ray fewer steps than this.
BVH_MIN_STEPS = 256


def bvh_step_cap(world: World, lights: int, shadows: bool, reflect: bool, max_depth: int) -> int:
    """The per-ray, per-mesh-node traversal bound (``BVH_MAX_STEPS``) of the BVH program:
    every ray of a pixel may traverse every mesh node's BVH to the bound, and the
    sum with the other loops (node records, analytic nodes, lights, bounces) stays within
    :data:`LOOP_LIMIT`. A ray that reaches it is flagged (alpha 0) and the render
    raises. Raises :class:`RayTraceError` when the budget leaves too few steps."""
    bounces = 1 + (max_depth if reflect else 0)
    rays = (1 + (lights if shadows else 0)) * bounces
    meshes = sum(1 for node in world.nodes if node.kind.triangles)
    other = rays * (len(world.nodes) + 1) + bounces * (lights + 1) + 64
    cap = (LOOP_LIMIT - other) // max(1, rays * meshes)
    if BVH_STEP_CAP is not None:
        cap = min(cap, BVH_STEP_CAP)
    if cap < min(BVH_MIN_STEPS, BVH_STEP_CAP or BVH_MIN_STEPS):
        raise RayTraceError(
            f"the gpu engine's BVH traversal would get only {max(cap, 0):,} steps a ray within llvmpipe's "
            f"{LOOP_LIMIT:,} loop iterations ({meshes} mesh nodes, {rays} rays a pixel): "
            "use renderer=ray_numpy (engine='numpy')")
    return int(cap)


#: Scenes with at most this many nodes, of which at most UNROLL_LOOPS have
#: more than UNROLL_TRIS triangles, get a program with the node list
#: unrolled (``SCENE_NODES`` in ``shaders/raytrace.glsl``). The bounds keep
#: Mesa's compile time (no shader cache) within about 2 s: it grows
#: exponentially with the number of triangle loops outside the bounce loop
#: (8 cubes 0.7 s, 12 cubes 3 s, 16 cubes 82 s), linearly otherwise; 16
#: nodes of which 8 loop measured 0.9 to 2.2 s.
UNROLL_NODES = 16
UNROLL_LOOPS = 8
#: Mesh nodes of at most this many triangles are tested without a loop
#: (a loop iteration measured about twice the cost of the same test unrolled).
UNROLL_TRIS = 2
#: vec4 records the uniform block may hold at most: 64 KiB, what llvmpipe
#: allows (about 450 triangles); less where the context's
#: GL_MAX_UNIFORM_BLOCK_SIZE is smaller (OpenGL guarantees 16 KiB).
BLOCK_RECORDS = 4096

#: The attribute of a moderngl context that holds its tracer. The tracer lives
#: and dies with its context object: a module-level table would keep every
#: tracer (and, through its programs, every context) alive after its renderer
#: closed, about 0.1 MB per renderer opened and closed; it cannot be keyed
#: weakly, since the tracer's GL objects refer to their context.
_TRACER_ATTRIBUTE = "_glsandbox_gpu_tracer"


def gpu_tracer(ctx: moderngl.Context) -> GpuTracer:
    """The tracer of ``ctx`` (made once per context: programs and targets are kept),
    kept on the context object itself and freed with it."""
    tracer = getattr(ctx, _TRACER_ATTRIBUTE, None)
    if tracer is None:
        tracer = GpuTracer(ctx)
        setattr(ctx, _TRACER_ATTRIBUTE, tracer)
    return tracer


def _at_least_one(rows: NDArray[np.float32]) -> NDArray[np.float32]:
    """``rows``, or one record of zeros for an empty array (a GLSL array has at least one element)."""
    return rows if rows.shape[0] else np.zeros((1, 4), dtype=np.float32)


#: The warnings already printed by this process (once per run, not per frame).
_WARNED: set[str] = set()


def clear_warnings() -> None:
    """Print each warning again from now on (a renderer kept for many graded submissions: once per submission)."""
    _WARNED.clear()


def _keep_first_textures(scene: Scene, world: World) -> None:
    """A viewport with more textures than the shader's samplers (a model file with many
    materials): the nodes of the textures beyond :data:`MAX_TEXTURES` are traced with their
    colour alone, and one ``warning:`` line says so (the numpy engine samples them all)."""
    untextured = [node.name for node in world.nodes if node.texture >= MAX_TEXTURES]
    for node in world.nodes:
        if node.texture >= MAX_TEXTURES:
            node.texture = -1
    del world.textures[MAX_TEXTURES:]
    shown = ", ".join(untextured[:3]) + (f" and {len(untextured) - 3} more" if len(untextured) > 3 else "")
    line = (f"warning: scene {scene.name!r}: the GLSL ray tracer samples at most {MAX_TEXTURES} textures per "
            f"viewport; {shown} traced without their textures (renderer=ray_numpy samples them all)")
    if line not in _WARNED:
        _WARNED.add(line)
        print(line, file=sys.stderr, flush=True)


#: Corners :func:`world_anchor` takes its median over, at most (every k-th triangle's first).
ANCHOR_SAMPLES = 4096


def world_anchor(world: World) -> NDArray[np.float64]:
    """The point the gpu engine's coordinates are relative to: the per-axis median of
    the triangles' first corners (every k-th, at most :data:`ANCHOR_SAMPLES`) and the
    analytic nodes' centres (the origin for an empty world).

    float32 has 24 bits: at 1e5 its spacing is 0.0078, at 1e6 0.0625, so a scene
    traced in world coordinates there loses its shape (ids off on 2.9% and 15%
    of the pixels, and BVH boxes padded in proportion to the coordinates). Every
    position is therefore taken relative to this anchor in float64 on the CPU
    (vertices, boxes, lights, the eye, analytic nodes' inverse matrices) and only the
    difference is rounded to float32: the picture at 1e6 is the one at the
    origin. The anchor is the scene's own, not the eye, so a camera moving
    around the scene keeps the upload (the eye is one uniform).

    A median, not the centre of the boxes: one stray vertex far away (a triangle
    at 1e6 beside a quad at the origin) would move a centre half-way there, and
    the quad, then 5e5 from the anchor, would be rounded to 0.03 units. The median
    stays with the bulk of the scene; the stray triangle is rounded relative to
    its own distance, far below a pixel wherever it is seen from the bulk."""
    centres = [0.5 * (node.box_min + node.box_max) for node in world.nodes if not node.kind.triangles]
    step = max(1, -(-world.triangle_count // ANCHOR_SAMPLES))
    points = np.concatenate([world.v0[::step], np.reshape(centres, (-1, 3))])
    if not len(points):
        return np.zeros(3)
    return np.median(points, axis=0)


def pack_triangles(world: World, anchor: NDArray[np.float64] | None = None,
                   rows: slice = slice(None), ok: NDArray[np.bool_] | None = None) -> NDArray[np.float32]:
    """``TRI_RECORDS`` vec4 per triangle (layout in ``shaders/raytrace.glsl``), positions
    relative to ``anchor`` (see :func:`world_anchor`); ``rows``: only those triangles
    (:func:`triangle_chunks` packs a large World a slice at a time); ``ok``: every
    triangle's :func:`~glsandbox.raytrace.watertight.nondegenerate`, where it was taken
    before the corners were moved (else it is taken here)."""
    anchor = np.zeros(3) if anchor is None else anchor
    v0w, v1w, v2w = world.v0[rows], world.v1[rows], world.v2[rows]
    m = v0w.shape[0]
    # Filled in float32 directly (each value rounded once, as a float64 array cast
    # afterwards would): a 1M-triangle model's records are 144 MB, not 288 + 144.
    rec = np.zeros((m, TRI_RECORDS, 4), dtype=np.float32)
    # The corners themselves, not v0 and two edges: the watertight test needs a
    # corner shared by two triangles to be the same three floats in both.
    # The BVH's rule: a triangle without area is never hit.
    ok = nondegenerate(v0w, v1w, v2w) if ok is None else ok[rows]
    v0 = v0w - anchor
    rec[:, TRI["v0"], :3] = v0
    rec[:, TRI["v1"], :3] = np.where(ok[:, None], v1w - anchor, v0)  # degenerate: one point, det = 0
    rec[:, TRI["v2"], :3] = np.where(ok[:, None], v2w - anchor, v0)
    normals, colors = world.normals[rows], world.colors[rows]
    for k in range(3):
        rec[:, TRI["normal"] + k, :3] = normals[:, k]
        rec[:, TRI["color"] + k, :3] = colors[:, k]
    flat_uv = world.uvs[rows].reshape(m, 6)  # uv0.x, uv0.y, uv1.x, uv1.y, uv2.x, uv2.y
    rec[:, TRI["normal"]:TRI["color"] + 3, 3] = flat_uv
    return rec.reshape(-1, 4)


#: Triangles packed at a time by :func:`triangle_chunks` (9 MB of records; 65,536 triangles
#: are 576 full rows of a :data:`TEX_WIDTH` texture).
PACK_CHUNK = 1 << 16


def triangle_chunks(world: World, anchor: NDArray[np.float64] | None = None,
                    ok: NDArray[np.bool_] | None = None) -> Iterator[NDArray[np.float32]]:
    """:func:`pack_triangles` of ``world`` in slices of :data:`PACK_CHUNK` triangles, in order:
    a large model is uploaded and digested without its whole records in memory at once
    (a 1M-triangle model's are 144 MB, and the texture holds a copy of them)."""
    m = world.triangle_count
    for start in range(0, m, PACK_CHUNK):
        yield pack_triangles(world, anchor, slice(start, min(m, start + PACK_CHUNK)), ok)


def node_order(world: World) -> list[int]:
    """The nodes as the shader stores them: mesh nodes first, then analytic nodes (scene order within)."""
    meshes = [k for k, node in enumerate(world.nodes) if node.kind.triangles]
    return meshes + [k for k, node in enumerate(world.nodes) if not node.kind.triangles]


def pack_nodes(world: World, anchor: NDArray[np.float64] | None = None) -> NDArray[np.float32]:
    """``NODE_RECORDS`` vec4 per node in :func:`node_order` (layout in ``shaders/raytrace.glsl``),
    positions relative to ``anchor`` (see :func:`world_anchor`)."""
    anchor = np.zeros(3) if anchor is None else anchor
    rec = np.zeros((len(world.nodes), NODE_RECORDS, 4), dtype=np.float64)
    for slot, k in enumerate(node_order(world)):
        node = world.nodes[k]
        lo, hi = node.box_min - anchor, node.box_max - anchor
        # Pad the box by a relative hair: float32 slab arithmetic must not
        # reject a ray that the triangle test would accept at the box's face.
        pad = NODE_BOX_PAD * (1.0 + float(np.abs(np.concatenate([lo, hi])).max()))
        rec[slot, NODE["box_min"]] = (*(lo - pad), float(node.kind.code))
        rec[slot, NODE["box_max"]] = (*(hi + pad), 1.0 if node.cull else 0.0)
        rec[slot, NODE["range"]] = (node.start, node.count, k, 0.0)  # k: the scene order, for ties
        rec[slot, NODE["color"]] = (*node.color, node.mode)
        rec[slot, NODE["phong"]] = (node.ka, node.kd, node.ks, node.shininess)
        rec[slot, NODE["extra"]] = (node.reflectivity, node.texture, node.lamp_of, 0.0)
        # world -> the node's own space for anchor-relative points: M⁻¹(p + anchor), in float64.
        inverse = slice(NODE["inverse"], NODE["inverse"] + 3)
        rec[slot, inverse, :3] = node.inverse[:3, :3]
        rec[slot, inverse, 3] = node.inverse[:3, :3] @ anchor + node.inverse[:3, 3]
        rec[slot, NODE["normal"]:NODE["normal"] + 3, :3] = node.normal_matrix
        rec[slot, NODE["look"]] = (node.alpha, node.alpha_mode, node.alpha_cutoff,
                                   int(node.vertex_colors) | 2 * int(node.two_sided))
    return rec.reshape(-1, 4).astype(np.float32)


def _scene_key(scene: Scene, viewport: int, analytic_spheres: bool) -> tuple[object, ...]:
    """What the World of ``scene`` depends on (not the camera): compared by identity for the nodes."""
    vp = scene.viewports[viewport]
    return (scene.nodes, scene.lights, vp.clear_color, scene.clear_color, getattr(scene, "mirror", None),
            viewport, analytic_spheres)


def _same_key(a: tuple[object, ...] | None, b: tuple[object, ...]) -> bool:
    if a is None:
        return False
    nodes_a, nodes_b = a[0], b[0]
    assert isinstance(nodes_a, tuple) and isinstance(nodes_b, tuple)
    if len(nodes_a) != len(nodes_b) or any(x is not y for x, y in zip(nodes_a, nodes_b)):
        return False
    try:
        return bool(a[1:] == b[1:])
    except (ValueError, TypeError):  # array-valued fields: treat as changed
        return False


class _RecordsDigest:
    """A blake2b digest of the packed records (equal records, equal digests), fed the
    triangle records chunk by chunk (:func:`triangle_chunks`) and then the node records."""

    def __init__(self, tri_rows: int) -> None:
        self._hash = hashlib.blake2b(digest_size=20)
        self._hash.update(np.int64(tri_rows).tobytes())

    def passing(self, chunks: Iterable[NDArray[np.float32]]) -> Iterator[NDArray[np.float32]]:
        """``chunks`` unchanged, each hashed as it goes by."""
        for chunk in chunks:
            self._hash.update(np.ascontiguousarray(chunk).data)
            yield chunk

    def finish(self, nodes: NDArray[np.float32]) -> bytes:
        self._hash.update(np.int64(nodes.shape[0]).tobytes())
        self._hash.update(np.ascontiguousarray(nodes).data)
        return self._hash.digest()


def _records_digest(world: World, anchor: NDArray[np.float64], nodes: NDArray[np.float32]) -> bytes:
    """The digest of ``world``'s records (:class:`_RecordsDigest`), packed a chunk at a time."""
    digest = _RecordsDigest(world.triangle_count * TRI_RECORDS)
    for _ in digest.passing(triangle_chunks(world, anchor)):
        pass
    return digest.finish(nodes)


def _drop_triangle_arrays(world: World, corners: bool) -> None:
    """Empty ``world``'s per-triangle shading arrays (normals, uvs, colours) and, with
    ``corners``, its corners too (an upload's own World, once its textures hold them)."""
    world.normals, world.uvs, world.colors = np.zeros((0, 3, 3)), np.zeros((0, 3, 2)), np.zeros((0, 3, 3))
    if corners:
        world.v0 = world.v1 = world.v2 = np.zeros((0, 3))
        world.tri_node = np.zeros(0, dtype=np.intp)


def _emptying(parts: list[NDArray[np.float32]]) -> Iterator[NDArray[np.float32]]:
    """The arrays of ``parts`` in order, each let go by the list as it is handed on."""
    while parts:
        yield parts.pop(0)


def _return_freed_memory() -> None:
    """Hand the heap's free pages back to the system after a large upload (glibc's
    ``malloc_trim``; nothing elsewhere). numpy's arrays of a few MB come from the heap,
    whose freed space glibc keeps: after a 1M-triangle upload 200 to 400 MiB of it stayed
    resident, free, beside what the textures hold (measured: 170 MiB kept over the model
    with the trim, 370 to 580 without)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.malloc_trim(0)
    except (OSError, AttributeError):  # another C library (musl): nothing to hand back this way
        pass


def _packed_bvh(bvh: BVH, wide: bool, tri_offset: int, record_offset: int
                ) -> tuple[NDArray[np.float32], NDArray[np.float32], int, int]:
    """``(nodes, tris, texels a record, stack)`` of one mesh node's BVH, packed for
    ``shaders/common/bvh.glsl`` (:func:`~glsandbox.raytrace.gpu_bvh.pack_bvh`, or
    :func:`~glsandbox.raytrace.gpu_bvh.pack_wide` of its 4-wide collapse), its refs moved
    to where its records and triangles start in the shared textures."""
    from glsandbox.raytrace.bvh_wide import collapse
    from glsandbox.raytrace.gpu_bvh import RECORD_TEXELS, WIDE_RECORD_TEXELS, pack_bvh, pack_wide, wide_stack

    if wide:
        tree = collapse(bvh)
        nodes, tris = pack_wide(tree)
        records = nodes.reshape(-1, WIDE_RECORD_TEXELS, 4)  # a view: texel 6 the refs, 7 the counts
        count = records[:, 7]
        records[:, 6] += np.where(count > 0, tri_offset, np.where(count == 0, record_offset, 0)).astype(np.float32)
        return nodes, tris, WIDE_RECORD_TEXELS, wide_stack(tree.depth)
    nodes, tris = pack_bvh(bvh)
    children = nodes.reshape(-1, 2, 4)  # (box min, ref), (box max, count) per child: a view
    leaf = children[:, 1, 3] > 0
    children[:, 0, 3] += np.where(leaf, tri_offset, record_offset).astype(np.float32)
    return nodes, tris, RECORD_TEXELS, max(2, bvh.depth + 1)


class _Uploaded:
    """One scene's World on the context: its records and images, kept between renders.

    A small scene (at most :data:`UNROLL_NODES` nodes, records within
    :data:`BLOCK_RECORDS`) has its node and triangle records in one uniform
    buffer, the shader's ``SceneData`` block, and gets a program with its
    node list unrolled (:meth:`scene_nodes`); a larger one has them in two
    RGBA32F textures and the shader's general loops.
    """

    def __init__(self, ctx: moderngl.Context, world: World, key: tuple[object, ...], block_records: int,
                 relative: bool = True, wide: bool = False) -> None:
        self.key = key
        self.world = world
        #: The BVHs uploaded as 4-wide trees (:data:`BVH_WIDE`).
        self.wide = wide
        #: Every uploaded position is relative to this point (:func:`world_anchor`; the
        #: origin for ``relative=False``, world-space float32, what the tradeoffs knob shows).
        self.anchor = world_anchor(world) if relative else np.zeros(3)
        nodes = pack_nodes(world, self.anchor)
        tri_rows = world.triangle_count * TRI_RECORDS
        #: Triangles of the World uploaded (its corner arrays are dropped after a BVH upload).
        self.triangle_count = world.triangle_count
        self.mesh_count = sum(1 for node in world.nodes if node.kind.triangles)
        #: Analytic nodes (spheres, cylinders): the records after the mesh nodes'.
        self.shape_count = len(world.nodes) - self.mesh_count
        #: The node kinds present (the program's HAS_<KIND> defines).
        self.kinds = frozenset(node.kind for node in world.nodes)
        loops = sum(1 for node in world.nodes if node.kind.triangles and node.count > UNROLL_TRIS)
        #: Some mesh node is large enough that its BVH beats the scan (:data:`BVH_TRIANGLES`).
        self.large_mesh = max((node.count for node in world.nodes if node.kind.triangles),
                              default=0) > BVH_TRIANGLES
        self.unrolled = (not self.large_mesh and len(world.nodes) <= UNROLL_NODES and loops <= UNROLL_LOOPS
                         and max(1, tri_rows) + max(1, nodes.shape[0]) <= block_records)
        self.block: moderngl.Buffer | None = None
        #: The BVH program's stack depth once its textures are uploaded (0: not yet).
        self.bvh_stack = 0
        #: Samplers by uniform name, in texture unit order.
        self.textures: dict[str, moderngl.Texture] = {}
        #: What the records pack to (:meth:`same_data`), not the records themselves: a
        #: 1M-triangle model's are 144 MB, and the texture holds them already.
        digest = _RecordsDigest(tri_rows)
        anchor, ok = self.anchor, None
        if self.large_mesh:
            # Every render of this scene traces its meshes through BVHs: build them first,
            # and keep of the World (this upload's own) only what the renders read (its
            # nodes, lights, textures): its per-triangle float64 arrays are 200 bytes a
            # triangle, and the textures hold what the shader needs of them. The build
            # moves the corners to the anchor in place (no copy of them beside the build's
            # own arrays), so the triangle records are packed afterwards from the moved
            # corners (anchor 0: x - 0 is x) with the degenerate rule taken before the
            # move. In this order the BVH build's working arrays meet the World's shading
            # arrays, not the triangle texture (which is larger).
            world.tri_node = np.zeros(0, dtype=np.intp)
            # The shading arrays as the float32 their records hold (the same one rounding the
            # packing does), so that the build meets half their bytes; a view (no vertex
            # colours) stays one. Without a texture no uv is ever read (sample_texture):
            # their records hold zeros.
            world.normals = world.normals.astype(np.float32)
            world.uvs = world.uvs.astype(np.float32) if world.textures else \
                np.broadcast_to(np.zeros((1, 3, 2), dtype=np.float32), world.uvs.shape)
            if world.colors.strides[0] != 0:
                world.colors = world.colors.astype(np.float32)
            slices = [slice(start, start + PACK_CHUNK) for start in range(0, world.triangle_count, PACK_CHUNK)]
            ok = np.concatenate([np.zeros(0, dtype=bool),
                                 *(nondegenerate(world.v0[at], world.v1[at], world.v2[at]) for at in slices)])
            self.bvh_textures(ctx, own_corners=True)
            _return_freed_memory()  # the build's freed arrays, before the triangle texture is allocated
            anchor = np.zeros(3)
        if self.unrolled:
            tris = np.concatenate([np.zeros((0, 4), dtype=np.float32),
                                   *digest.passing(triangle_chunks(world, anchor))])
            self.block = ctx.buffer(np.concatenate([_at_least_one(nodes), _at_least_one(tris)]).tobytes())
            del tris
        else:
            from glsandbox.raytrace.gpu_bvh import texture_from_chunks

            # Packed and written a chunk at a time (:func:`triangle_chunks`): the records
            # never exist whole on the host, only in the texture.
            chunks = digest.passing(triangle_chunks(world, anchor, ok))
            self.textures["u_tris"] = texture_from_chunks(ctx, chunks if tri_rows else (np.zeros((1, 4), np.float32),),
                                                          max(1, tri_rows), TEX_WIDTH)
            self.textures["u_nodes"] = texture_from_chunks(ctx, (_at_least_one(nodes),), max(1, nodes.shape[0]),
                                                           TEX_WIDTH)
        self.digest = digest.finish(nodes)
        for slot, (image, _wrap) in enumerate(world.textures):
            pixels = np.floor(image * 255.0 + 0.5).astype(np.uint8)
            h, w = pixels.shape[:2]
            texture = ctx.texture((w, h), 4, np.ascontiguousarray(pixels).tobytes())
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.textures[f"u_tex{slot}"] = texture
        del nodes
        if self.large_mesh:
            del ok
            _drop_triangle_arrays(world, corners=True)
            _return_freed_memory()

    def bvh_textures(self, ctx: moderngl.Context, own_corners: bool = False) -> int:
        """Upload (once) one BVH per mesh node, concatenated into one node/triangle
        texture pair (``shaders/common/bvh.glsl``'s layout, indices offset per node;
        stored triangle indices are the World's), and ``u_bvh_roots`` (texel k: mesh
        slot k's root). Returns the stack depth the shader needs. ``own_corners``: the
        World's corners are not read afterwards, so they are moved to the anchor in place
        (the same float64 differences, without a copy of them beside the build's)."""
        if self.bvh_stack:
            return self.bvh_stack
        from glsandbox.raytrace.bvh import build_bvh
        from glsandbox.raytrace.gpu_bvh import TEX_WIDTH as BVH_TEX_WIDTH, _texture, texture_from_chunks

        world = self.world
        node_parts: list[NDArray[np.float32]] = []
        tri_parts: list[NDArray[np.float32]] = []
        roots: list[int] = []
        record_offset = tri_offset = 0
        stack = 2  # the deepest of the BVHs' stacks
        record_texels = 4
        for k in node_order(world)[: self.mesh_count]:
            node = world.nodes[k]
            stop = node.start + node.count
            rows = slice(node.start, stop)
            # Built, not taken from bvh.py's cache: these are anchor-relative triangles
            # no other engine asks for, and the upload keeps what the shader needs.
            if own_corners:
                corners = tuple(np.subtract(v[rows], self.anchor, out=v[rows]) for v in (world.v0, world.v1, world.v2))
            else:
                corners = tuple(v[rows] - self.anchor for v in (world.v0, world.v1, world.v2))
            bvh = build_bvh(*corners, leaf_size=BVH_LEAF_SIZE)
            del corners
            nodes, tris, record_texels, needs = _packed_bvh(bvh, self.wide, tri_offset, record_offset)
            stack = max(stack, needs)
            del bvh  # its float64 arrays: the records hold what the shader reads
            tris = tris.reshape(-1, 3, 4)
            tris[:, 0, 3] += node.start
            roots.append(record_offset)
            record_offset += nodes.shape[0] // record_texels
            tri_offset += tris.shape[0]
            node_parts.append(nodes)
            tri_parts.append(tris.reshape(-1, 4))
            del nodes, tris
        if record_texels * record_offset > (1 << 24) or 3 * tri_offset > (1 << 24):
            raise RayTraceError(f"the gpu BVH holds at most {(1 << 24) // 3:,} triangles, this scene has {tri_offset:,}")
        # The parts written one after the other (no concatenated copy), each freed once written.
        for name, parts in (("u_bvh_nodes", node_parts), ("u_bvh_tris", tri_parts)):
            count = sum(part.shape[0] for part in parts)
            self.textures[name] = texture_from_chunks(ctx, _emptying(parts), count, BVH_TEX_WIDTH)
        root_rows = np.zeros((max(1, len(roots)), 4), dtype=np.float32)
        root_rows[: len(roots), 0] = roots
        self.textures["u_bvh_roots"] = _texture(ctx, root_rows, root_rows.shape[0])
        self.bvh_stack = stack
        return self.bvh_stack

    def defines(self, cull: bool | None) -> tuple[tuple[str, str], ...]:
        """The program variant's scene-shaped defines (see ``shaders/raytrace.glsl``)."""
        found = [("VERTEX_COLORS", str(int(any(node.mode == MODES["vertex_color"] or node.vertex_colors
                                               for node in self.world.nodes)))),
                 ("TWO_SIDED", str(int(any(node.two_sided for node in self.world.nodes)))),
                 ("SEE_THROUGH", str(int(any(node.see_through for node in self.world.nodes))))]
        if any(node.texel_shadow for node in self.world.nodes):  # shadow rays read a cut-out's texels
            found.append(("CUTOUT_SHADOWS", "1"))
        if self.unrolled:
            found += [("SCENE_NODES", self.scene_nodes(cull)), ("NODE_COUNT", str(max(1, len(self.world.nodes)))),
                      ("TRI_COUNT", str(max(1, self.world.triangle_count)))]
        else:  # the node loops' bounds as literals (see MESH_NODES in the shader)
            found += [("MESH_NODES", str(self.mesh_count)), ("SHAPE_NODES", str(self.shape_count))]
        return tuple(found)

    def scene_nodes(self, cull: bool | None) -> str:
        """The shader's unrolled node list: each node in scene order as
        ``MESH(slot, start, count, cull, lamps)`` or ``SHAPE(slot, KIND_<NAME>, cull, lamps)``,
        ``cull`` resolved from the render's ``cull_backfaces`` (None: the node's own)."""
        slots = {k: slot for slot, k in enumerate(node_order(self.world))}
        parts: list[str] = []
        run: list[str] = []  # consecutive looped nodes whose triangles follow each other
        end = -1

        def close_run() -> None:
            if len(run) == 1:
                parts.append(f"MESH{run[0]}")
            elif run:
                parts.append("RUN_BEGIN " + " ".join(f"RUN_NODE{r}" for r in run) + " RUN_LOOP "
                             + " ".join(f"RUN_PICK{r}" for r in run) + " RUN_END")
            run.clear()

        for k, node in enumerate(self.world.nodes):
            one_sided = int(node.cull if cull is None else cull)
            if node.kind.triangles and node.count > UNROLL_TRIS:
                if node.start != end:
                    close_run()
                run.append(f"({slots[k]},{node.start},{node.count},{one_sided},{node.lamp_of})")
                end = node.start + node.count
                continue
            close_run()
            end = -1
            if not node.kind.triangles:
                parts.append(f"SHAPE({slots[k]},KIND_{node.kind.name},{one_sided},{node.lamp_of})")
            else:
                pair = self._shared_corners(node.start) if node.count == 2 else None
                if pair is not None:
                    parts.append(f"PAIR({slots[k]},{node.start},{one_sided},{node.lamp_of},{pair})")
                else:
                    parts += [f"TRI({slots[k]},{j},{one_sided},{node.lamp_of})"
                              for j in range(node.start, node.start + node.count)]
        close_run()
        return " ".join(parts)

    def _shared_corners(self, j: int) -> str | None:
        """``s0,s1,s2,fresh`` of the shader's ``PAIR`` when triangle ``j + 1`` has two corners
        exactly equal to corners of triangle ``j`` (a quad): for each of its corners, the
        index of the equal corner of ``j`` or 3, and which of its own corners is the other.
        Equal float64 corners pack to equal float32 corners, so the shader may share them."""
        w = self.world
        first = [w.v0[j], w.v1[j], w.v2[j]]
        picks = []
        for m, corner in enumerate((w.v0[j + 1], w.v1[j + 1], w.v2[j + 1])):
            same = [i for i, v in enumerate(first) if np.array_equal(v, corner)]
            picks.append(same[0] if same else 3)
        if picks.count(3) != 1:
            return None
        return ",".join(map(str, picks)) + f",{picks.index(3)}"

    def same_data(self, world: World) -> bool:
        """Whether ``world`` packs to exactly what is uploaded (then the upload can be kept)."""
        old = self.world
        if world.triangle_count != self.triangle_count or len(world.nodes) != len(old.nodes):
            return False  # not worth packing a model to find out
        if not (np.array_equal(world.background, old.background) and np.array_equal(world.light_positions, old.light_positions)
                and np.array_equal(world.light_colors, old.light_colors)):
            return False
        return (len(world.textures) == len(self.world.textures)
                and all(a is b or np.array_equal(a, b) for (a, _), (b, _) in zip(world.textures, self.world.textures))
                and [w for _, w in world.textures] == [w for _, w in self.world.textures]
                and _records_digest(world, self.anchor_of(world),
                                    pack_nodes(world, self.anchor_of(world))) == self.digest)

    def anchor_of(self, world: World) -> NDArray[np.float64]:
        """Where ``world`` would be anchored in an upload like this one."""
        return world_anchor(world) if self.key[-1] else np.zeros(3)

    def release(self) -> None:
        for texture in self.textures.values():
            texture.release()
        self.textures.clear()
        if self.block is not None:
            self.block.release()
            self.block = None


class GpuTracer:
    """Programs (one per variant), a target per size and the last scenes uploaded, on one context."""

    #: Uploaded scenes kept (one per viewport of a split-screen lesson, and a few more).
    KEEP_SCENES = 4
    #: Program variants kept (compiled again when needed after that).
    KEEP_PROGRAMS = 32

    def __init__(self, ctx: moderngl.Context, wide_bvh: bool | None = None) -> None:
        self.ctx = ctx
        #: This tracer's meshes go through 4-wide BVHs (None: :data:`BVH_WIDE`, read now).
        self.wide_bvh = BVH_WIDE if wide_bvh is None else bool(wide_bvh)
        self._programs: dict[tuple[tuple[str, str], ...], moderngl.Program] = {}
        self._vaos: dict[tuple[tuple[str, str], ...], moderngl.VertexArray] = {}
        self._targets: dict[tuple[int, int], tuple[moderngl.Texture, moderngl.Framebuffer]] = {}
        self._scenes: list[_Uploaded] = []
        #: vec4 records a uniform block holds on this context (at most BLOCK_RECORDS).
        self.block_records = min(BLOCK_RECORDS, int(ctx.info.get("GL_MAX_UNIFORM_BLOCK_SIZE", 16384)) // 16)
        #: Uploads made and reused (what the benchmark's cold and warm figures show).
        self.uploads = 0
        self.reuses = 0

    def _program(self, lights: int, textures: int, shadows: bool = True, reflect: bool = True,
                 kinds: frozenset[NodeKind] = frozenset(NodeKind),
                 scene: tuple[tuple[str, str], ...] = ()) -> tuple[moderngl.Program, moderngl.VertexArray]:
        shapes = [kind for kind in NodeKind if not kind.triangles]
        flags = (lights, textures, int(shadows and lights > 0), int(reflect), int(NodeKind.MESH in kinds),
                 int(any(kind in kinds for kind in shapes)), *(int(kind in kinds) for kind in shapes))
        names = ("NUM_LIGHTS", "NUM_TEXTURES", "SHADOWS", "REFLECT", "HAS_MESHES", "HAS_SHAPES",
                 *(f"HAS_{kind.name}" for kind in shapes))
        defines = (tuple((name, str(value)) for name, value in zip(names, flags)) + glsl_defines() + kind_defines()
                   + glsl_dispatch({kind.value for kind in shapes if kind in kinds}) + layout_defines() + scene)
        if defines in self._programs:
            self._programs[defines] = self._programs.pop(defines)  # most recently used last
            self._vaos[defines] = self._vaos.pop(defines)
        else:
            while len(self._programs) >= self.KEEP_PROGRAMS:  # variants are per scene shape: keep the recent
                oldest = next(iter(self._programs))
                self._vaos.pop(oldest).release()
                self._programs.pop(oldest).release()
            program = compile_program(self.ctx, ProgramVariant("raytrace", defines))
            self._programs[defines] = program
            self._vaos[defines] = self.ctx.vertex_array(program, [])
        return self._programs[defines], self._vaos[defines]

    def _target(self, size: tuple[int, int]) -> moderngl.Framebuffer:
        if size not in self._targets:
            if len(self._targets) > 8:  # the interactive lesson changes size: keep a few
                self._release_targets()
            color = self.ctx.texture(size, 4)
            self._targets[size] = (color, self.ctx.framebuffer(color_attachments=[color]))
        return self._targets[size][1]

    def _upload(self, scene: Scene, viewport: int, analytic_spheres: bool, relative: bool = True) -> _Uploaded:
        """The scene's upload: kept from an earlier render when its World cannot have changed."""
        key = (*_scene_key(scene, viewport, analytic_spheres), relative)
        for i, entry in enumerate(self._scenes):
            if _same_key(entry.key, key):
                self._scenes.insert(0, self._scenes.pop(i))
                self.reuses += 1
                return entry
        world = build_world(scene, viewport, analytic_spheres=analytic_spheres)
        if len(world.textures) > MAX_TEXTURES:
            _keep_first_textures(scene, world)
        for i, entry in enumerate(self._scenes):  # new objects, same data (glsandbox.frame.trace_viewports rebuilds nodes)
            if entry.key[-1] == relative and entry.same_data(world):
                entry.key = key
                self._scenes.insert(0, self._scenes.pop(i))
                self.reuses += 1
                return entry
        entry = _Uploaded(self.ctx, world, key, self.block_records, relative, self.wide_bvh)
        self.uploads += 1
        self._scenes.insert(0, entry)
        while len(self._scenes) > self.KEEP_SCENES:
            self._scenes.pop().release()
        return entry

    def forget_scenes(self) -> None:
        """Drop the uploaded scenes (the next render uploads again: a cold render)."""
        for entry in self._scenes:
            entry.release()
        self._scenes.clear()

    def render_viewport(self, scene: Scene, size: tuple[int, int], viewport: int = 0, *, max_depth: int = 2,
                        shadows: bool = True, cull_backfaces: bool | None = None, aabb: bool = True,
                        analytic_spheres: bool = True, offset: str = "bound",
                        relative: bool = True) -> NDArray[np.uint8]:
        """Trace one viewport at ``size``: ``(H, W, 4)`` uint8, top row first (a read-only view).
        ``relative=False`` traces world coordinates in float32 (the tradeoffs knob's
        bad example; see :func:`world_anchor`)."""
        uploaded = self._upload(scene, viewport, analytic_spheres, relative)
        world = uploaded.world
        width, height = size
        vp = scene.viewports[viewport]
        eye, basis, half_w, half_h = camera_basis(vp.camera or scene.camera, width / height)
        lights = world.light_positions.shape[0]
        # The bounce loop only where some node reflects or lets rays through (a cut-out, a blend).
        reflect = max_depth > 0 and any(node.reflectivity > 0.0 or node.see_through for node in world.nodes)
        scene_defines = uploaded.defines(cull_backfaces) + (("SIMPLE_OFFSET", str(int(OFFSETS[offset]))),)
        use_bvh = False
        try:
            check_loop_budget(world, lights, bool(shadows), reflect, int(max_depth))
        except RayTraceError:
            if uploaded.unrolled or uploaded.mesh_count == 0:
                raise
            use_bvh = True
        if use_bvh or uploaded.large_mesh:
            # Too large for the scan: trace mesh nodes through their BVHs, each
            # ray's traversal bounded so the pixel stays within the loop limit.
            use_bvh = True
            cap = bvh_step_cap(world, lights, bool(shadows), reflect, int(max_depth))
            stack = uploaded.bvh_textures(self.ctx)
            scene_defines += (("BVH", "1"), ("BVH_STACK", str(stack)), ("BVH_MAX_STEPS", str(cap)),
                              ("BVH_WIDE", str(int(uploaded.wide))))
        program, vao = self._program(lights, len(world.textures), shadows=bool(shadows), reflect=reflect,
                                     kinds=uploaded.kinds,
                                     scene=scene_defines)
        if uploaded.block is not None:
            program["SceneData"].binding = 0
            uploaded.block.bind_to_uniform_block(0)
        # The records and images are read by texelFetch with their own NEAREST, mipmap-free
        # state; a sampler object another user of the context left on a unit (a rasterized
        # material's mipmapped filter) would override it and make them incomplete: zeros.
        self.ctx.clear_samplers(0, len(uploaded.textures))
        for unit, (name, texture) in enumerate(uploaded.textures.items()):
            texture.use(unit)
            if name in program:
                program[name].value = unit
        if world.textures:  # as bytes: moderngl wants a bare int for a one-element array (one texture)
            program["u_wrap"].write(np.array([wrap for _, wrap in world.textures], dtype="i4").tobytes())
        values = {
            "u_mesh_count": uploaded.mesh_count, "u_shape_count": uploaded.shape_count,
            "u_size": (float(width), float(height)),
            "u_eye": tuple(eye - uploaded.anchor), "u_half": (half_w, half_h), "u_background": tuple(world.background),
            "u_max_depth": int(max_depth),
            "u_cull": -1 if cull_backfaces is None else int(bool(cull_backfaces)), "u_aabb": bool(aabb),
            "u_offset": SIMPLE_OFFSET, "u_offset_origin": tuple(uploaded.anchor),
        }
        for name, value in values.items():
            if name in program:
                program[name].value = value
        if "u_basis" in program:
            program["u_basis"].write(np.asarray(basis, dtype="f4").T.tobytes())  # column-major
        if lights:
            if "u_light_pos" in program:
                program["u_light_pos"].write((world.light_positions - uploaded.anchor).astype("f4").tobytes())
            if "u_light_color" in program:
                program["u_light_color"].write(world.light_colors.astype("f4").tobytes())
        target = self._target((width, height))
        target.use()
        target.viewport = (0, 0, width, height)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)
        vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        data = target.read(components=4, alignment=1)
        if use_bvh or uploaded.shape_count:
            alpha = np.frombuffer(data, dtype=np.uint8)[3::4]
            unknown = int(np.count_nonzero(alpha == BAD_KIND_ALPHA))
            if unknown:  # shape_t or shape_surface met a kind code it has no case for
                raise RayTraceError(f"the gpu engine met a node kind with no GLSL case on {unknown:,} pixels "
                                    f"(node kinds: {', '.join(k.value for k in uploaded.kinds)})")
            cut = int(np.count_nonzero(alpha < 128))
            if cut:
                raise RayTraceError(
                    f"the gpu engine's BVH traversal ran out of its {cap:,} steps a ray on {cut:,} of "
                    f"{alpha.size:,} pixels (llvmpipe ends a shader's loops after {LOOP_LIMIT:,} iterations); "
                    "their hits would be wrong: use renderer=ray_numpy (engine='numpy')")
        # A read-only view flipped by a negative stride, as the rasterizer's
        # read-back: copying a fresh 800x600 frame costs about 2.5 ms (page
        # faults on new memory), a tenth of a primary-ray render.
        return np.frombuffer(data, dtype=np.uint8).reshape(height, width, 4)[::-1]

    def _release_targets(self) -> None:
        for color, fbo in self._targets.values():
            fbo.release()
            color.release()
        self._targets.clear()

    def release(self) -> None:
        """Free the programs, targets and uploaded scenes (the context stays)."""
        self._release_targets()
        self.forget_scenes()
        for vao in self._vaos.values():
            vao.release()
        for program in self._programs.values():
            program.release()
        self._vaos.clear()
        self._programs.clear()
