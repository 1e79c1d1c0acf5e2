"""Frames are opaque: every pixel's alpha is 255, as the window shows it.

The rule is :data:`glsandbox.gl.target.FRAME_COLOR_MASK`: every clear writes a
target's alpha as 1 (:func:`glsandbox.gl.target.clear_opaque`) and no draw writes it, so the mirror's blended glass and shadow, an
unblended translucent node and a translucent clear colour all leave it 1.
Checked on every lesson (raster and ray-traced), with MSAA, on a scene made
to write alpha, and on the PNG ``glsandbox render`` writes. Every lesson's
default frame and its ``effects=all`` frame are checked where they are rendered
already (tests/measure/test_tradeoffs_bench.py, ``effects=all``); here, each
lesson with its other renderer, and the mirror's other settings.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support import run_cli

from glsandbox import geometry
from glsandbox.files import load_png
from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.scene import Material, Node, Scene, Viewport

SIZE = (96, 72)
#: Each lesson with the renderer it does not use by default (its default frame is checked
#: with effects=all), then the mirror's own settings.
OTHER_RENDERER = {"ray": "raster", "raster": "ray"}
MIRROR = (["mirror=off"], ["mirror=no_stencil", "shadow=double_blend"],
          ["depth=standard", "offset=off", "light=directional", "lx=-0.5", "ly=1", "lz=0.4"])
CASES = [(cls.name, [f"renderer={OTHER_RENDERER[cls().values['renderer']]}"]) for cls in all_lessons()]
CASES += [("mirror", settings) for settings in MIRROR]


def assert_opaque(image: np.ndarray, what: str) -> None:
    alpha = image[..., 3]
    values, counts = np.unique(alpha[alpha != 255], return_counts=True)
    assert (alpha == 255).all(), f"{what}: alpha below 255 at {dict(zip(values.tolist(), counts.tolist()))}"


@pytest.mark.parametrize(("name", "settings"), CASES, ids=[" ".join([n, *s]) for n, s in CASES])
def test_every_lesson_frame_is_opaque(gl, name: str, settings: list[str]) -> None:
    lesson = find_lesson(name).from_settings(settings)
    assert_opaque(gl.render(lesson, SIZE).image, f"{name} {settings}")


def test_msaa_frames_are_opaque_after_the_resolve(gl) -> None:
    assert_opaque(gl.render(find_lesson("mirror")(), SIZE, samples=4).image, "mirror, 4x MSAA")


def test_translucent_clear_colours_and_unblended_translucent_draws_leave_alpha_alone(gl) -> None:
    # Two viewports cleared with alpha 0.3 and 0, a node whose colour has alpha 0.4 drawn without
    # blending over part of the first: the rgb is what they ask for, the alpha stays 255.
    node = Node("quad", geometry.quad_strip(), material=Material(color=(1.0, 0.5, 0.0, 0.4)), viewports=(0,))
    left = Viewport(rect=(0.0, 0.0, 0.5, 1.0), clear_color=(0.0, 0.25, 0.5, 0.3))
    right = Viewport(rect=(0.5, 0.0, 0.5, 1.0), clear_color=(0.5, 0.25, 0.0, 0.0))
    image = gl.render_scene(Scene("translucent", nodes=(node,), viewports=(left, right)), SIZE).image
    assert_opaque(image, "translucent clears and draws")
    assert tuple(image[2, 2, :3]) == (0, 64, 128)  # the left clear, outside the quad
    assert tuple(image[2, -3, :3]) == (128, 64, 0)  # the right clear
    assert tuple(image[SIZE[1] // 2, SIZE[0] // 4, :3]) == (255, 128, 0)  # the quad, unblended


def test_render_writes_an_opaque_png_of_the_mirror(gl, tmp_path: Path) -> None:
    out = tmp_path / "mirror.png"
    proc = run_cli("render", "mirror", "--size", "160x120", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    png = load_png(out)
    assert_opaque(png, "glsandbox render mirror")
    # The same picture as the frame (the glass and the shadow are there, now opaque).
    assert np.array_equal(png, gl.render(find_lesson("mirror")(), (160, 120)).image)
