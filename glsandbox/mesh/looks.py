"""How a model file's parts look: their materials, and what of the file is not drawn.

:mod:`glsandbox.mesh.load` reads a file into parts (trimesh's meshes); this
module turns each part's trimesh material into a :class:`Look` (the fields a
:class:`~glsandbox.scene.Material` takes from it) and says, in words, what
the file asks for that glsandbox does not draw, so that a user is told
instead of silently seeing less:

- **glTF**: ``baseColorFactor`` and ``baseColorTexture`` (drawn), ``alphaMode``
  and ``alphaCutoff``, ``doubleSided`` (drawn); a metallic-roughness, normal,
  occlusion or emissive map, an emissive colour and material extensions (not
  drawn: the course's Phong has no such terms); animations, cameras and
  skins (not drawn); a base colour texture that the file names but that
  could not be read (not drawn, and said). Read from the file's own JSON
  (trimesh drops animations and cameras, and a texture it could not read).
- **OBJ**: ``Kd`` and ``map_Kd`` (drawn), ``d`` (or ``Tr``) below 1: blended,
  with that alpha (drawn); a ``map_Kd`` that is missing or
  unreadable, and bump, normal, specular and alpha maps (not drawn). Read
  from the ``.mtl`` files the OBJ names (the ``mtllib`` lines).
- **PLY, STL, OFF** have no materials; vertex colours are drawn.

Sidedness (:func:`is_closed`): glTF says per material (``doubleSided``);
the other formats do not, so a part is one-sided (back faces culled) only
when the whole model is closed, every edge shared by two faces that run
it in opposite directions. An open scan, whichever way its faces wind, is
drawn from both sides.
"""

from __future__ import annotations

import functools
import hashlib
import json
import re
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.mesh.normals import BLOCK_FACES

__all__ = ["Look", "file_warnings", "is_closed", "look_of", "warning_data"]

Rgba = tuple[float, float, float, float]

#: glTF ``alphaMode`` to :data:`glsandbox.scene.ALPHA_MODES`.
_ALPHA = {"OPAQUE": "opaque", "MASK": "mask", "BLEND": "blend"}
#: glTF's material maps that the course's Phong does not use, and what to call them.
_GLTF_MAPS = (("normalTexture", "normal map"), ("occlusionTexture", "occlusion map"),
              ("emissiveTexture", "emissive map"))
#: An OBJ ``.mtl``'s maps that are not drawn (the keyword, lower case, and its name).
_MTL_MAPS = {"map_bump": "bump map", "bump": "bump map", "norm": "normal map", "map_ks": "specular map",
             "map_ns": "shininess map", "map_d": "alpha map", "disp": "displacement map", "map_ke": "emissive map"}
#: The most bytes of a material library that are scanned for texture names.
_MTL_LIMIT = 1 << 22


@dataclass(frozen=True, eq=False)
class Look:
    """A part's material as the file gives it (None: the file does not say)."""

    name: str
    image: NDArray[np.uint8] | None  # base colour, RGBA, row 0 at the top
    color: Rgba | None
    alpha_mode: str = "opaque"
    alpha_cutoff: float = 0.5
    double_sided: bool | None = None

    @functools.cached_property
    def key(self) -> tuple[Any, ...]:
        """Parts with equal keys are drawn alike and become one node (the image by a hash of its pixels)."""
        digest = None
        if self.image is not None:
            digest = hashlib.blake2b(np.asarray(self.image.shape).tobytes() + self.image.tobytes(),
                                     digest_size=12).hexdigest()
        return self.name, self.color, self.alpha_mode, self.alpha_cutoff, self.double_sided, digest


def look_of(material: Any, index: int) -> Look:
    """The :class:`Look` of a trimesh material (``None``: a part without one);
    ``index`` names a material that has no name of its own."""
    name = str(getattr(material, "name", None) or f"material {index}")
    if material is None:
        return Look(name, None, None)
    picture = getattr(material, "baseColorTexture", None)
    if picture is None:
        # An OBJ material's map_Kd: an image decoded from a file has a format; the 2x2 grey
        # placeholder trimesh gives an OBJ with uvs but no material file has none.
        picture = getattr(material, "image", None)
        if getattr(picture, "format", None) is None:
            picture = None
    image = None
    if picture is not None:
        try:
            image = np.ascontiguousarray(np.asarray(picture.convert("RGBA"), dtype=np.uint8))
        except Exception:
            image = None
        if image is not None and (image.ndim != 3 or 0 in image.shape):
            image = None
    factor = getattr(material, "baseColorFactor", None)
    if factor is None and hasattr(material, "diffuse") and image is None:
        # An OBJ's Kd (trimesh keeps it as uint8 rgba). With a map_Kd the image is the colour:
        # exporters write a grey Kd beside it that viewers do not multiply in.
        factor = getattr(material, "diffuse", None)
    color = _rgba(factor)
    mode = _ALPHA.get(str(getattr(material, "alphaMode", None) or "OPAQUE").upper(), "opaque")
    dissolve = _dissolve(getattr(material, "kwargs", None))
    if dissolve is not None and dissolve < 1.0:  # an OBJ's see-through material: blended, as glTF's BLEND
        color = (*(color or (1.0, 1.0, 1.0, 1.0))[:3], dissolve)
        mode = "blend"
    cutoff = getattr(material, "alphaCutoff", None)
    cutoff = 0.5 if cutoff is None or not np.isfinite(cutoff) else float(np.clip(cutoff, 0.0, 1.0))
    sided = getattr(material, "doubleSided", None)
    return Look(name, image, color, mode, cutoff, None if sided is None else bool(sided))


def _dissolve(options: Any) -> float | None:
    """An OBJ material's opacity: ``d`` (1 opaque), or ``Tr`` (its complement); None if neither."""
    if not isinstance(options, dict):
        return None
    for key, flip in (("d", False), ("tr", True)):
        value = options.get(key)
        try:
            number = float(value[0] if isinstance(value, (list, tuple)) else value)
        except (TypeError, ValueError, IndexError):
            continue
        if np.isfinite(number):
            number = float(np.clip(number, 0.0, 1.0))
            return 1.0 - number if flip else number
    return None


def _rgba(factor: Any) -> Rgba | None:
    """A colour factor as rgba floats in 0..1 (trimesh gives uint8 0..255 or floats)."""
    if factor is None:
        return None
    f = np.asarray(factor).reshape(-1)
    if f.size < 3:
        return None
    f = f.astype(np.float64) / 255.0 if f.dtype.kind in "iu" else f.astype(np.float64)
    f = np.clip(np.nan_to_num(f, nan=1.0), 0.0, 1.0)
    return float(f[0]), float(f[1]), float(f[2]), float(f[3]) if f.size >= 4 else 1.0


def is_closed(positions: NDArray[np.float64], faces: NDArray[np.int64],
              position_ids: NDArray[np.intp] | None = None) -> bool:
    """Whether the triangles close a volume with a consistent winding: with vertices at
    equal positions taken as one, the directed edges ``a→b`` of all faces are, as a
    multiset, their own reverses ``b→a`` (the faces on either side of an edge run it in
    opposite directions). Then back faces can never be seen from outside, and culling
    them is safe.

    Tested in linear time, without sorting: each position gets a 64-bit hash of its
    bits, each directed edge a hash of its two ends' (order matters), and the sum of
    the edges' hashes must equal the sum of the reversed edges' (mod 2⁶⁴). Two
    different multisets agree by chance with odds of about 2⁻⁶⁴; then an open mesh
    would be culled as if closed. ``position_ids``: equal exactly where the positions are
    (:func:`glsandbox.mesh.normals.row_ids`), when the caller has them: each id is hashed
    instead of each position's bits."""
    if faces.shape[0] == 0:
        return False
    with np.errstate(over="ignore"):
        if position_ids is not None:
            position_key = _mix(position_ids.astype(np.uint64) + np.uint64(1))  # (_mix(0) is 0)
        else:
            bits = np.ascontiguousarray(positions + 0.0, dtype=np.float64).view(np.uint64).reshape(-1, 3)  # -0 is 0
            position_key = _mix(_mix(_mix(bits[:, 0]) ^ bits[:, 1]) ^ bits[:, 2])
        # Sums mod 2⁶⁴ in blocks of faces (bounded temporaries; the order of a modular sum is free),
        # one corner column with the next at a time (edge k runs from corner k to corner k + 1).
        forward = backward = np.uint64(0)
        for lo in range(0, faces.shape[0], BLOCK_FACES):
            key = position_key.take(faces[lo:lo + BLOCK_FACES])
            for k in range(3):
                start, end = key[:, k], key[:, (k + 1) % 3]
                forward += _mix(start * _ODD ^ end).sum(dtype=np.uint64)
                backward += _mix(end * _ODD ^ start).sum(dtype=np.uint64)
        return bool(forward == backward)


#: An odd 64-bit constant: ``a * _ODD ^ b`` is not symmetric in a and b.
_ODD = np.uint64(0x9E3779B97F4A7C15)


def _mix(x: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """SplitMix64's finaliser: every input bit flips about half the output bits."""
    x = x ^ (x >> np.uint64(30))
    x = x * np.uint64(0xBF58476D1CE4E5B9)
    x = x ^ (x >> np.uint64(27))
    x = x * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


# --- what is not drawn ------------------------------------------------------


def warning_data(data: bytes, file_type: str) -> bytes:
    """The part of a file's bytes that :func:`file_warnings` reads: a glTF's JSON, a GLB's
    header and JSON chunk (not its binary buffers), an OBJ's ``mtllib`` lines (not its
    vertices and faces), nothing of the other formats. Taken before the reader parses the
    file, so the file's bytes need not be kept beside what it makes of them (the peak)."""
    if file_type == "gltf":
        return data
    if file_type == "glb":
        try:
            length, kind = struct.unpack_from("<I4s", data, 12)
        except struct.error:
            return b""
        return data[:20 + length] if kind == b"JSON" else b""
    if file_type == "obj":  # the lines _obj_warnings matches, one a line (pos/endpos: no copy of the text)
        return b"\n".join(match.group(0) for match in _MTLLIB.finditer(data, 0, _MTL_LIMIT))
    return b""


def file_warnings(path: Path, data: bytes, file_type: str, looks: list[Look]) -> dict[str, list[str]]:
    """What the file asks for that is not drawn: ``{part name: [what, ...]}``, the
    file-wide things (animations, cameras) under ``""``. ``data``: the file's bytes, or
    their part that :func:`warning_data` keeps. Never raises: a file this
    cannot read was refused by trimesh already or has nothing to say."""
    try:
        if file_type in ("gltf", "glb"):
            return _gltf_warnings(_gltf_json(data, file_type), looks)
        if file_type == "obj":
            return _obj_warnings(path, data, looks)
    except Exception:
        pass
    return {}


def _gltf_json(data: bytes, file_type: str) -> dict[str, Any]:
    """A glTF's JSON: the whole file, or a GLB's first chunk (12-byte header, then
    chunk length and type ``JSON``)."""
    if file_type == "gltf":
        return json.loads(data.decode("utf-8-sig"))
    length, kind = struct.unpack_from("<I4s", data, 12)
    if kind != b"JSON":
        return {}
    return json.loads(data[20:20 + length].decode("utf-8"))


def _gltf_warnings(doc: dict[str, Any], looks: list[Look]) -> dict[str, list[str]]:
    found: dict[str, list[str]] = {}
    for key, one, many in (("animations", "an animation", "animations"), ("cameras", "a camera", "cameras"),
                           ("skins", "a skin", "skins")):
        count = len(doc.get(key) or ())
        if count:
            found.setdefault("", []).append(one if count == 1 else f"{count} {many}")
    textured = {look.name for look in looks if look.image is not None}
    used = {look.name for look in looks}
    for i, material in enumerate(doc.get("materials") or ()):
        if not isinstance(material, dict):
            continue
        name = str(material.get("name") or f"material {i}")
        if name not in used:
            continue
        what = []
        pbr = material.get("pbrMetallicRoughness") or {}
        if "baseColorTexture" in pbr and name not in textured:
            what.append(f"its base colour texture{_image_name(doc, pbr['baseColorTexture'])} (missing or unreadable)")
        if "metallicRoughnessTexture" in pbr:
            what.append("metallic-roughness map")
        what += [label for key, label in _GLTF_MAPS if key in material]
        if any(float(v) != 0.0 for v in material.get("emissiveFactor") or ()):
            what.append("emissive colour")
        what += [f"extension {name}" for name in sorted(material.get("extensions") or ())]
        if what:
            found.setdefault(name, []).extend(what)
    return found


def _image_name(doc: dict[str, Any], reference: Any) -> str:
    """`` skin.png`` for a texture reference whose image is a file, else nothing."""
    try:
        image = doc["images"][doc["textures"][reference["index"]]["source"]]
        uri = image.get("uri", "")
    except (KeyError, IndexError, TypeError, AttributeError):
        return ""
    return f" {uri}" if isinstance(uri, str) and uri and not uri.startswith("data:") else ""


_MTLLIB = re.compile(rb"^[ \t]*mtllib[ \t]+(.+?)[ \t]*$", re.MULTILINE)


def _obj_warnings(path: Path, data: bytes, looks: list[Look]) -> dict[str, list[str]]:
    """The maps an OBJ's ``.mtl`` files name per material that are not drawn, and a
    ``map_Kd`` that was not read (missing or unreadable)."""
    found: dict[str, list[str]] = {}
    textured = {look.name for look in looks if look.image is not None}
    used = {look.name for look in looks}
    for match in _MTLLIB.finditer(data[:_MTL_LIMIT]):
        name = match.group(1).decode("utf-8", "replace").strip()
        library = path.parent / name
        if not library.is_file():
            found.setdefault("", []).append(f"its material library {name} (not found)")
            continue
        with open(library, "rb") as handle:
            text = handle.read(_MTL_LIMIT).decode("utf-8", "replace")
        current = ""
        for line in text.splitlines():
            words = line.split()
            if not words:
                continue
            keyword = words[0].lower()
            if keyword == "newmtl":
                current = " ".join(words[1:])
            elif current in used and keyword == "map_kd" and current not in textured:
                found.setdefault(current, []).append(f"its texture {words[-1]} (missing or unreadable)")
            elif current in used and keyword in _MTL_MAPS:
                found.setdefault(current, []).append(_MTL_MAPS[keyword])
    return found
