"""The notebook helpers without a notebook server: the returned objects, their PNGs, the widgets."""

from __future__ import annotations

import io
import sys

import numpy as np
import pytest
from PIL import Image

import glsandbox
from glsandbox.errors import SandboxError
from glsandbox.lesson import find_lesson

SIZE = (160, 120)


def png_pixels(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


def test_show_returns_an_inline_picture_of_the_headless_render(gl) -> None:
    picture = glsandbox.show("phong", size=SIZE, specular=False, lights=1)
    data = picture._repr_png_()
    assert data.startswith(b"\x89PNG")
    expected = gl.render(find_lesson("phong").from_settings(["specular=off", "lights=1"]), SIZE).image
    np.testing.assert_array_equal(png_pixels(data), expected)
    assert picture.to_pil().size == SIZE
    # a Scene, a class and an instance work too; --set text is accepted as well as Python values
    scene = find_lesson("triangle")().scene()
    np.testing.assert_array_equal(glsandbox.show(scene, SIZE).image, gl.render(find_lesson("triangle")(), SIZE).image)
    np.testing.assert_array_equal(glsandbox.show(find_lesson("phong"), SIZE, specular="off", lights="1").image,
                                  expected)


def test_show_refuses_bad_values_with_the_parameter_named(gl) -> None:
    with pytest.raises(SandboxError, match="lights=7: must be at most 2"):
        glsandbox.show("phong", size=SIZE, lights=7)
    with pytest.raises(SandboxError, match="phong has no parameter 'specularr'; did you mean 'specular'"):
        glsandbox.show("phong", size=SIZE, specularr=False)


def test_widget_has_a_control_per_parameter_and_changing_one_re_renders(gl) -> None:
    box = glsandbox.widget("phong", SIZE)
    lesson = find_lesson("phong")
    names = {p.name for p in lesson.all_params()} - {"camera"}
    assert set(box.controls) == names
    assert type(box.controls["shading"]).__name__ == "Dropdown"
    assert type(box.controls["specular"]).__name__ == "Checkbox"
    assert type(box.controls["lights"]).__name__ == "IntSlider" and box.controls["lights"].max == 2
    assert box.image in box.children and all(w in box.children for w in box.controls.values())
    before = box.image.value
    np.testing.assert_array_equal(png_pixels(before), gl.render(lesson(), SIZE).image)
    box.controls["specular"].value = False
    assert box.image.value != before
    np.testing.assert_array_equal(png_pixels(box.image.value), gl.render(lesson(specular=False), SIZE).image)
    box.controls["shading"].value = "gouraud"
    np.testing.assert_array_equal(png_pixels(box.image.value),
                                  gl.render(lesson(specular=False, shading="gouraud"), SIZE).image)


def test_widget_text_fields_report_a_bad_value_and_keep_the_picture(gl) -> None:
    box = glsandbox.widget("texture", SIZE)
    before = box.image.value
    box.controls["image"].value = "no-such-file.png"
    assert box.error.value.startswith("error: ") and "no-such-file.png" in box.error.value
    assert box.image.value == before and box.lesson.values["image"] == "labels"
    box.controls["tile"].value = 1.0  # the next change renders with the last good image
    assert box.error.value == "" and box.image.value != before


@pytest.mark.parametrize("helper, module", [("widget", "ipywidgets"), ("view", "jupyter_rfb")])
def test_without_the_notebook_extra_the_helpers_say_what_to_install(monkeypatch, helper: str, module: str) -> None:
    monkeypatch.setitem(sys.modules, module, None)  # `import MODULE` raises ImportError
    monkeypatch.delitem(sys.modules, "glsandbox.app.notebook_view", raising=False)  # imported again, without it
    with pytest.raises(SandboxError) as caught:
        getattr(glsandbox, helper)("phong")
    assert str(caught.value) == (f"glsandbox.{helper} needs {module}: install the notebook extra "
                                 "(pip install 'glsandbox[notebook]', or uv sync --extra notebook)")
