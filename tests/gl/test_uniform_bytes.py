"""Uniform bytes as the shaders read them (course sections "World, View, Projection" and
"Lighting"): the eye from the view matrix, the material's constants, and what changes between draws."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from glsandbox import transforms
from glsandbox.gl.uniform_bytes import (_MODEL_BYTES, _NORMAL_BYTES, PassCamera, _constants_change, _Uniforms,
                                        _Written, eye_position, material_constants)
from glsandbox.scene import Material


def floats(data: bytes) -> list[float]:
    return list(struct.unpack(f"{len(data) // 4}f", data))


def test_the_eye_is_the_inverse_views_translation_and_the_pass_is_relative_to_its_origin() -> None:
    view = transforms.look_at((1.0, 3.0, 10.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    np.testing.assert_allclose(eye_position(view), (1.0, 3.0, 10.0), atol=1e-12)
    proj = transforms.perspective(45.0, 4 / 3, 0.1, 100.0)
    camera = PassCamera(view, proj)  # relative to the eye: the eye sits at 0, the view only rotates
    assert floats(camera.eye_bytes) == pytest.approx([0.0, 0.0, 0.0], abs=1e-5)
    moved = np.asarray(view) @ transforms.translate(1.0, 3.0, 10.0)
    np.testing.assert_allclose(moved[:3, 3], 0.0, atol=1e-12)
    np.testing.assert_allclose(floats(camera.view_bytes), floats(transforms.gl_bytes(moved)), atol=1e-6)  # column-major
    light = PassCamera(view, proj, origin=np.array([0.0, 10.0, 0.0]))  # a shadow map's pass: from the light
    assert floats(light.eye_bytes) == pytest.approx([1.0, -7.0, 10.0], abs=1e-5)


def test_a_materials_constants_are_its_colour_the_formulas_coefficients_the_cutoff_and_texture_unit() -> None:
    unlit = dict(material_constants(Material(color=(1.0, 0.5, 0.25, 1.0)), lit=False))
    assert list(unlit) == ["u_color", "u_alpha_cutoff"]
    assert floats(unlit["u_color"]) == [1.0, 0.5, 0.25, 1.0]
    lit = dict(material_constants(Material(), lit=True))
    # The course's 0.1*mesh + 0.4*diffuse + 0.3*specular, exponent 32.
    assert [floats(lit[n])[0] for n in ("u_ambient", "u_diffuse", "u_specular", "u_shininess")] == \
        pytest.approx([0.1, 0.4, 0.3, 32.0])


def test_only_the_constants_that_differ_from_what_the_program_holds_are_written() -> None:
    red = material_constants(Material(color=(1.0, 0.0, 0.0, 1.0)), lit=True)
    blue = material_constants(Material(color=(0.0, 0.0, 1.0, 1.0)), lit=True)
    assert [name for name, _ in _constants_change({}, red, blue)] == ["u_color"]  # walls differing in colour
    assert _constants_change({}, red, red) == ()
    written = _Written(dict(red))  # not known which draw wrote last: compared with the program's bytes
    assert [name for name, _ in _constants_change(written, None, blue)] == ["u_color"]
    assert len(_constants_change(_Written(), None, blue)) == len(blue)  # a fresh program: everything


def test_model_and_normal_bytes_are_made_from_the_matrix_content() -> None:
    model = transforms.scale(2.0, 1.0, 1.0)
    content = np.asarray(model, dtype=np.float64).tobytes()
    assert _MODEL_BYTES[content] == transforms.gl_bytes(model)
    assert _NORMAL_BYTES[content] == transforms.gl_bytes(transforms.normal_matrix(model))
    assert _NORMAL_BYTES[content] is _NORMAL_BYTES[content]  # made once


def test_a_uniform_the_program_lacks_takes_writes_and_does_nothing() -> None:
    uniforms = _Uniforms()
    uniforms["u_missing"].write(b"\x00" * 4)
    assert "u_missing" not in uniforms
