"""Real models from files: OBJ, PLY, STL, OFF and glTF/GLB into a :class:`~glsandbox.geometry.Mesh`.

``trimesh`` reads the formats (no parser is written here); this module
checks what it gets and turns it into the project's conventions:

- **one mesh**: every part of a file (OBJ groups, glTF nodes) is moved by
  its transform in the file's scene graph and joined into one indexed
  triangle list (``mode="triangles"``); a transform that mirrors (negative
  determinant) has its triangles' winding reversed, so counter-clockwise
  stays the front (OpenGL's rule). Coordinates are kept as the file has
  them: OBJ and glTF are right-handed ``+y`` up like the project; STL and
  PLY files are often ``+z`` up (turn the node in the scene if so).
- **normals** (``normals=``): ``"auto"`` (default) takes the file's vertex
  normals when every part has them, else ``"crease"``; ``"file"`` insists on
  the file's; ``"crease"`` smooths across edges flatter than
  ``crease_angle`` (30° by default) and keeps sharper ones sharp;
  ``"smooth"`` and ``"flat"`` are the two extremes
  (:mod:`glsandbox.meshnormals`). Vertices are split where their normals
  (or uv, or colours) differ and shared where they are identical.
- **uv** where the file has texture coordinates, flipped to the course's
  convention (``v = 0`` at the top row of the image, see
  :mod:`glsandbox.images`; trimesh gives OpenGL's bottom-left origin).
- **texture**: the base colour image of a glTF material (or an OBJ
  material's ``map_Kd``) as an RGBA ``uint8`` array, row 0 at the top,
  in :attr:`LoadedMesh.texture`; the material's colour factor in
  :attr:`LoadedMesh.base_color`. One texture per mesh: parts with another
  image are counted in :attr:`LoadedMesh.ignored_textures`.
- **degenerate faces** (a repeated corner, or zero area by the ray
  tracer's rule ``|e1 × e2| <= 64·eps·|e1|·|e2|``) are dropped, and counted
  in :attr:`LoadedMesh.dropped_degenerate`; they draw nothing.
- ``fit=True`` centres the model's box at the origin and scales it so its
  longest side is :data:`FIT_SIZE` (2: the size of the built-in cube and
  sphere, ``-1..1``).

Everything wrong with a file raises :class:`~glsandbox.errors.SandboxError`
with one line naming the file: missing, a folder, a named pipe or device
(checked before opening, so a FIFO never blocks), empty, an unsupported
extension, binary garbage, truncated, no faces, NaN or infinite
coordinates, indices out of range. trimesh's own log messages and warnings
are silenced while it reads. Nothing is downloaded: a glTF's external
buffers and images are read from beside the file only.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import os
import stat
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh
from glsandbox.meshnormals import corner_normals, unique_vertices

__all__ = ["FIT_SIZE", "FORMATS", "NORMALS", "LoadedMesh", "load_mesh"]

#: File extensions read, and trimesh's name for each format.
FORMATS: dict[str, str] = {".obj": "obj", ".ply": "ply", ".stl": "stl", ".off": "off", ".gltf": "gltf",
                           ".glb": "glb"}
#: The ``normals=`` choices.
NORMALS = ("auto", "file", "crease", "smooth", "flat")
#: The longest side of a model loaded with ``fit=True``.
FIT_SIZE: float = 2.0
#: Zero area, by the ray tracer's rule (:data:`glsandbox.raytrace.triangle.DEGENERATE_SIN`).
_DEGENERATE_SIN = 64.0 * float(np.finfo(np.float64).eps)
_TEXT_FORMATS = ("obj", "off", "gltf")


@dataclass(frozen=True, eq=False)
class LoadedMesh:
    """A model read from a file: the mesh, and what the file said besides."""

    mesh: Mesh
    path: Path
    #: The base colour image (RGBA uint8, row 0 at the top), sampled at ``mesh.uvs``; None without one.
    texture: NDArray[np.uint8] | None = None
    #: The material's colour (glTF ``baseColorFactor``, OBJ ``Kd``), rgba 0..1; white without one.
    base_color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    #: Faces dropped for having no area (a repeated corner or collinear corners).
    dropped_degenerate: int = 0
    #: Where the normals came from: "file", "crease", "smooth" or "flat".
    normals: str = "crease"
    #: Parts (meshes placed in the file's scene) joined into ``mesh``.
    parts: int = 1
    #: Parts whose texture differs from the one kept.
    ignored_textures: int = 0
    #: ``fit=True``: positions became ``(p − fit_center)·fit_scale``.
    fit_scale: float = 1.0
    fit_center: tuple[float, float, float] = field(default=(0.0, 0.0, 0.0))

    @property
    def triangle_count(self) -> int:
        return self.mesh.element_count // 3

    def describe(self) -> str:
        """One line for ``glsandbox plan``: size, normals, what was dropped or ignored."""
        parts = [f"{self.path.name}: {self.triangle_count:,} triangles, {self.mesh.vertex_count:,} vertices",
                 f"normals {'from the file' if self.normals == 'file' else self.normals}"]
        if self.mesh.uvs is not None:
            parts.append("uv")
        if self.texture is not None:
            parts.append(f"texture {self.texture.shape[1]}x{self.texture.shape[0]}")
        if self.dropped_degenerate:
            parts.append(f"{self.dropped_degenerate:,} degenerate faces dropped")
        if self.ignored_textures:
            parts.append(f"{self.ignored_textures} other textures ignored")
        if self.fit_scale != 1.0 or any(self.fit_center):
            parts.append(f"fitted (scale {self.fit_scale:.4g})")
        return ", ".join(parts)


# --- reading the bytes ------------------------------------------------------------


def _format_of(path: Path) -> str:
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        shown = path.suffix or "no extension"
        raise SandboxError(f"{path}: unsupported mesh file type ({shown}); use one of {', '.join(FORMATS)}")
    return fmt


def _kind_of(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a regular file"


def _read_bytes(path: Path) -> bytes:
    """The file's bytes, refusing anything but a regular file *before* reading it.

    A named pipe would block ``open`` until a writer came: the type is
    checked with ``stat`` first, and the file is opened non-blocking and
    checked again (``fstat``) in case it was swapped in between.
    """
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise SandboxError(f"{path}: mesh file not found") from None
    except OSError as exc:
        raise SandboxError(f"{path}: cannot read the mesh file ({exc.strerror or exc})") from None
    if not stat.S_ISREG(info.st_mode):
        raise SandboxError(f"{path}: is {_kind_of(info.st_mode)}, not a mesh file")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise SandboxError(f"{path}: cannot read the mesh file ({exc.strerror or exc})") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise SandboxError(f"{path}: is {_kind_of(mode)}, not a mesh file")
        with os.fdopen(fd, "rb", closefd=False) as handle:
            data = handle.read()
    except OSError as exc:
        raise SandboxError(f"{path}: cannot read the mesh file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if not data:
        raise SandboxError(f"{path}: the file is empty (0 bytes)")
    return data


def _check_bytes(path: Path, fmt: str, data: bytes) -> bytes:
    """Catch garbage and truncation trimesh would report badly (or not at all);
    text formats come back as UTF-8 (non-UTF-8 text is read as Latin-1)."""
    name = fmt.upper()
    if fmt in _TEXT_FORMATS:
        if b"\x00" in data:
            raise SandboxError(f"{path}: binary data where a text {name} file was expected")
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            text = data.decode("latin-1")  # numbers are ASCII; only names and comments can be odd
            data = text.encode("utf-8")
        if fmt == "gltf":
            try:
                json.loads(text)
            except ValueError as exc:
                raise SandboxError(f"{path}: not a glTF file: invalid JSON ({exc})") from None
        return data
    if fmt == "ply":
        if not data.startswith((b"ply\n", b"ply\r\n")):
            raise SandboxError(f"{path}: not a PLY file (it does not start with a 'ply' line)")
        return data
    if fmt == "glb":
        if len(data) < 12 or data[:4] != b"glTF":
            raise SandboxError(f"{path}: not a GLB file (no 'glTF' header)")
        declared = int.from_bytes(data[8:12], "little")
        if declared != len(data):
            raise SandboxError(f"{path}: truncated or damaged GLB: its header says {declared:,} bytes, "
                               f"the file has {len(data):,}")
        return data
    # STL: binary (80-byte header, a triangle count, 50 bytes a triangle) or ASCII ("solid ...").
    if len(data) >= 84:
        count = int.from_bytes(data[80:84], "little")
        if 84 + 50 * count == len(data):
            return data
    ascii_like = data[:5].lower() == b"solid" and b"\x00" not in data
    if ascii_like:
        try:
            return data.decode("utf-8").encode("utf-8")
        except UnicodeDecodeError:
            return data.decode("latin-1").encode("utf-8")
    if len(data) < 84:
        raise SandboxError(f"{path}: too short for an STL file ({len(data)} bytes)")
    count = int.from_bytes(data[80:84], "little")
    raise SandboxError(f"{path}: not a valid binary STL file: its header counts {count:,} triangles "
                       f"({84 + 50 * count:,} bytes) but the file has {len(data):,} bytes (truncated?)")


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Silence trimesh while it reads: its logger, Python warnings, numpy's floating-point
    warnings, and anything printed."""
    logger = logging.getLogger("trimesh")
    was = logger.disabled
    logger.disabled = True
    sink = io.StringIO()
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"), contextlib.redirect_stdout(sink), \
                contextlib.redirect_stderr(sink):
            warnings.simplefilter("ignore")
            yield
    finally:
        logger.disabled = was


def _load_scene(path: Path, fmt: str, data: bytes) -> Any:
    import trimesh  # imported here: reading a model is rare, starting the program is not

    resolver = trimesh.resolvers.FilePathResolver(str(path))
    try:
        with _quiet():
            return trimesh.load_scene(file_obj=io.BytesIO(data), file_type=fmt, resolver=resolver, process=False)
    except SandboxError:
        raise
    except Exception as exc:  # trimesh raises anything from ValueError to IndexError to KeyError
        reason = " ".join(str(exc).split()) or type(exc).__name__
        if isinstance(exc, (IndexError, KeyError)):
            reason = f"indices out of range: a face or accessor refers to data the file does not have ({reason})"
        raise SandboxError(f"{path}: cannot read this {fmt.upper()} file: {reason}") from None


# --- from trimesh's scene to arrays ---------------------------------------------


@dataclass
class _Part:
    positions: NDArray[np.float64]
    faces: NDArray[np.int64]
    normals: NDArray[np.float64] | None
    uvs: NDArray[np.float64] | None
    colors: NDArray[np.float64] | None
    image: Any  # a PIL image or None
    base_color: tuple[float, float, float, float] | None


def _file_normals(geometry: Any) -> NDArray[np.float64] | None:
    """The vertex normals the file gave, if any (trimesh keeps them in its cache, where
    its own exporters look for them, instead of recomputing)."""
    cache = getattr(getattr(geometry, "_cache", None), "cache", {})
    normals = cache.get("vertex_normals") if isinstance(cache, dict) else None
    if normals is None:
        return None
    normals = np.asarray(normals, dtype=np.float64)
    return normals if normals.shape == np.shape(geometry.vertices) else None


def _visual(geometry: Any, vertex_count: int
            ) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None, Any,
                       tuple[float, float, float, float] | None]:
    """``(uvs, colours, image, base colour)`` of a trimesh geometry."""
    visual = getattr(geometry, "visual", None)
    kind = getattr(visual, "kind", None)
    uvs: NDArray[np.float64] | None = None
    colors: NDArray[np.float64] | None = None
    image: Any = None
    base: tuple[float, float, float, float] | None = None
    if kind == "texture":
        uv = getattr(visual, "uv", None)
        if uv is not None and np.shape(uv) == (vertex_count, 2):
            uvs = np.asarray(uv, dtype=np.float64).copy()
            uvs[:, 1] = 1.0 - uvs[:, 1]  # trimesh's origin is bottom-left; the course's v = 0 is the top row
        material = getattr(visual, "material", None)
        image = getattr(material, "baseColorTexture", None) or getattr(material, "image", None)
        placeholder = image is not None and _placeholder(image)
        if placeholder:  # trimesh's stand-in material: no image, no colour from the file
            image = material = None
        # glTF's baseColorFactor, an OBJ material's Kd.
        factor = getattr(material, "baseColorFactor", None)
        if factor is None:
            factor = getattr(material, "diffuse", None)
        if factor is not None:
            rgba = [float(x) / 255.0 for x in np.asarray(factor, dtype=np.float64).reshape(-1)[:4]]
            rgba += [1.0] * (4 - len(rgba))
            base = (rgba[0], rgba[1], rgba[2], rgba[3])
        attribute = getattr(geometry, "vertex_attributes", {}).get("color")
        if attribute is not None and np.shape(attribute)[0] == vertex_count:
            colors = np.asarray(attribute, dtype=np.float64)[:, :3] / 255.0
    elif kind == "vertex" and visual is not None:
        colors = np.asarray(visual.vertex_colors, dtype=np.float64)[:, :3] / 255.0
    return uvs, colors, image, base


def _placeholder(image: Any) -> bool:
    """trimesh gives a textured mesh whose file names no material a tiny one-colour image
    (``empty_material``): that is no texture."""
    width, height = image.size
    if width * height > 4:
        return False
    pixels = np.asarray(image.convert("RGBA")).reshape(-1, 4)
    return bool((pixels == pixels[0]).all())


def _parts(path: Path, scene: Any) -> list[_Part]:
    """Every mesh instance of trimesh's scene, in world coordinates of the file's scene graph."""
    import trimesh

    parts: list[_Part] = []
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        geometry = scene.geometry.get(geometry_name)
        if not isinstance(geometry, trimesh.Trimesh):
            continue  # points and lines have no surface
        positions = np.asarray(geometry.vertices, dtype=np.float64)
        faces = np.asarray(geometry.faces, dtype=np.int64).reshape(-1, 3)
        normals = _file_normals(geometry)
        uvs, colors, image, base = _visual(geometry, positions.shape[0])
        m = np.asarray(transform, dtype=np.float64)
        if not np.array_equal(m, np.eye(4)):
            positions = positions @ m[:3, :3].T + m[:3, 3]
            if normals is not None:  # by the normal matrix (M³ˣ³)⁻ᵀ
                with np.errstate(all="ignore"):
                    normals = normals @ np.linalg.inv(m[:3, :3])
            if np.linalg.det(m[:3, :3]) < 0.0:  # a mirror flips the winding: keep counter-clockwise in front
                faces = faces[:, ::-1]
        parts.append(_Part(positions, faces, normals, uvs, colors, image, base))
    return parts


def _image_array(image: Any) -> NDArray[np.uint8]:
    return np.ascontiguousarray(np.asarray(image.convert("RGBA"), dtype=np.uint8))


# --- checks, normals, the Mesh ---------------------------------------------------


def _check_arrays(path: Path, positions: NDArray[np.float64], faces: NDArray[np.int64]) -> None:
    if faces.shape[0] == 0:
        raise SandboxError(f"{path}: the file has no faces (triangles) to draw")
    bad = ~np.isfinite(positions).all(axis=1)
    if bad.any():
        raise SandboxError(f"{path}: vertex {int(np.argmax(bad))} has a NaN or infinite coordinate "
                           f"({int(bad.sum())} such vertices)")
    low, high = int(faces.min()), int(faces.max())
    if low < 0 or high >= positions.shape[0]:
        wrong = high if high >= positions.shape[0] else low
        raise SandboxError(f"{path}: a face refers to vertex {wrong} but the file has {positions.shape[0]} vertices "
                           f"(indices out of range)")


def _degenerate(positions: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Faces with a repeated corner or no area (the ray tracer's rule)."""
    repeated = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    a, b, c = positions[faces[:, 0]], positions[faces[:, 1]], positions[faces[:, 2]]
    e1, e2 = b - a, c - a
    area2 = np.linalg.norm(np.cross(e1, e2), axis=1)
    flat = ~(area2 > _DEGENERATE_SIN * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1))
    result: NDArray[np.bool_] = repeated | flat
    return result


def load_mesh(path: str | os.PathLike[str], *, normals: str = "auto", crease_angle: float = 30.0,
              fit: bool = False, name: str | None = None) -> LoadedMesh:
    """Read a triangle mesh file (OBJ, PLY, STL, OFF, glTF, GLB) into a :class:`LoadedMesh`.

    ``normals`` is one of :data:`NORMALS` (module docstring), ``crease_angle``
    in degrees for ``"crease"``; ``fit=True`` centres the model and scales
    its longest side to :data:`FIT_SIZE`; ``name`` names the Mesh (default:
    the file's stem). Raises :class:`SandboxError` with one line naming the
    file for anything wrong with it.
    """
    path = Path(path)
    if normals not in NORMALS:
        raise SandboxError(f"unknown normals choice {normals!r}; use one of {', '.join(NORMALS)}")
    if not 0.0 <= float(crease_angle) <= 180.0:
        raise SandboxError(f"crease_angle must be between 0 and 180 degrees, got {crease_angle}")
    fmt = _format_of(path)
    data = _check_bytes(path, fmt, _read_bytes(path))
    parts = _parts(path, _load_scene(path, fmt, data))
    if not parts:
        raise SandboxError(f"{path}: the file has no faces (triangles) to draw")
    # Join the parts into one vertex list.
    offsets = np.cumsum([0] + [p.positions.shape[0] for p in parts])
    positions = np.concatenate([p.positions for p in parts])
    faces = np.concatenate([p.faces + off for p, off in zip(parts, offsets)])
    _check_arrays(path, positions, faces)
    dropped = _degenerate(positions, faces)
    if dropped.all():
        raise SandboxError(f"{path}: all {faces.shape[0]:,} faces are degenerate (no area): nothing to draw")
    faces = faces[~dropped]
    has_normals = all(p.normals is not None for p in parts)
    source = ("file" if has_normals else "crease") if normals == "auto" else normals
    if source == "file" and not has_normals:
        raise SandboxError(f"{path}: the file has no vertex normals (use normals='crease', 'smooth' or 'flat')")
    if source == "file":
        file_n = np.concatenate([p.normals for p in parts if p.normals is not None])[faces]  # (F, 3, 3)
        size = np.linalg.norm(file_n, axis=2, keepdims=True)
        own = corner_normals(positions, faces, "flat")
        corner_n = np.where(size > 1e-12, file_n / np.where(size > 1e-12, size, 1.0), own)
    else:
        corner_n = corner_normals(positions, faces, source, float(crease_angle))
    # Fit: centre the box, longest side FIT_SIZE.
    used = positions[np.unique(faces)]
    lo, hi = used.min(axis=0), used.max(axis=0)
    center = (lo + hi) / 2.0 if fit else np.zeros(3)
    longest = float((hi - lo).max())
    scale = FIT_SIZE / longest if fit and longest > 0.0 else 1.0
    if fit:
        positions = (positions - center) * scale
    # Per corner: position, normal, and uv / colour where any part has them.
    corner_vertex = faces.reshape(-1)
    columns = [positions[corner_vertex], corner_n.reshape(-1, 3)]
    with_uv = any(p.uvs is not None for p in parts)
    with_color = any(p.colors is not None for p in parts)
    if with_uv:
        uvs = np.concatenate([p.uvs if p.uvs is not None else np.zeros((p.positions.shape[0], 2)) for p in parts])
        columns.append(uvs[corner_vertex])
    if with_color:
        cols = np.concatenate([p.colors if p.colors is not None else np.ones((p.positions.shape[0], 3))
                               for p in parts])
        columns.append(cols[corner_vertex])
    rows = np.concatenate(columns, axis=1)
    index, first = unique_vertices(rows)
    vertices = rows[first]
    mesh = Mesh(name or path.stem, vertices[:, 0:3].copy(), index.astype(np.uint32 if first.size < 2**32 else np.int64),
                vertices[:, 3:6].copy(), vertices[:, 6:8].copy() if with_uv else None,
                vertices[:, 8 if with_uv else 6:][:, :3].copy() if with_color else None)
    # The texture: the first part's image; others with a different one are counted.
    images = [p.image for p in parts if p.image is not None]
    texture = _image_array(images[0]) if images else None
    ignored = sum(1 for im in images[1:] if im is not images[0])
    base = next((p.base_color for p in parts if p.base_color is not None), None)
    return LoadedMesh(mesh, path, texture, tuple(base) if base is not None else (1.0, 1.0, 1.0, 1.0),  # type: ignore[arg-type]
                      int(dropped.sum()), source, len(parts), ignored, float(scale),
                      tuple(float(x) for x in center))  # type: ignore[arg-type]
