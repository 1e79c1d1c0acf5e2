"""What one draw writes into its program (glsandbox/gl/uniform_writes.py): each uniform only where
its bytes differ from what the program holds, the model matrix relative to the pass camera's
origin, a lit draw's lights relative to it too, and a light's bytes made once per lights tuple and
origin. Recording uniforms stand in for a program's: no GL needed."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from glsandbox import transforms
from glsandbox.gl.uniform_bytes import _CONSTANTS, PassCamera, _Uniforms, _Written
from glsandbox.gl.uniform_writes import LightBytes, uniform_writer, write_constants, write_lighting, write_matrices
from glsandbox.scene import Light


class Recorder:
    """A uniform that records each write."""

    def __init__(self, name: str, log: list[tuple[str, bytes]]) -> None:
        self.name, self.log = name, log

    def write(self, data: bytes) -> None:
        self.log.append((self.name, data))


def program_uniforms(*names: str) -> tuple[_Uniforms, list[tuple[str, bytes]]]:
    log: list[tuple[str, bytes]] = []
    return _Uniforms({name: Recorder(name, log) for name in names}), log


def camera_at(x: float) -> PassCamera:
    view = transforms.look_at((x, 0.0, 5.0), (x, 0.0, 0.0), (0.0, 1.0, 0.0))
    return PassCamera(view, transforms.perspective(60.0, 1.0, 0.1, 100.0))


def written_names(log: list[tuple[str, bytes]]) -> list[str]:
    return [name for name, _ in log]


def test_a_second_draw_of_the_same_model_through_the_same_camera_writes_nothing() -> None:
    uniforms, log = program_uniforms("m_model", "m_view", "m_proj", "m_normal")
    written, setup, camera = _Written(), SimpleNamespace(normal=True), camera_at(0.0)
    model = transforms.translate(1.0, 2.0, 3.0)
    write_matrices(setup, written, uniforms, model, camera)
    assert written_names(log) == ["m_model", "m_view", "m_proj", "m_normal"]
    log.clear()
    write_matrices(setup, written, uniforms, model.copy(), camera)
    assert log == []
    write_matrices(setup, written, uniforms, transforms.translate(0.0, 0.0, 1.0), camera)
    assert written_names(log) == ["m_model"]  # a translation leaves the normal matrix as it was


def test_the_model_is_written_relative_to_the_cameras_origin_in_float64() -> None:
    uniforms, log = program_uniforms("m_model", "m_view", "m_proj")
    far = 1.0e5
    write_matrices(SimpleNamespace(normal=False), _Written(), uniforms, transforms.translate(far + 0.25, 0.0, 0.0),
                   camera_at(far))
    model = np.frombuffer(dict(log)["m_model"], dtype="f4").reshape(4, 4).T  # column-major in GL
    assert model[0, 3] == 0.25  # T(-eye) @ model: what float32 would have rounded away at 1e5


def test_only_the_constants_that_differ_from_the_last_materials_are_written() -> None:
    uniforms, log = program_uniforms("u_color", "u_alpha_cutoff")
    written = _Written()
    red = SimpleNamespace(constants=(("u_color", b"red"), ("u_alpha_cutoff", b"half")), change=(None, ()))
    blue = SimpleNamespace(constants=(("u_color", b"blue"), ("u_alpha_cutoff", b"half")), change=(None, ()))
    write_constants(red, written, uniforms)
    write_constants(blue, written, uniforms)
    assert log == [("u_color", b"red"), ("u_alpha_cutoff", b"half"), ("u_color", b"blue")]
    assert written[_CONSTANTS] is blue.constants


def test_a_lit_draw_writes_its_eye_and_lights_once_while_they_stay() -> None:
    uniforms, log = program_uniforms("u_eye", "u_light_pos", "u_light_color")
    written, camera, lights = _Written(), camera_at(0.0), (Light((1.0, 2.0, 3.0), (1.0, 0.5, 0.25)),)
    step = SimpleNamespace(lights=(None, b"", b"", None))
    light_bytes = LightBytes()
    write_lighting(step, written, uniforms, camera, lights, light_bytes)
    assert written_names(log) == ["u_eye", "u_light_pos", "u_light_color"]
    position = np.frombuffer(dict(log)["u_light_pos"], dtype="f4")
    assert np.allclose(position, np.array([1.0, 2.0, 3.0]) - camera.origin)  # relative to the eye
    log.clear()
    write_lighting(step, written, uniforms, camera, lights, light_bytes)
    assert log == []


def test_light_bytes_are_kept_per_lights_tuple_and_origin() -> None:
    light_bytes, lights = LightBytes(), (Light((0.0, 4.0, 0.0)),)
    first = light_bytes(lights, camera_at(0.0))
    assert light_bytes(lights, camera_at(0.0))[0] is first[0]  # the same origin: the bytes made once
    moved = light_bytes(lights, camera_at(2.0))
    assert np.allclose(np.frombuffer(moved[0], dtype="f4"), [-2.0, 4.0, -5.0])
    assert light_bytes((Light((0.0, 4.0, 0.0)),), camera_at(0.0)) == first  # equal lights, equal bytes


def test_the_writer_writes_only_the_programs_uniforms_and_only_changed_bytes() -> None:
    log: list[tuple[str, bytes]] = []
    program = {"u_a": Recorder("u_a", log)}
    written = _Written()
    write = uniform_writer(written, program, frozenset(program))
    write("u_a", b"1")
    write("u_a", b"1")
    write("u_gone", b"2")  # removed by the compiler: nothing to write
    write("u_a", b"3")
    assert log == [("u_a", b"1"), ("u_a", b"3")] and written == {"u_a": b"3"}
