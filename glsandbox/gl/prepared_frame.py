"""The draw passes of a kept plan prepared once for the frames that only time moves.

A lesson moved by time alone (:meth:`glsandbox.lesson.Lesson.motion`) keeps its scene and its
plan from frame to frame (:meth:`glsandbox.frame.FrameRenderer.render_motion`): the same
draws of the same nodes, in the same order, through the same cameras; only some model
matrices and light positions move. :func:`prepare_draw_pass` finds once, per draw of such a
pass, all that :meth:`~glsandbox.gl.executor.Executor.draw_node` looks up every frame: the
prepared draw (program, uniforms, VAO, material constants), its culling, and for a node the
motion does not move its ``m_model`` (and ``m_normal``) bytes seen from the pass camera. A
frame is then one loop over the draws that writes what moved (the moved models, the lit
draws' lights) and what another draw of the same program changed since, and draws.

What it writes is what :meth:`~glsandbox.gl.executor.Executor.draw_node` would write, through
the same record of what each program holds (:mod:`glsandbox.gl.uniform_writes`), so prepared
and unprepared draws of one program follow each other freely. The prepared pass is made for
one scene's nodes and one set of the executor's prepared draws: a frame of any other scene
(``FrameState.nodes`` not the ones it was made for) or after the prepared draws were dropped
(a program reloaded, a mesh released: :class:`~glsandbox.gl.draw_steps._Steps` counts) draws through the runner.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from glsandbox.gl.draw_steps import _DrawStep
from glsandbox.gl.passes import FrameState, RunPass
from glsandbox.gl.uniform_bytes import _CAMERA, _CONSTANTS, _EYE, _FLOAT64, _MODEL_BYTES, _NORMAL_BYTES
from glsandbox.gl.uniform_writes import write_camera, write_constants, write_lighting, write_lights
from glsandbox.passes.plan_parts import Pass
from glsandbox.scene import Node


class PreparedDraw:
    """One draw of a prepared pass: the node's name (its key in a frame's moved models), the
    node, the executor's prepared draw, whether it draws without textures, shadow map or
    blending (then straight from its VAO), and the ``m_model``/``m_normal`` bytes of the
    node's own model for one pass camera (made on the first frame through that camera)."""

    __slots__ = ("name", "node", "step", "plain", "render", "mode", "count", "still")

    def __init__(self, node: Node, step: _DrawStep) -> None:
        self.name, self.node, self.step = node.name, node, step
        draw, setup = step.draw, step.setup
        self.plain = step.material.texture is None and draw.shadow_map is None and not draw.blend
        self.render, self.mode, self.count = setup.vao.render, setup.gpu.mode, setup.gpu.count
        self.still: tuple[object, bytes, bytes | None] | None = None  # (pass camera, m_model, m_normal)


def prepare_draw_pass(executor: Any, step: Pass, nodes: Mapping[str, Node], fallback: RunPass) -> RunPass | None:
    """The ``draw`` pass ``step`` of ``nodes`` prepared (a runner with the runner's signature), or
    None where a draw needs more than a plain draw: a node's own shader (checked every frame),
    the X-ray's node ids. ``fallback``: the pass's runner, for a frame it was not prepared for."""
    if executor.primitive_ids or any(draw.program in executor._user for draw in step.draws):
        return None
    draws = []
    for draw in step.draws:
        node = nodes[draw.node]
        draws.append(PreparedDraw(node, executor._prepared_draw(node, draw, node.material, "ccw")))
    prepared_draws = tuple(draws)
    made = executor._steps.made

    def run(ex: Any, frame: FrameState, pass_step: Pass, camera: Any) -> None:
        if frame.nodes is not nodes or ex._steps.made != made:  # another scene, or the draws dropped since
            fallback(ex, frame, pass_step, camera)
            return
        draw_prepared(ex, prepared_draws, camera, frame.models, frame.lights)

    return run


def draw_prepared(ex: Any, draws: tuple[PreparedDraw, ...], camera: Any, models: Mapping[str, Any],
                  lights: tuple) -> None:
    """Draw ``draws`` through ``camera``: :meth:`~glsandbox.gl.executor.Executor.draw_node`'s
    writes and draw for each, with what it looks up found once (see the module's text)."""
    last_frame, frame_number = ex._mesh_last_frame, ex._frame
    light_bytes = ex._light_bytes
    for prepared in draws:
        step = prepared.step
        setup = step.setup
        last_frame[setup.mesh_key] = frame_number
        if step.culling != ex._culling:
            ex._set_culling(*step.culling)
        written, uniforms = setup.written, setup.uniforms
        model = models.get(prepared.name)
        if model is None:  # not moved: the bytes of its own model through this camera, made once
            still = prepared.still
            if still is None or still[0] is not camera:
                matrix = np.asarray(prepared.node.model, dtype=np.float64)
                content = matrix.tobytes()
                still = prepared.still = (camera, _MODEL_BYTES[content + camera.origin_bytes],
                                          _NORMAL_BYTES[content] if setup.normal else None)
            model_bytes, normal_bytes = still[1], still[2]
        else:  # moved: converted as write_matrices converts it (a matrix seen before: a lookup)
            if type(model) is not np.ndarray or model.dtype != _FLOAT64:
                model = np.asarray(model, dtype=np.float64)
            content = model.tobytes()
            model_bytes = _MODEL_BYTES[content + camera.origin_bytes]
            normal_bytes = _NORMAL_BYTES[content] if setup.normal else None
        if written["m_model"] != model_bytes:
            written["m_model"] = model_bytes
            uniforms["m_model"].write(model_bytes)
        if normal_bytes is not None and written["m_normal"] != normal_bytes:
            written["m_normal"] = normal_bytes
            uniforms["m_normal"].write(normal_bytes)
        if written[_CAMERA] is not camera:  # (as write_matrices: a pass's draws share its camera)
            write_camera(written, uniforms, camera)
        if step.lit:
            kept = step.lights
            if written[_EYE] is camera and lights and kept[0] is lights and kept[3] is camera:
                write_lights(written, uniforms, kept[1], kept[2])  # (the eye written, these lights' bytes made)
            else:
                write_lighting(step, written, uniforms, camera, lights, light_bytes)
        constants = step.constants
        last = written[_CONSTANTS]
        if last is not constants:
            change = step.change
            if change[0] is last and last is not None:  # (write_constants's kept answer: the same writes)
                for name, data in change[1]:
                    written[name] = data
                    uniforms[name].write(data)
                written[_CONSTANTS] = constants
            else:
                write_constants(step, written, uniforms)
        if prepared.plain:
            prepared.render(prepared.mode, vertices=prepared.count)
        else:
            ex._bind_and_render(step.draw, step.material, setup, camera)
