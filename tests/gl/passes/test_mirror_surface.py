"""The ``mirror_surface`` pass's runner (glsandbox/gl/passes/mirror_surface.py): the glass blended
over its reflection, the blending set by the pass and left on for the executor to put back."""

from __future__ import annotations

from glsandbox.gl.passes import runner
from glsandbox.gl.passes.mirror_surface import RUNNER
from glsandbox.gl.planar_state import mirror_surface
from glsandbox.passes.mirror_surface import mirror_surface_pass
from glsandbox.passes.plan_parts import Draw


def test_the_runner_is_the_registrys_and_draws_the_glass() -> None:
    assert runner("mirror_surface") is RUNNER and RUNNER.run is mirror_surface and RUNNER.moved


def test_it_sets_its_blending_and_leaves_only_that_changed() -> None:
    step = mirror_surface_pass(0, Draw("glass", "basic", True, blend=True))
    assert RUNNER.state(step) == (frozenset({"blend"}), frozenset({"blend"}))
