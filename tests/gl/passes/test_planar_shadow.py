"""The ``planar_shadow`` pass's runner (glsandbox/gl/passes/planar_shadow.py): it sets its stencil
(with a stencil state) and its blending, and leaves depth writes off and the polygon offset set
(course "The stencil Test", ``XMMatrixShadow``): those groups are put back after it."""

from __future__ import annotations

from dataclasses import replace

from glsandbox.gl.passes import runner
from glsandbox.gl.passes.planar_shadow import RUNNER
from glsandbox.gl.planar_state import planar_shadow
from glsandbox.passes.plan_parts import Pass
from glsandbox.passes.planar_effects import PLANAR_SHADOW_STENCIL

LEFT = frozenset({"stencil", "masks", "blend", "offset"})


def test_the_runner_is_the_registrys_and_draws_the_flattened_casters() -> None:
    assert runner("planar_shadow") is RUNNER and RUNNER.run is planar_shadow and RUNNER.moved


def test_the_stencil_is_its_own_only_with_a_stencil_state_and_four_groups_are_left_changed() -> None:
    plain = Pass("planar_shadow", 0, depth_test=True)
    assert RUNNER.state(plain) == (frozenset({"blend"}), LEFT)
    assert RUNNER.state(replace(plain, stencil=PLANAR_SHADOW_STENCIL)) == (frozenset({"stencil", "blend"}), LEFT)
