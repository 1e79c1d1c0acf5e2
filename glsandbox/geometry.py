"""Meshes as plain numpy arrays, and the course's shapes.

Everything here is already in OpenGL's right-handed, counter-clockwise-front
convention; shapes the course gives in DirectX form go through
:func:`glsandbox.transforms.from_directx_mesh` exactly once, here.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from glsandbox.errors import NUMBER_LIMIT, SandboxError, plain
from glsandbox.mesh.normals import face_normals
from glsandbox.transforms import from_directx_mesh

#: Primitive topologies a mesh can use (the course's D3D11_PRIMITIVE_TOPOLOGY_*).
#: The line modes draw paths (the transform-order lesson's trail); they have no triangles.
MODES = ("triangles", "triangle_strip", "lines", "line_strip")


@dataclass(frozen=True, eq=False)
class Mesh:
    """Vertex arrays and an optional index buffer.

    ``positions`` is (N, 3); ``normals`` (N, 3), ``uvs`` (N, 2) and ``colors``
    (N, 3) are optional;
    ``indices`` is a flat array, three per triangle for ``"triangles"``.
    ``name`` identifies the mesh (GPU buffers are cached by it). ``notes``
    says where a loaded mesh came from and what loading did to it (dropped
    faces, how its normals were made): ``glsandbox plan`` prints them.
    ``warnings`` says what of its file is not drawn (a normal map, an
    animation, a missing texture): ``plan`` lists them and ``render``, ``run``
    and ``tour`` print each once as a ``warning:`` line.
    ``analytic`` names the exact shape the triangles tessellate, for the ray
    tracer (``"sphere"``: :func:`sphere`, the unit sphere; ``"cylinder"``:
    :func:`cylinder`, the capped unit cylinder; None: the
    triangles are the shape); :mod:`glsandbox.raytrace.world` traces that
    shape instead of the triangles.
    """

    name: str
    positions: np.ndarray
    indices: np.ndarray | None = None
    normals: np.ndarray | None = None
    uvs: np.ndarray | None = None
    colors: np.ndarray | None = None
    mode: str = "triangles"
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    analytic: str | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise SandboxError(f"mesh {self.name!r}: unknown mode {self.mode!r}; use one of {', '.join(MODES)}")
        check_mesh_arrays(self)
        # Meshes are shared, immutable data (renderers cache per mesh object).
        for array in (self.positions, self.indices, self.normals, self.uvs, self.colors):
            if isinstance(array, np.ndarray):
                array.flags.writeable = False

    @property
    def vertex_count(self) -> int:
        return len(self.positions)

    @property
    def element_count(self) -> int:
        """Vertices drawn: the index count, or the vertex count when not indexed."""
        return len(self.indices) if self.indices is not None else len(self.positions)

    def triangle_indices(self) -> np.ndarray:
        """The triangles as (T, 3) vertex indices, whatever the topology (none for lines).

        A strip's triangle k uses vertices (k, k+1, k+2), with every odd
        triangle's first two swapped so all keep the strip's winding.
        """
        if self.mode in ("lines", "line_strip"):
            return np.zeros((0, 3), dtype=np.intp)
        order = self.indices if self.indices is not None else np.arange(self.vertex_count)
        if self.mode == "triangles":
            return np.asarray(order, dtype=np.intp).reshape(-1, 3)
        return np.array([
            (order[k + 1], order[k], order[k + 2]) if k % 2 else (order[k], order[k + 1], order[k + 2])
            for k in range(len(order) - 2)
        ], dtype=np.intp).reshape(-1, 3)

    def triangles(self) -> np.ndarray:
        """The triangles as (T, 3, 3) positions, whatever the topology (see :meth:`triangle_indices`)."""
        if self.mode in ("lines", "line_strip"):
            return np.zeros((0, 3, 3))
        return self.positions[self.triangle_indices()]


#: The columns of each per-vertex array (None: any of these counts).
_VERTEX_COLUMNS = {"positions": (3,), "normals": (3,), "uvs": (2,), "colors": (3, 4)}
#: How many indices make one primitive, per topology (strips take any count).
_PER_PRIMITIVE = {"triangles": 3, "lines": 2}


def check_mesh_arrays(mesh: Mesh) -> None:
    """Refuse a mesh the renderers would draw torn or fail on, with one line naming the array and value.

    Per-vertex arrays are (N, columns) finite numbers, one row per position,
    positions within +-NUMBER_LIMIT as a model matrix's entries are;
    an index names a vertex that exists (``0 <= i < N``: the rasterizer would
    read past the vertex buffer and draw a torn picture, the ray tracers
    raise); a list topology gets whole primitives. Checked once, where the
    Mesh is made: one ``isfinite`` pass per array and one ``min``/``max`` of the
    indices, so a cached mesh costs nothing per frame. Lists are taken as
    arrays (kept as numpy arrays).
    """
    count = None
    for field_name, columns in _VERTEX_COLUMNS.items():
        value = getattr(mesh, field_name)
        if value is None and field_name != "positions":
            continue
        array = value if isinstance(value, np.ndarray) else _as_array(mesh, field_name, value)
        if array.ndim != 2 or array.shape[1] not in columns or array.dtype.kind not in "iuf":
            want = " or ".join(f"(N, {c})" for c in columns)
            raise SandboxError(f"mesh {mesh.name!r}: {field_name} must be an {want} array of numbers, "
                               f"got shape {array.shape} of {array.dtype}")
        if count is not None and len(array) != count:
            raise SandboxError(f"mesh {mesh.name!r}: {len(array)} {field_name} for {count} positions; "
                               "every vertex array has one row per position")
        count = len(array)
        if array.dtype.kind == "f" and not np.isfinite(array).all():
            row = int(np.argwhere(~np.isfinite(array))[0][0])
            raise SandboxError(f"mesh {mesh.name!r}: {field_name}[{row}] is not finite: {plain(array[row])}")
        if field_name == "positions" and len(array) and np.abs(array).max() > NUMBER_LIMIT:
            # The bound of a model matrix's entries: float32 (the GPU's) keeps 24 bits, so a
            # vertex at 1e8 is rounded to 8 units, and its triangle is drawn torn (docs/numerics.md).
            row = int(np.argmax(np.abs(array).max(axis=1)))
            raise SandboxError(f"mesh {mesh.name!r}: positions[{row}] = {plain(array[row])} is beyond "
                               f"+-{NUMBER_LIMIT:g}; keep vertices within +-{NUMBER_LIMIT:g} and place "
                               "the mesh with its node's model matrix")
        if array is not value:
            object.__setattr__(mesh, field_name, array)  # a frozen dataclass keeping its own array
    if mesh.indices is not None:
        _check_indices(mesh, count or 0)
    per = _PER_PRIMITIVE.get(mesh.mode)
    if per is not None and mesh.element_count % per:
        what = "indices" if mesh.indices is not None else "vertices"
        raise SandboxError(f"mesh {mesh.name!r}: {mesh.element_count} {what} do not make whole {mesh.mode} "
                           f"({per} per {mesh.mode[:-1]})")


def _as_array(mesh: Mesh, field_name: str, value: object) -> np.ndarray:
    try:
        return np.array(value, dtype=np.float64 if field_name != "indices" else None)
    except (TypeError, ValueError):
        raise SandboxError(f"mesh {mesh.name!r}: {field_name} must be an array of numbers, "
                           f"got {plain(value)}") from None


def _check_indices(mesh: Mesh, count: int) -> None:
    """An index buffer of whole numbers, each naming one of the ``count`` vertices."""
    indices = mesh.indices if isinstance(mesh.indices, np.ndarray) else _as_array(mesh, "indices", mesh.indices)
    if indices.dtype.kind not in "iu" or indices.ndim not in (1, 2):
        raise SandboxError(f"mesh {mesh.name!r}: indices must be a flat array of integers, "
                           f"got shape {indices.shape} of {indices.dtype}")
    if indices.ndim == 2:  # (T, 3) triangles: the flat buffer the GPU reads, three per row
        indices = indices.reshape(-1)
    if indices is not mesh.indices:
        object.__setattr__(mesh, "indices", indices)
    if not len(indices):
        return
    low, high = int(indices.min()), int(indices.max())
    if low < 0 or high >= count:
        bad = low if low < 0 else high
        at = int(np.argmax(indices == bad))
        raise SandboxError(f"mesh {mesh.name!r}: indices[{at}] = {bad} names no vertex; it has {count} "
                           f"(indices 0..{count - 1})" if count else
                           f"mesh {mesh.name!r}: indices[{at}] = {bad} names no vertex; it has none")


_FACE_NORMALS: weakref.WeakKeyDictionary[Mesh, Mesh] = weakref.WeakKeyDictionary()


def with_face_normals(mesh: Mesh) -> Mesh:
    """``mesh`` for lit shading when it has no normals: flat shading, as the ray tracer shades it.

    A vertex shared by faces that point different ways cannot carry one
    normal for all of them (the course's 8-vertex cube), so the triangles are
    un-indexed: each gets its own three vertices carrying its face normal
    ``(V1 − V0) × (V2 − V0)``, normalised (:func:`glsandbox.mesh.normals.face_normals`;
    zero for a zero-area triangle, which covers no pixel). Uvs and colours
    follow their corners. A mesh that has normals, or no triangles, comes back
    as it is. Meshes are immutable, so the result is made once per mesh object.
    """
    if mesh.normals is not None or mesh.mode in ("lines", "line_strip"):
        return mesh
    flat = _FACE_NORMALS.get(mesh)
    if flat is None:
        tri = mesh.triangle_indices()
        positions = np.asarray(mesh.positions, dtype=np.float64)
        corners = tri.reshape(-1)
        normals = np.repeat(face_normals(positions, tri), 3, axis=0)

        def per_corner(array: np.ndarray | None) -> np.ndarray | None:
            return None if array is None else np.asarray(array)[corners]

        flat = _FACE_NORMALS[mesh] = Mesh(f"{mesh.name}/face_normals", positions[corners], None, normals,
                                          per_corner(mesh.uvs), per_corner(mesh.colors), notes=mesh.notes,
                                          warnings=mesh.warnings)
    return flat


# --- the course's indexed cube (DirectX SDK Tutorial 04) --------------------

#: The eight corners as the course lists them, in DirectX (left-handed) form.
COURSE_CUBE_VERTICES = np.array(
    [(-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1),
     (-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)],
    dtype=np.float64,
)
#: The 36 indices, three per triangle, clockwise front faces (DirectX).
COURSE_CUBE_INDICES = np.array(
    [3, 1, 0, 2, 1, 3, 0, 5, 4, 1, 5, 0, 3, 4, 7, 0, 4, 3,
     1, 6, 5, 2, 6, 1, 2, 7, 6, 3, 7, 2, 6, 4, 5, 7, 4, 6],
    dtype=np.int64,
)


#: Tutorial 04's per-vertex colours, so each face shows a distinct gradient.
COURSE_CUBE_COLORS = np.array(
    [(0, 0, 1), (0, 1, 0), (0, 1, 1), (1, 0, 0), (1, 0, 1), (1, 1, 0), (1, 1, 1), (0, 0, 0)],
    dtype=np.float64,
)


@functools.cache
def cube() -> Mesh:
    """The course's indexed cube: 8 vertices, 36 indices, converted to OpenGL."""
    pos, idx = from_directx_mesh(COURSE_CUBE_VERTICES, COURSE_CUBE_INDICES)
    return Mesh("cube", pos, idx.astype(np.uint32), colors=COURSE_CUBE_COLORS.copy())


@functools.cache
def cube24() -> Mesh:
    """A cube with 24 vertices: per-face normals and uv (0..1 on every face).

    Corners are shared by three faces with different normals and uv, so a
    face needs its own four vertices (the course's textured cube).
    """
    faces = [  # (normal, u axis, v axis): u right and v up as seen from outside
        ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
        ((0, 0, -1), (-1, 0, 0), (0, 1, 0)),
        ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
        ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
        ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
        ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
    ]
    positions, normals, uvs, indices = [], [], [], []
    for n, u, v in faces:
        n, u, v = (np.array(a, dtype=np.float64) for a in (n, u, v))
        base = len(positions)
        for su, sv in ((0, 0), (1, 0), (1, 1), (0, 1)):
            positions.append(n + (2 * su - 1) * u + (2 * sv - 1) * v)
            normals.append(n)
            uvs.append((su, 1 - sv))  # image row 0 at the top, as textures are stored
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return Mesh("cube24", np.array(positions), np.array(indices, dtype=np.uint32),
                np.array(normals), np.array(uvs, dtype=np.float64))


# --- quads: the strip-versus-list lesson ------------------------------------

_QUAD_CORNERS = np.array([(-0.5, -0.5, 0), (0.5, -0.5, 0), (-0.5, 0.5, 0), (0.5, 0.5, 0)], dtype=np.float64)


@functools.cache
def quad_strip() -> Mesh:
    """A unit quad as a 4-vertex triangle strip (TRIANGLESTRIP)."""
    return Mesh("quad_strip", _QUAD_CORNERS.copy(), mode="triangle_strip")


@functools.cache
def quad_list() -> Mesh:
    """The same quad as a 6-vertex triangle list (TRIANGLELIST): two corners repeat."""
    c = _QUAD_CORNERS
    return Mesh("quad_list", np.array([c[0], c[1], c[2], c[2], c[1], c[3]]))


@functools.cache
def quad_list_swapped() -> Mesh:
    """The list quad with its second triangle's winding swapped: a back face."""
    c = _QUAD_CORNERS
    return Mesh("quad_list_swapped", np.array([c[0], c[1], c[2], c[2], c[3], c[1]]))


@functools.cache
def triangle() -> Mesh:
    """The course's first triangle, counter-clockwise."""
    return Mesh("triangle", np.array([(-0.5, -0.5, 0.0), (0.5, -0.5, 0.0), (0.0, 0.5, 0.0)]))


@functools.cache
def plane(size: float = 1.0) -> Mesh:
    """A square in the xz plane, facing +y, with uv 0..1."""
    h = size / 2.0
    pos = np.array([(-h, 0, h), (h, 0, h), (h, 0, -h), (-h, 0, -h)], dtype=np.float64)
    return Mesh("plane", pos, np.array([0, 1, 2, 0, 2, 3], dtype=np.uint32),
                np.tile([0.0, 1.0, 0.0], (4, 1)), np.array([(0, 1), (1, 1), (1, 0), (0, 0)], dtype=np.float64))


@functools.cache
def sphere(stacks: int = 24, slices: int = 48) -> Mesh:
    """A unit sphere (UV sphere) with outward normals and uv.

    Built once per (stacks, slices), like the other built-in meshes: a lesson
    rebuilding its scene every frame gets the same Mesh object back, so the
    executor's upload (keyed per mesh object) is found instead of re-hashed.

    Vertex (i, j) sits at polar angle ``pi*i/stacks`` from +y and azimuth
    ``2*pi*j/slices``; on a unit sphere the normal equals the position. The
    seam column is duplicated so u runs 0..1 without wrapping back.
    Triangles are counter-clockwise seen from outside (OpenGL's front).
    """
    theta = np.linspace(0.0, np.pi, stacks + 1)[:, None]  # from the north pole down
    phi = np.linspace(0.0, 2.0 * np.pi, slices + 1)[None, :]
    x = np.sin(theta) * np.sin(phi)
    y = np.cos(theta) * np.ones_like(phi)
    z = np.sin(theta) * np.cos(phi)
    positions = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    u, v = np.meshgrid(np.linspace(0, 1, slices + 1), np.linspace(0, 1, stacks + 1))
    uvs = np.stack([u, v], axis=-1).reshape(-1, 2)
    indices = []
    row = slices + 1
    for i in range(stacks):
        for j in range(slices):
            a, b = i * row + j, (i + 1) * row + j  # a above b; a+1, b+1 one step east
            if i > 0:
                indices += [a, b, a + 1]
            if i < stacks - 1:
                indices += [a + 1, b, b + 1]
    return Mesh("sphere", positions, np.array(indices, dtype=np.uint32), positions.copy(), uvs, analytic="sphere")


@functools.cache
def cylinder(slices: int = 48) -> Mesh:
    """The capped unit cylinder ``x² + z² ≤ 1, |y| ≤ 1`` (axis +y), with outward normals and uv.

    The side is one band of ``slices`` quads: column ``j`` at azimuth
    ``2*pi*j/slices`` from +z towards +x (as :func:`sphere`), ``u = j/slices``
    (the seam column duplicated), ``v = (1 − y)/2``; each cap is a fan around
    its centre with the cap's normal and ``uv = (½ + x/2, ½ + z/2)``, its own
    vertices so the rim has both normals. The ray tracer traces the exact
    cylinder (``analytic="cylinder"``, :class:`glsandbox.raytrace.world.NodeKind`)
    under the node's model matrix. Counter-clockwise seen from outside.
    """
    phi = np.linspace(0.0, 2.0 * np.pi, slices + 1)
    x, z = np.sin(phi), np.cos(phi)
    x[-1], z[-1] = x[0], z[0]  # the seam: the same point twice, exactly
    ring = slices + 1
    side = np.concatenate([np.stack([x, np.ones(ring), z], axis=1), np.stack([x, -np.ones(ring), z], axis=1)])
    side_n = side * np.array([1.0, 0.0, 1.0])
    u = np.linspace(0.0, 1.0, ring)
    side_uv = np.concatenate([np.stack([u, np.zeros(ring)], axis=1), np.stack([u, np.ones(ring)], axis=1)])
    indices = []
    for j in range(slices):
        a, b = j, ring + j  # a on top, b below it
        indices += [a, b, a + 1, a + 1, b, b + 1]
    positions, normals, uvs = [side], [side_n], [side_uv]
    base = 2 * ring
    for y in (1.0, -1.0):  # the caps: centre, then the rim
        cap = np.concatenate([[[0.0, y, 0.0]], np.stack([x[:-1], np.full(slices, y), z[:-1]], axis=1)])
        positions.append(cap)
        normals.append(np.tile([0.0, y, 0.0], (slices + 1, 1)))
        uvs.append(np.stack([0.5 + 0.5 * cap[:, 0], 0.5 + 0.5 * cap[:, 2]], axis=1))
        for j in range(slices):
            p, q = base + 1 + j, base + 1 + (j + 1) % slices
            indices += [base, p, q] if y > 0 else [base, q, p]
        base += slices + 1
    return Mesh("cylinder", np.concatenate(positions), np.array(indices, dtype=np.uint32), np.concatenate(normals),
                np.concatenate(uvs), analytic="cylinder")


#: Built-in meshes by name, for scene files.
BUILTIN_MESHES: dict[str, Callable[[], Mesh]] = {
    "cube": cube,
    "cube24": cube24,
    "quad_strip": quad_strip,
    "quad_list": quad_list,
    "quad_list_swapped": quad_list_swapped,
    "triangle": triangle,
    "plane": plane,
    "sphere": sphere,
    "cylinder": cylinder,
}


def builtin_mesh(name: str) -> Mesh:
    """A built-in mesh by name; :class:`SandboxError` lists the names otherwise."""
    try:
        return BUILTIN_MESHES[name]()
    except KeyError:
        raise SandboxError(f"unknown mesh {name!r}; built-in meshes: {', '.join(BUILTIN_MESHES)}") from None
