"""A plan's parts: program variant keys, how draws and stencil states read in ``glsandbox plan``,
and the stencil values an 8-bit buffer refuses (course section "The stencil Test")."""

from __future__ import annotations

import pytest

from glsandbox.errors import SandboxError
from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant, StencilState, describe_draws
from glsandbox.passes.planar_effects import MARK_MIRROR_STENCIL, PLANAR_SHADOW_STENCIL, REFLECTION_STENCIL


def test_a_variants_key_names_the_shader_and_its_defines() -> None:
    assert ProgramVariant("phong").key == "phong"
    assert ProgramVariant("basic", (("SOLID_COLOR", ""), ("LIGHTS", "2"))).key == "basic[SOLID_COLOR,LIGHTS=2]"
    assert ProgramVariant("phong", user=True) != ProgramVariant("phong")  # a node's own file is another program


def test_a_draw_says_its_program_culling_blending_and_texture_units() -> None:
    assert Draw("cube", "phong", True).describe() == "cube with phong"
    assert Draw("glass", "basic", False, texture="checker", blend=True, shadow_map=0).describe() == (
        "glass with basic (no culling) (blended, no depth writes) + texture unit 0: checker"
        " + texture unit 1: shadow map 0")
    assert describe_draws(Pass("draw", 0)) == "nothing"
    assert describe_draws(Pass("draw", 0, draws=(Draw("a", "x", True), Draw("b", "y", True)))) == \
        "a with x; b with y"


def test_the_mirror_and_shadow_stencil_states_read_as_the_course_names_them() -> None:
    assert MARK_MIRROR_STENCIL.describe() == "always, replace 1"  # MarkMirrorDSS
    assert REFLECTION_STENCIL.describe() == "equal 1, keep"  # DrawReflectionDSS
    assert PLANAR_SHADOW_STENCIL.describe() == "equal 0 on bit 2, set it"  # darken each pixel once
    assert StencilState("always", 0, write_mask=0x3, on_pass="invert").describe() == "always, invert bits 3"


@pytest.mark.parametrize(("state", "message"), [
    (dict(test="less", ref=0), "unknown stencil test 'less'"),
    (dict(test="equal", ref=0, on_pass="decr_wrap"), "unknown stencil operation 'decr_wrap'"),
    (dict(test="equal", ref=256), "stencil ref must lie in 0..255"),
    (dict(test="equal", ref=0, write_mask=-1), "stencil write_mask must lie in 0..255"),
])
def test_stencil_states_an_8_bit_buffer_cannot_hold_are_refused(state: dict, message: str) -> None:
    with pytest.raises(SandboxError, match=message):
        StencilState(**state)
