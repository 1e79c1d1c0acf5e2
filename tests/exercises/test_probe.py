"""Probe pictures: the classes and colours, and goldens of a few exercises' pictures.

Each golden is the probe of the reference (dark and grey only: where it answers, shaded by its
value) or of one named mistake (its colours where it goes wrong), at the checker's 256x256.
They pin the fields and the drawing: a change to either shows as a changed golden."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.exercises import get
from glsandbox.exercises.isolation import InProcess
from glsandbox.exercises.probe import CLASSES, COLOURS, classify, probe_picture, reference_values

GOLDENS = [("ray_sphere", None), ("ray_sphere", "far_root"), ("ray_triangle", "plane_only"),
           ("ray_triangle", "edge_reversed"), ("phong", None), ("phong", "specular_behind"),
           ("shadow", "the_notes_erratum"), ("aabb", "no_swap")]


class _Reference:
    """The reference as the student's side of a probe, all at once (as the probe computes it)."""

    def __init__(self, exercise) -> None:
        self.exercise = exercise

    def batch(self, inputs):
        return reference_values(self.exercise, inputs), {}


def _caller(name: str, mistake: str | None):
    exercise = get(name)
    if mistake is None:
        return exercise, _Reference(exercise)
    return exercise, InProcess(next(m.function for m in exercise.mistakes if m.name == mistake))


@pytest.mark.parametrize(("name", "mistake"), GOLDENS)
def test_probe_pictures_match_their_goldens(golden, name: str, mistake: str | None) -> None:
    exercise, caller = _caller(name, mistake)
    probe = probe_picture(exercise, caller, 256)
    assert probe.image.shape == (256, 256, 4)
    assert probe.agrees == (mistake is None)
    golden(probe.image, f"exercises/{name}_{mistake or 'reference'}", threshold=0, max_bad_share=0.0)


def test_each_class_has_its_colour() -> None:
    exercise = get("ray_sphere")
    reference = [1.0, None, None, 1.0, 1.0, 1.0]
    student = [1.0, None, 2.0, None, 1.5, "x"]
    classes = classify(exercise, reference, student, {})
    assert [CLASSES[c] for c in classes] == ["agree", "both none", "student only", "reference only",
                                             "value differs", "broken"]
    assert len({tuple(c) for c in COLOURS}) == len(CLASSES)


def test_a_coarse_field_is_drawn_at_full_size() -> None:
    exercise = get("shadow")
    probe = probe_picture(exercise, _Reference(exercise), 256)
    assert exercise.probe.resolution == 64 and probe.classes.shape == (64, 64)
    assert probe.image.shape == (256, 256, 4)
    np.testing.assert_array_equal(probe.image[::4, ::4], probe.image[3::4, 3::4])


def test_distances_are_shaded_all_at_once_as_each_would_be_alone() -> None:
    from glsandbox.exercises.probe import _brightness, _levels

    exercise = get("ray_sphere")  # shade: 1 - t / 4
    values = [0.5, 3.0, 9.0, -2.0, 4, 1e300]
    assert np.array_equal(_levels(exercise, values), [_brightness(exercise, v) for v in values])
    odd = [0.5, [1.0], None]  # not all distances: each judged alone, a wrong type mid-grey
    assert np.array_equal(_levels(exercise, odd), [_brightness(exercise, v) for v in odd])
    assert _levels(exercise, [0.5, float("nan")])[1] == 0.75


def test_a_probe_begun_and_finished_later_is_the_probe_drawn_at_once() -> None:
    from glsandbox.exercises.probe import start_probe

    exercise = get("ray_sphere")
    mistake = next(m for m in exercise.mistakes if m.name == "far_root")
    finish = start_probe(exercise, InProcess(mistake.function), 64)
    later, now = finish(), probe_picture(exercise, InProcess(mistake.function), 64)
    assert np.array_equal(later.image, now.image) and later.counts() == now.counts()
    assert later.counts()["value differs"] > 0
