"""The BVHs of a :class:`~glsandbox.raytrace.world.World`: one per mesh node, and their root boxes.

:func:`~glsandbox.raytrace.world.build_world` puts every node's triangles
into world space in one array, node after node (``NodeInfo.start`` /
``count``). :class:`WorldBVH` builds (or finds in the cache,
:func:`~glsandbox.raytrace.bvh.bvh_for_triangles`) a BVH over each mesh
node's world triangles, so a node that did not move is not built again.

The top level, the loop over the nodes that decides which nodes a ray
enters at all (the course's per-object AABB test) and hands its rays to the
node's BVH or to its kind's own hit function, is one function, the numpy
engine's ``_top_level`` (:mod:`glsandbox.raytrace.numpy_engine`): renders
and tests both go through it. A scene has few nodes (a lesson has at most
dozens), so it is a loop over nodes in scene order, vectorised over the
rays; on an equal ``t`` the earlier node keeps the hit, and within a node
the lower triangle.

Analytic shapes (a :class:`~glsandbox.raytrace.world.NodeKind` whose shape is
not triangles) have no BVH here: the top level tests them with their own
hit function.
"""

from __future__ import annotations

from dataclasses import dataclass

from glsandbox.raytrace.bvh import BVH, bvh_for_triangles
from glsandbox.raytrace.world import World

__all__ = ["NodeBVH", "WorldBVH"]


@dataclass(frozen=True)
class NodeBVH:
    """One mesh node's BVH: ``node`` its index in ``World.nodes``, ``start`` its first world triangle."""

    node: int
    start: int
    bvh: BVH
    cull: bool
    lamp_of: int


class WorldBVH:
    """Per-node BVHs of a World's mesh nodes (traced by the numpy engine's top level)."""

    def __init__(self, nodes: list[NodeBVH]) -> None:
        self.nodes = nodes
        #: The entries by ``World.nodes`` index (mesh nodes with triangles of non-zero area only).
        self.by_node = {entry.node: entry for entry in nodes}

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
        return cls(nodes)
