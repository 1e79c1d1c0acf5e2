"""The checker: a plain record of cases and groups, the named mistakes, the notebook's report."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import glsandbox
from glsandbox.errors import SandboxError
from glsandbox.exercises import get
from glsandbox.exercises.check import check_function, static_check


def far_and_behind(origin, direction, center, radius):
    """Two mistakes at once: the far root, and no test for a sphere behind."""
    l = [c - o for c, o in zip(center, origin)]  # noqa: E741
    s = sum(a * b for a, b in zip(l, direction))
    m2 = sum(a * a for a in l) - s * s
    if m2 > radius * radius:
        return None
    return s + math.sqrt(radius * radius - m2)  # s + q from outside too, and even when t < 0


def test_the_result_is_a_plain_record_with_groups_ready_for_points() -> None:
    exercise = get("ray_sphere")
    result = check_function(exercise, exercise.reference, hidden=True, probe_size=32)
    data = json.loads(json.dumps(result.to_dict()))
    assert data["visible_passed"] is True
    assert data["groups"]["visible"] == {"passed": 4, "total": 4}
    assert set(data["groups"]) == {c.group for c in exercise.cases(hidden=True)}
    assert sum(g["total"] for g in data["groups"].values()) == len(data["cases"])
    assert data["probe"]["counts"]["agree"] > 0 and data["mistakes"] == []


def test_hidden_cases_are_left_out_unless_asked() -> None:
    exercise = get("ray_sphere")
    result = check_function(exercise, exercise.reference, probe=False)
    assert {c.group for c in result.cases} == {"visible"}


def test_the_mistake_whose_answers_are_the_students_is_named_first() -> None:
    exercise = get("ray_sphere")
    result = check_function(exercise, far_and_behind, hidden=True, probe_size=64)
    assert result.mistakes[0] == "far_root"
    assert result.hints[0].startswith("your function returns the far intersection")


def test_a_right_answer_names_no_mistake_even_where_a_mistake_is_right_too() -> None:
    exercise = get("shadow")
    result = check_function(exercise, exercise.reference, hidden=True, probe_size=32)
    assert all(c.passed for c in result.cases) and result.mistakes == []


@pytest.mark.parametrize(("body", "fragment"), [
    ("intersect_sphere = lambda o, d, c, r: None\n", None),
    ("def intersect_sphere(o, d, c, r, extra=1):\n    return None\n", None),
    ("def intersect_sphere(*args):\n    return None\n", None),
    ("def intersect_sphere(o, d, c, r, e):\n    return None\n", "takes 5 parameters"),
    ("def intersect_sphere(o, d, c, r):\n\treturn None\n  x\n", "syntax error"),
    ("\xff\xfe", "cannot be read"),
])
def test_the_files_shape_is_checked_before_it_runs(tmp_path: Path, body: str, fragment: str | None) -> None:
    path = tmp_path / "mine.py"
    path.write_bytes(body.encode("latin-1"))
    if fragment is None:
        static_check(path, get("ray_sphere"))
    else:
        with pytest.raises(SandboxError, match=fragment):
            static_check(path, get("ray_sphere"))


def test_the_notebook_shows_the_table_and_pictures_inline_without_hidden_cases() -> None:
    exercise = get("ray_sphere")
    wrong = next(m.function for m in exercise.mistakes if m.name == "far_root")
    report = glsandbox.exercise("ray_sphere", wrong)
    html = report._repr_html_()
    assert not report.passed
    assert "<table" in html and "far intersection" in html and html.count("data:image/png;base64,") == 2
    assert "inside" not in {c.group for c in report.result.cases}
    assert "✗" in repr(report)
    with pytest.raises(SandboxError, match="expected a function"):
        glsandbox.exercise("ray_sphere", 3)


def test_a_check_pauses_the_cycle_collector_and_puts_it_back_as_it_was() -> None:
    import gc

    exercise = get("reflect")
    seen = []
    function = lambda d, n: seen.append(gc.isenabled()) or exercise.reference(d, n)  # noqa: E731
    assert gc.isenabled()
    check_function(exercise, function, probe=False)
    assert seen and not any(seen) and gc.isenabled()
    gc.disable()
    try:
        check_function(exercise, function, probe=False)
        assert not gc.isenabled()
    finally:
        gc.enable()
