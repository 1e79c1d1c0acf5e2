"""Every exercise in the catalogue (glsandbox/exercises/catalogue/, one module each): its reference
passes its cases, its starter and each of its named mistakes fail, the mistakes are told apart by
their probe pictures, and the catalogue lists every module of its folder."""

from __future__ import annotations

import itertools
import pkgutil
from pathlib import Path

import numpy as np
import pytest

from glsandbox.exercises import all_exercises, catalogue, get
from glsandbox.exercises.catalogue import MODULES
from glsandbox.exercises.check import PASS, check_function
from glsandbox.exercises.compare import judge
from glsandbox.exercises.isolation import InProcess
from glsandbox.exercises.probe import picture, reference_values
from glsandbox.exercises.starter import starter

NAMES = list(MODULES)
#: Probes are compared at this size in the tests (each mistake runs over the whole field).
PROBE = 48


def _plain(value):
    from glsandbox.exercises import student_process

    return student_process._encode(value)


@pytest.mark.parametrize("name", NAMES)
def test_the_reference_passes_every_case_of_its_exercise(name: str) -> None:
    exercise = get(name)
    cases = exercise.cases(hidden=True)
    assert len(exercise.visible) >= 1 and len(cases) > len(exercise.visible)
    for case in cases:
        passed, note = judge(case, _plain(exercise.reference(*case.args)), exercise.returns)
        assert passed, (case.name, exercise.reference(*case.args), case.expected, note)


@pytest.mark.parametrize("name", NAMES)
def test_hidden_cases_are_the_same_every_time_and_state_why_when_two_answers_pass(name: str) -> None:
    exercise = get(name)
    assert exercise.hidden() == exercise.hidden()
    for case in exercise.hidden():
        assert case.group != "visible"
        assert bool(case.also) == bool(case.margin), case.name


@pytest.mark.parametrize("name", NAMES)
def test_the_starter_fails_every_visible_case(name: str) -> None:
    exercise = get(name)
    namespace: dict = {}
    exec(compile(starter(exercise), "starter.py", "exec"), namespace)  # noqa: S102 - our own text
    result = check_function(exercise, namespace[exercise.function], probe=False)
    assert result.cases and not any(c.passed for c in result.cases)
    assert not result.visible_passed


@pytest.mark.parametrize("name", NAMES)
def test_every_named_mistake_fails_a_hidden_case_and_is_named_by_its_own_failures(name: str) -> None:
    exercise = get(name)
    for mistake in exercise.mistakes:
        result = check_function(exercise, mistake.function, hidden=True, probe_size=PROBE)
        failed = [c for c in result.cases if c.group != "visible" and c.status != PASS]
        assert failed, f"{mistake.name} passes every hidden case of {name}"
        assert result.mistakes[:1] == [mistake.name], (mistake.name, result.mistakes)
        assert mistake.hint.endswith(".") and len(mistake.hint) < 260  # one sentence


@pytest.mark.parametrize("name", NAMES)
def test_the_named_mistakes_probe_pictures_differ_pairwise_and_from_the_reference(name: str) -> None:
    exercise = get(name)
    inputs = exercise.probe.inputs(PROBE)
    reference = reference_values(exercise, inputs)
    pictures = {"reference": picture(exercise, reference, reference, {}, PROBE)[1]}
    for mistake in exercise.mistakes:
        values, errors = InProcess(mistake.function).batch(inputs)
        pictures[mistake.name] = picture(exercise, reference, values, errors, PROBE)[1]
    for (a, pa), (b, pb) in itertools.combinations(pictures.items(), 2):
        assert not np.array_equal(pa, pb), f"{name}: the probes of {a} and {b} are the same picture"


@pytest.mark.parametrize("name", NAMES)
def test_the_worked_example_in_the_docstring_is_what_the_reference_gives(name: str) -> None:
    exercise = get(name)
    assert eval(exercise.example, {exercise.function: exercise.reference})  # noqa: S307 - our own text
    assert exercise.section in exercise.doc and exercise.term
    assert exercise.signature.startswith(f"{exercise.function}(")


@pytest.mark.parametrize("name", NAMES)
def test_correct_variants_pass_every_case(name: str) -> None:
    exercise = get(name)
    for variant, function in exercise.extra.get("variants", {}).items():
        result = check_function(exercise, function, hidden=True, probe_size=PROBE)
        assert all(c.passed for c in result.cases), (variant, [c for c in result.cases if not c.passed])
        assert result.probe.agrees and not result.mistakes, variant


def test_the_catalogue_lists_every_exercise_once_in_course_order() -> None:
    folder = Path(catalogue.__file__).parent  # (tests/test_suite.py counts a listed module as tested here)
    assert sorted(NAMES) == sorted(m.name for m in pkgutil.iter_modules([str(folder)])), "list it in MODULES"
    exercises = all_exercises()
    assert [e.name for e in exercises] == NAMES
    assert len({e.function for e in exercises}) == len(exercises)
