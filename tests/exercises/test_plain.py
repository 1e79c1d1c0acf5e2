"""The named mistakes' vector steps (glsandbox/exercises/plain.py), on plain lists as a student
writes them: exact on small integers, and the zero vector has no direction."""

from __future__ import annotations

import pytest

from glsandbox.exercises.plain import cross, dot, sub, unit


def test_the_steps_on_the_course_axes() -> None:
    assert sub([1, 2, 3], [1, 1, 1]) == [0, 1, 2] and dot([1, 2, 3], [4, -5, 6]) == 12
    assert cross([1, 0, 0], [0, 1, 0]) == [0, 0, 1] and cross([0, 1, 0], [1, 0, 0]) == [0, 0, -1]  # x × y = z
    assert cross([2, 3, 4], [5, 6, 7]) == [-3, 6, -3]
    assert unit([0.0, 3.0, 4.0]) == [0.0, 0.6, 0.8] and unit([0, 0, 0]) is None


def test_vectors_of_different_lengths_are_refused() -> None:
    with pytest.raises(ValueError):
        dot([1, 2, 3], [1, 2])
