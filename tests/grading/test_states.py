"""A state exercise graded for a class (glsandbox.grading.states): ``check DIR --exercise mirror_states``
and a rubric's ``exercise = "mirror_states"`` with points per leak kind."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from support import glsandbox

from glsandbox.errors import SandboxError
from glsandbox.exercises.states.mirror import REFERENCE_SOURCE, starter
from glsandbox.grading.rubric import load_rubric
from glsandbox.grading.states import find_tables, groups_of

KINDS = list(groups_of("mirror_states").values())

#: Two of the named mistakes, each leaking as one kind.
ALWAYS = REFERENCE_SOURCE.replace('"StencilFunc": "D3D11_COMPARISON_EQUAL",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP",',
                                  '"StencilFunc": "D3D11_COMPARISON_ALWAYS",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP",')
TWICE = REFERENCE_SOURCE.replace('"StencilPassOp": "D3D11_STENCIL_OP_INCR"', '"StencilPassOp": "D3D11_STENCIL_OP_KEEP"')

RUBRIC = """\
[[check]]
exercise = "mirror_states"
name = "mirror"
points = { reflection_outside = 2, shadow_twice = 1, hidden = 0.5 }
"""


def _class(folder: Path) -> Path:
    assert ALWAYS != REFERENCE_SOURCE and TWICE != REFERENCE_SOURCE
    folder.mkdir()
    (folder / "right.py").write_text(REFERENCE_SOURCE)
    (folder / "always.py").write_text(ALWAYS)
    (folder / "twice.py").write_text(TWICE)
    (folder / "blank.py").write_text(starter())
    (folder / "code.py").write_text("import os\nMARK_MIRROR_DSS = os.getcwd()\n")
    helped = folder / "helped"  # a student's folder: the file assigning the tables is the one graded
    helped.mkdir()
    (helped / "notes.py").write_text("print('my notes')\n")
    (helped / "tables.py").write_text(REFERENCE_SOURCE)
    (folder / "linked.py").symlink_to(folder / "right.py")
    return folder


def test_points_per_leak_kind_are_read(tmp_path: Path) -> None:
    path = tmp_path / "grading.toml"
    path.write_text(RUBRIC)
    (check,) = load_rubric(path).checks
    assert check.kind == "exercise" and check.exercise == "mirror_states"
    assert [g for g, _ in check.group_points] == KINDS
    points = dict(check.group_points)
    assert points["reflection_outside"] == 2 and points["shadow_twice"] == 1 and points["other"] == pytest.approx(0.125)
    path.write_text('[[check]]\nexercise = "mirror_states"\npoints = { stencil = 1 }\n')
    with pytest.raises(SandboxError, match="points.stencil: no case group 'stencil'"):
        load_rubric(path)


def test_the_tables_file_of_a_students_folder(tmp_path: Path) -> None:
    folder = _class(tmp_path / "class")
    assert find_tables(folder / "helped") == folder / "helped" / "tables.py"
    (folder / "helped" / "more.py").write_text(REFERENCE_SOURCE)
    with pytest.raises(SandboxError, match="several .py file assigning MARK_MIRROR_DSS"):
        find_tables(folder / "helped")


def test_a_class_graded_by_a_rubric_with_points_per_leak_kind(tmp_path: Path, gl) -> None:
    folder = _class(tmp_path / "class")
    rubric = tmp_path / "mirror.grading.toml"
    rubric.write_text(RUBRIC)
    data, gs = tmp_path / "marks.json", tmp_path / "results.json"
    proc = glsandbox("check", str(folder), "--rubric", str(rubric), "--json", str(data), "--gradescope", str(gs),
                     cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    marks = {s["name"]: s for s in json.loads(data.read_text())["submissions"]}
    assert {n: s["status"] for n, s in marks.items()} == {
        "right.py": "PASS", "helped": "PASS", "always.py": "FAIL", "twice.py": "FAIL", "blank.py": "BROKEN",
        "code.py": "BROKEN", "linked.py": "BROKEN"}
    full = 2 + 1 + 0.5
    assert marks["right.py"]["score"] == pytest.approx(full) and marks["right.py"]["total"] == pytest.approx(full)
    assert marks["always.py"]["score"] == pytest.approx(full - 2)  # the reflection outside the mirror
    assert marks["twice.py"]["score"] == pytest.approx(full - 1)  # the shadow blended twice
    always = {c["check"]: c for c in marks["always.py"]["checks"]}
    assert always["mirror: reflection_outside"]["status"] == "FAIL"
    assert "hint (stencil_always" in always["mirror: reflection_outside"]["error"]
    assert all(c["status"] == "PASS" for n, c in always.items() if n != "mirror: reflection_outside")
    assert "left blank" in marks["blank.py"]["checks"][0]["error"]
    assert "only assignments" in marks["code.py"]["checks"][0]["error"]  # read as data, never run
    assert "is a link" in marks["linked.py"]["checks"][0]["error"]
    tests = {t["name"]: t for t in json.loads(gs.read_text())["tests"]}
    assert len(tests) == len(marks) * len(KINDS)
    assert tests["twice.py: mirror: shadow_twice"]["max_score"] == 1 and tests["twice.py: mirror: shadow_twice"]["score"] == 0


def test_check_exercise_mirror_states_without_a_rubric(tmp_path: Path, gl) -> None:
    folder = _class(tmp_path / "class")
    proc = glsandbox("check", str(folder), "--exercise", "mirror_states", cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    table = proc.stdout.split("\n\n")[-1]
    assert "right.py" in table and "6/6" in table and "5/6" in table and "0/6" in table
    one = glsandbox("check", str(folder / "right.py"), "--exercise", "mirror_states", cwd=tmp_path)
    assert one.returncode == 0 and "6/6 points" in one.stdout, one.stdout + one.stderr
    wrong = glsandbox("check", str(folder / "twice.py"), "--exercise", "mirror_states", cwd=tmp_path)
    assert wrong.returncode == 1 and "FAIL    mirror_states: shadow_twice" in wrong.stdout, wrong.stdout
    bad = glsandbox("check", str(folder / "code.py"), "--exercise", "mirror_states", cwd=tmp_path)
    assert bad.returncode == 2 and bad.stderr.startswith("error: ") and bad.stderr.count("\n") == 1, bad.stderr
