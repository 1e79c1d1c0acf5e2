"""Shadow maps: which lights need one, and the camera each is drawn from.

A shadow map is a depth picture of the scene taken from a light: a texel
holds how far the nearest caster is along that texel's ray. A lit receiver
point p is in shadow when something nearer than p lies on its ray to the
light: project p with the light's camera and compare its depth with the
texel's (OpenGL's comparison sampler does the compare, and percentage-closer
filtering averages several). Unlike the planar shadow (``XMMatrixShadow``,
one receiving plane), any surface receives and any shape casts, at the price
of a resolution (aliased edges), a depth bias (acne below it, peter-panning
above it) and a second pass.

The light's camera here is one perspective frustum (a point light has no
direction of its own): from the light towards the centre of the casters'
bounds, fitted to the casters and receivers and at most :attr:`ShadowMap.fov`
wide (:func:`light_frame`). A cube map (six frusta) would cover every
direction; this covers what the lessons need, and a point outside the
frustum is treated as lit. Pure numpy: no GL in here.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh
from glsandbox.scene import Light, Node, Scene, scene_origin


def casting_light(scene: Scene) -> int | None:
    """The index of the light with a shadow map, or None. One light at most:
    the phong shader samples one map (a second would need a sampler array)."""
    lights = [i for i, light in enumerate(scene.lights) if light.shadow is not None]
    if len(lights) > 1:
        raise SandboxError(f"lights {', '.join(map(str, lights))} all cast shadow maps; at most one light may "
                           "(ShadowMap on one light, the others without)")
    return lights[0] if lights else None


def raster_viewports(scene: Scene) -> list[int]:
    return [i for i, viewport in enumerate(scene.viewports) if viewport.renderer == "raster"]


def receivers(scene: Scene) -> list[Node]:
    """Lit nodes that look the shadow map up and are drawn by the rasterizer somewhere."""
    views = raster_viewports(scene)
    return [node for node in scene.nodes if node.receives_shadow and node.material.lit and node.shader is None
            and any(node.shown_in(i) for i in views)]


def casters(scene: Scene) -> list[Node]:
    """Nodes drawn into the shadow map: casting, shown in some rasterized viewport."""
    views = raster_viewports(scene)
    return [node for node in scene.nodes if node.casts_shadow and any(node.shown_in(i) for i in views)]


#: Each mesh's 8 bounding-box corners (meshes are immutable: found once per mesh object).
_CORNERS: weakref.WeakKeyDictionary[Mesh, np.ndarray] = weakref.WeakKeyDictionary()


def _corners(mesh: Mesh) -> np.ndarray:
    corners = _CORNERS.get(mesh)
    if corners is None:
        positions = np.asarray(mesh.positions, dtype=np.float64)
        low, high = positions.min(axis=0), positions.max(axis=0)
        corners = _CORNERS[mesh] = np.array([[(low, high)[i >> k & 1][k] for k in range(3)] for i in range(8)])
    return corners


#: No node moved (:func:`light_frame` without models).
_NO_MODELS: Mapping[str, Any] = MappingProxyType({})

#: Each node's world corners by (its model's bytes, id of its mesh), with the mesh kept to
#: check: a node that does not move is transformed once, not every frame.
_WORLD_CORNERS: dict[tuple[bytes, int], tuple[Mesh, np.ndarray]] = {}
#: Entries kept; past this many (a moving node adds one per frame) it starts again.
_WORLD_CORNERS_KEPT = 256


def _node_corners(node: Node, model: object = None) -> np.ndarray:
    """The corners of ``node``'s mesh bounds in world space (8 rows, read-only), placed by
    ``model`` (None: the node's own)."""
    model = np.asarray(node.model if model is None else model, dtype=np.float64)
    key = (model.tobytes(), id(node.mesh))
    kept = _WORLD_CORNERS.get(key)
    if kept is None or kept[0] is not node.mesh:
        if len(_WORLD_CORNERS) >= _WORLD_CORNERS_KEPT:
            _WORLD_CORNERS.clear()
        corners = transforms.transform_points(model, _corners(node.mesh))
        corners.flags.writeable = False
        kept = _WORLD_CORNERS[key] = (node.mesh, corners)
    return kept[1]


def _world_corners(nodes: list[Node], models: Mapping[str, Any]) -> np.ndarray:
    """The corners of each node's mesh bounds in world space (8 per node), each node placed
    by ``models[node.name]`` where it names one."""
    if not nodes:
        return np.zeros((0, 3))
    return np.concatenate([_node_corners(node, models.get(node.name)) for node in nodes])


def _casters_and_receivers(scene: Scene) -> tuple[list[Node], list[Node]]:
    """:func:`casters` and :func:`receivers` of ``scene``. Which nodes they are depends on nothing
    a lesson's motion changes (:func:`glsandbox.scene.moved_scene` keeps every node's flags and
    material, and the viewports): for a moved scene they are found once, by index, on the scene
    it was moved from, and for any other scene on the scene itself (a frame moved only by time
    hands the executor the scene it is moved from and the models apart)."""
    origin = scene_origin(scene) or scene
    kept = origin.__dict__.get("_shadow_map_nodes")
    if kept is None:
        index = {id(node): i for i, node in enumerate(origin.nodes)}
        kept = origin.__dict__["_shadow_map_nodes"] = (tuple(index[id(node)] for node in casters(origin)),
                                                         tuple(index[id(node)] for node in receivers(origin)))
    nodes = scene.nodes
    return [nodes[i] for i in kept[0]], [nodes[i] for i in kept[1]]


@dataclass(frozen=True)
class LightFrame:
    """A shadow map's light camera: ``view`` and ``proj`` (float64), and ``tan_half``, the
    tangent of half its field of view. One texel at distance ``d`` from the light is
    ``2·tan_half·d / size`` wide: the footprint the biases are measured in."""

    view: np.ndarray
    proj: np.ndarray
    tan_half: float

    def footprint(self, size: int) -> float:
        """World width of one of ``size`` texels at unit distance from the light."""
        return 2.0 * self.tan_half / size


#: Room left around the fitted frustum (a share of its half-width): a percentage-closer
#: filter reads a few texels beyond a corner exactly on its edge.
FIT_MARGIN = 1.02


def _extent(view: np.ndarray, points: np.ndarray) -> float:
    """``max(|x|, |y|) / depth`` over ``points`` in the light's view (the tangent of the half
    field of view that holds them); inf when one lies beside or behind the light."""
    if not len(points):
        return math.inf
    local = transforms.transform_points(view, points)
    depth = -local[:, 2]
    if np.any(depth <= 0.0):
        return math.inf
    return float((np.abs(local[:, :2]).max(axis=1) / depth).max())


def light_frame(scene: Scene, light: Light, models: Mapping[str, Any] | None = None) -> LightFrame:
    """The shadow map's camera for ``light`` (which has a ShadowMap), fitted to the scene, its
    nodes placed by ``models`` (model matrices by node name, :func:`glsandbox.scene.motion_parts`:
    the scene moved there; None or a name left out: a node's own model).

    The view looks from the light at the centre of the casters' bounds. The field of
    view is the narrowest that holds every caster's bounds or every receiver's,
    whichever is narrower, and at most :attr:`ShadowMap.fov`: only a point inside both
    can be in shadow, and a frustum fitted to them spends every texel where shadows
    can fall, at any scale (a scene a thousandth the size gets the same texels). Near
    and far enclose every caster and receiver corner in front of the light, so the
    map's depth precision is spent on the scene and not on empty space.
    """
    assert light.shadow is not None
    eye = np.asarray(light.position, dtype=np.float64)
    casting, receiving = _casters_and_receivers(scene)
    models = models or _NO_MODELS
    cast, received = _world_corners(casting, models), _world_corners(receiving, models)
    target = cast.mean(axis=0) if len(cast) else eye - np.array([0.0, 1.0, 0.0])
    forward = target - eye
    reach = max(float(np.abs(eye).max()), 1.0)
    if np.linalg.norm(forward) <= 1e-12 * reach:
        forward = np.array([0.0, -1.0, 0.0])
        target = eye + forward
    forward = forward / np.linalg.norm(forward)
    # Any up not along the view works (the map's rotation about its axis does not matter).
    up = (0.0, 0.0, 1.0) if abs(forward[1]) > 0.9 else (0.0, 1.0, 0.0)
    view = transforms.look_at(tuple(eye), tuple(target), up)
    widest = math.tan(math.radians(light.shadow.fov) / 2.0)
    fitted = min(_extent(view, cast), _extent(view, received)) * FIT_MARGIN
    if 0.0 < fitted < widest:
        # Rounded up to a step of 1/8 octave: a caster that turns or moves a little keeps
        # the same texel grid (no crawling edges frame to frame), at any scale.
        fitted = 2.0 ** (math.ceil(8.0 * math.log2(fitted)) / 8.0)
    tan_half = min(widest, fitted) if fitted > 0.0 else widest
    points = np.concatenate([cast, received])
    depths = -(transforms.transform_points(view, points)[:, 2]) if len(points) else np.array([1.0])
    far = max(float(depths.max()), 1e-9 * reach) * 1.01
    near = max(float(depths.min()) * 0.99, far * 1e-3)
    fov = math.degrees(2.0 * math.atan(tan_half))
    return LightFrame(view, transforms.perspective(fov, 1.0, near, far), tan_half)


def light_camera(scene: Scene, light: Light) -> tuple[np.ndarray, np.ndarray]:
    """The shadow map's view and projection for ``light`` (:func:`light_frame`)."""
    frame = light_frame(scene, light)
    return frame.view, frame.proj
