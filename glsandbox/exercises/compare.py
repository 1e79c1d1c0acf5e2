"""Judging one answer against the expected one, with the tolerance its case states.

An answer comes back from the student's process as JSON (see
:mod:`glsandbox.exercises.student_process`): numbers, ``null``, ``true``/``false``,
lists, or ``{"__type__": ..., "repr": ...}`` for anything else. :func:`normalize`
turns it into the exercise's kind of value or says, in words, why it is not
one (the wrong type, a NaN, a vector of four); :func:`matches` compares.
"""

from __future__ import annotations

import math
from typing import Any

from glsandbox.exercises.definition import Case

__all__ = ["normalize", "matches", "judge", "describe"]


class WrongType(Exception):
    """The answer is not a value of the exercise's kind: the message says what it is."""


def _what(value: Any) -> str:
    if isinstance(value, dict) and "__type__" in value:
        return f"a {value['__type__']} ({str(value.get('repr', ''))[:40]})"
    if isinstance(value, bool):
        return f"the bool {value}"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if isinstance(value, str):
        return f"the str {value[:40]!r}"
    return f"{value!r}"[:60]


def _number(value: Any, kind: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise WrongType(f"returned {_what(value)}, expected {kind}")
    number = float(value)
    if math.isnan(number):
        raise WrongType("returned nan (a 0/0 or a sqrt of a negative somewhere?)")
    return number


def _vector(value: Any, size: int, kind: str) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != size:
        raise WrongType(f"returned {_what(value)}, expected {kind}")
    return tuple(_number(v, kind) for v in value)


def normalize(value: Any, returns: str) -> Any:
    """``value`` as the exercise's kind (``returns``, one of :data:`RESULT_KINDS`); raises
    :class:`WrongType` with a sentence when it is not one."""
    if returns == "t":
        return None if value is None else _number(value, "a number t > 0 or None")
    if returns == "number":
        return _number(value, "a number")
    if returns == "bool":
        if not isinstance(value, bool):
            raise WrongType(f"returned {_what(value)}, expected True or False")
        return value
    if returns == "vec3":
        return _vector(value, 3, "three numbers (x, y, z)")
    if returns == "vec3_or_none":
        return None if value is None else _vector(value, 3, "three numbers or None")
    if returns == "matrix4":
        if not isinstance(value, list) or len(value) != 4:
            raise WrongType(f"returned {_what(value)}, expected a 4x4 matrix (four rows of four)")
        return tuple(_vector(row, 4, "a 4x4 matrix (four rows of four)") for row in value)
    if returns == "indices":
        return _indices(value)
    raise ValueError(f"unknown result kind {returns!r}")


def _indices(value: Any) -> tuple[tuple[int, int, int], ...]:
    """An index buffer as its triangles, each turned to start at its smallest index (the same
    triangle, the same winding) and sorted: two buffers listing the same triangles agree."""
    kind = "a list of whole numbers >= 0, three per triangle"
    if not isinstance(value, list) or len(value) % 3:
        raise WrongType(f"returned {_what(value)}, expected {kind}")
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int) or v < 0:
            raise WrongType(f"returned an index {_what(v)}, expected {kind}")
    triangles = []
    for i in range(0, len(value), 3):
        a, b, c = value[i:i + 3]
        first = min(range(3), key=lambda k: (a, b, c)[k])
        triangles.append(((a, b, c) * 2)[first:first + 3])
    return tuple(sorted(triangles))


def _flat(value: Any) -> list[float]:
    if isinstance(value, (tuple, list)):
        return [x for v in value for x in _flat(v)]
    return [float(value)]


def matches(got: Any, expected: Any, rel: float, abs_: float) -> bool:
    """Whether two normalized values agree within ``abs_ + rel·|expected|`` (or, for an expected
    value that judges answers itself, whether it ``accepts`` ``got``)."""
    if hasattr(expected, "accepts"):
        return bool(expected.accepts(got))
    if expected is None or got is None or isinstance(expected, bool) or isinstance(got, bool):
        return got == expected and type(got) is type(expected)
    g, e = _flat(got), _flat(expected)
    if len(g) != len(e):
        return False
    scale = max(abs(x) for x in e) if e else 0.0
    bound = abs_ + rel * scale
    for a, b in zip(g, e, strict=True):
        if math.isinf(b) or math.isinf(a):
            if a != b:
                return False
        elif not abs(a - b) <= bound:
            return False
    return True


def judge(case: Case, value: Any, returns: str) -> tuple[bool, str]:
    """(passed, note): the note says why an answer of the wrong type fails, else is empty."""
    try:
        got = normalize(value, returns)
    except WrongType as exc:
        return False, str(exc)
    for expected in (case.expected, *case.also):
        if matches(got, expected, case.rel, case.abs):
            return True, ""
    return False, ""


def describe(value: Any) -> str:
    """A short text of a value for the table: ``35``, ``None``, ``(0, 0.6, -0.8)``."""
    if isinstance(value, dict) and "__type__" in value:
        return f"<{value['__type__']}>"
    if value is None or isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value) or math.isinf(value):
            return str(value)
        return f"{value:.6g}"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, (list, tuple)):
        inner = ", ".join(describe(v) for v in value)
        return f"({inner})" if len(inner) < 120 else f"({inner[:117]}...)"
    if isinstance(value, str):
        return repr(value[:40])
    return repr(value)[:60]
