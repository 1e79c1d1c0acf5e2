"""The ``trace`` pass's runner (glsandbox/gl/passes/trace.py): the executor draws raster viewports
only, so a trace pass that reaches it is refused naming the viewport; never drawn at moved models."""

from __future__ import annotations

import pytest

from glsandbox.gl.passes import FrameState, runner
from glsandbox.gl.passes.trace import RUNNER, run
from glsandbox.passes.plan_parts import Pass
from glsandbox.scene import Scene


def test_the_runner_is_the_registrys_and_a_moved_frame_never_takes_it() -> None:
    assert runner("trace") is RUNNER and not RUNNER.moved
    assert RUNNER.state(Pass("trace", 0)) == (frozenset(), frozenset())


def test_a_trace_pass_is_refused_naming_its_viewport() -> None:
    with pytest.raises(ValueError, match=r"trace viewport 2: trace it first \(glsandbox.frame.trace_viewports\)"):
        run(None, FrameState(Scene("s"), {}, None, (4, 4), {}, ()), Pass("trace", 2), None)
