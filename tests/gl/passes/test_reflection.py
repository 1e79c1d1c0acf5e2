"""The ``reflection`` pass's runner (glsandbox/gl/passes/reflection.py): it sets its stencil where
it has a stencil state, and the depth mask only where a state table turns depth writes off; what it
sets is what it leaves changed (course "The stencil Test", ``DrawReflectionDSS``)."""

from __future__ import annotations

from dataclasses import replace

from glsandbox.gl.passes import runner
from glsandbox.gl.passes.reflection import RUNNER
from glsandbox.gl.planar_state import reflection
from glsandbox.passes.plan_parts import Pass
from glsandbox.passes.planar_effects import REFLECTION_STENCIL


def test_the_runner_is_the_registrys_and_draws_the_reflected_nodes() -> None:
    assert runner("reflection") is RUNNER and RUNNER.run is reflection and RUNNER.moved


def test_the_groups_it_sets_are_the_stencil_with_a_state_and_the_masks_without_depth_writes() -> None:
    plain = Pass("reflection", 0, depth_test=True)
    assert RUNNER.state(plain) == (frozenset(), frozenset())
    assert RUNNER.state(replace(plain, stencil=REFLECTION_STENCIL)) == (frozenset({"stencil"}),) * 2
    assert RUNNER.state(replace(plain, depth_write=False)) == (frozenset({"masks"}),) * 2
    assert RUNNER.state(replace(plain, depth_write=True)) == (frozenset(),) * 2
