"""The ``overlay`` pass's runner (glsandbox/gl/passes/overlay.py): the material texture's sampler
let go first, the pass's overlays drawn with its compiled program, and the executor told that the
drawer switched culling off."""

from __future__ import annotations

from glsandbox.gl.passes import FrameState, runner
from glsandbox.gl.passes.overlay import RUNNER, run
from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.scene import Scene


class Recording:
    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def unbind_texture(self) -> None:
        self.calls.append(("unbind_texture",))

    def compiled(self, key: str) -> str:
        return f"program {key}"

    def overlay_drawer(self) -> "Recording":
        return self

    def draw(self, scene, step, framebuffer, size, program) -> None:
        self.calls.append(("draw", scene.name, step.viewport, framebuffer, size, program))

    def culling_switched_off(self) -> None:
        self.calls.append(("culling_switched_off",))


def test_the_runner_is_the_registrys_and_touches_no_state_group() -> None:
    assert runner("overlay") is RUNNER and RUNNER.moved
    assert RUNNER.state(Pass("overlay", -1)) == (frozenset(), frozenset())


def test_the_texture_is_let_go_before_the_overlays_and_culling_is_noted_after() -> None:
    executor = Recording()
    frame = FrameState(Scene("labels"), {}, "the frame", (16, 8), {}, ())
    run(executor, frame, Pass("overlay", -1, draws=(Draw("title", "overlay", False),), camera=None), None)
    assert executor.calls == [("unbind_texture",), ("draw", "labels", -1, "the frame", (16, 8), "program overlay"),
                              ("culling_switched_off",)]
