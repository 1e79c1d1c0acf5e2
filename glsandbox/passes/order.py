"""The order blended parts are drawn in: farthest from the eye first.

Sorted by part, not by triangle: the planners of the draw and reflection passes
and :func:`glsandbox.plan.motion_decisions` all sort with these.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from glsandbox.geometry import Mesh
from glsandbox.scene import Camera, Node


_CENTRES: weakref.WeakKeyDictionary[Mesh, np.ndarray] = weakref.WeakKeyDictionary()


def distance(node: Node, camera: Camera | np.ndarray) -> float:
    """How far the centre of a node's bounding box lies from the eye, in world space:
    blended nodes are drawn farthest first, so each blends over what lies behind it
    (sorted by part, not by triangle: a part that wraps round another can still be
    wrong, as in any rasterizer that sorts objects). ``camera``: a camera, or the eye's position."""
    centre = _CENTRES.get(node.mesh)
    if centre is None:  # meshes are immutable: once per mesh, not per frame
        points = np.asarray(node.mesh.positions, dtype=np.float64)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2.0 if points.size else np.zeros(3)
        _CENTRES[node.mesh] = centre
    world = np.asarray(node.model, dtype=np.float64) @ np.append(centre, 1.0)
    return float(np.linalg.norm(world[:3] - np.asarray(camera.eye if isinstance(camera, Camera) else camera,
                                                        dtype=np.float64)))


def farthest_first(blended: list[tuple[Node, Any]], camera: Camera | np.ndarray) -> list[tuple[Node, Any]]:
    """``(node, anything)`` pairs of blended nodes in drawing order: farthest from the eye first
    (``camera``: a camera, or the eye's position)."""
    return sorted(blended, key=lambda pair: -distance(pair[0], camera))


def mirrored_eye(mirror: Any, camera: Camera) -> np.ndarray:
    """The eye's mirror image: seen in the mirror, a node lies as far as it lies from this point
    (the reflection is an isometry), so blended reflected nodes are sorted from it."""
    return (mirror.matrix() @ np.append(np.asarray(camera.eye, dtype=np.float64), 1.0))[:3]

