"""Which shader variant each node is drawn with: the ``#define`` lines a program is compiled with.

Only what a node's material asks for is compiled in (course sections "Lighting"
and "Texture Mapping"): a plan lists each variant once (:func:`glsandbox.plan.plan`).
"""

from __future__ import annotations

import functools

from glsandbox.passes.plan_parts import ProgramVariant
from glsandbox.scene import Node


def program_for(node: Node, lights: int = 0, shadow_light: int | None = None, shadow_pcf: int = 1) -> ProgramVariant:
    """The shader variant a node needs: ``basic`` with its colour source, or
    ``phong`` (:func:`lit_program_for`) when its material is lit; ``TEXTURED``
    only when it has a texture. ``lights`` is the number of lights in the scene;
    ``shadow_light`` the light whose shadow map a lit node receives (None: none),
    filtered ``shadow_pcf`` texels wide.
    A node with a shader of its own gets that file, with ``NUM_LIGHTS`` (and
    ``TEXTURED``) defined, whatever its material's shading."""
    material = node.material
    if node.shader is not None:
        return _user_variant(str(node.shader), lights, material.texture is not None)
    if material.lit:
        return lit_program_for(node, lights, shadow_light, shadow_pcf)
    return _basic_variant(material.shading == "vertex_color", material.texture is not None,
                          material.alpha_mode == "mask")


@functools.cache
def _user_variant(path: str, lights: int, textured: bool) -> ProgramVariant:
    return ProgramVariant(path, (("NUM_LIGHTS", str(lights)), *_texture_defines(textured)), user=True)



def _texture_defines(textured: bool) -> tuple[tuple[str, str], ...]:
    return (("TEXTURED", ""),) if textured else ()


def _mask_defines(mask: bool) -> tuple[tuple[str, str], ...]:
    """``ALPHA_MASK``: fragments whose alpha is below the material's cutoff are discarded."""
    return (("ALPHA_MASK", ""),) if mask else ()


# One ProgramVariant object per combination: planning runs every frame.
@functools.cache
def _basic_variant(vertex_color: bool, textured: bool, mask: bool = False) -> ProgramVariant:
    source = "VERTEX_COLOR" if vertex_color else "SOLID_COLOR"
    return ProgramVariant("basic", ((source, ""), *_texture_defines(textured), *_mask_defines(mask)))


def lit_program_for(node: Node, lights: int, shadow_light: int | None = None, shadow_pcf: int = 1) -> ProgramVariant:
    """The ``phong`` variant for a lit node (course section "Lighting").

    ``NUM_LIGHTS`` sizes the light loop to the lights present (no unused
    slots are looped over); ``PER_VERTEX`` evaluates the formula at the
    vertices (Gouraud), ``BLINN`` uses the half vector, ``NAIVE_NORMALS``
    the course's ``mul(Input.Norm, world)`` instead of the normal matrix.
    A model file's materials add ``VERTEX_COLOR`` (the mesh colour times the
    vertex colours), ``TWO_SIDED`` (back faces lit with the normal reversed)
    and ``ALPHA_MASK`` (cut-outs), each only for a material that asks.
    ``SHADOW_LIGHT i`` looks light i's shadow map up (:mod:`glsandbox.shadowmap`) with a
    ``SHADOW_PCF`` x ``SHADOW_PCF`` grid of comparisons (a constant: the loop unrolls).
    """
    material = node.material
    return _lit_variant(lights, material.shading, material.normals, material.texture is not None,
                        material.vertex_colors, material.double_sided, material.alpha_mode == "mask",
                        shadow_light, shadow_pcf)


@functools.cache
def _lit_variant(lights: int, shading: str, normals: str, textured: bool, vertex_colors: bool = False,
                 two_sided: bool = False, mask: bool = False, shadow_light: int | None = None,
                 shadow_pcf: int = 1) -> ProgramVariant:
    defines: list[tuple[str, str]] = [("NUM_LIGHTS", str(lights))]
    if shading == "gouraud":
        defines.append(("PER_VERTEX", ""))
    if shading == "blinn_phong":
        defines.append(("BLINN", ""))
    if normals == "naive":
        defines.append(("NAIVE_NORMALS", ""))
    defines.extend(_texture_defines(textured))
    if vertex_colors:
        defines.append(("VERTEX_COLOR", ""))
    if two_sided:
        defines.append(("TWO_SIDED", ""))
    defines.extend(_mask_defines(mask))
    if shadow_light is not None:
        defines += [("SHADOW_LIGHT", str(shadow_light)), ("SHADOW_PCF", str(shadow_pcf))]
    return ProgramVariant("phong", tuple(defines))

