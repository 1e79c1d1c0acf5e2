"""From the rasterizer's Scene to what a ray tracer needs: world triangles and primary rays.

Both engines (:mod:`glsandbox.raytrace.numpy_engine`, numpy float64, and
:mod:`glsandbox.raytrace.gpu`, GLSL float32) trace a :class:`World`, built
once per viewport by :func:`build_world` from the *same*
:class:`glsandbox.scene.Scene` the rasterizer draws:

- every node's mesh is moved into world space by its model matrix, exactly
  as the vertex shader's ``m_model`` does: positions by ``M``, normals by the
  normal matrix ``(M³ˣ³)⁻ᵀ`` (course errata: never ``mul(Norm, world)``);
  triangle strips become triangles with the strip's winding
  (:meth:`glsandbox.geometry.Mesh.triangles`); line meshes have no surface
  and are not traced;
- a node whose mesh says it tessellates the unit sphere
  (``Mesh.analytic == "sphere"``, as :func:`glsandbox.geometry.sphere` does,
  and every vertex lies on it) is a :attr:`NodeKind.SPHERE` node, traced as the
  *exact* unit sphere under its model matrix (an ellipsoid in general; the capped
  unit cylinder, :func:`glsandbox.geometry.cylinder`, likewise a
  :attr:`NodeKind.CYLINDER` node): the ray is taken into the sphere's own space
  with ``M⁻¹`` and tested against ``|p| = 1`` (course section "Işın-Küre kesim testi"). An
  affine map keeps ``t``: ``M⁻¹(O + t·d) = M⁻¹O + t·(M⁻¹d)``, so no
  renormalising is needed. The rasterizer draws the tessellation; the
  difference at the silhouette is one of the approximations the
  raster-versus-ray comparison shows. ``analytic_spheres=False`` traces the
  triangles instead, and so does a sphere whose model matrix has no usable
  inverse (a scale of 0, or below :data:`~glsandbox.scene.MIN_SCALE`, along
  a direction flattens it to a disc: the triangles the rasterizer draws are
  then the only honest shape);
- a model matrix that flattens a mesh that way has no normal matrix: its
  triangles get their face normals, the flat sheet they now form;
- each node gets a world axis-aligned bounding box, the course's
  "Hızlandırma: AABB": a ray that misses the box skips every triangle inside.
  An unlit node (``solid``/``vertex_color``) whose box holds a light is that
  light's lamp (the lessons draw each light as a small cube around it) and
  casts no shadow *for that light*; otherwise every shadow ray would enter
  the lamp. Lit nodes cast shadows, as the rasterizer's planar shadow and
  shadow map draw them (:func:`glsandbox.plan.caster_program`): a blended
  node casts none (light passes it as a camera ray does), a cut-out only
  through its drawn texels (:attr:`NodeInfo.texel_shadow`: a shadow ray
  meeting a texel whose alpha is below the cutoff goes on), and a cut-out
  whose colour's alpha is below its cutoff (cut out everywhere) none. A
  textured cut-out is traced as its triangles even where it tessellates a
  sphere or cylinder: the analytic kinds give a ray's nearest hit only, and a
  shadow ray must see every texel it passes.

Primary rays (course section "Bakış noktası, görüntü düzlemi GD(x,y)")
---------------------------------------------------------------------
The notes put the eye at the origin and the image plane at ``z = 10``; the
pixel ``(x, y)`` of an 800x450 image goes to
``GD(x, y) = (16x/799 − 8, 4.5 − 9y/449, 10)`` (:func:`course_image_plane`):
the first and last pixel sit exactly on the plane's edges. The rasterizer
samples pixel *centres* instead, so to render the same picture the engines
use :func:`camera_rays`: pixel ``(i, j)`` (row ``j`` from the top) goes
through ``x_ndc = 2(i + ½)/W − 1``, ``y_ndc = 1 − 2(j + ½)/H`` on a plane one
unit in front of the eye, ``tan(fov/2)`` high and ``aspect`` times that wide,
turned into world space by the camera's basis. The direction is *not*
normalised: its component along the view axis is 1, so the ``t`` of a hit is
its depth, the raster's view-space ``z`` (near and far are not clipped: every
lesson's scene lies well inside them).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Any
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from glsandbox import transforms
from glsandbox.geometry import Mesh
from glsandbox.images import texture_levels
from glsandbox.plan import traced_reflectivity
from glsandbox.raytrace import shapes
from glsandbox.raytrace.constants import LENGTH_TINY, SQUARES_UNDERFLOW
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.shape_kind import ShapeKind
from glsandbox.scene import MIN_SCALE, Camera, Node, Scene, Texture

__all__ = [
    "MODES",
    "NodeKind",
    "NodeInfo",
    "NodeMaterials",
    "World",
    "build_world",
    "camera_rays",
    "course_image_plane",
]

#: How a node's surface is coloured, as the engines number it.
MODES = {"solid": 0, "vertex_color": 1, "phong": 2, "gouraud": 2, "blinn_phong": 3}
#: Alpha modes (:data:`glsandbox.scene.ALPHA_MODES`) as the engines number them.
ALPHA_CODES = {"opaque": 0, "mask": 1, "blend": 2}
#: Texture wrap modes as the engines number them.
WRAPS = {"repeat": 0, "mirrored": 1, "clamp": 2}


class _Kind(str, enum.Enum):
    """What a traced node is: the one table both engines loop over.

    ``MESH``: world-space triangles (``NodeInfo.start``/``count``), hit by the
    watertight test (a BVH or a scan), surface from barycentrics. Every other
    member is an analytic kind of :data:`glsandbox.raytrace.shapes.KINDS` (its
    :attr:`shape`, one module ``raytrace/shapes/<kind>.py`` and one
    ``shaders/shapes/<kind>.glsl``): the exact unit shape under the node's model
    matrix. Its rays are taken into its own space by ``NodeInfo.inverse`` (an
    affine map keeps ``t``), hit there, and its normal goes back through
    ``NodeInfo.normal_matrix``. A mesh says it tessellates one
    (``Mesh.analytic``, the kind's value) and :meth:`holds` checks its vertices
    lie on it.

    The value is the kind's name (so ``kind == "sphere"`` reads true);
    :attr:`code` is the number the gpu engine stores in a node record
    (``KIND_<NAME>`` defines from :func:`kind_defines`)."""

    @property
    def code(self) -> int:
        """The kind's number in the gpu engine's node records: its place in the table."""
        return list(type(self)).index(self)

    @property
    def triangles(self) -> bool:
        """Whether the kind's shape is its node's triangles (BVH and scan apply)."""
        return self.value == "mesh"

    @property
    def shape(self) -> ShapeKind:
        """An analytic kind's parts (:class:`glsandbox.raytrace.shapes.ShapeKind`)."""
        return shapes.by_name(self.value)

    @property
    def own_box(self) -> NDArray[np.float64]:
        """An analytic kind's box in its own space, ``(2, 3)`` min and max."""
        return self.shape.own_box.copy()

    def holds(self, positions: NDArray[np.float64]) -> bool:
        """Whether every point lies on this analytic kind's unit shape (to
        :data:`~glsandbox.raytrace.constants.UNIT_SHAPE_TOLERANCE`)."""
        return not self.triangles and self.shape.holds(positions)


#: The node kinds: ``MESH`` (code 0), then one per registered shape kind, in the registry's order.
NodeKind = _Kind("NodeKind", [("MESH", "mesh"), *((kind.name.upper(), kind.name) for kind in shapes.KINDS)],
                 module=__name__, qualname="NodeKind")


def kind_defines() -> tuple[tuple[str, str], ...]:
    """``KIND_MESH 0``, ``KIND_SPHERE 1``...: the node kinds as shader defines."""
    return tuple((f"KIND_{kind.name}", str(kind.code)) for kind in NodeKind)


def analytic_kind(mesh: Mesh) -> NodeKind | None:
    """The analytic kind ``mesh`` tessellates (``Mesh.analytic`` names it and every
    vertex lies on it), or None: then its triangles are the shape."""
    kinds = {kind.value: kind for kind in NodeKind if not kind.triangles}
    kind = kinds.get(mesh.analytic or "")
    if kind is None or mesh.mode != "triangles" or not kind.holds(mesh.positions):
        return None
    return kind


@dataclass
class NodeInfo:
    """One traced node: its shape, its box, its material (already numbered for the engines)."""

    name: str
    kind: NodeKind
    start: int  # first triangle in the world arrays
    count: int  # number of triangles
    box_min: NDArray[np.float64]
    box_max: NDArray[np.float64]
    cull: bool
    color: NDArray[np.float64]  # rgb
    mode: int  # MODES value
    ka: float
    kd: float
    ks: float
    shininess: float
    reflectivity: float
    texture: int  # index into World.textures, -1 for none
    #: A sphere's model matrix inverted (world to the unit sphere's space) and its
    #: normal matrix; identities for a mesh, whose triangles are in world space.
    inverse: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    normal_matrix: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))
    #: Bit ``i`` set: light ``i`` lies inside this unlit node's box, so the node is
    #: that light's lamp (the lessons draw each light as a small cube around
    #: it) and casts no shadow for it.
    lamp_of: int = 0
    #: A model file's material (:class:`glsandbox.scene.Material`): the colour's alpha, the
    #: alpha mode (:data:`ALPHA_CODES`) and cutoff; the lit colour times the vertex colours;
    #: back faces lit with the normal reversed.
    alpha: float = 1.0
    alpha_mode: int = 0
    alpha_cutoff: float = 0.5
    vertex_colors: bool = False
    two_sided: bool = False

    @property
    def lit(self) -> bool:
        return self.mode >= 2

    @property
    def see_through(self) -> bool:
        """Whether rays may pass it (a cut-out or a blended surface): the engines
        continue such a ray behind it (:func:`coverage`)."""
        return self.alpha_mode != ALPHA_CODES["opaque"]

    @property
    def casts_no_shadow(self) -> bool:
        """A blended node (shadow rays pass it as camera rays do, and the rasterizer's
        shadows leave it out too), or a cut-out cut away everywhere (its colour's alpha,
        the most its texels can reach, below its cutoff)."""
        return self.alpha_mode == ALPHA_CODES["blend"] or (self.alpha_mode == ALPHA_CODES["mask"]
                                                           and self.alpha < self.alpha_cutoff)

    @property
    def texel_shadow(self) -> bool:
        """A textured cut-out: a shadow ray is blocked by it only where its alpha (the
        colour's times the texel's, as shading reads it) reaches the cutoff."""
        return self.alpha_mode == ALPHA_CODES["mask"] and self.texture >= 0 and not self.casts_no_shadow


@dataclass
class World:
    """Everything the engines trace in one viewport, in world space (float64).

    Triangle ``k`` is ``v0[k], v1[k], v2[k]`` with per-vertex ``normals[k]``
    (the face normal three times when the mesh has none), ``uvs[k]`` and
    ``colors[k]``; it belongs to node ``tri_node[k]``.
    """

    nodes: list[NodeInfo]
    v0: NDArray[np.float64]
    v1: NDArray[np.float64]
    v2: NDArray[np.float64]
    normals: NDArray[np.float64]  # (M, 3, 3)
    uvs: NDArray[np.float64]  # (M, 3, 2)
    colors: NDArray[np.float64]  # (M, 3, 3)
    tri_node: NDArray[np.intp]
    light_positions: NDArray[np.float64]  # (L, 3)
    light_colors: NDArray[np.float64]  # (L, 3)
    background: NDArray[np.float64]  # rgb of the viewport's clear colour
    textures: list[tuple[NDArray[np.float64], int]]  # (image (H, W, 4) in 0..1, wrap code)
    #: Hit tests that replace the numpy engine's own for a node kind (``"sphere"``,
    #: ``"triangles"``): see :func:`glsandbox.raytrace.numpy_engine.render_viewport`; and the
    #: single-ray story's other seams (``"aabb"``, ``"backface"``, ``"reflect"``, ``"phong"``,
    #: ``"shadow"``): see :data:`glsandbox.raytrace.numpy_engine.SEAMS`.
    hit_tests: dict[str, Any] = field(default_factory=dict)

    @property
    def triangle_count(self) -> int:
        return int(self.v0.shape[0])

    @cached_property
    def materials(self) -> NodeMaterials:
        """The nodes' shading numbers as arrays, indexed by node (see :class:`NodeMaterials`)."""
        return NodeMaterials.of(self.nodes)


@dataclass(frozen=True)
class NodeMaterials:
    """Per-node material arrays, ``(K,)`` each: the Phong boyama modeli's ``ka, kd,
    ks`` and exponent, whether the node is lit at all and whether it uses
    Blinn-Phong, and the Yansıma (reflection) share. The numpy engine looks them
    up for a whole batch of hits with one ``array[hit_nodes]`` instead of a
    Python loop over the hits."""

    lit: NDArray[np.bool_]
    ka: NDArray[np.float64]
    kd: NDArray[np.float64]
    ks: NDArray[np.float64]
    shininess: NDArray[np.float64]
    blinn: NDArray[np.bool_]  # Blinn-Phong: N·H instead of R·E
    reflectivity: NDArray[np.float64]
    alpha_mode: NDArray[np.intp]  # ALPHA_CODES
    alpha_cutoff: NDArray[np.float64]

    @classmethod
    def of(cls, nodes: list[NodeInfo]) -> NodeMaterials:
        def floats(name: str) -> NDArray[np.float64]:
            return np.array([getattr(n, name) for n in nodes], dtype=np.float64)

        return cls(lit=np.array([n.lit for n in nodes], dtype=bool), ka=floats("ka"), kd=floats("kd"),
                   ks=floats("ks"), shininess=floats("shininess"),
                   blinn=np.array([n.mode == MODES["blinn_phong"] for n in nodes], dtype=bool),
                   reflectivity=floats("reflectivity"),
                   alpha_mode=np.array([n.alpha_mode for n in nodes], dtype=np.intp),
                   alpha_cutoff=floats("alpha_cutoff"))


def coverage(alpha_mode: NDArray[np.intp], alpha: NDArray[np.float64],
             cutoff: NDArray[np.float64]) -> NDArray[np.float64]:
    """How much of a hit surface covers what lies behind it, 0..1, as the rasterizer
    draws it: opaque 1; a cut-out 1 where its alpha reaches the cutoff and 0 (discarded)
    below; blended its alpha (``a·surface + (1−a)·behind``)."""
    mask = np.where(alpha >= cutoff, 1.0, 0.0)
    return np.where(alpha_mode == ALPHA_CODES["mask"], mask,
                    np.where(alpha_mode == ALPHA_CODES["blend"], alpha, 1.0))


def _unit_rows(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each row of ``v`` scaled to length 1 (a zero row stays zero). A row too
    small for its squares (a triangle of a tiny node: ``|v|² < 1e-300``
    underflows) is rescaled by its largest component first, so its direction
    survives instead of blowing up by ``1/1e-300``."""
    length = np.linalg.norm(v, axis=1, keepdims=True)
    tiny = length[:, 0] < SQUARES_UNDERFLOW
    if np.any(tiny):
        big = np.abs(v[tiny]).max(axis=1, keepdims=True)
        v = v.copy()
        v[tiny] = np.divide(v[tiny], big, out=np.zeros_like(v[tiny]), where=big > 0.0)
        length[tiny] = np.linalg.norm(v[tiny], axis=1, keepdims=True)
    return v / np.maximum(length, LENGTH_TINY)


def _texture_image(texture: Texture) -> NDArray[np.float64]:
    """The base level of a texture as float rgba in 0..1 (the ray tracer samples level 0 only)."""
    return np.asarray(texture_levels(texture)[0], dtype=np.float64) / 255.0


def build_world(scene: Scene, viewport: int = 0, *, analytic_spheres: bool = True) -> World:
    """The :class:`World` of ``scene`` as seen in viewport ``viewport``.

    Nodes restricted to other viewports are left out; the background is the
    viewport's clear colour (or the scene's).
    """
    if not 0 <= viewport < len(scene.viewports):
        raise RayTraceError(f"viewport {viewport} does not exist ({len(scene.viewports)} defined)")
    vp = scene.viewports[viewport]
    clear = vp.clear_color if vp.clear_color is not None else scene.clear_color
    nodes: list[NodeInfo] = []
    v0s, v1s, v2s, ns, uvs, cols, owners = [], [], [], [], [], [], []
    textures: list[tuple[NDArray[np.float64], int]] = []
    texture_index: dict[tuple[str, str, str], int] = {}
    start = 0
    for node in scene.nodes:
        if not node.shown_in(viewport):
            continue
        mesh = node.mesh
        if mesh.mode in ("lines", "line_strip"):
            continue  # a path has no surface to hit
        model = np.asarray(node.model, dtype=np.float64)
        material = node.material
        tex = -1
        if material.texture is not None:
            key = (material.texture.source, material.texture.digest, material.texture.wrap)
            if key not in texture_index:
                texture_index[key] = len(textures)
                textures.append((_texture_image(material.texture), WRAPS[material.texture.wrap]))
            tex = texture_index[key]
        common = dict(
            name=node.name, cull=bool(node.cull_back_faces),
            color=np.asarray(material.color[:3], dtype=np.float64), mode=MODES[material.shading],
            ka=float(material.ambient), kd=float(material.diffuse), ks=float(material.specular),
            shininess=float(material.shininess), reflectivity=traced_reflectivity(scene, node),
            texture=tex, alpha=float(material.color[3]), alpha_mode=ALPHA_CODES[material.alpha_mode],
            alpha_cutoff=float(material.alpha_cutoff), vertex_colors=bool(material.vertex_colors),
            two_sided=bool(material.double_sided),
        )
        # A model that flattens the node (a scale of 0, or below MIN_SCALE) has no usable inverse.
        invertible = transforms.smallest_scale(model) >= MIN_SCALE
        # A textured cut-out stays triangles: its shadow rays test every texel they pass.
        cut_out = material.alpha_mode == "mask" and tex >= 0
        kind = analytic_kind(mesh) if analytic_spheres and invertible and not cut_out else None
        if kind is not None:
            lo, hi = kind.own_box
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
            world_corners = transforms.transform_points(model, corners)
            nodes.append(NodeInfo(kind=kind, start=start, count=0, box_min=world_corners.min(axis=0),
                                  box_max=world_corners.max(axis=0), inverse=np.linalg.inv(model),
                                  normal_matrix=transforms.normal_matrix(model), **common))
            continue
        tri = mesh.triangle_indices()  # a strip's keep its winding
        if len(tri) == 0:
            continue
        world = transforms.transform_points(model, np.asarray(mesh.positions, dtype=np.float64))
        a, b, c = world[tri[:, 0]], world[tri[:, 1]], world[tri[:, 2]]
        if mesh.normals is not None and invertible:
            n_world = np.asarray(mesh.normals, dtype=np.float64) @ transforms.normal_matrix(model).T
            n_world /= np.maximum(np.linalg.norm(n_world, axis=1, keepdims=True), LENGTH_TINY)
            n = n_world[tri]
        else:  # flat (or flattened by the model): the face normal, counter-clockwise front (OpenGL's rule)
            face = _unit_rows(np.cross(b - a, c - a))
            n = np.repeat(face[:, None, :], 3, axis=1)
        uv = np.asarray(mesh.uvs, dtype=np.float64)[tri] if mesh.uvs is not None else np.zeros((len(tri), 3, 2))
        # No vertex colours: white at every corner, as a read-only view of one row (a 1M-triangle
        # model's would be 72 MB of ones); stacked with other nodes' it becomes a real array.
        col = np.asarray(mesh.colors, dtype=np.float64)[tri] if mesh.colors is not None else \
            np.broadcast_to(np.ones((1, 3, 3)), (len(tri), 3, 3))
        v0s.append(a), v1s.append(b), v2s.append(c), ns.append(n), uvs.append(uv), cols.append(col)
        owners.append(np.full(len(tri), len(nodes), dtype=np.intp))
        nodes.append(NodeInfo(kind=NodeKind.MESH, start=start, count=len(tri), box_min=world.min(axis=0),
                              box_max=world.max(axis=0), **common))
        start += len(tri)
    lights = scene.lights
    for info in nodes:
        if info.casts_no_shadow:  # blended, or cut out everywhere (as the rasterizer's shadows)
            info.lamp_of = (1 << len(lights)) - 1
            continue
        for i, light in enumerate(lights):
            inside = np.all(info.box_min <= light.position) and np.all(np.asarray(light.position) <= info.box_max)
            if inside and not info.lit:
                info.lamp_of |= 1 << i

    def stack(parts: list[NDArray[np.float64]], shape: tuple[int, ...]) -> NDArray[np.float64]:
        # One node's arrays are the World's as they are: np.concatenate would copy them
        # (a 1M-triangle model's World is 260 MiB, and the copy doubled its peak).
        if len(parts) == 1:
            return parts[0]
        return np.concatenate(parts) if parts else np.zeros((0, *shape))

    return World(
        nodes=nodes, v0=stack(v0s, (3,)), v1=stack(v1s, (3,)), v2=stack(v2s, (3,)), normals=stack(ns, (3, 3)),
        uvs=stack(uvs, (3, 2)), colors=stack(cols, (3, 3)),
        tri_node=(owners[0] if len(owners) == 1 else np.concatenate(owners)) if owners else np.zeros(0, dtype=np.intp),
        light_positions=np.array([l.position for l in lights], dtype=np.float64).reshape(-1, 3),
        light_colors=np.array([l.color for l in lights], dtype=np.float64).reshape(-1, 3),
        background=np.asarray(clear[:3], dtype=np.float64), textures=textures,
    )


def camera_basis(camera: Camera, aspect: float) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float]:
    """``(eye, basis, half_width, half_height)``: the image plane one unit in front of the eye.

    ``basis`` is the 3x3 rotation from view space to world space (the inverse
    of the view matrix's rotation): its columns are the camera's right, up
    and backward axes in world coordinates.
    """
    view = camera.view()
    inverse = np.linalg.inv(np.asarray(view, dtype=np.float64))
    half_h = math.tan(math.radians(camera.fov_y) / 2.0)
    return inverse[:3, 3].copy(), inverse[:3, :3].copy(), half_h * aspect, half_h


def camera_rays(camera: Camera, width: int, height: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Primary rays through pixel centres: ``(eye (3,), directions (H·W, 3))``, row 0 at the top.

    ``t`` along a direction is the depth in front of the eye (see the module docstring).
    """
    if width <= 0 or height <= 0:
        raise RayTraceError(f"image size must be positive, got {width}x{height}")
    eye, basis, half_w, half_h = camera_basis(camera, width / height)
    x = (2.0 * (np.arange(width) + 0.5) / width - 1.0) * half_w
    y = (1.0 - 2.0 * (np.arange(height) + 0.5) / height) * half_h
    xs, ys = np.meshgrid(x, y)
    d_view = np.stack([xs, ys, -np.ones_like(xs)], axis=-1).reshape(-1, 3)
    # d_view @ basisᵀ, a few thousand rows at a time: every row is the same product,
    # but one tall (H·W, 3) @ (3, 3) product is handed to BLAS's threads, which on a
    # shared two-core machine measured 5 to 15 times slower than these small calls.
    dirs = np.empty_like(d_view)
    for lo in range(0, d_view.shape[0], 1 << 13):
        np.matmul(d_view[lo:lo + (1 << 13)], basis.T, out=dirs[lo:lo + (1 << 13)])
    return eye, dirs


def course_image_plane(x: NDArray[np.float64] | float, y: NDArray[np.float64] | float, width: int = 800,
                       height: int = 450, half_width: float = 8.0, half_height: float = 4.5,
                       distance: float = 10.0) -> NDArray[np.float64]:
    """The notes' ``GD(x, y)``: pixel ``(x, y)`` to its point on the image plane (DirectX, looking +z).

    ``GD(x, y) = (2·8·x/(W−1) − 8, 4.5 − 2·4.5·y/(H−1), 10)``; for 800x450 that is
    ``(16x/799 − 8, 4.5 − 9y/449, 10)``: pixel (0, 0) is the top-left corner
    ``(−8, 4.5, 10)`` and (799, 449) the bottom-right ``(8, −4.5, 10)``.
    """
    xs = np.asarray(x, dtype=np.float64)
    ys = np.asarray(y, dtype=np.float64)
    px = 2.0 * half_width * xs / (width - 1) - half_width
    py = half_height - 2.0 * half_height * ys / (height - 1)
    return np.stack(np.broadcast_arrays(px, py, np.full_like(px + py, distance)), axis=-1)
