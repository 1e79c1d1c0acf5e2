"""The ``draw`` pass's runner (glsandbox/gl/passes/draw.py): each draw of the pass drawn through
the pass camera, at the frame's model matrix where the frame moves the node (its own elsewhere)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry
from glsandbox.gl.passes import FrameState, runner
from glsandbox.gl.passes.draw import RUNNER, run
from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.scene import Node, Scene


class Recording:
    def __init__(self) -> None:
        self.drawn: list[tuple[str, str, object, object]] = []

    def draw_node(self, node, draw, camera, *, model=None) -> None:
        self.drawn.append((node.name, draw.program, camera, model))


def test_the_runner_is_the_registrys_draws_at_moved_models_and_touches_no_state_group() -> None:
    assert runner("draw") is RUNNER and RUNNER.moved
    assert RUNNER.state(Pass("draw", 0)) == (frozenset(), frozenset())


def test_each_draw_is_drawn_through_the_pass_camera_at_the_frames_model_for_it() -> None:
    nodes = {name: Node(name, geometry.cube()) for name in ("a", "b")}
    moved = np.eye(4) * 2.0
    frame = FrameState(Scene("s", nodes=tuple(nodes.values())), nodes, None, (4, 4), {"b": moved}, ())
    executor, camera = Recording(), object()
    run(executor, frame, Pass("draw", 0, draws=(Draw("a", "basic", True), Draw("b", "phong", False))), camera)
    assert [(n, p, c is camera) for n, p, c, _ in executor.drawn] == [("a", "basic", True), ("b", "phong", True)]
    assert executor.drawn[0][3] is None and executor.drawn[1][3] is moved


def test_a_draw_pass_needs_its_viewports_camera() -> None:
    frame = FrameState(Scene("s"), {}, None, (4, 4), {}, ())
    with pytest.raises(AssertionError):
        run(Recording(), frame, Pass("draw", 0), None)
