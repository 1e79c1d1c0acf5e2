"""``glsandbox exercise list | start | check``: what a student types, and what it answers."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import SPHERE_ANSWER, assert_user_error, run_cli

from glsandbox.exercises import all_exercises
from glsandbox.exercises.states import STATE_EXERCISES

SPHERE = SPHERE_ANSWER


def test_list_gives_a_line_per_exercise_with_its_section_and_signature() -> None:
    run = run_cli("exercise", "list")
    assert run.returncode == 0
    lines = run.stdout.strip().splitlines()
    assert len(lines) == len(all_exercises()) + len(STATE_EXERCISES)
    for line, exercise in zip(lines, all_exercises(), strict=False):
        assert line.split()[0] == exercise.name
        assert exercise.section in line and line.endswith(exercise.signature)
    for line, state in zip(lines[len(all_exercises()):], STATE_EXERCISES.values(), strict=True):
        assert line.split()[0] == state.name and state.section in line and line.endswith(state.holds)


def test_start_writes_a_starter_that_fails_and_refuses_to_overwrite_it(tmp_path: Path) -> None:
    run = run_cli("exercise", "start", "ray_sphere", cwd=tmp_path)
    assert run.returncode == 0
    starter = tmp_path / "ray_sphere.py"
    text = starter.read_text()
    assert "def intersect_sphere(origin, direction, center, radius):" in text
    assert "#   intersect_sphere((0, 0, 0), (0, 0.6, 0.8), (0, 0, 100), 75) == 35.0" in text
    assert "Işın-Küre kesim testi" in text
    again = run_cli("exercise", "start", "ray_sphere", cwd=tmp_path)
    assert_user_error(again, "ray_sphere.py", "already exists", "not overwritten")
    assert starter.read_text() == text
    check = run_cli("exercise", "check", "ray_sphere", str(starter), "--no-lesson", cwd=tmp_path)
    assert check.returncode == 1
    assert "✗" in check.stdout and "✓" not in check.stdout and "NotImplementedError" in check.stdout


def test_start_with_out_and_an_unknown_exercise(tmp_path: Path) -> None:
    out = tmp_path / "mine.py"
    assert run_cli("exercise", "start", "reflect", "--out", str(out)).returncode == 0
    assert "def reflect(direction, normal):" in out.read_text()
    assert_user_error(run_cli("exercise", "start", "nope"), "no exercise 'nope'", "ray_sphere")
    assert_user_error(run_cli("exercise", "start", "reflect", "--out", str(tmp_path / "no" / "x.py")),
                      "does not exist")


def test_check_passes_a_right_function_with_exit_0_and_writes_the_pictures(tmp_path: Path) -> None:
    mine = tmp_path / "sphere.py"
    mine.write_text(SPHERE)
    run = run_cli("exercise", "check", "ray_sphere", str(mine))
    assert run.returncode == 0, run.stdout
    assert run.stdout.count("✓") == 4 and "✗" not in run.stdout
    assert "every visible case passes" in run.stdout
    probe = tmp_path / "sphere_check" / "ray_sphere_probe.png"
    lesson = tmp_path / "sphere_check" / "ray_sphere_lesson.png"
    assert probe.is_file() and lesson.is_file()
    assert f"probe picture: {probe}" in run.stdout
    assert "100.0% agree" in run.stdout and "0 of 14,400 pixels differ" in run.stdout


def test_check_names_the_mistake_and_exits_1(tmp_path: Path) -> None:
    mine = tmp_path / "far.py"
    mine.write_text(SPHERE.replace("s - q", "s + q"))
    run = run_cli("exercise", "check", "ray_sphere", str(mine), "--no-lesson")
    assert run.returncode == 1
    assert "hint: your function returns the far intersection" in run.stdout
    assert "expected 35" in run.stdout and "got 125" in run.stdout


def test_check_with_html_writes_a_page_and_its_pictures_beside_it(tmp_path: Path) -> None:
    mine = tmp_path / "far.py"
    mine.write_text(SPHERE.replace("s - q", "s + q"))
    page = tmp_path / "report.html"
    run = run_cli("exercise", "check", "ray_sphere", str(mine), "--html", str(page), "--no-lesson")
    assert run.returncode == 1
    html = page.read_text()
    assert "far intersection" in html and "data:image/png;base64," in html and "<table" in html
    assert (tmp_path / "report_pictures" / "ray_sphere_probe.png").is_file()


@pytest.mark.parametrize(("body", "fragments"), [
    ("def intersect_sphere(o, d, c, r)\n    return 1\n", ("bad.py:1:", "syntax error")),
    ("def something_else(o, d, c, r):\n    return 1\n", ("bad.py:1:", "defines no function intersect_sphere()")),
    ("x = 1\n\n\ndef intersect_sphere(o, d):\n    return 1\n",
     ("bad.py:4:", "takes 2 parameters", "intersect_sphere(origin, direction, center, radius)")),
])
def test_check_refuses_a_file_that_is_not_the_function_with_one_error_line(tmp_path: Path, body: str,
                                                                         fragments: tuple[str, ...]) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text(body)
    run = run_cli("exercise", "check", "ray_sphere", str(bad), unchanged=tmp_path)
    assert_user_error(run, *fragments)


def test_check_of_a_missing_file_or_exercise_is_one_error_line(tmp_path: Path) -> None:
    assert_user_error(run_cli("exercise", "check", "ray_sphere", str(tmp_path / "none.py")), "no such file")
    (tmp_path / "a.py").write_text("def f():\n    pass\n")
    assert_user_error(run_cli("exercise", "check", "nope", str(tmp_path / "a.py")), "no exercise 'nope'")
