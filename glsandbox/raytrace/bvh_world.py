"""The top level: one BVH per mesh node of a :class:`~glsandbox.raytrace.world.World`, and the nodes' boxes.

:func:`~glsandbox.raytrace.world.build_world` puts every node's triangles
into world space in one array, node after node (``NodeInfo.start`` /
``count``). :class:`WorldBVH` builds (or finds in the cache,
:func:`~glsandbox.raytrace.bvh.bvh_for_triangles`) a BVH over each mesh
node's world triangles, so a node that did not move is not built again, and
keeps the nodes' boxes as the top level: the course's per-object AABB test
decides which nodes a ray enters at all, the node's BVH does the rest.

A scene has few nodes (a lesson has at most dozens), so the top level is a
loop over nodes in scene order, each taking the rays whose box test passes
(vectorised over the rays). A node's rays are traced with ``t_max`` equal to
their best hit so far: strictly nearer hits replace it, so on an equal
``t`` the earlier node keeps it, and within a node the lower triangle: the
same tie rule as :func:`glsandbox.raytrace.numpy_engine._nearest`, by world
triangle index.

Analytic shapes (a :class:`~glsandbox.raytrace.world.NodeKind` whose shape is
not triangles) are not the BVH's business: this
level answers for mesh nodes only (the engine tests its spheres as before).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.aabb import AABB, reciprocals
from glsandbox.raytrace.base import broadcast_rays
from glsandbox.raytrace.bvh import BVH, bvh_for_triangles
from glsandbox.raytrace.bvh_traverse import any_hit, closest_hit
from glsandbox.raytrace.constants import BVH_BOX_PAD_F64
from glsandbox.raytrace.world import World

__all__ = ["NodeBVH", "WorldBVH", "WorldHits"]


@dataclass(frozen=True)
class NodeBVH:
    """One mesh node's BVH: ``node`` its index in ``World.nodes``, ``start`` its first world triangle."""

    node: int
    start: int
    bvh: BVH
    cull: bool
    lamp_of: int


@dataclass
class WorldHits:
    """Nearest hits over the mesh nodes: ``t`` (inf: miss), ``node`` and world ``triangle``
    (−1: miss), barycentrics ``u, v`` of the world triangle."""

    t: NDArray[np.float64]
    node: NDArray[np.int64]
    triangle: NDArray[np.int64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]


class WorldBVH:
    """Per-node BVHs of a World's mesh nodes, with their boxes as the top level."""

    def __init__(self, nodes: list[NodeBVH], box_min: NDArray[np.float64], box_max: NDArray[np.float64]) -> None:
        self.nodes = nodes
        #: The entries by ``World.nodes`` index (mesh nodes with triangles of non-zero area only).
        self.by_node = {entry.node: entry for entry in nodes}
        self.box_min = box_min
        self.box_max = box_max

    @classmethod
    def from_world(cls, world: World) -> WorldBVH:
        """Build (or fetch from the cache) a BVH for every mesh node of ``world``."""
        nodes: list[NodeBVH] = []
        for k, info in enumerate(world.nodes):
            if not info.kind.triangles or info.count == 0:
                continue
            part = slice(info.start, info.start + info.count)
            bvh = bvh_for_triangles(world.v0[part], world.v1[part], world.v2[part])
            if bvh.empty:  # only zero-area triangles: nothing to hit
                continue
            nodes.append(NodeBVH(k, info.start, bvh, bool(info.cull), int(info.lamp_of)))
        box_min = np.array([n.bvh.node_min[0] for n in nodes]).reshape(-1, 3)
        box_max = np.array([n.bvh.node_max[0] for n in nodes]).reshape(-1, 3)
        return cls(nodes, box_min, box_max)

    def _candidates(self, i: int, o: NDArray[np.float64], inverse: NDArray[np.float64],
                    limit: NDArray[np.float64]) -> NDArray[np.intp]:
        """Rays whose slab test against node ``i``'s box passes before ``limit`` (Hızlandırma: AABB).
        The box test is only a shortcut: the node's own BVH tests robustly."""
        lo, hi = self.box_min[i], self.box_max[i]
        pad = BVH_BOX_PAD_F64 * (1.0 + max(np.abs(lo).max(), np.abs(hi).max()))
        near, far = AABB(lo - pad, hi + pad).slabs_reciprocal(o, inverse)
        return np.flatnonzero((near <= far) & (far >= 0.0) & (near <= limit))

    def closest_hit(self, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = np.inf, *,
                    cull_backfaces: bool | None = None) -> WorldHits:
        """The nearest mesh hit with ``0 < t < t_max`` per ray; ``cull_backfaces=None``
        culls per node as the rasterizer does (``NodeInfo.cull``)."""
        o, d = broadcast_rays(origins, directions)
        n = d.shape[0]
        best_t = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,)).copy()
        out = WorldHits(np.full(n, np.inf), np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64),
                        np.zeros(n), np.zeros(n))
        inverse = reciprocals(d)
        for i, entry in enumerate(self.nodes):
            rays = self._candidates(i, o, inverse, best_t)
            if rays.size == 0:
                continue
            cull = entry.cull if cull_backfaces is None else bool(cull_backfaces)
            hits = closest_hit(entry.bvh, o[rays], d[rays], best_t[rays], cull_backfaces=cull)
            won = hits.triangle >= 0  # strictly nearer than every earlier node's hit
            sel = rays[won]
            best_t[sel] = hits.t[won]
            out.t[sel] = hits.t[won]
            out.node[sel] = entry.node
            out.triangle[sel] = entry.start + hits.triangle[won]
            out.u[sel] = hits.u[won]
            out.v[sel] = hits.v[won]
        return out

    def any_hit(self, origins: ArrayLike, directions: ArrayLike, t_max: ArrayLike = 1.0, *,
                cull_backfaces: bool | None = None, light: int = -1) -> NDArray[np.bool_]:
        """Whether any mesh node is hit with ``0 < t < t_max`` (shadow rays). ``light >= 0``
        skips that light's lamps (``NodeInfo.lamp_of``), as the engines' shadow query does."""
        o, d = broadcast_rays(origins, directions)
        n = d.shape[0]
        limit = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,)).copy()
        found = np.zeros(n, dtype=bool)
        inverse = reciprocals(d)
        for i, entry in enumerate(self.nodes):
            if light >= 0 and entry.lamp_of >> light & 1:
                continue
            rays = self._candidates(i, o, inverse, limit)
            rays = rays[~found[rays]]
            if rays.size == 0:
                continue
            cull = entry.cull if cull_backfaces is None else bool(cull_backfaces)
            found[rays] |= any_hit(entry.bvh, o[rays], d[rays], limit[rays], cull_backfaces=cull)
        return found
