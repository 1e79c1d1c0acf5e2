"""An exercise's parts (glsandbox/exercises/definition.py): a case hidden unless visible, the signature
as the student reads it, the cases a check runs, and expected vectors as plain floats. (Every
exercise's parts against its cases: test_catalogue.py.)"""

from __future__ import annotations

import numpy as np

from glsandbox.exercises import get
from glsandbox.exercises.definition import RESULT_KINDS, Case, vec


def test_a_case_is_hidden_unless_it_is_visible() -> None:
    assert not Case("worked example 4", (1,), 35.0).hidden
    assert Case("grazing", (1,), None, group="tangent rays").hidden


def test_the_signature_and_the_cases_a_check_runs() -> None:
    exercise = get("ray_sphere")
    assert exercise.signature == f"{exercise.function}({', '.join(exercise.params)})"
    visible = exercise.cases()
    assert visible == list(exercise.visible) and all(not c.hidden for c in visible)
    every = exercise.cases(hidden=True)
    assert every[:len(visible)] == visible and len(every) > len(visible)
    assert all(c.hidden for c in every[len(visible):])
    assert exercise.returns in RESULT_KINDS


def test_expected_vectors_are_plain_floats() -> None:
    v = vec(np.array([1, 2, 3], dtype=np.float32))
    assert v == (1.0, 2.0, 3.0) and all(type(x) is float for x in v)
