"""The lesson rendered with the student's function, through the numpy engine's hit-test seam."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.exercises import get
from glsandbox.exercises.isolation import InProcess
from glsandbox.exercises.lesson_view import render_lesson, sphere_scene
from glsandbox.raytrace.numpy_engine import render_viewport
from glsandbox.raytrace.sphere import Sphere


@pytest.mark.parametrize("name", ["ray_sphere", "ray_triangle"])
def test_the_reference_plugged_in_draws_the_engines_own_picture(name: str) -> None:
    exercise = get(name)
    result = render_lesson(exercise, InProcess(exercise.reference))
    width, height = exercise.lesson.size
    assert result.image.shape == (height, 3 * width + 8, 4)
    assert result.differing == 0 and result.calls > 1000 and not result.error
    yours, reference = result.image[:, :width], result.image[:, width + 4:2 * width + 4]
    np.testing.assert_array_equal(yours, reference)
    assert len(np.unique(yours.reshape(-1, 4), axis=0)) > 10  # a real picture, not a blank


@pytest.mark.parametrize(("name", "mistake"), [("ray_sphere", "far_root"), ("ray_triangle", "plane_only"),
                                               ("ray_triangle", "edge_reversed")])
def test_a_named_mistake_draws_a_different_picture(name: str, mistake: str) -> None:
    exercise = get(name)
    wrong = next(m for m in exercise.mistakes if m.name == mistake)
    result = render_lesson(exercise, InProcess(wrong.function))
    assert result.differing > 100


def test_a_function_that_raises_draws_nothing_and_says_so() -> None:
    def broken(*args):
        raise ValueError("no")

    result = render_lesson(get("ray_sphere"), InProcess(broken))
    assert result.differing > 0 and "failed" in result.error


def test_the_seam_replaces_only_the_named_kind_and_keeps_the_engines_pixels() -> None:
    scene = sphere_scene()
    unit = Sphere((0.0, 0.0, 0.0), 1.0)
    calls = []

    def sphere(o, d):
        calls.append(len(d))
        return unit.intersect_many(o, d)

    plain = render_viewport(scene, (64, 36))
    seamed = render_viewport(scene, (64, 36), hit_tests={"sphere": sphere})
    np.testing.assert_array_equal(plain, seamed)
    assert sum(calls) > 64 * 36 * 0.2
    missing = render_viewport(scene, (64, 36), hit_tests={"sphere": lambda o, d: np.full(len(d), np.inf)})
    assert (missing[..., :3] == missing[0, 0, :3]).all()  # nothing hit: the background everywhere
