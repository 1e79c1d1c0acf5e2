"""What one draw writes into its program's uniforms, each only where its bytes differ from
what the program holds (a program keeps its uniform values between draws and frames, so what
does not change, the view while the camera stands, lights, materials, a wall's model, is
written once): the matrices, a lit draw's eye and lights (course "Lighting"), the material's
constants. The bytes themselves are made in :mod:`glsandbox.gl.uniform_bytes`; the draw
passes write them through :meth:`glsandbox.gl.executor.Executor.draw_node`."""

from __future__ import annotations

from collections.abc import Callable, Collection

import moderngl
import numpy as np

from glsandbox.gl.draw_steps import _DrawSetup, _DrawStep
from glsandbox.gl.uniform_bytes import (_CAMERA, _CONSTANTS, _EYE, _FLOAT64, _MODEL_BYTES, _NORMAL_BYTES,
                                        PassCamera, _constants_change, _Uniforms, _Written)
from glsandbox.scene import Light


def write_matrices(setup: _DrawSetup, written: _Written, uniforms: _Uniforms, matrix: np.ndarray,
                   camera: PassCamera) -> None:
    """``m_model`` (and ``m_normal``, its inverse transpose: course "Lighting"), then the pass
    camera's ``m_view`` and ``m_proj`` where the program holds another camera's."""
    if type(matrix) is not np.ndarray or matrix.dtype != _FLOAT64:
        matrix = np.asarray(matrix, dtype=np.float64)
    content = matrix.tobytes()
    data = _MODEL_BYTES[content + camera.origin_bytes]
    if written["m_model"] != data:
        written["m_model"] = data
        uniforms["m_model"].write(data)
    if written[_CAMERA] is not camera:  # (a pass's draws share its camera)
        write_camera(written, uniforms, camera)
    if setup.normal:
        data = _NORMAL_BYTES[content]
        if written["m_normal"] != data:
            written["m_normal"] = data
            uniforms["m_normal"].write(data)


def write_camera(written: _Written, uniforms: _Uniforms, camera: PassCamera) -> None:
    """The pass camera's ``m_view`` and ``m_proj``, each where the program holds other bytes;
    the program then holds ``camera``'s (its ``written[_CAMERA]``)."""
    if camera.view_bytes != written["m_view"]:
        written["m_view"] = camera.view_bytes
        uniforms["m_view"].write(camera.view_bytes)
    if camera.proj_bytes != written["m_proj"]:
        written["m_proj"] = camera.proj_bytes
        uniforms["m_proj"].write(camera.proj_bytes)
    written[_CAMERA] = camera


def write_lighting(step: _DrawStep, written: _Written, uniforms: _Uniforms, camera: PassCamera,
                   frame_lights: tuple[Light, ...], light_bytes: LightBytes) -> None:
    """A lit draw's eye position and lights (course "Lighting": ``vEyePos``, the light loop)."""
    if written[_EYE] is not camera:
        data = camera.eye_bytes
        if written["u_eye"] != data:
            written["u_eye"] = data
            uniforms["u_eye"].write(data)
        written[_EYE] = camera
    if frame_lights:  # with none, the shader's arrays do not exist (NUM_LIGHTS 0)
        if step.lights[0] is not frame_lights or step.lights[3] is not camera:
            # (lights that do not move, seen from an eye that does not: the same bytes every frame)
            step.lights = (frame_lights, *light_bytes(frame_lights, camera), camera)
        write_lights(written, uniforms, step.lights[1], step.lights[2])


def write_lights(written: _Written, uniforms: _Uniforms, light_pos: bytes, light_color: bytes) -> None:
    """``u_light_pos`` and ``u_light_color``, each where the program holds other bytes."""
    if written["u_light_pos"] != light_pos:
        written["u_light_pos"] = light_pos
        uniforms["u_light_pos"].write(light_pos)
    if written["u_light_color"] != light_color:
        written["u_light_color"] = light_color
        uniforms["u_light_color"].write(light_color)


def write_constants(step: _DrawStep, written: _Written, uniforms: _Uniforms) -> None:
    """The material's constant uniforms, only the bytes that differ from the program's."""
    constants = step.constants
    last = written[_CONSTANTS]
    change = step.change
    if change[0] is not last or last is None:
        change = (last, _constants_change(written, last, constants))
        step.change = change
    for name, data in change[1]:
        written[name] = data
        uniforms[name].write(data)
    written[_CONSTANTS] = constants


def uniform_writer(written: _Written, program: moderngl.Program,
                   members: Collection[str]) -> Callable[[str, bytes], None]:
    """``write(name, data)`` for one program: the bytes go to GL only where the program has the
    uniform (a term the compiler removed has none) and they differ from what was written last."""
    uniforms: dict[str, moderngl.Uniform] = {}

    def write(name: str, data: bytes) -> None:
        if written.get(name) != data and name in members:
            uniform = uniforms.get(name)
            if uniform is None:
                uniform = uniforms[name] = program[name]
            uniform.write(data)
            written[name] = data

    return write


class LightBytes:
    """``u_light_pos`` (relative to a camera's origin, the difference taken in float64) and
    ``u_light_color`` bytes of a lights tuple, made once per tuple and origin: every lit draw of
    a frame writes the same ones, and lights that do not move (the scene's, and the mirror's
    reflected ones) seen from an eye that does not keep them from frame to frame."""

    #: Entries kept: lights or an eye that move make an entry a frame, all dropped past this many.
    KEPT = 8

    def __init__(self) -> None:
        # by id of the lights tuple and the pass origin (the tuple kept to check)
        self._cache: dict[tuple[int, bytes], tuple[tuple[Light, ...], bytes, bytes]] = {}
        self._colors: dict[tuple, bytes] = {}  # u_light_color's bytes by the lights' colours

    def __call__(self, lights: tuple[Light, ...], camera: PassCamera) -> tuple[bytes, bytes]:
        key = (id(lights), camera.origin_bytes)
        cached = self._cache.get(key)
        if cached is None or cached[0] is not lights:
            if len(self._cache) >= self.KEPT:
                self._cache.clear()
            positions = np.array([l.position for l in lights], dtype=np.float64) - camera.origin
            colors = tuple(l.color for l in lights)
            color_bytes = self._colors.get(colors)  # (moving lights keep their colours: made once)
            if color_bytes is None:
                if len(self._colors) >= self.KEPT:
                    self._colors.clear()
                color_bytes = self._colors[colors] = np.array(colors, dtype="f4").tobytes()
            cached = self._cache[key] = (lights, positions.astype("f4").tobytes(), color_bytes)
        return cached[1], cached[2]
