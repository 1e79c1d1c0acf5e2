"""The numpy engine: the float64 reference ray tracer, vectorized over rays.

:func:`render_viewport` traces one viewport of a Scene (the front door,
:func:`glsandbox.raytrace.render`, lays the viewports out). It follows the
algorithm of :mod:`glsandbox.raytrace.render` step by step, on whole batches
of rays at once:

- :func:`_nearest`: the nearest hit (``tDistances``/``min_indis``) of each
  ray over the :class:`~glsandbox.raytrace.world.World`'s nodes;
- :func:`_occluded`: the shadow query (Gölge testi), whether anything but the
  light's lamp lies at ``0 < s < 1`` along each shadow ray;
- :func:`_surface`: point, normal, base colour and alpha at the hits
  (barycentric normals, uv and vertex colours; textures sampled bilinearly by
  hand; a two-sided node's back face lit with its normal reversed);
- :func:`_shade`: the rasterizer's per-light Phong with a shadow ray per light;
- :func:`_trace`: reflections followed iteratively, ``(1 − r)·local + r·reflected``,
  and rays passed on straight through cut-outs and blended surfaces,
  ``a·local + (1 − a)·behind``.

Primary rays are traced :data:`RAY_BLOCK` at a time, each block through every
step before the next.

The BVH
-------
:func:`_nearest` and :func:`_occluded` are the only places that look for hits.
Both go through :func:`_top_level`, the one loop over the nodes in scene
order (the top level is the nodes' boxes, course "Hızlandırma: AABB"; the
tests call it too). Each node is tested by its kind's hit function, in the
node's own space (:func:`_hit_kind`: the triangles, or the kind's own test in
``raytrace/shapes/<kind>.py``). With ``bvh=True`` (the
default) a mesh node's rays that enter its box are traced through the node's
BVH instead (:class:`~glsandbox.raytrace.bvh_world.WorldBVH`, built once per mesh and
cached by content; :func:`~glsandbox.raytrace.bvh_traverse.closest_hit`, the
watertight triangle test) with ``t_max`` their best hit so far: only strictly
nearer hits replace it, so the tie rule holds (an equal ``t`` goes to the
earlier node, then the lower triangle). Shadow rays are then an any-hit query
(:func:`~glsandbox.raytrace.bvh_traverse.any_hit`): a ray leaves at its first
occluder. With ``bvh=False`` a mesh node's kind function tests every triangle of
a node whose box a ray enters (the watertight test too,
:func:`~glsandbox.raytrace.watertight.nearest_watertight`), and :func:`_occluded` is that scan cut at
``t = 1``: what ``ray_acceleration`` compares the BVH with.
:class:`RenderStats` counts the ray-shape tests and the ray-box tests either
way.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.raytrace.aabb import AABB, reciprocals
from glsandbox.raytrace.bvh_traverse import Accept, TraversalCounts, any_hit, closest_hit
from glsandbox.raytrace.bvh_world import NodeBVH, WorldBVH
from glsandbox.raytrace.constants import (BVH_BOX_PAD_F64, LENGTH_TINY, OFFSETS, SIMPLE_OFFSET, RAY_POINT_GAMMA,
                                          TRIANGLE_POINT_GAMMA, UNIT_F64, gamma)
from glsandbox.raytrace.vec import length, moved_off
from glsandbox.raytrace.watertight import nearest_watertight
from glsandbox.raytrace.world import NodeInfo, World, build_world, camera_rays, coverage
from glsandbox.scene import Scene

__all__ = ["RAY_BLOCK", "HitTest", "RenderStats", "render_viewport", "to_rgba8"]

#: A hit test handed to :func:`render_viewport` for one node kind (see :func:`_replaced_hit`).
HitTest = Callable[..., Any]

#: Primary rays are traced this many at a time, each block through every step
#: (nearest hit, shading, shadow rays, bounces) before the next. Every ray's
#: colour depends on that ray alone, so the blocks give the same pixels as one
#: pass over the image; but a block's temporaries (a few dozen arrays of
#: ``RAY_BLOCK`` numbers or 3-vectors) stay in a core's cache, where a
#: whole-image pass streams every ``(W·H, 3)`` temporary through memory and
#: pays the page faults of allocating it: about twice as fast at 800x600.
RAY_BLOCK: int = 1 << 14

#: A seam for :mod:`glsandbox.story`: ``probe(step, **arrays)`` is called by :func:`_trace`
#: and :func:`_shade` with the arrays of each step (``"ray"``: a depth's rays and nearest
#: hits; ``"surface"``: point, normal, base colour, alpha of the hits; ``"light"``: one
#: light's Phong terms and shadow ray; ``"local"``: the local colour, reflectivity and
#: coverage; ``"bounce"``: the rays followed next). It only reads: the pixels are the same
#: with or without one. Renders pass none.
Probe = Callable[..., None]

#: The story's seams besides the hit tests (:mod:`glsandbox.story.seams`, an exercise's
#: function traced through one ray): each key of a World's ``hit_tests`` replaces one step.
#: ``"aabb"``: ``(node, o, d) -> bool`` per ray, whether it enters the node's box;
#: ``"backface"``: ``(world, node, o, d) -> (t, world triangle)`` of a one-sided mesh node;
#: ``"reflect"``: ``(d, n) -> R``; ``"phong"``: ``(world, light, nodes, values) -> term`` (a
#: light's per-hit colour, ``min(ka·C + lighting, 1)``); ``"shadow"``:
#: ``(world, point, start, light, cull, aabb) -> bool``; ``"normal"``: ``(world, node, triangles)
#: -> N`` (the face normal of a two-sided node's back-face test and of the secondary rays' offset).
#: Renders hand none: only :mod:`glsandbox.story` builds a World with them.
SEAMS = ("aabb", "backface", "reflect", "phong", "shadow", "normal")


@dataclass
class RenderStats:
    """What one numpy render did: rays cast by kind, and its time."""

    primary: int = 0
    shadow: int = 0
    reflection: int = 0
    #: Ray-shape tests done (one per ray and triangle, or ray and sphere):
    #: what backface culling, the AABB and the BVH save.
    tests: int = 0
    #: Ray-box slab tests done: the nodes' boxes (``aabb``), and with ``bvh``
    #: every BVH box a ray was tested against. What the shape tests saved costs these.
    box_tests: int = 0
    seconds: float = 0.0

    @property
    def rays(self) -> int:
        return self.primary + self.shadow + self.reflection


# --- finding hits: the nearest hit, and the shadow query ------------------------


@dataclass
class _Hits:
    t: NDArray[np.float64]  # inf for a miss
    node: NDArray[np.intp]  # -1 for a miss
    tri: NDArray[np.intp]  # world triangle index (meshes), -1 otherwise


def _rows(o: NDArray[np.float64], rays: NDArray[np.intp] | NDArray[np.bool_]) -> NDArray[np.float64]:
    """The origins of the rays ``rays`` picks: ``o`` itself when it is the one ``(3,)``
    origin every ray shares (primary rays start at the eye), else those rows."""
    return o if o.ndim == 1 else o[rays]


def _nearest(world: World, o: NDArray[np.float64], d: NDArray[np.float64], cull: bool | None, aabb: bool,
             stats: RenderStats | None = None, bvh: WorldBVH | None = None) -> _Hits:
    """Nearest hit with ``t > 0`` of each ray over every node (the course's ``min_indis`` loop).

    ``o`` is ``(N, 3)``, or ``(3,)`` for rays that share one origin (the eye):
    the kernels then form the origin's terms once (see
    :func:`~glsandbox.raytrace.shape_protocol.shared_origin`). ``cull`` is the render's
    ``cull_backfaces`` (None: each node's own), ``aabb`` whether boxes are
    tested first; ``bvh`` (the render's ``bvh=True``) traces mesh nodes through
    their BVHs instead of testing all their triangles.
    """
    return _top_level(world, o, d, np.inf, cull, aabb, -1, stats, bvh)


def _occluded(world: World, o: NDArray[np.float64], d: NDArray[np.float64], light: int, cull: bool | None,
              aabb: bool, stats: RenderStats | None = None, bvh: WorldBVH | None = None) -> NDArray[np.bool_]:
    """Gölge testi for shadow rays towards light ``light``: whether each ray ``o + s·d``
    hits something at ``0 < s < 1`` (``d`` reaches the light at ``s = 1``, so an
    occluder beyond the light never counts). The light's lamp is skipped, and so
    are blended nodes; a textured cut-out occludes only at its drawn texels
    (:func:`_drawn_texels`, an any-hit filter).

    With a BVH an any-hit query (a ray leaves at its first occluder); without one
    the nearest-hit scan cut at ``s = 1`` (what ``ray_acceleration`` counts)."""
    return _top_level(world, o, d, 1.0, cull, aabb, light, stats, bvh, first=bvh is not None).node >= 0


def _box_candidates(entry: NodeBVH, o: NDArray[np.float64], inverse: NDArray[np.float64],
                    limit: NDArray[np.float64] | float, stats: RenderStats | None) -> NDArray[np.intp]:
    """Which rays enter a mesh node's BVH root box before ``limit``: the node's world box
    (course "Hızlandırma: AABB"), widened as the BVH's own boxes are (a ray aimed
    exactly at a corner vertex must not miss it)."""
    if stats is not None:
        stats.box_tests += inverse.shape[1]
    lo, hi = entry.bvh.node_min[0], entry.bvh.node_max[0]
    pad = BVH_BOX_PAD_F64 * (1.0 + max(np.abs(lo).max(), np.abs(hi).max(), float(np.abs(o).max(initial=0.0))))
    near, far = AABB(lo - pad, hi + pad).slabs_reciprocal(o, inverse)
    return np.flatnonzero((near <= far) & (far >= 0.0) & (near <= limit))


def _add_counts(stats: RenderStats | None, counts: TraversalCounts) -> None:
    if stats is not None:
        stats.box_tests += counts.boxes
        stats.tests += counts.triangles


def _top_level(world: World, o: NDArray[np.float64], d: NDArray[np.float64], t_max: float, cull: bool | None,
               aabb: bool, light: int, stats: RenderStats | None, bvh: WorldBVH | None = None,
               first: bool = False) -> _Hits:
    """The top level, the one loop over a World's nodes that renders and tests use: the
    nearest hit with ``0 < t < t_max``, every node in scene order; ``light >= 0`` skips
    that light's lamp.

    Each node's box (its slab test, ``1/d`` formed once for all nodes) picks the rays
    that enter it before their best hit so far; only those are tested against the node,
    by its kind's hit function (:func:`_hit_kind`, in the node's own space). A strict ``<``
    keeps ties with the earlier node. With ``bvh``, a mesh node's rays are traced
    through its BVH instead (its root box widened as the BVH's own boxes are,
    :func:`_box_candidates`) with ``t_max`` their best hit so far (strictly nearer hits
    only, so the tie rule holds: the earlier node, then the lower triangle index).

    ``first`` (shadow rays with a BVH): an any-hit query. A ray that has found an
    occluder is tested against no further node, and a BVH answers with
    :func:`~glsandbox.raytrace.bvh_traverse.any_hit`; the hits' ``t`` and triangle are
    then not the nearest, only ``node >= 0`` means something.
    """
    n = d.shape[0]
    best_t = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,)).copy()
    best_node = np.full(n, -1, dtype=np.intp)
    best_tri = np.full(n, -1, dtype=np.intp)
    inverse = reciprocals(d) if aabb or bvh is not None else None  # 1/d once for every node's slab test
    boxes, backface = world.hit_tests.get("aabb"), world.hit_tests.get("backface")  # the story's seams
    for k, node in enumerate(world.nodes):
        if light >= 0 and node.lamp_of >> light & 1:
            continue
        one_sided = bool(node.cull if cull is None else cull)
        cut_out = light >= 0 and node.texel_shadow  # a shadow ray passes its cut-away texels
        # The rays still looking: all of them, or (any hit) those without an occluder yet.
        rays = np.flatnonzero(best_node < 0) if first else None
        ro = o if rays is None else _rows(o, rays)
        rinv = inverse if rays is None or inverse is None else inverse[:, rays]
        if bvh is not None and node.kind.triangles:
            entry = bvh.by_node.get(k)
            if entry is None:  # no triangle of non-zero area
                continue
            assert rinv is not None
            idx = _box_candidates(entry, ro, rinv, t_max if first else best_t, stats)
            if rays is not None:
                idx = rays[idx]
            if idx.size == 0:
                continue
            counts = TraversalCounts()
            if first:
                accept = _drawn_texels(world, k, _rows(o, idx), d[idx], t_max) if cut_out else None
                found = any_hit(entry.bvh, _rows(o, idx), d[idx], t_max, cull_backfaces=one_sided, counts=counts,
                                accept=accept)
                best_node[idx[found]] = k
                _add_counts(stats, counts)
                continue
            hits = closest_hit(entry.bvh, _rows(o, idx), d[idx], best_t[idx], cull_backfaces=one_sided,
                               counts=counts)
            _add_counts(stats, counts)
            won = hits.triangle >= 0  # strictly nearer than every earlier node's hit
            sel = idx[won]
            best_t[sel] = hits.t[won]
            best_node[sel] = k
            best_tri[sel] = entry.start + hits.triangle[won]
            continue
        count = n if rays is None else rays.size
        if boxes is not None and aabb:
            idx = np.flatnonzero(boxes(node, ro, d if rays is None else d[rays]))
        elif rinv is not None and aabb:
            if stats is not None:
                stats.box_tests += count
            near, far = AABB(node.box_min, node.box_max).slabs_reciprocal(ro, rinv)
            limit = best_t if rays is None else best_t[rays]
            idx = np.flatnonzero((near <= far) & (far > 0.0) & (near < limit))
        else:
            idx = np.arange(count)
        if rays is not None:
            idx = rays[idx]
        if idx.size == 0:
            continue
        if backface is not None and node.kind.triangles and one_sided:
            t, j = backface(world, node, _rows(o, idx), d[idx])
        elif node.kind.triangles and (cut_out or one_sided) and "triangles" not in world.hit_tests:
            # Every triangle (on a drawn texel, when cut out); with culling, the pairs facing
            # away are skipped after a dot product and only the tests run are counted.
            rows = slice(node.start, node.start + node.count)
            tested: list[int] = []
            t, j = nearest_watertight(world.v0[rows], world.v1[rows], world.v2[rows], _rows(o, idx), d[idx],
                                      cull_backfaces=one_sided, tested=tested,
                                      accept=_drawn_texels(world, k, _rows(o, idx), d[idx], t_max) if cut_out
                                      else None)
            j = np.where(j >= 0, j + node.start, -1)
            if stats is not None:
                stats.tests += tested[0] if one_sided else idx.size * max(node.count, 1)
        else:
            if stats is not None:
                stats.tests += idx.size * max(node.count, 1)
            t, j = _hit_node(world, k, _rows(o, idx), d[idx], one_sided)
        better = t < best_t[idx]
        sel = idx[better]
        best_t[sel] = t[better]
        best_node[sel] = k
        best_tri[sel] = j[better]
    hit = best_node >= 0
    return _Hits(np.where(hit, best_t, np.inf), best_node, best_tri)


def _drawn_texels(world: World, k: int, o: NDArray[np.float64], d: NDArray[np.float64], t_max: float) -> Accept:
    """The any-hit filter of shadow rays ``o + s·d`` meeting the textured cut-out ``k``
    (:attr:`~glsandbox.raytrace.world.NodeInfo.texel_shadow`): a hit before ``t_max``
    counts only where the part is drawn, its alpha (the colour's times the texel's,
    what :func:`_surface` gives the shading) at or above the cutoff; elsewhere the ray
    goes on, as the rasterizer's planar shadow and shadow map discard those texels."""
    node = world.nodes[k]

    def accept(rays: NDArray[np.intp], triangles: NDArray[np.intp], t: NDArray[np.float64]) -> NDArray[np.bool_]:
        ok = t < t_max
        sel = np.flatnonzero(ok)
        if sel.size:
            hits = _Hits(t[sel], np.full(sel.size, k, dtype=np.intp), triangles[sel] + node.start)
            alpha = _surface(world, hits, _rows(o, rays[sel]), d[rays[sel]], need_spawn=False)[3]
            ok[sel] = alpha >= node.alpha_cutoff
        return ok

    return accept


def _hit_node(world: World, k: int, o: NDArray[np.float64], d: NDArray[np.float64], one_sided: bool
              ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Rays against node ``k`` alone: ``(t, world triangle index)``, ``(inf, −1)`` for a miss
    and ``−1`` for an analytic node's hits.

    An analytic node is its unit shape under its model matrix: the ray is taken
    into the shape's own space (the sphere's Işın-Küre kesim testi there; ``t`` is
    kept by the affine map). A mesh node's triangles are tested with the watertight test
    (:func:`~glsandbox.raytrace.watertight.nearest_watertight`, as the BVH does), the
    lowest index winning a tie. ``one_sided``: backface culling (course "Hızlandırma:
    backface culling").
    """
    node = world.nodes[k]
    replaced = world.hit_tests.get(_hit_test_name(node)) if world.hit_tests else None
    if replaced is not None:
        return _replaced_hit(replaced, world, node, o, d, one_sided)
    return _hit_kind(node)(world, node, o, d, one_sided)


def _hit_test_name(node: NodeInfo) -> str:
    """The name :func:`render_viewport`'s ``hit_tests`` replaces a node's test by: ``"triangles"``
    for a mesh, else its kind's (``"sphere"``)."""
    return "triangles" if node.kind.triangles else str(node.kind.value)


def _replaced_hit(test: HitTest, world: World, node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64],
                  one_sided: bool) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """A node's rays through a hit test handed to :func:`render_viewport` (``hit_tests``).

    A sphere node's test gets the rays in the unit sphere's own space, ``(origins,
    directions)`` (directions not unit: ``t`` is the affine map's, as the engine's own);
    a mesh node's gets ``(origins, directions, v0, v1, v2, one_sided)`` with the node's
    triangles and answers ``(t, triangle index within them)``.
    """
    o = np.broadcast_to(o, d.shape)
    if not node.kind.triangles:
        oo, dd = _own_space(node, o, d)
        t = np.asarray(test(oo, dd), dtype=np.float64).reshape(d.shape[0])
        return np.where(t > 0.0, t, np.inf), np.full(d.shape[0], -1, dtype=np.intp)
    rows = slice(node.start, node.start + node.count)
    t, j = test(o, d, world.v0[rows], world.v1[rows], world.v2[rows], one_sided)
    t, j = np.asarray(t, dtype=np.float64), np.asarray(j, dtype=np.intp)
    return np.where(t > 0.0, t, np.inf), np.where(j >= 0, j + node.start, -1)


def _own_space(node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64]
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rays taken into an analytic node's own space by its inverse model matrix (an
    affine map keeps ``t``: ``M⁻¹(O + t·d) = M⁻¹O + t·(M⁻¹d)``)."""
    inv = node.inverse
    return o @ inv[:3, :3].T + inv[:3, 3], d @ inv[:3, :3].T


def _hit_shape(world: World, node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64], one_sided: bool
               ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """An analytic node's hits: its kind's own-space test (``raytrace/shapes/<kind>.py``)."""
    oo, dd = _own_space(node, o, d)
    return node.kind.shape.hit(oo, dd, one_sided), np.full(d.shape[0], -1, dtype=np.intp)


def _hit_triangles(world: World, node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64], one_sided: bool
                   ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    rows = slice(node.start, node.start + node.count)
    t, j = nearest_watertight(world.v0[rows], world.v1[rows], world.v2[rows], o, d, cull_backfaces=one_sided)
    return t, np.where(j >= 0, j + node.start, -1)


# --- surface attributes at the hits --------------------------------------------


def _barycentric(v0: NDArray[np.float64], e1: NDArray[np.float64], e2: NDArray[np.float64], o: NDArray[np.float64],
                 d: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Möller–Trumbore's ``(u, v)`` of each ray on its own triangle ``(V0, e1, e2)``: ``P = V0 + u·e1 + v·e2``."""
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    det = np.where(det == 0.0, 1.0, det)
    s = o - v0
    q = np.cross(s, e1)
    return np.einsum("ij,ij->i", s, p) / det, np.einsum("ij,ij->i", d, q) / det


def _sample(image: NDArray[np.float64], wrap: int, uv: NDArray[np.float64]) -> NDArray[np.float64]:
    """Bilinear filtering of ``image`` (row 0 = v 0, as GL reads the uploaded image) at ``uv``."""
    h, w = image.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]

    def wrap_index(i: NDArray[np.float64], size: int) -> NDArray[np.intp]:
        i = i.astype(np.intp)
        if wrap == 0:  # repeat
            return np.mod(i, size)
        if wrap == 1:  # mirrored repeat: 0..size-1, size-1..0, ...
            m = np.mod(i, 2 * size)
            return np.where(m < size, m, 2 * size - 1 - m)
        return np.clip(i, 0, size - 1)  # clamp to edge

    xa, xb = wrap_index(x0, w), wrap_index(x0 + 1, w)
    ya, yb = wrap_index(y0, h), wrap_index(y0 + 1, h)
    top = image[ya, xa] * (1 - fx) + image[ya, xb] * fx
    bottom = image[yb, xa] * (1 - fx) + image[yb, xb] * fx
    return top * (1 - fy) + bottom * fy


@dataclass
class _Spawn:
    """Where secondary rays start (pbrt-v4's robust spawned origins): the hit point
    recomputed where its rounding error is bounded, that bound per component, and
    the geometric normal. A triangle's point is ``b0·V0 + b1·V1 + b2·V2``, off its
    plane by at most ``γ(7)·Σ|b_i·V_i|``; a sphere's is ``O + t·D`` with
    ``γ(16)·(|O| + |t·D|)`` (:mod:`glsandbox.raytrace.constants`)."""

    point: NDArray[np.float64]
    error: NDArray[np.float64]
    normal: NDArray[np.float64]

    def subset(self, rows: NDArray[np.intp] | NDArray[np.bool_]) -> _Spawn:
        return _Spawn(self.point[rows], self.error[rows], self.normal[rows])


def _surface(world: World, hits: _Hits, o: NDArray[np.float64], d: NDArray[np.float64], need_spawn: bool = True
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                        _Spawn | None]:
    """``(point, unit normal, base colour, alpha, spawn)`` for hit rays (all of ``hits`` must be
    hits). ``alpha`` is the material colour's times the texture's (what a cut-out or a blend
    reads); ``spawn`` None unless ``need_spawn`` (no shadow ray or bounce leaves these hits)."""
    n = d.shape[0]
    point = o + hits.t[:, None] * d
    # Analytic shapes' spawn points are the ray's point; triangles' are replaced below.
    spawn = _Spawn(point.copy(), gamma(RAY_POINT_GAMMA, UNIT_F64) * (np.abs(o) + np.abs(hits.t[:, None] * d)),
                   np.zeros((n, 3))) if need_spawn else None
    normal = np.zeros((n, 3))
    base = np.zeros((n, 3))
    alpha = np.ones(n)
    for k, node in enumerate(world.nodes):
        sel = np.nonzero(hits.node == k)[0]
        if sel.size == 0:
            continue
        normal[sel], uv, colors = _surface_kind(node)(world, node, hits, sel, o, d, point, spawn)
        color = np.broadcast_to(node.color, (sel.size, 3)).copy()
        if colors is not None:  # vertex colours, times the material colour (basic.glsl, phong.glsl)
            color *= colors
        alpha[sel] = node.alpha
        if node.texture >= 0:
            image, wrap = world.textures[node.texture]
            texel = _sample(image, wrap, uv)
            color *= texel[:, :3]
            alpha[sel] *= texel[:, 3]
        base[sel] = color
    normal /= np.maximum(length(normal), LENGTH_TINY)[:, None]
    if spawn is not None:
        spawn.normal /= np.maximum(length(spawn.normal), LENGTH_TINY)[:, None]
    return point, normal, base, alpha, spawn


def _surface_shape(world: World, node: NodeInfo, hits: _Hits, sel: NDArray[np.intp], o: NDArray[np.float64],
                   d: NDArray[np.float64], point: NDArray[np.float64], spawn: _Spawn | None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]:
    """An analytic node's (normal, uv, vertex colour) at its hits: its kind's own-space surface at
    ``M⁻¹P``, the normal taken to the world by the normal matrix ``(M³ˣ³)⁻ᵀ``; its spawn points stay ``O + t·D``."""
    inv = node.inverse
    q = point[sel] @ inv[:3, :3].T + inv[:3, 3]  # the hit in the kind's own space
    own, uv = node.kind.shape.surface(q)
    normal = own @ node.normal_matrix.T
    if spawn is not None:
        spawn.normal[sel] = normal
    return normal, uv, np.ones((sel.size, 3)) if node.mode == 1 else None


def _surface_triangles(world: World, node: NodeInfo, hits: _Hits, sel: NDArray[np.intp], o: NDArray[np.float64],
                       d: NDArray[np.float64], point: NDArray[np.float64], spawn: _Spawn | None
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """A mesh node's (normal, uv, vertex colour) at its hits, barycentric (uv None without a
    texture: nothing reads it); its spawn points are the barycentric points with their error
    bound and the face normal."""
    tri = hits.tri[sel]
    v0, v1, v2 = world.v0[tri], world.v1[tri], world.v2[tri]  # each gathered once
    e1 = v1 - v0
    e2 = v2 - v0
    u, v = _barycentric(v0, e1, e2, _rows(o, sel), d[sel])
    w = (1.0 - u - v)[:, None], u[:, None], v[:, None]  # weights of V0, V1, V2
    normal = _interpolate(world.normals[tri], w)
    face = np.cross(e1, e2) if node.two_sided or spawn is not None else None
    normals = world.hit_tests.get("normal")  # the story's seam
    if normals is not None and face is not None:
        face = normals(world, node, tri)
    if node.two_sided:
        # A back face seen (the ray runs along the face normal: clockwise from the eye,
        # the rasterizer's !gl_FrontFacing) is lit as its other side: the normal reversed.
        back = np.einsum("ij,ij->i", face, d[sel]) > 0.0
        normal[back] *= -1.0
    if spawn is not None:
        corners = v0 * w[0], v1 * w[1], v2 * w[2]
        spawn.point[sel] = corners[0] + corners[1] + corners[2]
        reach = np.abs(corners[0], out=corners[0])
        reach += np.abs(corners[1])
        reach += np.abs(corners[2])
        spawn.error[sel] = gamma(TRIANGLE_POINT_GAMMA, UNIT_F64) * reach
        spawn.normal[sel] = face
    colors = _interpolate(world.colors[tri], w) if node.mode == 1 or node.vertex_colors else None  # when shown
    uv = _interpolate(world.uvs[tri], w) if node.texture >= 0 else None  # read by a texture only
    return normal, uv, colors


def _hit_kind(node: NodeInfo) -> Callable[..., tuple[NDArray[np.float64], NDArray[np.intp]]]:
    """A node's hit test ``(world, node, o, d, one_sided) -> (t, world triangle or −1)``."""
    return _hit_triangles if node.kind.triangles else _hit_shape


def _surface_kind(node: NodeInfo) -> Callable[..., tuple[NDArray[np.float64], NDArray[np.float64] | None,
                                                         NDArray[np.float64] | None]]:
    """A node's surface ``-> (normal, uv, vertex colour or None unless the node shows them)``,
    filling the spawn points when given."""
    return _surface_triangles if node.kind.triangles else _surface_shape


def _interpolate(values: NDArray[np.float64], w: tuple[NDArray[np.float64], ...]) -> NDArray[np.float64]:
    """``w0·values[:, 0] + w1·values[:, 1] + w2·values[:, 2]``: per-vertex values (``(N, 3, k)``)
    at the barycentric weights ``w`` (three ``(N, 1)``), summed in that order."""
    return values[:, 0] * w[0] + values[:, 1] * w[1] + values[:, 2] * w[2]


def _offset(spawn: _Spawn, normal: NDArray[np.float64], side: NDArray[np.float64],
            simple: bool = False) -> NDArray[np.float64]:
    """Secondary-ray origins off their surface: each spawn point moved along its
    geometric normal by its error bound's reach along it, ``Σ|n_i|·err_i``, then
    every moved component rounded one float further (so the move cannot round back
    onto the surface). The side is the one the shading ``normal`` puts ``side``
    on, as the shading decides whether a point faces its light (on a tessellated
    sphere's terminator the facet may face away while the normal does not: the ray
    then starts outside and the facet shadows it). ``simple``: the teaching variant,
    :data:`~glsandbox.raytrace.constants.SIMPLE_OFFSET`·max(1, max|P|)."""
    p, n = spawn.point, spawn.normal
    if simple:
        reach = SIMPLE_OFFSET * np.maximum(1.0, np.abs(p).max(axis=1))
    else:
        reach = np.einsum("ij,ij->i", np.abs(n), spawn.error)
    sign = np.where(np.einsum("ij,ij->i", normal, side) < 0.0, -1.0, 1.0)
    sign *= np.where(np.einsum("ij,ij->i", n, normal) < 0.0, -1.0, 1.0)  # a geometric normal against the shading one
    return moved_off(p, (reach * sign)[:, None] * n)


# --- shading and bounces -------------------------------------------------------


def _shade(world: World, hits: _Hits, o: NDArray[np.float64], d: NDArray[np.float64], shadows: bool,
           cull: bool | None, aabb: bool, stats: RenderStats, bvh: WorldBVH | None = None, simple: bool = False,
           bounce: bool = True, probe: Probe | None = None
           ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], _Spawn | None]:
    """Local colour of hit rays (the raster's per-light formula), plus normal, alpha and
    spawn point for bounces (``bounce``: some may follow; else the spawn is None).
    ``probe`` is told the surface and each light's terms (see :data:`Probe`)."""
    point, normal, base, alpha, spawn = _surface(world, hits, o, d, need_spawn=shadows or bounce)
    if probe is not None:
        probe("surface", point=point, normal=normal, base=base, alpha=alpha, spawn=spawn, lit=world.materials.lit[hits.node])
    color = base.copy()  # unlit surfaces keep their colour
    table = world.materials
    lit = table.lit[hits.node]
    if lit.any():
        idx = np.nonzero(lit)[0]
        every = idx.size == lit.size  # every hit lit (a lit model): the arrays as they are, read only
        pick = slice(None) if every else idx
        nodes = hits.node[pick]
        ka = table.ka[nodes][:, None]
        kd = table.kd[nodes][:, None]
        ks = table.ks[nodes][:, None]
        shin = table.shininess[nodes]
        blinn = table.blinn[nodes]
        p, nrm, mesh = point[pick], normal[pick], base[pick]
        lit_spawn = spawn if every or spawn is None else spawn.subset(idx)
        dl = d[pick]
        to_eye = -dl / length(dl)[:, None]
        total = np.zeros_like(mesh)
        shading, shadow_test = world.hit_tests.get("phong"), world.hit_tests.get("shadow")  # the story's seams
        for index, (light, light_color) in enumerate(zip(world.light_positions, world.light_colors)):
            to_light = light - p
            to_light /= np.maximum(length(to_light), LENGTH_TINY)[:, None]
            n_dot_l = np.einsum("ij,ij->i", nrm, to_light)
            diffuse = np.maximum(n_dot_l, 0.0)[:, None] * mesh * light_color
            reflected = -to_light + 2.0 * n_dot_l[:, None] * nrm  # fromLight − 2(fromLight·N)N
            r_dot_e = np.einsum("ij,ij->i", to_eye, reflected)
            cosine = r_dot_e
            if blinn.any():  # Blinn-Phong: N·H, H the unit halfway vector
                halfway = to_light + to_eye
                halfway /= np.maximum(length(halfway), LENGTH_TINY)[:, None]
                cosine = np.where(blinn, np.einsum("ij,ij->i", nrm, halfway), r_dot_e)
            cosine = np.maximum(cosine, 0.0)
            highlight = np.where(n_dot_l > 0.0, cosine ** shin, 0.0)
            specular = highlight[:, None] * light_color
            lighting = kd * diffuse + ks * specular
            start = blocked = None
            if shadows:
                assert lit_spawn is not None
                start = _offset(lit_spawn, nrm, light - p, simple)
                stats.shadow += idx.size
                blocked = shadow_test(world, p, start, index, cull, aabb) if shadow_test is not None else \
                    _occluded(world, start, light - start, index, cull, aabb, stats, bvh)
                lighting *= np.where(blocked, 0.0, 1.0)[:, None]  # in shadow only the ambient term stays
            term = np.minimum(ka * mesh + lighting, 1.0)
            given = None
            if shading is not None:
                given = term = shading(world, index, nodes, {"normal": nrm, "to_light": light - p, "to_eye": -dl,
                                                             "color": mesh, "ka": ka, "kd": kd, "ks": ks,
                                                             "shininess": shin, "blinn": blinn,
                                                             "blocked": blocked, "term": term})
            total += term
            if probe is not None:
                probe("light", index=index, ka=ka, kd=kd, ks=ks, shininess=shin, blinn=blinn, mesh=mesh,
                      to_light=to_light, to_eye=to_eye, n_dot_l=n_dot_l, cosine=cosine, diffuse=diffuse,
                      specular=specular, start=start, blocked=blocked, given=given)
        color[pick] = total
    return color, normal, alpha, spawn


def _trace(world: World, o: NDArray[np.float64], d: NDArray[np.float64], max_depth: int, shadows: bool,
           cull: bool | None, aabb: bool, stats: RenderStats, bvh: WorldBVH | None = None,
           simple: bool = False, probe: Probe | None = None) -> NDArray[np.float64]:
    """Colour of each ray, reflections followed iteratively: ``(1−r)·local + r·reflected``.

    A see-through surface (a cut-out, a blended one) covers a share ``a`` of what lies
    behind it (:func:`~glsandbox.raytrace.world.coverage`): ``a·local + (1−a)·behind``,
    the ray going on straight through it. Such a pass is one of the ``max_depth`` bounces
    (at the last one the surface's own colour stands in), and a see-through surface does
    not also reflect: one ray per pixel, as in the GLSL engine's loop. ``probe`` is told
    every step's values (:data:`Probe`; ``glsandbox explain`` records one ray's)."""
    n = d.shape[0]
    out = np.zeros((n, 3))
    weight = np.ones(n)
    alive = np.arange(n)
    for depth in range(max_depth + 1):
        hits = _nearest(world, o, d, cull, aabb, stats, bvh)
        if probe is not None:
            probe("ray", depth=depth, origin=o, direction=d, weight=weight, t=hits.t, node=hits.node, tri=hits.tri)
        miss = hits.node < 0
        out[alive[miss]] += weight[miss, None] * world.background
        hit = ~miss
        if not hit.any():
            break
        sub = _Hits(hits.t[hit], hits.node[hit], hits.tri[hit])
        last = depth >= max_depth
        local, normal, alpha, spawn = _shade(world, sub, _rows(o, hit), d[hit], shadows, cull, aabb, stats, bvh,
                                             simple, bounce=not last, probe=probe)
        table = world.materials
        r = table.reflectivity[sub.node] if not last else np.zeros(sub.node.size)
        a = np.ones(sub.node.size) if last else coverage(table.alpha_mode[sub.node], alpha,
                                                          table.alpha_cutoff[sub.node])
        through = a < 1.0
        r = np.where(through, 0.0, r)
        if probe is not None:
            probe("local", local=local, reflectivity=r, coverage=a, last=last)
        w = weight[hit]
        out[alive[hit]] += (w * a * (1.0 - r))[:, None] * local
        bounce = (r > 0.0) | through
        if not bounce.any():
            break
        dh = d[hit][bounce]
        nh = normal[bounce]
        on = through[bounce][:, None]
        mirror = world.hit_tests.get("reflect")  # the story's seam
        reflected = mirror(dh, nh) if mirror is not None else \
            dh - 2.0 * np.einsum("ij,ij->i", dh, nh)[:, None] * nh  # Yansıma vektörü
        assert spawn is not None  # not the last depth: _shade made it
        o = _offset(spawn.subset(bounce), nh, np.where(on, dh, -dh), simple)  # behind the surface, or back in front
        d = np.where(on, dh, reflected)
        weight = np.where(through, w * (1.0 - a), w * r)[bounce]
        alive = alive[hit][bounce]
        if probe is not None:
            probe("bounce", through=through[bounce], reflected=reflected)
        stats.reflection += alive.size
    return out


def to_rgba8(rgb: NDArray[np.float64]) -> NDArray[np.uint8]:
    """Clamp to 0..1 and round to 8 bits as GL's unorm conversion does; alpha 255."""
    c = np.clip(rgb, 0.0, 1.0) * 255.0  # the same steps in place: floor(x·255 + 0.5)
    c += 0.5
    np.floor(c, out=c)
    out = np.empty((*c.shape[:-1], 4), dtype=np.uint8)
    out[..., :3] = c  # astype's conversion, written into place
    out[..., 3] = 255
    return out


#: The World (and its BVHs) of each Scene object rendered, while the Scene lives: a
#: Scene is immutable, and a 1M-triangle World took 1.1 s to build, half of its
#: 800x600 frame. The window's lessons make a new Scene every frame (no reuse there).
_WORLDS: weakref.WeakKeyDictionary[Scene, dict[tuple[int, bool, bool], tuple[World, WorldBVH | None]]] = \
    weakref.WeakKeyDictionary()


def _world_of(scene: Scene, viewport: int, analytic_spheres: bool, bvh: bool) -> tuple[World, WorldBVH | None]:
    kept = _WORLDS.setdefault(scene, {})
    key = (viewport, analytic_spheres, bvh)
    if key not in kept:
        world = build_world(scene, viewport, analytic_spheres=analytic_spheres)
        kept[key] = (world, WorldBVH.from_world(world) if bvh else None)  # BVHs: cached by content too
    return kept[key]


#: The primary rays of each Scene object rendered, per viewport and size, while the Scene
#: lives (its camera cannot change): a frame of the same Scene again casts them without
#: making them (about 10 ms at 800x600), as Embree's bench caster keeps its rays. Read-only.
_RAYS: weakref.WeakKeyDictionary[Scene, dict[tuple[int, int, int], tuple[NDArray[np.float64], NDArray[np.float64]]]] \
    = weakref.WeakKeyDictionary()


def _rays_of(scene: Scene, viewport: int, width: int, height: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    kept = _RAYS.setdefault(scene, {})
    key = (viewport, width, height)
    if key not in kept:
        vp = scene.viewports[viewport]
        eye, dirs = camera_rays(vp.camera or scene.camera, width, height)
        eye.setflags(write=False)
        dirs.setflags(write=False)
        kept[key] = (eye, dirs)
    return kept[key]


def render_viewport(scene: Scene, size: tuple[int, int], viewport: int = 0, *, max_depth: int = 2,
                    shadows: bool = True, cull_backfaces: bool | None = None, aabb: bool = True,
                    bvh: bool = True, analytic_spheres: bool = True,
                    stats: RenderStats | None = None, offset: str = "bound",
                    hit_tests: Mapping[str, HitTest] | None = None) -> NDArray[np.uint8]:
    """Trace one viewport at ``size``: ``(H, W, 4)`` uint8, top row first (see :func:`to_rgba8`).

    The options are :func:`glsandbox.raytrace.render`'s; ``stats`` counts the rays cast.
    ``hit_tests`` replaces the engine's own hit test of a node kind, ``"sphere"`` or
    ``"triangles"``, by a function of whole batches of rays (see :func:`_replaced_hit`):
    the seam through which an exercise renders a scene with a student's function (mesh
    nodes are then tested triangle by triangle, without their BVH).
    """
    width, height = size
    world, accel = _world_of(scene, viewport, analytic_spheres, bvh and not hit_tests)
    if hit_tests:
        world, accel = replace(world, hit_tests=dict(hit_tests)), None
    eye, dirs = _rays_of(scene, viewport, width, height)
    stats = stats if stats is not None else RenderStats()
    stats.primary += dirs.shape[0]
    rgb = np.empty((dirs.shape[0], 3))
    for lo in range(0, dirs.shape[0], RAY_BLOCK):
        rays = slice(lo, lo + RAY_BLOCK)
        rgb[rays] = _trace(world, eye, dirs[rays], max_depth, shadows, cull_backfaces, aabb, stats, accel,
                           OFFSETS[offset])
    return to_rgba8(rgb.reshape(height, width, 3))
