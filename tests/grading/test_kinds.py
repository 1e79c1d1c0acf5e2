"""The kinds of check a rubric may hold (glsandbox/grading/kinds.py): the registry, and the
``picture`` kind's judge by the golden rule. (A new kind read from a rubric: test_rubric.py.)"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from glsandbox.grading import kinds
from glsandbox.grading.kinds import COMMON_KEYS, KINDS, CheckKind, Verdict, kind_of, known, register_kind


def test_the_built_in_kinds_are_picture_and_exercise() -> None:
    assert {"picture", "exercise"} <= set(known()) and known() == sorted(KINDS)
    assert kind_of("picture").keys >= {"golden", "tolerance", "size"} and kind_of("exercise").keys == {"exercise"}
    assert not any(kind.keys & COMMON_KEYS for kind in KINDS.values())  # a kind's own keys only
    with pytest.raises(KeyError):
        kind_of("no_such_kind")


def test_a_second_kind_of_a_name_replaces_the_first(monkeypatch) -> None:
    monkeypatch.setattr(kinds, "KINDS", dict(KINDS))
    first = register_kind(CheckKind("mine", frozenset(), lambda c, i, e: Verdict(True)))
    assert kinds.kind_of("mine") is first
    second = register_kind(CheckKind("mine", frozenset({"x"}), lambda c, i, e: Verdict(False)))
    assert kinds.kind_of("mine") is second and kinds.known().count("mine") == 1


def _check(**tolerances) -> SimpleNamespace:
    return SimpleNamespace(name="spin", kind="picture", tolerances=tolerances)


def test_a_picture_passes_within_its_tolerances_and_fails_past_them() -> None:
    expected = np.full((4, 4, 4), 100, dtype=np.uint8)
    near = expected.copy()
    near[0, 0, 0] += 20  # one channel of one pixel off by 20 levels
    judge = kind_of("picture").judge
    same = judge(_check(), expected.copy(), expected)
    assert same.passed and same.match is not None and same.match.passed
    assert not judge(_check(threshold=10, max_bad_share=0.0), near, expected).passed
    assert judge(_check(threshold=25, max_bad_share=0.0), near, expected).passed
    assert judge(_check(threshold=10, max_bad_share=1 / 16), near, expected).passed  # 1 pixel of 16 may be off


def test_an_exercise_is_never_judged_by_a_picture() -> None:
    with pytest.raises(TypeError, match="check 'spin' is an exercise"):
        kind_of("exercise").judge(_check(), np.zeros((1, 1, 4), np.uint8), np.zeros((1, 1, 4), np.uint8))
