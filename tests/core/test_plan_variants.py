"""glsandbox.plan_variants: the #define lines each node's material asks for, and nothing more."""

from __future__ import annotations

from glsandbox import geometry
from glsandbox.plan_variants import lit_program_for, program_for
from glsandbox.scene import Material, Node, Texture


def node(**material: object) -> Node:
    return Node("n", geometry.cube24(), material=Material(**material))  # type: ignore[arg-type]


def test_an_unlit_node_gets_basic_with_its_colour_source_and_only_the_parts_it_has() -> None:
    assert program_for(node()).key == "basic[SOLID_COLOR]"
    coloured = Node("n", geometry.cube(), material=Material(shading="vertex_color"))
    assert program_for(coloured).key == "basic[VERTEX_COLOR]"
    textured = program_for(node(texture=Texture("checker"), alpha_mode="mask"))
    assert textured.key == "basic[SOLID_COLOR,TEXTURED,ALPHA_MASK]"


def test_a_lit_node_gets_phong_sized_to_the_lights_with_its_shading_options() -> None:
    assert program_for(node(shading="phong"), lights=2).key == "phong[NUM_LIGHTS=2]"
    assert program_for(node(shading="gouraud"), lights=1).key == "phong[NUM_LIGHTS=1,PER_VERTEX]"
    assert program_for(node(shading="blinn_phong", normals="naive"), lights=1).key == \
        "phong[NUM_LIGHTS=1,BLINN,NAIVE_NORMALS]"
    shadowed = lit_program_for(node(shading="phong", double_sided=True), 1, shadow_light=0, shadow_pcf=3)
    assert shadowed.key == "phong[NUM_LIGHTS=1,TWO_SIDED,SHADOW_LIGHT=0,SHADOW_PCF=3]"


def test_a_node_with_its_own_shader_gets_that_file_whatever_its_shading() -> None:
    own = Node("n", geometry.cube24(), material=Material(shading="phong", texture=Texture("checker")), shader="my.glsl")
    variant = program_for(own, lights=3)
    assert variant.user and variant.shader == str(own.shader) and variant.shader.endswith("my.glsl")
    assert variant.defines == (("NUM_LIGHTS", "3"), ("TEXTURED", ""))


def test_one_variant_object_per_combination() -> None:
    """Planning runs every frame: equal materials give the very same variant."""
    assert program_for(node(shading="phong"), lights=1) is program_for(node(shading="phong"), lights=1)
    assert program_for(node()) is program_for(node())
