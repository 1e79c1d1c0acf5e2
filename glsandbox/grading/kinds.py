"""The kinds of check a rubric may hold, in one registry: a new kind is one :func:`register_kind`.

A kind names the ``[[check]]`` keys it reads besides the common ones
(``name``, ``points``, ``hidden``, ``kind``) and judges what a submission
sent back for one check. ``picture``: a rendered image
against a reference PNG, by the golden rule (:func:`glsandbox.measure.golden.compare_images`);
``exercise``: a student's function against an exercise's cases (:mod:`glsandbox.grading.exercise`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from glsandbox.measure.golden import ImageMatch, compare_images

#: A rubric's check (:class:`glsandbox.grading.rubric.Check`, which imports this module).
Check = Any

__all__ = ["CheckKind", "Verdict", "KINDS", "register_kind", "kind_of", "known"]

#: The keys every kind accepts.
COMMON_KEYS = frozenset({"name", "points", "hidden", "kind"})


@dataclass(frozen=True)
class Verdict:
    """A kind's judgement of one check: passed or not, and the comparison's figures when there are any
    (a failed comparison's pictures are then written by the grader)."""

    passed: bool
    match: ImageMatch | None = None
    detail: str = ""


@dataclass(frozen=True)
class CheckKind:
    """One kind of check: its name in a rubric, the keys it reads, and its judge.

    ``judge(check, image, expected)`` judges what the submission sent back
    for ``check`` against the reference the grader read for it (a picture's
    judge is also given ``margin=``, the reference's, where it has one).
    """

    name: str
    keys: frozenset[str]
    judge: Callable[..., Verdict]
    summary: str = ""


#: Every kind, by name (``kind = "..."`` in a ``[[check]]``; ``picture`` when left out).
KINDS: dict[str, CheckKind] = {}


def register_kind(kind: CheckKind) -> CheckKind:
    """Add ``kind`` to :data:`KINDS` (a second kind of the same name replaces the first)."""
    KINDS[kind.name] = kind
    return kind


def kind_of(name: str) -> CheckKind:
    """The kind called ``name``; KeyError when there is none (:func:`known` lists them)."""
    return KINDS[name]


def known() -> list[str]:
    """The names of every kind, sorted."""
    return sorted(KINDS)


def judge_picture(check: Check, image: np.ndarray, expected: np.ndarray,
                  margin: np.ndarray | None = None) -> Verdict:
    """The ``picture`` kind: the rendered image against the reference by the check's tolerances,
    and the reference's per-pixel ``margin`` (:mod:`glsandbox.measure.margin`) when it has one."""
    match = compare_images(image, expected, **check.tolerances, margin=margin)
    return Verdict(match.passed, match)


def judge_exercise(check: Check, image: np.ndarray, expected: np.ndarray) -> Verdict:
    """The ``exercise`` kind is graded case by case (:mod:`glsandbox.grading.exercise`), not by a picture."""
    raise TypeError(f"check {check.name!r} is an exercise: glsandbox.grading.exercise grades it")


register_kind(CheckKind("exercise", frozenset({"exercise"}), judge_exercise,
                        "a student's function against an exercise's cases, points per case group"))
register_kind(CheckKind("picture", frozenset({"golden", "set", "size", "samples", "renderer", "tolerance"}),
                        judge_picture, "a rendered picture against a reference PNG"))
