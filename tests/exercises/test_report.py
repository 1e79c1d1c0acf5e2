"""A check's report (glsandbox/exercises/report.py): the terminal's lines per case group, the HTML
fragment with its pictures inline and everything the student's code sent escaped, the pictures
written beside the file. On ray_sphere, checked in this process."""

from __future__ import annotations

from pathlib import Path

import pytest

from glsandbox.exercises import get, report
from glsandbox.exercises.check import check_function
from glsandbox.files import load_png


@pytest.fixture(scope="module")
def right():
    exercise = get("ray_sphere")
    return check_function(exercise, exercise.reference, hidden=True, probe_size=32)


@pytest.fixture(scope="module")
def wrong():
    def intersect_sphere(*args):
        return "nope"  # a str: the report says "<str>", escaped in the HTML

    return check_function(get("ray_sphere"), intersect_sphere, hidden=True, probe_size=32)


def test_the_terminal_report_counts_each_group_and_marks_each_case(right, wrong) -> None:
    lines = report.text(right).splitlines()
    assert lines[0] == f"ray_sphere: {right.signature}"
    groups = [line.strip() for line in lines if line.strip().endswith(" pass")]
    assert groups and all(line.split()[2] == line.split()[4] for line in groups)  # N of N pass
    assert sum(line.startswith("    ✓ ") for line in lines) == len(right.cases)
    bad = report.text(wrong).splitlines()
    assert sum(line.startswith("    ✗ ") for line in bad) == len(wrong.cases)
    visible_only = report.text(wrong, hidden_shown=False)
    assert "visible cases:" in visible_only and len(visible_only.splitlines()) < len(bad)


def test_the_html_escapes_what_the_student_sent_and_inlines_the_probe(wrong) -> None:
    page = report.html(wrong)
    assert wrong.cases[0].got == "<str>" and "<code>&lt;str&gt;</code>" in page and "<str>" not in page
    assert page.count("<tr>") == len(wrong.cases) + 1  # a row per case under the header
    assert ('<img alt="probe" src="data:image/png;base64,' in page) == ("probe" in report.pictures_of(wrong))


def test_the_pictures_are_written_and_named_in_the_report(wrong, tmp_path: Path) -> None:
    report.write_pictures(wrong, tmp_path / "out")
    for name, image in report.pictures_of(wrong).items():
        path = tmp_path / "out" / f"ray_sphere_{name}.png"
        assert wrong.pictures[name] == str(path) and (load_png(path) == image).all()
        assert f"  {name} picture: {path}" in report.text(wrong)
    report.write_html(wrong, tmp_path / "r.html")
    assert (tmp_path / "r.html").read_text(encoding="utf-8").startswith("<!doctype html><meta charset=utf-8>")
