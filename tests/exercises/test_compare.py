"""Judging an answer: its kind, NaN and wrong types in words, the case's tolerance, the other answers."""

from __future__ import annotations

import pytest

from glsandbox.exercises.compare import WrongType, describe, judge, matches, normalize
from glsandbox.exercises.definition import Case


@pytest.mark.parametrize(("value", "returns", "expected"), [
    (35, "t", 35.0), (None, "t", None), ([1, 2, 3], "vec3", (1.0, 2.0, 3.0)), (True, "bool", True),
    ([[1, 0, 0, 0]] * 4, "matrix4", ((1.0, 0.0, 0.0, 0.0),) * 4), (None, "vec3_or_none", None),
])
def test_answers_of_the_kind_are_taken(value, returns, expected) -> None:
    assert normalize(value, returns) == expected


@pytest.mark.parametrize(("value", "returns", "words"), [
    (float("nan"), "t", "nan"), ("35", "t", "the str '35'"), (True, "t", "the bool True"),
    ([1, 2], "vec3", "a list of 2"), (1, "bool", "True or False"), ({"__type__": "Foo", "repr": ""}, "t", "a Foo"),
    ([1, 2, float("nan")], "vec3", "nan"), (None, "vec3", "three numbers"),
])
def test_other_answers_say_what_they_are(value, returns, words) -> None:
    with pytest.raises(WrongType, match=words):
        normalize(value, returns)


def test_the_tolerance_is_relative_to_the_expected_value_plus_an_absolute_floor() -> None:
    assert matches(35.0 * (1 + 5e-10), 35.0, 1e-9, 0.0)
    assert not matches(35.0 * (1 + 5e-9), 35.0, 1e-9, 0.0)
    assert matches((0.0, 0.6 + 1e-12, -0.8), (0.0, 0.6, -0.8), 1e-9, 0.0)  # the vector's scale, not 0's
    assert not matches(None, 0.0, 1e-9, 1e-9) and matches(None, None, 0, 0)
    assert not matches(True, 1.0, 0, 0)


def test_a_case_with_a_margin_accepts_either_answer() -> None:
    case = Case("tangent", (), 100.0, also=(None,), margin="on the decision")
    assert judge(case, 100.0, "t") == (True, "")
    assert judge(case, None, "t") == (True, "")
    assert judge(case, 99.0, "t") == (False, "")
    assert judge(case, "x", "t")[0] is False and "str" in judge(case, "x", "t")[1]


def test_values_are_described_short() -> None:
    assert describe(35.0) == "35" and describe(None) == "None" and describe([0, 0.6, -0.8]) == "(0, 0.6, -0.8)"
    assert describe({"__type__": "Foo"}) == "<Foo>"
