"""Model files: triangle meshes from OBJ, PLY, STL, OFF and glTF/GLB, read by trimesh.

:func:`load_model` reads a file into a :class:`Model`: one
:class:`ModelPart` per material of the file, each a
:class:`~glsandbox.geometry.Mesh` (positions, normals, uvs and vertex colours
where the file has them) with its material as the file gives it (base
colour, base colour texture in memory as a :class:`~glsandbox.scene.Texture`,
alpha mode and cutoff, sidedness: :mod:`glsandbox.mesh.looks`), and what
loading did. :meth:`Model.nodes` makes one scene node per part;
:func:`load_mesh` is all parts as one mesh. No format is parsed here: trimesh
reads them (``process=False``: the file's vertices and faces as written,
nothing merged); this module turns what it read into the course's
conventions and checks it.

- **Positions** as written; a glTF's node transforms are applied (its meshes
  that share a material become one part); a mirroring transform gets its
  triangles' winding swapped so fronts stay counter-clockwise.
- **Normals** (``normals=``): ``"auto"`` takes the file's vertex normals when
  it has usable ones (OBJ ``vn``, PLY ``nx ny nz``, glTF ``NORMAL``) and
  otherwise makes them with the crease angle (:mod:`glsandbox.mesh.normals`,
  30° by default: a cube keeps its edges, a scanned surface looks smooth);
  ``"file"`` insists on the file's; ``"crease"``, ``"smooth"`` and ``"flat"``
  always compute them that way. STL's per-facet normals are not vertex
  normals: STL, like OFF, gets computed ones.
- **Uvs**: trimesh gives them with v up (OpenGL's origin at the image's
  bottom-left, glTF's flipped on reading); the course's textures have v
  down, row 0 at the top (:mod:`glsandbox.images`), so v becomes ``1 − v``.
- **Degenerate faces** (zero area: a repeated vertex index, coincident or
  collinear corners) are dropped, not fatal, and counted: the count is in
  :attr:`Model.dropped_faces` and in the mesh's ``notes``, which
  ``glsandbox plan`` prints for the node.
- ``fit=True`` centres the model's bounding box on the origin and scales it
  uniformly so its longest side spans -1..1: the box of the built-in cube and
  sphere, so a model can replace ``mesh = "cube"`` at the same size.

Every problem with the file is one :class:`SandboxError` line naming it: not
found, a folder, a FIFO or device (checked with ``stat`` before anything opens
it, so nothing blocks), empty, unreadable, an unknown extension, data trimesh
cannot read (garbage, truncated), no faces, vertices that are NaN or infinite,
face indices out of range; before trimesh reads it, an ASCII PLY or OFF cut
short or with a face line that does not match its count, and a model that
needs more memory than ``GLSANDBOX_MODEL_MEMORY`` allows
(:mod:`glsandbox.mesh.precheck`). Time and memory are linear in the triangles:
normals and vertices are made by :mod:`glsandbox.mesh.normals` (integer ids,
no per-position square work), a glTF's nodes placed once each, the per-face
steps done in blocks (about 155-190 bytes per triangle of numpy's arrays at the peak, from the parsed
file to the first frame). An OBJ's text is trimesh's largest cost: its parse peaks at about 8 bytes
per byte of the file (572 per triangle for the bunny with normals), so the text is handed to trimesh
and no copy of it is kept here. Loads are cached by (resolved path, modification
time, size, options): loading a file again returns the same :class:`Model`
(and the same Mesh object, whose GPU buffers the executor keeps), until the
file changes. trimesh's log messages and warnings are kept off stderr.
"""

from __future__ import annotations

import contextlib
import functools
import gc
import io
import logging
import math
import os
import warnings
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from numpy.typing import NDArray

from glsandbox.errors import SandboxError
from glsandbox.files import open_user_file
from glsandbox.geometry import Mesh
from glsandbox.mesh.precheck import MEMORY_ENV, check_memory, checked_data, claimed_triangles, needed_bytes
from glsandbox.mesh.looks import Look, file_warnings, is_closed, look_of, warning_data
from glsandbox.mesh.normals import face_geometry, normal_groups, row_ids, split_vertices
from glsandbox.scene import Material, Node, Texture

__all__ = ["CREASE_ANGLE", "FORMATS", "NORMALS", "Model", "ModelPart", "fit_mesh", "is_model_path", "load_mesh",
           "load_model"]

#: File extensions (lower case) and the trimesh file type each is read as.
FORMATS: dict[str, str] = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".off": "off", ".gltf": "gltf",
                           ".glb": "glb"}

#: How normals are made (module docstring): from the file when it has them, else crease; only
#: the file's; or always computed (:data:`glsandbox.mesh.normals.MODES`).
NORMALS = ("auto", "file", "crease", "smooth", "flat")

#: The default crease angle in degrees: faces meeting at a sharper angle keep a hard edge.
CREASE_ANGLE = 30.0

#: A face whose doubled area is at most this share of its longest edge squared is degenerate
#: (the sine of its largest angle is that small): zero area up to rounding.
DEGENERATE_SHARE = 1e-12

#: How many loaded models are kept (least recently used dropped first).
CACHE_SIZE = 16


Rgba = tuple[float, float, float, float]


@dataclass(frozen=True, eq=False)
class ModelPart:
    """The triangles of a model file that share one material, and that material:
    base colour (glTF ``baseColorFactor``, OBJ ``Kd``; None: the file gives none),
    base colour texture (glTF ``baseColorTexture``, OBJ ``map_Kd``: in memory, the
    default sampler), alpha mode and cutoff, and sidedness (glTF ``doubleSided``;
    for the other formats, double-sided unless the model is closed)."""

    name: str
    mesh: Mesh
    texture: Texture | None
    color: Rgba | None
    alpha_mode: str
    alpha_cutoff: float
    double_sided: bool
    triangles: int

    def material(self, **fields: Any) -> Material:
        """A :class:`~glsandbox.scene.Material` drawing this part as the file describes it
        (white when it gives no colour), other fields as given (``shading="phong"``, ...).
        A mesh with vertex colours gets them multiplied in (``vertex_colors``)."""
        fields.setdefault("color", self.color or (1.0, 1.0, 1.0, 1.0))
        fields.setdefault("texture", self.texture)
        fields.setdefault("alpha_mode", self.alpha_mode)
        fields.setdefault("alpha_cutoff", self.alpha_cutoff)
        fields.setdefault("double_sided", self.double_sided)
        unlit_colours = fields.get("shading", "solid") == "vertex_color"  # they are the colour already
        fields.setdefault("vertex_colors", self.mesh.colors is not None and not unlit_colours)
        return Material(**fields)


@dataclass(frozen=True, eq=False)
class Model:
    """A model file, loaded: one :class:`ModelPart` per material, and what loading did.

    Draw it as one node per part (:meth:`nodes`), each with its part's
    material; ``mesh`` is all parts as one mesh (built on first use), for a
    single node that ignores the materials.
    """

    path: Path
    parts: tuple[ModelPart, ...]
    #: Triangles kept, and degenerate ones dropped on loading.
    triangles: int
    dropped_faces: int
    #: Where the normals came from: ``"file"``, ``"crease 30°"``, ``"smooth"`` or ``"flat"``.
    normals: str
    #: Whether the triangles close a volume (:func:`glsandbox.mesh.looks.is_closed`; True for glTF,
    #: which says per material whether back faces are seen).
    closed: bool = True

    @property
    def texture(self) -> Texture | None:
        """The first part's base colour texture."""
        return next((part.texture for part in self.parts if part.texture is not None), None)

    @property
    def color(self) -> Rgba | None:
        """The first part's base colour (None: the file gives none)."""
        return next((part.color for part in self.parts if part.color is not None), None)

    @property
    def warnings(self) -> tuple[str, ...]:
        """What of the file is not drawn, one line each (also on the parts' meshes)."""
        return tuple(line for part in self.parts for line in part.mesh.warnings)

    @functools.cached_property
    def mesh(self) -> Mesh:
        """Every part in one mesh (the first part's mesh when there is one part)."""
        return _joined(self.path.name, [part.mesh for part in self.parts])

    def material(self, **fields: Any) -> Material:
        """The first part's material (:meth:`ModelPart.material`)."""
        return self.parts[0].material(**fields)

    def nodes(self, name: str, model: np.ndarray | None = None, **fields: Any) -> tuple[Node, ...]:
        """One :class:`~glsandbox.scene.Node` per part, named ``name`` (one part) or
        ``name/part``, each with its part's material (``fields`` as :meth:`ModelPart.material`)."""
        matrix = np.eye(4) if model is None else model
        return tuple(Node(name if len(self.parts) == 1 else f"{name}/{part.name}", part.mesh, matrix,
                          part.material(**fields)) for part in self.parts)


def _joined(name: str, meshes: list[Mesh]) -> Mesh:
    """Meshes as one (indices offset; an attribute some lack gets neutral values)."""
    if len(meshes) == 1:
        return meshes[0]
    offsets = np.cumsum([0] + [m.vertex_count for m in meshes])

    def stack(field: str, width: int, fill: float) -> NDArray[np.float64] | None:
        if all(getattr(m, field) is None for m in meshes):
            return None
        return np.concatenate([getattr(m, field) if getattr(m, field) is not None
                               else np.full((m.vertex_count, width), fill) for m in meshes])

    return Mesh(name, np.concatenate([m.positions for m in meshes]),
                np.concatenate([np.asarray(m.indices) + o for m, o in zip(meshes, offsets)]).astype(np.uint32),
                stack("normals", 3, 0.0), stack("uvs", 2, 0.0), stack("colors", 3, 1.0),
                notes=tuple(n for m in meshes for n in m.notes), warnings=tuple(w for m in meshes for w in m.warnings))


def is_model_path(name: str) -> bool:
    """Whether a scene file's ``mesh = "..."`` names a file rather than a built-in mesh:
    built-in names have neither a folder part nor a file extension."""
    return "/" in name or "\\" in name or Path(name).suffix != ""


def load_mesh(path: str | os.PathLike[str], *, fit: bool = False, normals: str = "auto",
              crease_angle: float = CREASE_ANGLE) -> Mesh:
    """The mesh of a model file (:func:`load_model`'s ``.mesh``)."""
    return load_model(path, fit=fit, normals=normals, crease_angle=crease_angle).mesh


def load_model(path: str | os.PathLike[str], *, fit: bool = False, normals: str = "auto",
               crease_angle: float = CREASE_ANGLE) -> Model:
    """Read a model file (OBJ, PLY, STL, OFF, glTF or GLB) into a :class:`Model`.

    ``fit``: centre it and scale it into the box -1..1; ``normals``: one of
    :data:`NORMALS`; ``crease_angle``: in degrees, 0..180, for crease normals.
    Every problem is one :class:`SandboxError` line naming the file (module
    docstring). Cached by path, modification time, size and options.
    numpy's floating-point warnings (a vertex at 1e300 overflows a cross
    product) are not printed: the checks on the results say what is wrong.
    """
    with np.errstate(all="ignore"):
        return _load_model(path, fit=fit, normals=normals, crease_angle=crease_angle)


def _load_model(path: str | os.PathLike[str], *, fit: bool, normals: str, crease_angle: float) -> Model:
    if normals not in NORMALS:
        raise SandboxError(f"unknown normals {normals!r} for a model file; use one of {', '.join(NORMALS)}")
    if isinstance(crease_angle, bool) or not isinstance(crease_angle, (int, float)) \
            or not (math.isfinite(crease_angle) and 0.0 <= crease_angle <= 180.0):
        raise SandboxError(f"crease angle must be a number of degrees in 0..180, got {crease_angle!r}")
    p = Path(path)
    handle, info = _open(p)
    with handle:
        file_type = FORMATS.get(p.suffix.lower())
        if file_type is None:
            known = ", ".join(FORMATS)
            what = f"extension {p.suffix!r}" if p.suffix else "no extension"
            raise SandboxError(f"model file {p}: unknown format ({what}); use one of {known}")
        key = (str(p.resolve()), info.st_mtime_ns, info.st_size, bool(fit), normals, float(crease_angle))
        model = _CACHE.get(key)
        if model is not None:
            _CACHE.move_to_end(key)
            return model
        try:
            data = handle.read()
        except OSError as exc:
            raise SandboxError(f"model file {p} cannot be read ({exc.strerror or exc})") from None
    data = checked_data(p, data, file_type)
    claimed = claimed_triangles(data, file_type)
    if claimed is not None:
        check_memory(p, claimed, needed_bytes(claimed, file_type, data))  # before the reader makes an array
    said = warning_data(data, file_type)  # only a glTF's JSON and an OBJ's mtllib lines are read again
    source = _Source(data, file_type)
    del data  # the reader holds the file's only copy: an OBJ's text is dropped as trimesh copies it
    scene = _trimesh_scene(p, source, file_type)
    del source
    parts = _parts(p, scene)
    del scene
    gc.collect()  # trimesh's objects hold reference cycles: its copies of the data go now, not later
    triangles = sum(part.faces.shape[0] for part in parts)
    check_memory(p, triangles)  # the count itself, for a glTF whose count no header gives
    try:
        model = _model(p, file_type, parts, bool(fit), normals, float(crease_angle), said)
    except MemoryError:
        raise SandboxError(f"model file {p}: out of memory making {triangles:,} triangles drawable (set "
                           f"{MEMORY_ENV} below the memory this machine has, so a model too big is refused "
                           "before loading)") from None
    _CACHE[key] = model
    while len(_CACHE) > CACHE_SIZE:
        _CACHE.popitem(last=False)
    return model


def clear_cache() -> None:
    """Forget every model loaded (a renderer kept for many graded submissions, before each)."""
    _CACHE.clear()


def fit_mesh(mesh: Mesh) -> Mesh:
    """``mesh`` centred on the origin and scaled uniformly so its bounding box's
    longest side spans -1..1 (normals unchanged: a uniform scale keeps their directions)."""
    positions = np.asarray(mesh.positions, dtype=np.float64)
    if positions.size == 0:
        return mesh
    centre, scale = _fit_transform(positions, mesh.name)
    return replace(mesh, positions=(positions - centre) * scale)


def _box(positions: NDArray[np.float64]) -> NDArray[np.float64]:
    """``[low, high]``, the bounding box of ``(N, 3)`` points: column by column (a reduction over
    the rows of an ``(N, 3)`` array is several times slower; minima and maxima are exact either way)."""
    return np.array([[column.min() for column in positions.T], [column.max() for column in positions.T]])


def _fit_transform(positions: NDArray[np.float64], name: str = "model") -> tuple[NDArray[np.float64], float]:
    """``(centre, scale)``: ``(p - centre) * scale`` puts the points' bounding box
    centred on the origin with its longest side spanning -1..1."""
    low, high = positions.min(axis=0), positions.max(axis=0)
    extent = float((high - low).max())
    if not (math.isfinite(extent) and extent > 0.0):
        raise SandboxError(f"mesh {name!r} has no extent to fit (all its vertices are one point)")
    return (low + high) / 2.0, 2.0 / extent


_CACHE: OrderedDict[tuple[Any, ...], Model] = OrderedDict()


# --- the file -------------------------------------------------------------


def _open(p: Path) -> tuple[BinaryIO, os.stat_result]:
    """The open model file and its ``stat``: anything but a regular, non-empty file is
    refused before a byte is read (a FIFO would wait for a writer forever)."""
    handle = open_user_file(p, "model file", "a model file")
    info = os.fstat(handle.fileno())
    if info.st_size == 0:
        handle.close()
        raise SandboxError(f"model file {p} is empty")
    return handle, info


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """trimesh's log records and warnings kept off stderr (its loggers are all under ``trimesh``)."""
    logger = logging.getLogger("trimesh")
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            yield
    finally:
        logger.setLevel(level)


def _reason(exc: BaseException) -> str:
    """A short, one-line reason from a reader's exception."""
    if isinstance(exc, ImportError):  # trimesh reached for an optional package: the data was not what it expected
        return "unrecognised data"
    if isinstance(exc, IndexError):
        return f"a face index is out of range ({' '.join(str(exc).split())})"
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


class _Source:
    """The file's bytes as trimesh reads them: a binary file from memory; an OBJ as its text,
    decoded here (:func:`glsandbox.mesh.precheck.checked_data` made it UTF-8, as trimesh would decode
    it) and handed over at trimesh's one ``read()``: trimesh copies the text as it cleans it up,
    and no copy of it is kept here (an OBJ's text is the reader's largest array)."""

    def __init__(self, data: bytes, file_type: str) -> None:
        self.text: str | None = data.decode("utf-8") if file_type == "obj" else None
        self.stream = None if self.text is not None else io.BytesIO(data)

    def reader(self) -> Any:
        return self if self.text is not None else self.stream

    def read(self, size: int = -1) -> str:  # trimesh's OBJ reader reads the whole text once
        text, self.text = self.text or "", None
        return text


def _trimesh_scene(p: Path, source: _Source, file_type: str) -> Any:
    """The file as a ``trimesh.Scene`` (every format becomes one), read from ``source``."""
    with _quiet():
        import trimesh  # only a model load pays for the import
        from trimesh.resolvers import FilePathResolver

        class RegularFiles(FilePathResolver):  # a .gltf's buffers and images: also never a FIFO
            def get(self, name: str) -> bytes:
                target = Path(self.parent) / name.strip()
                if target.exists() and not target.is_file():
                    raise ValueError(f"{name!r} is not a regular file")
                return super().get(name)

        try:
            resolver = RegularFiles(str(p))
            # trimesh names the scene's nodes after the file and hashes the names as UTF-8: a name
            # with bytes that are not UTF-8 (kept by Python as surrogates) is given printable stand-ins.
            resolver.file_name = _printable(resolver.file_name)
            resolver.file_path = _printable(resolver.file_path)
            loader = getattr(trimesh, "load_scene", None)
            if loader is not None:
                return loader(source.reader(), file_type=file_type, resolver=resolver, process=False)
            return trimesh.load(source.reader(), file_type=file_type, resolver=resolver, process=False,
                                force="scene")
        except SandboxError:
            raise
        except (Exception, RecursionError) as exc:  # anything a reader raises on bad data
            raise SandboxError(f"model file {p}: not a readable {file_type.upper()} file: {_reason(exc)}") from None


def _printable(name: str) -> str:
    """``name`` with the undecodable bytes of a file name (surrogates) replaced by U+FFFD."""
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


@dataclass
class _Part:
    """One mesh of the file, in the model's space (a glTF node's transform applied)."""

    positions: NDArray[np.float64]
    faces: NDArray[np.int64]
    normals: NDArray[np.float64] | None
    uvs: NDArray[np.float64] | None
    colors: NDArray[np.float64] | None  # per vertex (N, 3), or per corner (F, 3, 3) from face colours
    look: Look


def _parts(p: Path, scene: Any) -> list[_Part]:
    """Every triangle mesh the scene places, with its transform applied."""
    import trimesh

    parts = []
    looks: dict[int, Look] = {}  # by material object: many meshes may share one (and its big image)
    with _quiet():
        try:
            for transform, name in _placements(scene.graph, p):
                geometry = scene.geometry.get(name)
                if isinstance(geometry, trimesh.Trimesh):
                    parts.append(_part(geometry, transform, len(parts), looks))
        except SandboxError:
            raise
        except Exception as exc:
            raise SandboxError(f"model file {p}: not a readable model: {_reason(exc)}") from None
    return parts


def _placements(graph: Any, path: Path) -> list[tuple[NDArray[np.float64], Any]]:
    """``(world transform, geometry name)`` of every node with geometry, in trimesh's node order.

    A node that is its own ancestor (glTF nodes whose ``children`` form a cycle,
    which the glTF spec forbids) is refused naming ``path`` and the node: the
    walk up its parents would never reach the root.

    Asking trimesh's graph (``graph[node]``) walks the path from the root for
    every node and checks a hash of the whole graph on each call: a chain of
    5,000 nested nodes took minutes. Here each node's world transform is its
    parent's times its own edge's, each worked out once (linear in the nodes).
    """
    from trimesh.transformations import fix_rigid

    forest = graph.transforms
    base = graph.base_frame
    world: dict[Any, NDArray[np.float64]] = {base: np.eye(4)}

    def transform_of(node: Any) -> NDArray[np.float64]:
        chain = []  # the node and its ancestors whose transforms are not known yet, deepest first
        seen = set()
        while node not in world:
            if node in seen:
                raise SandboxError(f"model file {path}: node {node!r} is its own ancestor "
                                   "(its nodes' children form a cycle)")
            seen.add(node)
            parent = forest.parents.get(node)
            if parent is None:  # not under the root: trimesh would not place it either
                world[node] = np.eye(4)
                break
            chain.append((parent, node))
            node = parent
        for parent, child in reversed(chain):
            edge = forest.edge_data.get((parent, child), {}).get("matrix")
            world[child] = world[parent] if edge is None else world[parent] @ np.asarray(edge, dtype=np.float64)
        return world[node if not chain else chain[0][1]]

    placed = []
    for node in graph.nodes_geometry:
        matrix = transform_of(node)
        if graph.repair_rigid is not None:  # as trimesh does: an almost rigid product made rigid again
            matrix = fix_rigid(matrix, max_deviance=graph.repair_rigid)
        placed.append((np.asarray(matrix, dtype=np.float64), forest.node_data[node].get("geometry")))
    return placed


def _part(mesh: Any, transform: NDArray[np.float64], index: int, looks: dict[int, Look]) -> _Part:
    # Views of trimesh's arrays where their types already fit (no copy: every step below makes new arrays).
    positions = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    normals = _file_normals(mesh, positions.shape[0])
    linear = transform[:3, :3]
    if not np.array_equal(transform, np.eye(4)):
        positions = positions @ linear.T + transform[:3, 3]
        if normals is not None:
            with np.errstate(all="ignore"):
                normals = normals @ np.linalg.inv(linear)  # (M⁻¹)ᵀ applied to row vectors
        if np.linalg.det(linear) < 0.0:  # a mirror turns the winding: swap to keep fronts counter-clockwise
            faces = faces[:, [0, 2, 1]]
    uvs = colors = None
    visual = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    material = getattr(visual, "material", None)
    look = looks.get(id(material)) if material is not None else None
    if look is None:
        look = look_of(material, index)
        if material is not None:
            looks[id(material)] = look
    if kind == "texture":
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == positions.shape[0]:
            uvs = np.array(uv, dtype=np.float64).reshape(-1, 2)
            uvs[:, 1] = 1.0 - uvs[:, 1]  # trimesh's v up -> the course's v down
    elif kind == "vertex":
        colors = np.asarray(visual.vertex_colors, dtype=np.float64)[:, :3] / 255.0
    elif kind == "face":
        face_colors = np.asarray(visual.face_colors, dtype=np.float64)[:, :3] / 255.0
        colors = np.repeat(face_colors[:, None, :], 3, axis=1)
    return _Part(positions, faces, normals, uvs, colors, look)


def _file_normals(mesh: Any, count: int) -> NDArray[np.float64] | None:
    """The vertex normals the file gave, or None. trimesh keeps given normals in the
    mesh's cache (its exporters test the same way); asking ``mesh.vertex_normals``
    would compute some instead. The cache's own dict is read: asking the cache
    (``in``, ``[]``) first hashes the mesh's arrays to see whether they changed since,
    which they have not (``process=False``: nothing after reading touches them)."""
    store = getattr(getattr(mesh, "_cache", None), "cache", None)
    given = store.get("vertex_normals") if isinstance(store, dict) else None
    if given is None:
        return None
    normals = np.array(given, dtype=np.float64)
    return normals if normals.shape == (count, 3) else None


# --- from parts to one mesh ------------------------------------------------


def _model(p: Path, file_type: str, parts: list[_Part], fit: bool, normals_mode: str, crease: float,
           data: bytes) -> Model:
    vertex_total = sum(part.positions.shape[0] for part in parts)
    if not parts or sum(part.faces.shape[0] for part in parts) == 0:
        what = f" (only {vertex_total:,} vertices)" if vertex_total else ""
        raise SandboxError(f"model file {p} has no faces{what}")
    # One vertex and face list for all parts, to check them as the file numbers them.
    offsets = np.cumsum([0] + [part.positions.shape[0] for part in parts])
    positions, faces = _all_parts(parts, offsets)
    if not np.isfinite(positions.reshape(-1)).all():  # (flat: a row-wise test is ten times slower)
        bad = np.flatnonzero(~np.isfinite(positions).all(axis=1))
        raise SandboxError(f"model file {p}: {_count(bad.size, 'vertex', 'vertices')} with NaN or infinite "
                           f"coordinates (the first is vertex {int(bad[0])})")
    if faces.size and (faces.min() < 0 or faces.max() >= positions.shape[0]):
        outside = (faces < 0) | (faces >= positions.shape[0])
        f = int(np.flatnonzero(outside.any(axis=1))[0])
        index = int(faces[f][outside[f]][0])
        raise SandboxError(f"model file {p}: face {f} refers to vertex {index}, but the file has "
                           f"{positions.shape[0]:,} vertices (index out of range)")
    if any(part.uvs is not None and not np.isfinite(part.uvs).all() for part in parts):
        raise SandboxError(f"model file {p}: texture coordinates are NaN or infinite")
    # Parts that look alike (one material) become one mesh, one node when drawn.
    groups: dict[tuple[Any, ...], list[_Part]] = {}
    for part in parts:
        groups.setdefault(part.look.key, []).append(part)
    # Sidedness: glTF says per material; otherwise one-sided only when the model is closed.
    # Equal positions, numbered once for the whole file: for closedness and for every part's vertices.
    position_ids = row_ids(positions, ordered=False)[0]
    closed = file_type in ("gltf", "glb") or is_closed(positions, faces, position_ids)
    undrawn = file_warnings(p, data, file_type, [part.look for part in parts])
    built = []
    dropped = 0
    index = {id(part): i for i, part in enumerate(parts)}
    for members in groups.values():
        look = members[0].look
        ids = [position_ids[offsets[index[id(part)]]:offsets[index[id(part)] + 1]] for part in members]
        group_ids = ids[0] if len(ids) == 1 else np.concatenate(ids)
        if len(groups) > 1:  # numbered 0.. within the group (its arrays are sized by the largest id)
            group_ids = _compact_ids(group_ids)
        mesh, kept, lost, how = _group_mesh(p, file_type, members, group_ids, normals_mode, crease,
                                            look.name if len(groups) > 1 else None)
        dropped += lost
        if mesh is not None:
            built.append((look, mesh, kept, how))
    if not built:
        raise SandboxError(f"model file {p} has no faces: all {faces.shape[0]:,} are degenerate "
                           "(zero area or a repeated vertex)")
    transform = None
    if fit:  # the box of all parts' boxes
        corners = np.concatenate([_box(mesh.positions) for _, mesh, _, _ in built])
        transform = _fit_transform(corners)
    model_parts = []
    for i, (look, mesh, kept, how) in enumerate(built):
        said = [f"model file {p}: {', '.join(undrawn[''])} not drawn"] if i == 0 and undrawn.get("") else []
        if look.name in undrawn:
            said.append(f"model file {p}, part {look.name!r}: {', '.join(undrawn[look.name])} not drawn")
        texture = None
        notes = list(mesh.notes)
        if look.image is not None:
            if mesh.uvs is None:
                notes.append("its texture is not used: the mesh has no texture coordinates")
                said.append(f"model file {p}, part {look.name!r}: its texture not drawn "
                                "(the mesh has no texture coordinates)")
            else:
                where = "" if len(built) == 1 else f"{look.name}/"
                texture = Texture(f"{p}#{where}base_color", image=look.image)
        positions = mesh.positions
        if transform is not None:
            notes.append("fitted into -1..1")
            positions -= transform[0]
            positions *= transform[1]
        mesh = Mesh(mesh.name, positions, mesh.indices, mesh.normals, mesh.uvs, mesh.colors, notes=tuple(notes),
                    warnings=tuple(said))
        sided = look.double_sided if look.double_sided is not None else not closed
        model_parts.append(ModelPart(look.name, mesh, texture, look.color, look.alpha_mode, look.alpha_cutoff,
                                     sided, kept))
    total = sum(part.triangles for part in model_parts)
    return Model(p, tuple(model_parts), total, dropped, built[0][3], closed)


@dataclass
class _Arrays:
    """A part's mesh before it is fitted and made a :class:`~glsandbox.geometry.Mesh` (once: making one
    checks every array)."""

    name: str
    positions: NDArray[np.float64]
    indices: NDArray[np.uint32]
    normals: NDArray[np.float64]
    uvs: NDArray[np.float64] | None
    colors: NDArray[np.float64] | None
    notes: tuple[str, ...]


def _group_mesh(p: Path, file_type: str, parts: list[_Part], position_ids: NDArray[np.intp], normals_mode: str,
                crease: float,
                part_name: str | None) -> tuple[_Arrays | None, int, int, str]:
    """One mesh for parts that share a material: ``(its arrays, triangles, degenerate faces
    dropped, how its normals were made)``; none when every face was degenerate. ``position_ids``:
    the parts' vertices numbered by position (:func:`glsandbox.mesh.normals.row_ids`)."""
    offsets = np.cumsum([0] + [part.positions.shape[0] for part in parts])
    positions, faces = _all_parts(parts, offsets)
    # Optional attributes: a part without them gets neutral values when another has them.
    has_uvs = any(part.uvs is not None for part in parts)
    uvs = np.concatenate([part.uvs if part.uvs is not None else np.zeros((part.positions.shape[0], 2))
                          for part in parts]) if has_uvs else None
    corner_colors = _corner_colors(parts) if any(part.colors is not None for part in parts) else None
    file_normals = None
    if all(part.normals is not None for part in parts):
        file_normals = np.concatenate([part.normals for part in parts])  # type: ignore[misc]
    # What normals need of each face (its unit normal, its corner angles: none when the file's normals
    # will do), and its area: degenerate faces are dropped and counted.
    angles_needed = normals_mode not in ("auto", "file", "flat") or (normals_mode == "auto" and file_normals is None)
    unit, angles, flat = face_geometry(positions, faces, angles_needed, DEGENERATE_SHARE)
    keep = ~((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2]) | flat)
    del flat
    dropped = int(faces.shape[0] - keep.sum())
    if not keep.any():
        return None, 0, dropped, ""
    if dropped:
        faces, unit = faces[keep], unit[keep]
        if angles.size:
            angles = angles.reshape(-1, 3)[keep].reshape(-1)
    if corner_colors is not None:
        corner_colors = corner_colors[keep]
    del keep
    group, group_normals, how = _normal_groups(p, positions, faces, file_normals, normals_mode, crease,
                                               position_ids, (unit, angles))
    del unit, angles
    corners = faces.reshape(-1)
    index, first = _split_vertices(position_ids, uvs, corners, corner_colors, group)
    del position_ids
    # The drawn arrays, each corner-sized temporary dropped as soon as it is used (the peak).
    normals = group_normals.take(group.take(first), axis=0)
    del group, group_normals
    indices = index.astype(np.uint32)
    del index
    colors = None if corner_colors is None else corner_colors.reshape(-1, 3).take(first, axis=0)
    del corner_colors
    chosen = corners.take(first)
    del first
    where = p.name if part_name is None else f"{p.name}, part {part_name!r}"
    notes = [f"{where}: {_count(faces.shape[0], 'triangle')} ({file_type.upper()})"]
    if dropped:
        notes.append(f"{_count(dropped, 'degenerate face')} dropped (zero area or a repeated vertex)")
    notes.append(f"normals {'from the file' if how == 'file' else how}")
    name = p.name if part_name is None else f"{p.name}#{part_name}"
    mesh = _Arrays(name, positions.take(chosen, axis=0), indices, normals,
                   None if uvs is None else uvs.take(chosen, axis=0), colors, tuple(notes))
    return mesh, int(faces.shape[0]), dropped, how


def _compact_ids(ids: NDArray[np.intp]) -> NDArray[np.intp]:
    """``ids`` renumbered 0, 1, ... in the same order (equal stay equal, smaller stay smaller).

    The normals and vertices of a group size their arrays by its largest position id; with the
    file's numbering every group of a file of many materials (a glTF of many nodes) would pay for
    the whole file's positions, quadratic in the parts. An order-kept renumbering changes no
    result: only equality and order of the ids are used."""
    if ids.size == 0:
        return ids
    return np.unique(ids, return_inverse=True)[1].reshape(-1).astype(np.intp, copy=False)


def _all_parts(parts: list[_Part], offsets: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """All parts' positions and faces as one list (a single part's arrays as they are: no copy)."""
    if len(parts) == 1:
        return parts[0].positions, parts[0].faces
    return (np.concatenate([part.positions for part in parts]),
            np.concatenate([part.faces + offset for part, offset in zip(parts, offsets)]))


def _count(n: int, one: str, many: str | None = None) -> str:
    """``1 triangle``, ``1,280 triangles``."""
    return f"{n:,} {one if n == 1 else many or one + 's'}"


def _corner_colors(parts: list[_Part]) -> NDArray[np.float64]:
    """Colours per face corner, (F, 3, 3), for all parts (white where a part has none)."""
    blocks = []
    for part in parts:
        if part.colors is None:
            blocks.append(np.ones((part.faces.shape[0], 3, 3)))
        elif part.colors.ndim == 3:
            blocks.append(part.colors)
        else:
            blocks.append(part.colors[part.faces])
    return np.concatenate(blocks)


def _normal_groups(p: Path, positions: NDArray[np.float64], faces: NDArray[np.int64],
                   file_normals: NDArray[np.float64] | None, mode: str, crease: float,
                   position_ids: NDArray[np.intp], geometry: tuple[NDArray[np.float64], NDArray[np.float64]],
                   ) -> tuple[NDArray[np.intp], NDArray[np.float64], str]:
    """Corner normals as ``(group (C,), unit normals (G, 3))`` (corner ``c`` has ``normals[group[c]]``,
    :func:`glsandbox.mesh.normals.normal_groups`), and how they were made. ``geometry``: the faces'
    unit normals and corner angles (:func:`glsandbox.mesh.normals.face_geometry`; no angles when
    the file's normals were expected)."""
    if mode in ("auto", "file"):
        usable = None
        if file_normals is not None:
            with np.errstate(all="ignore"):
                size = np.sqrt(np.einsum("ij,ij->i", file_normals, file_normals))
                fine = np.isfinite(file_normals).all(axis=1) & (size > 1e-12)
                if fine[faces].all():  # only the vertices the faces use need a normal
                    usable = file_normals / np.where(fine, size, 1.0)[:, None]
        if usable is not None:  # one group per distinct normal: with the position, it tells vertices apart
            ids, firsts = row_ids(usable, ordered=False)
            return ids[faces.reshape(-1)], usable[firsts], "file"
        if mode == "file":
            why = "has no vertex normals" if file_normals is None else "has zero-length or non-finite normals"
            raise SandboxError(f"model file {p} {why} (normals = \"file\"); use \"auto\" to compute them")
        mode = "crease"
    known = geometry if mode == "flat" or geometry[1].size else None
    group, normals = normal_groups(positions, np.asarray(faces, dtype=np.intp), mode, crease, position_ids, known)
    return group, normals, f"crease {crease:g}°" if mode == "crease" else mode


def _split_vertices(position_ids: NDArray[np.intp], uvs: NDArray[np.float64] | None, corners: NDArray[np.int64],
                    corner_colors: NDArray[np.float64] | None,
                    group: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The drawn vertices: ``(index (C,), a corner of each)``. Corners share a vertex exactly when
    their position, uv, colour and normal are bit-identical; each is numbered once (positions and
    uvs per file vertex; normals by ``group``, which at one position is equal exactly when the
    normals are), so only integers are compared per corner."""
    attribute = position_ids
    if uvs is not None:
        attribute = split_vertices(position_ids, row_ids(uvs, ordered=False)[0])[0]
    attribute = attribute.take(corners)
    if corner_colors is not None:
        attribute = split_vertices(attribute, row_ids(corner_colors.reshape(-1, 3), ordered=False)[0],
                                   reuse=True)[0]
    return split_vertices(attribute, group, reuse=True)
