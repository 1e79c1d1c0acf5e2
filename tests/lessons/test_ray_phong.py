"""The ray_phong lesson (course "Phong boyama modeli" on the ray tracer): the exam scenes' figures,
the shadow of the 2013 hit point, and its goldens."""

from __future__ import annotations

import numpy as np
import pytest
from support import check_lesson_golden, variant_name

from glsandbox.lesson import find_lesson
from glsandbox.raytrace import render


def panel_rows(scene: str) -> str:
    """The rows the lesson's panel prints for one of its scenes (re-computed by the lesson's module)."""
    import glsandbox.lessons.ray_phong as module

    return "\n".join(getattr(module, scene)("x")[1])


def test_exam_2013_figures():
    rows = panel_rows("exam2013")
    assert "red hit t = 75 at (72, 21, 0), N = (-0.8, 0.6, 0)" in rows
    assert "reflected (0, 1, 0) hits blue at t = 65" in rows
    assert "distance 100, blue at t = 75 < 100: in shadow" in rows


def test_exam_2012_figures_and_erratum():
    rows = panel_rows("exam2012")
    assert "distance 30" in rows and "D = 39.2" in rows and "t = 40" in rows
    assert "P is LIT" in rows


def test_exam_scenes_shadow_the_2013_hit_point():
    """The red sphere's hit point of #8 is dark in the traced picture: the blue sphere blocks the light."""
    cls = find_lesson("ray_phong")
    scene = cls(scene="exam2013").scene()
    lit = render(scene, (64, 48), shadows=False)
    shadowed = render(scene, (64, 48))
    assert shadowed[..., :3].sum() < lit[..., :3].sum()


@pytest.mark.parametrize("settings", [(), ("scene=exam2013",), ("scene=exam2012",)], ids=variant_name)
def test_golden(gl, golden, settings):
    image = check_lesson_golden(gl, golden, "ray_phong", *settings)
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
