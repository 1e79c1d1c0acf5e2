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


def figure_pixels(image: np.ndarray, scene, color) -> list[bool]:
    """For each line of the scene's exam figure drawn in ``color``: whether pixels of that colour lie
    along its projected segment (at 0.4, 0.5 and 0.6 of it: clear of the labels at its ends)."""
    from glsandbox.overlay import WorldLines, project_segment

    figure = next(o for o in scene.overlays if isinstance(o, WorldLines))
    h, w = image.shape[:2]
    clip = scene.camera.projection(w / h) @ scene.camera.view()
    found = []
    for line in (line for line in figure.lines if line.color == color):
        (x0, y0), (x1, y1) = project_segment(clip, line.start, line.end, (w, h))
        for s in (0.4, 0.5, 0.6):
            x, y = round(x0 + s * (x1 - x0)), round(y0 + s * (y1 - y0))
            patch = image[max(y - 2, 0):y + 3, max(x - 2, 0):x + 3, :3].astype(int)
            found.append(bool((np.abs(patch - np.array(color[:3])).max(axis=2) <= 8).any()))
    return found


@pytest.mark.parametrize("renderer", ["raster", "ray"])
@pytest.mark.parametrize("which", ["exam2013", "exam2012"])
def test_the_exam_scenes_draw_their_question_over_the_picture(gl, renderer, which):
    """The ray, the reflected ray, the shadow ray (solid up to what it meets, dashed beyond) lie
    over the picture on their projected segments, in the rasterised and the traced picture
    alike; ``exam_rays=off`` takes them away (the text panel stays)."""
    import glsandbox.lessons.ray_phong as module

    cls = find_lesson("ray_phong")
    size = (320, 240)
    on = cls.from_settings([f"scene={which}", f"renderer={renderer}"])
    off = cls.from_settings([f"scene={which}", f"renderer={renderer}", "exam_rays=off"])
    with_rays, without = gl.render(on, size).image, gl.render(off, size).image
    colors = ((module.RAY_COLOR, module.REFLECTED_COLOR, module.SHADOW_RAY_COLOR) if which == "exam2013"
              else (module.LIT_COLOR,))
    for color in colors:
        assert all(figure_pixels(with_rays, on.scene(), color)), (which, color)
        assert not any(figure_pixels(without, on.scene(), color)), (which, color)
    assert [o.name for o in off.scene().overlays] == ["figures"]
    assert cls.from_settings([f"scene={which}", "overlay=off"]).scene().overlays == ()


def test_a_pixel_story_says_when_the_exam_figure_lies_over_the_pixel():
    from glsandbox.overlay import project_segment
    from glsandbox.story.ray_pixel import overlays_over

    scene = find_lesson("ray_phong")(scene="exam2013").scene()
    size = (320, 240)
    eye_ray = scene.overlays[0].lines[0]
    (x0, y0), (x1, y1) = project_segment(scene.camera.projection(4 / 3) @ scene.camera.view(),
                                         eye_ray.start, eye_ray.end, size)
    on_the_ray = (round((x0 + x1) / 2), round((y0 + y1) / 2))
    assert any("'exam rays'" in note for note in overlays_over(scene, size, on_the_ray))
    assert not any("'exam rays'" in note for note in overlays_over(scene, size, (300, 230)))
