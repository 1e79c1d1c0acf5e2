"""The BVH on the GPU: pack a :class:`~glsandbox.raytrace.bvh.BVH` for ``shaders/common/bvh.glsl``
and trace batches of rays with it (float32), to test the GLSL traversal against numpy's.

Packing (the layout ``bvh.glsl`` documents): two RGBA32F textures
:data:`TEX_WIDTH` texels wide, read with ``texelFetch``:

- nodes, one record of 4 texels per *inner* node holding its two children:
  ``(min.xyz, ref)``, ``(max.xyz, count)`` for the left child, then the same for
  the right one; ``ref`` is the child's record (an inner child, ``count`` 0) or
  its first stored triangle (a leaf of ``count`` triangles). Record 0 describes
  the root the same way (its first two texels; the other two unused). A visit
  of an inner node is then 4 fetches for both children's boxes, and a leaf
  needs no visit of its own. The boxes are rounded *outwards* to float32 (a
  float64 box edge never moves inside);
- triangles in the BVH's storage order, 3 texels each: ``(v0.xyz, caller's
  index)``, ``(v1.xyz, 0)``, ``(v2.xyz, 0)``.

Integers travel as float32, exact up to ``2^24`` (16,777,216): more nodes or
triangles than that are refused.

Tracing: ``shaders/bvh_probe.glsl`` runs one fragment per ray over a grid of
rays (origins and directions uploaded as two more float textures; or, for
:meth:`GpuBVH.trace_camera`, a camera's primary rays made in the shader as
``shaders/raytrace.glsl`` makes them) and writes ``(t, index, u, v)`` and
``(overflow, steps, any)`` into two float targets.

Overflow: llvmpipe stops a shader invocation's loops after 65,535 iterations
in all, silently. The GLSL traversal therefore bounds its one loop by
``max_steps`` (:data:`MAX_STEPS`: node visits plus triangle tests per ray)
and flags every ray that did not finish within it (or would have overflowed
its stack). :class:`GpuHits` carries the flags; with ``strict=True`` (the
default) :meth:`GpuBVH.trace` raises :class:`~glsandbox.raytrace.raytrace_error.RayTraceError`
saying how many rays were cut off, rather than return hits that may be wrong.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import moderngl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.gl.shaders import compile_program
from glsandbox.plan import ProgramVariant
from glsandbox.raytrace.bvh import BVH
from glsandbox.raytrace.bvh_wide import WIDTH, WideBVH, collapse
from glsandbox.raytrace.constants import glsl_defines
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_protocol import broadcast_rays
from glsandbox.raytrace.world import camera_basis
from glsandbox.scene import Camera

__all__ = ["EXACT_INTEGERS", "LOOP_LIMIT", "MAX_STEPS", "RECORD_TEXELS", "TEX_WIDTH", "WIDE_RECORD_TEXELS", "GpuBVH",
           "GpuHits", "pack_bvh", "pack_wide", "wide_stack"]

#: Texels per row of the node and triangle textures (``BVH_TEX_WIDTH`` in the shader): a power of
#: two (the shader takes a texel's row and column with a shift and a mask, and a node record's
#: 4 texels stay in one row).
TEX_WIDTH: int = 4096
#: Node visits plus triangle tests one ray may use (``BVH_MAX_STEPS``).
MAX_STEPS: int = 8192
#: llvmpipe's loop iterations per shader invocation, all loops together.
LOOP_LIMIT: int = 65535
#: Integers float32 holds exactly.
EXACT_INTEGERS: int = 1 << 24
#: Rays per row of the ray grid.
RAY_ROW: int = 1024


def _outward(values: NDArray[np.float64], down: bool) -> NDArray[np.float32]:
    """``values`` as float32, rounded towards −inf (``down``) or +inf: a box stays around its triangles."""
    rounded = values.astype(np.float32)
    wrong = rounded > values if down else rounded < values
    towards = np.float32(-np.inf if down else np.inf)
    return np.where(wrong, np.nextafter(rounded, towards), rounded).astype(np.float32)


#: Texels per node record (``BVH_RECORD`` in ``bvh.glsl``): two children, two texels each.
RECORD_TEXELS: int = 4


def wide_stack(depth: int) -> int:
    """The stack a 4-wide tree of ``depth`` levels needs: a visit keeps one child and pushes
    the other three at most, so a walk down ``depth`` levels holds ``3·depth`` entries at most."""
    return max(2, (WIDTH - 1) * depth + 1)


def pack_bvh(bvh: BVH) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The node and triangle records of ``bvh`` as ``(texels, 4)`` float32 arrays (module docstring):
    ``RECORD_TEXELS`` texels per record, record 0 the root, then one per inner node."""
    inner = np.flatnonzero(bvh.node_count == 0) if not bvh.empty else np.zeros(0, dtype=np.int64)
    if (inner.size + 1) * RECORD_TEXELS > EXACT_INTEGERS or bvh.triangle_count * 3 > EXACT_INTEGERS or \
            bvh.input_count > EXACT_INTEGERS:
        raise RayTraceError(f"the gpu BVH holds at most {EXACT_INTEGERS // 3:,} triangles and "
                            f"{EXACT_INTEGERS // RECORD_TEXELS:,} inner nodes; this one has "
                            f"{bvh.triangle_count:,} and {inner.size:,}")
    records = np.zeros((inner.size + 1, 2, 2, 4), dtype=np.float32)  # record, child, (min|max), xyzw
    tris = np.zeros((max(1, bvh.triangle_count), 3, 4), dtype=np.float32)
    if bvh.empty:
        # No triangles: a root leaf holding one zero-area triangle at the origin,
        # which the watertight test never hits (det = 0).
        records[0, 0, 1, 3] = 1
        return records.reshape(-1, 4), tris.reshape(-1, 4)
    record_of = np.zeros(bvh.node_total, dtype=np.int64)
    record_of[inner] = np.arange(1, inner.size + 1)
    lo = _outward(bvh.node_min, down=True)
    hi = _outward(bvh.node_max, down=False)
    ref = np.where(bvh.node_count == 0, record_of, bvh.node_first).astype(np.float32)

    def child(slot: NDArray[np.int64] | int, nodes: NDArray[np.int64] | int, side: int) -> None:
        records[slot, side, 0, :3] = lo[nodes]
        records[slot, side, 0, 3] = ref[nodes]
        records[slot, side, 1, :3] = hi[nodes]
        records[slot, side, 1, 3] = bvh.node_count[nodes]

    child(0, 0, 0)
    child(record_of[inner], bvh.node_first[inner], 0)
    child(record_of[inner], bvh.node_first[inner] + 1, 1)
    _pack_triangles(bvh, tris)
    return records.reshape(-1, 4), tris.reshape(-1, 4)


def _pack_triangles(bvh: BVH, tris: NDArray[np.float32]) -> None:
    """The stored triangles into ``tris`` ``(M, 3, 4)``: ``(v0, caller's index), (v1, 0), (v2, 0)``."""
    if bvh.triangle_count:
        tris[:, 0, :3], tris[:, 1, :3], tris[:, 2, :3] = bvh.v0, bvh.v1, bvh.v2
        tris[:, 0, 3] = bvh.tri_index


#: Texels per record of the 4-wide tree (``shaders/common/bvh_wide.glsl``): six planes of the
#: four child boxes, their refs, their counts.
WIDE_RECORD_TEXELS: int = 8


def pack_wide(wide: WideBVH) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The node and triangle records of a 4-wide tree (``bvh_wide.glsl``'s layout): record ``r``
    is texels ``8r .. 8r+7``, one plane (min x, y, z, max x, y, z) of its four child boxes per
    texel, then the children's refs and counts (``-1``: an empty slot). The triangles as
    :func:`pack_bvh`'s; the boxes rounded outwards as there."""
    bvh = wide.bvh
    records = wide.record_count
    if records * WIDE_RECORD_TEXELS > EXACT_INTEGERS or bvh.triangle_count * 3 > EXACT_INTEGERS or \
            bvh.input_count > EXACT_INTEGERS:
        raise RayTraceError(f"the gpu BVH holds at most {EXACT_INTEGERS // 3:,} triangles and "
                            f"{EXACT_INTEGERS // WIDE_RECORD_TEXELS:,} wide nodes; this one has "
                            f"{bvh.triangle_count:,} and {records:,}")
    packed = np.zeros((records, WIDE_RECORD_TEXELS, WIDTH), dtype=np.float32)  # record, texel, child
    tris = np.zeros((max(1, bvh.triangle_count), 3, 4), dtype=np.float32)
    ref, count, used = wide.slots()
    if bvh.empty:
        # As pack_bvh's: one leaf of one zero-area triangle, which is never hit.
        count, used = np.array([[1, 0, 0, 0]]), np.array([[True, False, False, False]])
    node = np.where(used, wide.child, 0)
    packed[:, 0:3] = np.moveaxis(_outward(bvh.node_min[node], down=True), 2, 1)
    packed[:, 3:6] = np.moveaxis(_outward(bvh.node_max[node], down=False), 2, 1)
    if bvh.empty:
        packed[:, 0:6] = 0.0
    packed[:, 6] = ref
    packed[:, 7] = np.where(used, count, -1)
    _pack_triangles(bvh, tris)
    return packed.reshape(-1, 4), tris.reshape(-1, 4)


@dataclass
class GpuHits:
    """What the GLSL traversal found per ray (float32 results, as float64 arrays).

    ``t`` is ``inf`` and ``triangle`` −1 for a miss; ``overflow`` marks rays
    the traversal could not finish (their ``t``/``triangle`` are not to be
    trusted); ``steps`` is the loop iterations each ray used.
    """

    t: NDArray[np.float64]
    triangle: NDArray[np.int64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]
    overflow: NDArray[np.bool_]
    steps: NDArray[np.int64]

    @property
    def hit(self) -> NDArray[np.bool_]:
        result: NDArray[np.bool_] = self.triangle >= 0
        return result

    def check(self, max_steps: int = MAX_STEPS) -> None:
        """Raise :class:`RayTraceError` if any ray was cut off by the loop bound."""
        _check_overflow(self.overflow, max_steps)


def _check_overflow(overflow: NDArray[np.bool_], max_steps: int) -> None:
    count = int(np.count_nonzero(overflow))
    if count:
        raise RayTraceError(f"the gpu BVH traversal cut off {count:,} of {overflow.size:,} rays at its bound of "
                            f"{max_steps:,} node visits and triangle tests per ray (llvmpipe ends a shader's loops "
                            f"after {LOOP_LIMIT:,} iterations); their hits would be wrong")


def _texture(ctx: moderngl.Context, rows: NDArray[np.float32], width: int) -> moderngl.Texture:
    """``(n, 4)`` float32 records as a ``width``-wide RGBA32F texture, texel i at
    ``(i % width, i // width)`` (:func:`texture_from_chunks` with one chunk)."""
    return texture_from_chunks(ctx, (rows,), rows.shape[0], width)


def texture_from_chunks(ctx: moderngl.Context, chunks: Iterable[NDArray[np.float32]], count: int,
                        width: int) -> moderngl.Texture:
    """``count`` float32 records (texels) arriving as ``(k, 4)`` chunks, in order, as a
    ``width``-wide RGBA32F texture, texel i at ``(i % width, i // width)``. Each chunk's full
    rows are written straight from it (no padded copy of the whole: a 1M-triangle model's
    records are 144 MB, and the texture holds a copy), a partial row carried to the next
    chunk; the texels past the last record are never read."""
    height = max(1, math.ceil(count / width))
    texture = ctx.texture((width, height), 4, dtype="f4")
    row, written = 0, 0
    carry = np.zeros((0, 4), dtype=np.float32)
    for chunk in chunks:
        chunk = np.ascontiguousarray(chunk, dtype=np.float32)
        written += chunk.shape[0]
        if carry.shape[0]:
            chunk = np.concatenate([carry, chunk])
        full = chunk.shape[0] // width
        if full:
            texture.write(chunk[: full * width], viewport=(0, row, width, full))
            row += full
        carry = chunk[full * width:]
    if carry.shape[0]:
        texture.write(carry, viewport=(0, row, carry.shape[0], 1))
    if written != count:
        texture.release()
        raise ValueError(f"texture_from_chunks: {written} records given, {count} announced")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture


class GpuBVH:
    """A BVH uploaded to ``ctx``, with the probe programs that trace rays through it."""

    def __init__(self, ctx: moderngl.Context, bvh: BVH, *, max_steps: int = MAX_STEPS, wide: bool = False) -> None:
        if int(max_steps) != max_steps or not 1 <= max_steps <= LOOP_LIMIT - 16:
            raise RayTraceError(f"max_steps must be an integer in 1..{LOOP_LIMIT - 16}, got {max_steps!r}")
        self.ctx = ctx
        self.bvh = bvh
        self.max_steps = int(max_steps)
        #: Traced as the 4-wide tree (:mod:`glsandbox.raytrace.bvh_wide`, ``BVH_WIDE``) or the binary one.
        self.wide = bool(wide)
        if self.wide:
            tree = collapse(bvh)
            nodes, tris = pack_wide(tree)
            #: The shader's stack (:func:`wide_stack`; binary: one entry a level at most).
            self.stack = wide_stack(tree.depth)
        else:
            nodes, tris = pack_bvh(bvh)
            self.stack = max(2, bvh.depth + 1)
        self._nodes = _texture(ctx, nodes, TEX_WIDTH)
        self._tris = _texture(ctx, tris, TEX_WIDTH)
        self._programs: dict[tuple[bool, bool], tuple[moderngl.Program, moderngl.VertexArray]] = {}
        #: The two float result targets, their framebuffer and the host arrays they are read
        #: back into, kept for the last grid size (a 800x600 grid's are 15 MB).
        self._target: tuple[tuple[int, int], list[moderngl.Texture], moderngl.Framebuffer,
                            list[NDArray[np.float32]]] | None = None
        #: The ray origin and direction textures of :meth:`trace` and :meth:`any_hit`, kept for the last grid size.
        self._rays: tuple[moderngl.Texture, ...] | None = None
        # A far point the padding rays of a grid start from, pointing away: they miss the root at once.
        root_hi = np.where(np.isfinite(bvh.node_max[0]), bvh.node_max[0], 0.0)
        self._away = root_hi + 1.0 + np.abs(root_hi)

    def defines(self, any_hit: bool = False, camera: bool = False) -> tuple[tuple[str, str], ...]:
        """The ``#define`` lines of the probe program (what an including shader sets too)."""
        return (("BVH_TEX_WIDTH", str(TEX_WIDTH)), ("BVH_STACK", str(self.stack)),
                ("BVH_MAX_STEPS", str(self.max_steps)), ("BVH_ANY", str(int(any_hit))),
                ("BVH_CAMERA", str(int(camera))), ("BVH_WIDE", str(int(self.wide))), *glsl_defines())

    def _program(self, any_hit: bool, camera: bool = False) -> tuple[moderngl.Program, moderngl.VertexArray]:
        key = (any_hit, camera)
        if key not in self._programs:
            program = compile_program(self.ctx, ProgramVariant("bvh_probe", self.defines(any_hit, camera)))
            self._programs[key] = (program, self.ctx.vertex_array(program, []))
        return self._programs[key]

    def _draw(self, program: moderngl.Program, vao: moderngl.VertexArray, width: int, height: int,
              rays: dict[str, moderngl.Texture]) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """One fragment per ray over a ``width x height`` grid: the two result targets, row 0 first
        (the targets and the arrays they are read into are kept for the next call of the same
        size: what is returned is overwritten by the next call)."""
        if self._target is None or self._target[0] != (width, height):
            self._release_target()
            outputs = [self.ctx.texture((width, height), 4, dtype="f4") for _ in range(2)]
            self._target = ((width, height), outputs, self.ctx.framebuffer(color_attachments=outputs),
                            [np.empty((width * height, 4), dtype=np.float32) for _ in range(2)])
        fbo, results = self._target[2], self._target[3]
        textures = {"u_bvh_nodes": self._nodes, "u_bvh_tris": self._tris, **rays}
        self.ctx.clear_samplers(0, len(textures))  # their own NEAREST state, not a sampler left bound
        for unit, (name, texture) in enumerate(textures.items()):
            texture.use(unit)
            if name in program:
                program[name].value = unit
        fbo.use()
        fbo.viewport = (0, 0, width, height)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.BLEND)
        vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        for attachment, result in enumerate(results):  # into the kept arrays: no new 7.7 MB bytes each
            fbo.read_into(result, components=4, attachment=attachment, dtype="f4")
        return results[0], results[1]

    def _release_target(self) -> None:
        if self._target is not None:
            self._target[2].release()
            for texture in self._target[1]:
                texture.release()
            self._target = None

    def _run(self, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike, cull: bool, any_hit: bool
             ) -> tuple[NDArray[np.float32], NDArray[np.float32], int]:
        o, d = broadcast_rays(origins, directions)
        n = d.shape[0]
        limit = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,))
        width = max(1, min(RAY_ROW, n))
        height = max(1, math.ceil(n / width))
        total = width * height
        rays_o = np.zeros((total, 4), dtype=np.float32)
        rays_d = np.zeros((total, 4), dtype=np.float32)
        rays_o[:n, :3], rays_o[:n, 3] = o, limit
        rays_d[:n, :3], rays_d[:n, 3] = d, 1.0 if cull else 0.0
        rays_o[n:, :3], rays_o[n:, 3] = self._away, 0.0
        rays_d[n:, 0] = 1.0
        program, vao = self._program(any_hit)
        if self._rays is None or self._rays[0].size != (width, height):  # kept for the next grid of this size
            self._release_rays()
            self._rays = tuple(self.ctx.texture((width, height), 4, dtype="f4") for _ in range(2))
            for texture in self._rays:
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        ray_o, ray_d = self._rays
        ray_o.write(rays_o)
        ray_d.write(rays_d)
        hit, info = self._draw(program, vao, width, height, {"u_ray_origins": ray_o, "u_ray_dirs": ray_d})
        return hit[:n], info[:n], n

    def _release_rays(self) -> None:
        for texture in self._rays or ():
            texture.release()
        self._rays = None

    @staticmethod
    def _hits(hit: NDArray[np.float32], info: NDArray[np.float32]) -> GpuHits:
        index = np.rint(hit[:, 1]).astype(np.int64)
        found = index >= 0
        return GpuHits(np.where(found, hit[:, 0].astype(np.float64), np.inf), np.where(found, index, -1),
                       np.where(found, hit[:, 2], 0.0).astype(np.float64),
                       np.where(found, hit[:, 3], 0.0).astype(np.float64),
                       info[:, 0] > 0.5, np.rint(info[:, 1]).astype(np.int64))

    def trace_camera(self, camera: Camera, width: int, height: int, *, cull_backfaces: bool = False,
                     strict: bool = True) -> GpuHits:
        """The primary rays of ``camera`` at ``width x height``, made in the shader as
        ``shaders/raytrace.glsl`` makes them, in the order of
        :func:`~glsandbox.raytrace.world.camera_rays` (row 0 at the top)."""
        eye, basis, half_w, half_h = camera_basis(camera, width / height)
        program, vao = self._program(False, camera=True)
        values = {"u_size": (float(width), float(height)), "u_eye": tuple(eye), "u_half": (half_w, half_h),
                  "u_t_max": float("inf"), "u_cull": bool(cull_backfaces)}
        for name, value in values.items():
            if name in program:
                program[name].value = value
        program["u_basis"].write(np.asarray(basis, dtype="f4").T.tobytes())  # column-major
        hit, info = self._draw(program, vao, width, height, {})
        flip = np.arange(width * height).reshape(height, width)[::-1].reshape(-1)  # GL's row 0 is the bottom
        result = self._hits(hit[flip], info[flip])
        if strict:
            result.check(self.max_steps)
        return result

    def trace(self, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = np.inf, *,
              cull_backfaces: bool = False, strict: bool = True) -> GpuHits:
        """The nearest hit of each ray with ``0 < t < t_max``, traced by ``bvh.glsl`` in float32.

        ``strict=True`` raises :class:`RayTraceError` when any ray was cut
        off by the loop bound; ``strict=False`` returns its ``overflow`` flag instead.
        """
        hit, info, _ = self._run(origins, directions, t_max, bool(cull_backfaces), False)
        result = self._hits(hit, info)
        if strict:
            result.check(self.max_steps)
        return result

    def any_hit(self, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = 1.0, *,
                cull_backfaces: bool = False, strict: bool = True) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """``(blocked, overflow)``: whether anything lies at ``0 < t < t_max`` along each ray (shadow rays)."""
        _, info, _ = self._run(origins, directions, t_max, bool(cull_backfaces), True)
        overflow = info[:, 0] > 0.5
        if strict:
            _check_overflow(overflow, self.max_steps)
        return info[:, 2] > 0.5, overflow

    def release(self) -> None:
        """Free the textures and programs (the context stays)."""
        for program, vao in self._programs.values():
            vao.release()
            program.release()
        self._programs.clear()
        self._release_target()
        self._release_rays()
        self._nodes.release()
        self._tris.release()
