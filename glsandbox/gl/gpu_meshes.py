"""What the GPU gets of a mesh: its vertex arrays as float32 and its indices as uint32,
keyed by name and content so that meshes uploading the same bytes share buffers."""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import moderngl
import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh
from glsandbox.scene import mesh_origin

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


class GpuMeshes:
    """The executor's uploaded meshes (by :func:`_mesh_key`) and their VAOs (by mesh key and
    program key): what :class:`glsandbox.gl.executor.Executor` keeps of meshes between frames.
    It sets ``ctx``, ``_meshes``, ``_mesh_last_frame``, ``_frame`` (the frame count), ``_vaos``,
    ``_programs``, ``_setups`` and ``_steps``."""

    #: Uploaded meshes kept between frames. A lesson that makes a new mesh
    #: every frame (transform_order's trail) would otherwise fill GPU memory
    #: in a long-running window: past this many, the least recently drawn
    #: are released (never one the current frame draws).
    MESH_LIMIT = 256

    def _gpu_mesh(self, mesh: Mesh) -> tuple[tuple[str, str], _GpuMesh]:
        origin = mesh_origin(mesh)
        if origin is not None:
            return self._moved_gpu_mesh(mesh, origin)
        arrays = None if mesh in _MESH_KEYS else _gpu_arrays(mesh)  # made once for the digest and the upload
        key = _mesh_key(mesh, arrays)
        gpu = self._meshes.get(key)
        if gpu is None:
            gpu = self._meshes[key] = self._upload(mesh, arrays or _gpu_arrays(mesh))
        self._mesh_last_frame[key] = self._frame
        return key, gpu

    def _upload(self, mesh: Mesh, arrays: dict[str, np.ndarray], moving: bool = False) -> _GpuMesh:
        """GPU buffers of ``arrays`` (:func:`_gpu_arrays` of ``mesh``); ``moving``: the positions
        are rewritten each frame (a dynamic buffer, and the mesh's positions remembered)."""
        index_array = arrays.pop("indices", None)
        buffers = {attr: self.ctx.buffer(array, dynamic=moving and attr == "in_position")
                   for attr, array in arrays.items()}
        index = None if index_array is None else self.ctx.buffer(index_array)
        return _GpuMesh(buffers, index, _MODES[mesh.mode], mesh.element_count, mesh.positions if moving else None)

    def _moved_gpu_mesh(self, mesh: Mesh, origin: Mesh) -> tuple[tuple[str, str], _GpuMesh]:
        """A moved mesh (:func:`glsandbox.scene.moved_mesh`): the buffers of the mesh it was moved
        from, its own, with ``mesh``'s positions written into the position buffer where they
        are not the ones it holds (once per frame however many passes draw it)."""
        key = _moved_key(origin)
        gpu = self._meshes.get(key)
        if gpu is None:
            gpu = self._meshes[key] = self._upload(mesh, _gpu_arrays(mesh), moving=True)
        elif gpu.positions is not mesh.positions:
            gpu.buffers["in_position"].write(np.ascontiguousarray(mesh.positions, dtype="f4"))
            gpu.positions = mesh.positions
        self._mesh_last_frame[key] = self._frame
        return key, gpu

    @property
    def mesh_count(self) -> int:
        """How many meshes are uploaded now."""
        return len(self._meshes)

    def _release_stale_meshes(self) -> None:
        """Keep at most :attr:`MESH_LIMIT` meshes, dropping the least recently drawn."""
        excess = len(self._meshes) - self.MESH_LIMIT
        if excess <= 0:
            return
        stale = sorted((frame, key) for key, frame in self._mesh_last_frame.items() if frame < self._frame)
        for _, key in stale[:excess]:
            gpu = self._meshes.pop(key)
            del self._mesh_last_frame[key]
            for vao_key in [k for k in self._vaos if k[0] == key]:
                self._vaos.pop(vao_key).release()
            self._setups.clear()
            self._steps.clear()
            for buffer in gpu.buffers.values():
                buffer.release()
            if gpu.index is not None:
                gpu.index.release()

    def _vao(self, mesh: Mesh, program_key: str) -> tuple[moderngl.VertexArray, _GpuMesh]:
        key, gpu = self._gpu_mesh(mesh)
        vao = self._vaos.get((key, program_key))
        if vao is None:
            program = self._programs[program_key][1]
            content = []
            for _, attr, width in _ATTRIBUTES:
                if attr in program:
                    if attr not in gpu.buffers:
                        raise SandboxError(f"mesh {mesh.name!r} has no {attr[3:]} data, which {program_key} needs")
                    content.append((gpu.buffers[attr], f"{width}f", attr))
            vao = self.ctx.vertex_array(program, content, index_buffer=gpu.index)
            self._vaos[(key, program_key)] = vao
        return vao, gpu
