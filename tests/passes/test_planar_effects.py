"""What the planar passes share: how a caster's shadow is cut out, the program it is drawn with,
and when a frame needs a stencil buffer (course section "The stencil Test")."""

from __future__ import annotations

import math

import pytest

from glsandbox import geometry
from glsandbox.passes.planar_effects import (CUTOUT_SHADOW_PROGRAM, PLANAR_SHADOW_PROGRAM, caster_program,
                                             cutout_caster_material, cutout_shadow, has_planar_effects,
                                             needs_stencil)
from glsandbox.planar import Mirror, PlanarShadow
from glsandbox.scene import Material, Node, Scene, Texture

CHECKER = Texture()


@pytest.mark.parametrize(("material", "cut"), [
    (Material(), None),  # opaque: the whole shadow
    (Material(alpha_mode="mask", texture=CHECKER, alpha_cutoff=0.5), 0.5),
    (Material(color=(1, 1, 1, 0.5), alpha_mode="mask", texture=CHECKER, alpha_cutoff=0.25), 0.5),  # texel alpha ≥ 0.5
    (Material(color=(1, 1, 1, 0.25), alpha_mode="mask", texture=CHECKER, alpha_cutoff=0.5), math.inf),  # no texel
    (Material(color=(1, 1, 1, 0.0), alpha_mode="mask", texture=CHECKER, alpha_cutoff=0.0), None),
    (Material(color=(1, 1, 1, 0.4), alpha_mode="mask", alpha_cutoff=0.5), math.inf),  # untextured, below
    (Material(color=(1, 1, 1, 0.6), alpha_mode="mask", alpha_cutoff=0.5), None),  # untextured, above
])
def test_cutout_shadow_is_the_cutoff_on_the_textures_alpha(material: Material, cut: float | None) -> None:
    assert cutout_shadow(material) == cut


def test_the_caster_program_is_whole_cut_out_or_none() -> None:
    textured = geometry.cube24()  # with uv
    whole = PLANAR_SHADOW_PROGRAM
    assert caster_program(Node("solid", textured), whole) is whole
    assert caster_program(Node("glass", textured, material=Material(alpha_mode="blend")), whole) is None
    cut = Material(alpha_mode="mask", texture=CHECKER)
    assert caster_program(Node("leaf", textured, material=cut), whole) is CUTOUT_SHADOW_PROGRAM
    gone = Material(color=(1, 1, 1, 0.1), alpha_mode="mask", texture=CHECKER)
    assert caster_program(Node("gone", textured, material=gone), whole) is None


def test_a_cut_out_casters_material_is_the_flat_colour_its_texture_and_the_alpha_cutoff() -> None:
    part = Material(color=(1, 1, 1, 0.5), alpha_mode="mask", texture=CHECKER, alpha_cutoff=0.25)
    drawn = cutout_caster_material(part, (0.0, 0.0, 0.0, 0.5))
    assert (drawn.color, drawn.texture, drawn.alpha_mode, drawn.alpha_cutoff) == ((0.0, 0.0, 0.0, 0.5), CHECKER,
                                                                                   "mask", 0.5)


def test_the_stencil_buffer_is_only_for_a_stencil_mirror_or_shadow() -> None:
    plain = Scene("s")
    mirror = Mirror("glass", (0.0, 0.0, 1.0, 0.0), ("cube",))
    shadow = PlanarShadow("floor", (0.0, 1.0, 0.0, 0.0), (0.0, 5.0, 0.0, 1.0), ("cube",), stencil=False)
    assert not has_planar_effects(plain) and not needs_stencil(plain)
    assert has_planar_effects(Scene("m", mirror=mirror)) and needs_stencil(Scene("m", mirror=mirror))
    assert has_planar_effects(Scene("p", planar_shadow=shadow)) and not needs_stencil(Scene("p", planar_shadow=shadow))
