"""What the GPU gets of a mesh (glsandbox/gl/gpu_meshes.py): float32 vertex arrays and uint32
indices, one upload for meshes of the same bytes, a moved mesh's own buffer rewritten in place,
and past the limit the least recently drawn meshes released."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry
from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh
from glsandbox.gl.gpu_meshes import GpuMeshes, _gpu_arrays, _mesh_key
from glsandbox.scene import moved_mesh

TRIANGLE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


class Meshes(GpuMeshes):
    """The mixin with the state the executor gives it (see GpuMeshes' docstring)."""

    def __init__(self, ctx) -> None:
        self.ctx, self._frame = ctx, 0
        self._meshes, self._mesh_last_frame, self._vaos, self._programs, self._setups, self._steps = {}, {}, {}, {}, {}, {}

    def release(self) -> None:
        for vao in self._vaos.values():
            vao.release()
        for gpu in self._meshes.values():
            for buffer in (*gpu.buffers.values(), *([gpu.index] if gpu.index is not None else [])):
                buffer.release()


@pytest.fixture
def meshes(gl):
    found = Meshes(gl.host.ctx)
    yield found
    found.release()


def test_the_gpu_gets_float32_arrays_and_uint32_indices() -> None:
    mesh = Mesh("tri", TRIANGLE, indices=np.array([0, 1, 2], dtype=np.int64), normals=np.tile([0.0, 0.0, 1.0], (3, 1)))
    arrays = _gpu_arrays(mesh)
    assert set(arrays) == {"in_position", "in_normal", "indices"}  # no uvs or colours: none sent
    assert set(_gpu_arrays(geometry.cube())) >= {"in_position", "indices"}
    assert all(a.dtype == np.float32 and a.flags.c_contiguous for k, a in arrays.items() if k != "indices")
    assert arrays["indices"].dtype == np.uint32


def test_meshes_of_the_same_bytes_share_a_key_and_a_changed_byte_does_not() -> None:
    a, b = Mesh("tri", TRIANGLE), Mesh("tri", TRIANGLE.copy())
    assert _mesh_key(a) == _mesh_key(b) and _mesh_key(a) is _mesh_key(a)  # made once per mesh object
    assert _mesh_key(Mesh("tri", TRIANGLE + [0, 0, 1e-6])) != _mesh_key(a)
    assert _mesh_key(Mesh("tri", TRIANGLE, mode="line_strip")) != _mesh_key(a)
    assert _mesh_key(Mesh("other", TRIANGLE))[1] == _mesh_key(a)[1]  # the name keys, the digest is the bytes'


def test_equal_meshes_upload_once_and_a_moved_mesh_rewrites_its_own_buffer(meshes) -> None:
    first, gpu = meshes._gpu_mesh(Mesh("tri", TRIANGLE))
    again, same = meshes._gpu_mesh(Mesh("tri", TRIANGLE.copy()))
    assert first == again and same is gpu and meshes.mesh_count == 1 and gpu.count == 3
    origin = Mesh("tri", TRIANGLE)
    _, moving = meshes._gpu_mesh(moved_mesh(origin, TRIANGLE * 2))
    assert meshes.mesh_count == 2  # a moved mesh shares its buffer with no mesh of equal bytes
    _, later = meshes._gpu_mesh(moved_mesh(origin, TRIANGLE * 3))
    assert later is moving
    written = np.frombuffer(moving.buffers["in_position"].read(), dtype="f4").reshape(3, 3)
    assert np.array_equal(written, TRIANGLE * 3) and meshes.mesh_count == 2


def test_past_the_limit_the_least_recently_drawn_are_released_but_none_of_this_frame(meshes, monkeypatch) -> None:
    monkeypatch.setattr(Meshes, "MESH_LIMIT", 1)
    keys = []
    for frame in range(4):
        meshes._frame = frame
        keys.append(meshes._gpu_mesh(Mesh(f"m{frame}", TRIANGLE + frame))[0])
    meshes._frame = 3
    meshes._gpu_mesh(Mesh("m0", TRIANGLE))  # drawn again this frame: kept
    meshes._release_stale_meshes()
    assert set(meshes._meshes) == {keys[0], keys[3]}  # over the limit still: never one this frame draws
    meshes._frame = 4
    meshes._gpu_mesh(Mesh("m3", TRIANGLE + 3))
    meshes._release_stale_meshes()
    assert set(meshes._meshes) == {keys[3]}


def test_a_program_that_needs_data_the_mesh_lacks_is_one_line(meshes, gl) -> None:
    program = gl.host.ctx.program(
        vertex_shader="#version 330\nin vec3 in_position; in vec3 in_normal; out vec3 n;\n"
                      "void main() { n = in_normal; gl_Position = vec4(in_position, 1.0); }",
        fragment_shader="#version 330\nin vec3 n; out vec4 c; void main() { c = vec4(n, 1.0); }")
    meshes._programs["lit"] = (None, program)
    try:
        with pytest.raises(SandboxError, match="mesh 'bare' has no normal data, which lit needs"):
            meshes._vao(Mesh("bare", TRIANGLE), "lit")
        vao, gpu = meshes._vao(Mesh("lit", TRIANGLE, normals=np.tile([0.0, 0.0, 1.0], (3, 1))), "lit")
        assert meshes._vao(Mesh("lit", TRIANGLE, normals=np.tile([0.0, 0.0, 1.0], (3, 1))), "lit")[0] is vao
    finally:
        program.release()
