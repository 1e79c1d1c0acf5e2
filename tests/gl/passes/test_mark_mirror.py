"""The ``mark_mirror`` pass's runner (glsandbox/gl/passes/mark_mirror.py): it sets the stencil and
both write masks itself (course "The stencil Test", ``MarkMirrorDSS``) and leaves them changed."""

from __future__ import annotations

from glsandbox.gl.passes import runner
from glsandbox.gl.passes.mark_mirror import RUNNER
from glsandbox.gl.planar_state import mark_mirror
from glsandbox.passes.mark_mirror import mark_mirror_pass
from glsandbox.passes.plan_parts import Draw, Pass


def test_the_runner_is_the_registrys_and_runs_the_stencil_marking() -> None:
    assert runner("mark_mirror") is RUNNER and RUNNER.run is mark_mirror and RUNNER.moved


def test_it_sets_the_stencil_and_the_masks_and_leaves_both_changed() -> None:
    marked = mark_mirror_pass(0, Draw("glass", "basic", True))
    assert RUNNER.state(marked) == (frozenset({"stencil", "masks"}), frozenset({"stencil", "masks"}))
    assert RUNNER.state(Pass("mark_mirror", 0)) == (frozenset({"masks"}), frozenset({"stencil", "masks"}))
