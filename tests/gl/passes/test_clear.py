"""The ``clear`` pass's runner (glsandbox/gl/passes/clear.py): the viewport's rectangle cleared to
its colour, opaque whatever the colour's alpha, and nothing outside it; no GL state left changed."""

from __future__ import annotations

import numpy as np

from glsandbox.gl.passes import FrameState, runner
from glsandbox.gl.passes.clear import RUNNER, run
from glsandbox.passes.plan_parts import Pass
from glsandbox.scene import Scene, Viewport

SIZE = (8, 4)


def test_the_runner_is_the_registrys_and_touches_no_state_group() -> None:
    assert runner("clear") is RUNNER and RUNNER.moved
    assert RUNNER.state(Pass("clear", 0)) == (frozenset(), frozenset())


def test_the_viewports_rectangle_is_cleared_opaque_and_the_rest_is_left(gl) -> None:
    ctx = gl.host.ctx
    target = ctx.simple_framebuffer(SIZE)
    try:
        target.use()
        target.clear(0.0, 0.0, 0.0, 1.0)
        scene = Scene("halves", viewports=(Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0))))
        frame = FrameState(scene, {}, target, SIZE, {}, ())
        executor = type("Executor", (), {"pass_rect": None, "clear_depth": 1.0, "raw": None})()
        run(executor, frame, Pass("clear", 1, clear_color=(1.0, 0.0, 0.0, 0.25)), None)
        pixels = np.frombuffer(target.read(components=4), dtype=np.uint8).reshape(SIZE[1], SIZE[0], 4)
    finally:
        target.release()
    assert (pixels[:, 4:] == (255, 0, 0, 255)).all()  # the right half, alpha 255 whatever the colour's
    assert (pixels[:, :4] == (0, 0, 0, 255)).all()
