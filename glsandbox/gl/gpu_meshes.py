"""What the GPU gets of a mesh: its vertex arrays as float32 and its indices as uint32,
keyed by name and content so that meshes uploading the same bytes share buffers."""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import moderngl
import numpy as np

from glsandbox.geometry import Mesh

try:  # hashlib.blake2b is this very type; importing hashlib loads OpenSSL too (~4 ms of every start)
    from _blake2 import blake2b
except ImportError:  # a Python built without its own BLAKE2
    from hashlib import blake2b

_MODES = {"triangles": moderngl.TRIANGLES, "triangle_strip": moderngl.TRIANGLE_STRIP,
          "lines": moderngl.LINES, "line_strip": moderngl.LINE_STRIP}
# Mesh arrays and the attribute names the shaders use for them.
_ATTRIBUTES = (("positions", "in_position", 3), ("normals", "in_normal", 3),
               ("uvs", "in_uv", 2), ("colors", "in_color", 3))


_MESH_KEYS: weakref.WeakKeyDictionary[Mesh, tuple[str, str]] = weakref.WeakKeyDictionary()


def _gpu_arrays(mesh: Mesh) -> dict[str, np.ndarray]:
    """What the GPU gets of ``mesh``: each vertex array as contiguous float32 (by attribute name),
    the indices as uint32 (``"indices"``)."""
    arrays = {attr: np.ascontiguousarray(getattr(mesh, field), dtype="f4")
              for field, attr, _ in _ATTRIBUTES if getattr(mesh, field) is not None}
    if mesh.indices is not None:
        arrays["indices"] = np.ascontiguousarray(mesh.indices, dtype="u4")
    return arrays


def _mesh_key(mesh: Mesh, arrays: dict[str, np.ndarray] | None = None) -> tuple[str, str]:
    """Name and a digest of what the GPU gets (``arrays``, :func:`_gpu_arrays`): meshes that upload
    the same bytes share GPU buffers. Meshes are immutable, so the digest is made once per mesh
    object."""
    key = _MESH_KEYS.get(mesh)
    if key is None:
        digest = blake2b(digest_size=12)
        for name, array in (arrays if arrays is not None else _gpu_arrays(mesh)).items():
            digest.update(name.encode())
            digest.update(array)  # the array's memory as it is: no copy
        digest.update(mesh.mode.encode())
        key = _MESH_KEYS[mesh] = (mesh.name, digest.hexdigest())
    return key


#: The GPU key of each mesh moved by a lesson's Motion (``Motion.positions``): its own buffers,
#: shared with no mesh of equal content, since the positions are written into them every frame.
_MOVED_KEYS: weakref.WeakKeyDictionary[Mesh, tuple[str, str]] = weakref.WeakKeyDictionary()


def _moved_key(origin: Mesh) -> tuple[str, str]:
    key = _MOVED_KEYS.get(origin)
    if key is None:
        key = _MOVED_KEYS[origin] = (origin.name, f"moved-{len(_MOVED_KEYS)}-{id(origin):x}")
    return key



@dataclass
class _GpuMesh:
    """A mesh's GPU buffers (shared by meshes that upload the same bytes), draw mode and element count."""

    buffers: dict[str, moderngl.Buffer]
    index: moderngl.Buffer | None
    mode: int
    count: int
    positions: np.ndarray | None = None  # a moved mesh's: the positions its buffer holds now

