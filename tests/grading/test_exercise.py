"""Grading students' functions: a rubric's ``exercise`` checks and ``check DIR --exercise NAME``."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest
from support import SPHERE_ANSWER, glsandbox

from glsandbox.errors import SandboxError
from glsandbox.exercises.catalogue import get
from glsandbox.exercises.compare import describe
from glsandbox.grading.rubric import load_rubric

RIGHT = SPHERE_ANSWER

#: The named mistake ``far_root``: s + q from outside too.
WRONG = RIGHT.replace("return None if s < 0 else s - q", "return None if s < 0 else s + q")

BROKEN = "def intersect_sphere(origin, direction, center, radius)\n    return 1\n"

LOOP = "def intersect_sphere(origin, direction, center, radius):\n    while True:\n        pass\n"

RUBRIC = """\
[[check]]
exercise = "ray_sphere"
name = "sphere"
points = { visible = 2, hidden = 3 }
"""

GROUPS = ["visible", "inside", "behind", "edge", "surface", "scale"]


def _class(folder: Path) -> Path:
    folder.mkdir()
    (folder / "right.py").write_text(RIGHT)
    (folder / "wrong.py").write_text(WRONG)
    (folder / "broken.py").write_text(BROKEN)
    (folder / "loop.py").write_text(LOOP)
    reference = Path(get("ray_sphere").reference.__code__.co_filename)
    (folder / "reader.py").write_text(textwrap.dedent(f"""\
        def intersect_sphere(origin, direction, center, radius):
            source = open({str(reference)!r}).read()   # the reference's own file
            return 35.0 if "def reference" in source else None
        """))
    helper = folder / "helped"  # a student's folder: the file defining the function is the one graded
    helper.mkdir()
    (helper / "scratch.py").write_text("print('my notes')\n")
    (helper / "sphere.py").write_text(RIGHT)
    return folder


def test_points_per_group_are_read_and_split(tmp_path: Path) -> None:
    path = tmp_path / "grading.toml"
    path.write_text(RUBRIC + '\n[[check]]\nexercise = "ray_sphere"\nname = "even"\npoints = 12\n')
    sphere, even = load_rubric(path).checks
    assert sphere.kind == "exercise" and sphere.exercise == "ray_sphere"
    assert [g for g, _ in sphere.group_points] == GROUPS
    assert dict(sphere.group_points) == pytest.approx({"visible": 2, **{g: 0.6 for g in GROUPS[1:]}})
    assert sphere.points == pytest.approx(5.0)
    assert dict(even.group_points) == pytest.approx({g: 2.0 for g in GROUPS})


@pytest.mark.parametrize("body, fragment", [
    ('exercise = "ray_cube"\n', "check 1: exercise = 'ray_cube': expected one of"),
    ('exercise = "ray_sphere"\npoints = { outside = 1 }\n', "check 'ray_sphere': points.outside: no case group"),
    ('exercise = "ray_sphere"\npoints = { visible = -1 }\n', "check 'ray_sphere': points.visible = -1"),
    ('exercise = "ray_sphere"\npoints = "all"\n', "check 'ray_sphere': points = 'all'"),
    ('exercise = "ray_sphere"\ngolden = "a.png"\n', "unknown key 'golden'"),
    ('kind = "exercise"\n', "check 1: exercise = None"),
])
def test_exercise_check_mistakes_are_one_line(tmp_path: Path, body: str, fragment: str) -> None:
    path = tmp_path / "grading.toml"
    path.write_text("[[check]]\n" + body)
    with pytest.raises(SandboxError) as error:
        load_rubric(path)
    message = str(error.value)
    assert message.startswith(str(path)) and fragment in message and "\n" not in message, message


def test_a_class_graded_by_a_rubric_with_points_per_group(tmp_path: Path) -> None:
    folder = _class(tmp_path / "class")
    rubric = tmp_path / "sphere.grading.toml"
    rubric.write_text(RUBRIC)
    gs, data = tmp_path / "results.json", tmp_path / "marks.json"
    proc = glsandbox("check", str(folder), "--rubric", str(rubric), "--timeout", "1", "--jobs", "2",
                     "--gradescope", str(gs), "--json", str(data), cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr  # not everyone passed
    marks = {s["name"]: s for s in json.loads(data.read_text())["submissions"]}
    assert {n: marks[n]["status"] for n in marks} == {
        "right.py": "PASS", "helped": "PASS", "wrong.py": "FAIL", "broken.py": "BROKEN", "loop.py": "TIMEOUT",
        "reader.py": "BROKEN"}
    assert marks["right.py"]["score"] == pytest.approx(5.0) and marks["right.py"]["total"] == pytest.approx(5.0)
    # far_root is wrong from outside: the notes' examples (2 points) and the scale group (0.6) lost
    assert marks["wrong.py"]["score"] == pytest.approx(5.0 - 2.0 - 0.6)
    assert all(marks[n]["score"] == 0 for n in ("broken.py", "loop.py", "reader.py"))
    wrong = {c["check"]: c for c in marks["wrong.py"]["checks"]}
    assert "hint (far_root)" in wrong["sphere: visible"]["error"]  # the teacher's report names the mistake
    assert any(c["expected"] == "35" and c["got"] == "125" for c in wrong["sphere: scale"]["cases"])
    assert "syntax error" in marks["broken.py"]["checks"][0]["error"]
    assert "Permission" in marks["reader.py"]["checks"][0]["error"] or "denied" in marks["reader.py"]["checks"][0]["error"]

    report = json.loads(gs.read_text())
    tests = {t["name"]: t for t in report["tests"]}
    assert len(tests) == 6 * len(GROUPS)  # one test per submission and case group
    for name in marks:
        for group in GROUPS:
            test = tests[f"{name}: sphere: {group}"]
            assert test["visibility"] == ("visible" if group == "visible" else "after_published")
    assert tests["wrong.py: sphere: visible"]["max_score"] == 2 and "expected 35" in tests["wrong.py: sphere: visible"]["output"]
    scale = tests["wrong.py: sphere: scale"]
    assert scale["score"] == 0 and scale["status"] == "failed" and scale["max_score"] == pytest.approx(0.6)
    hidden_values = {f"expected {describe(c.expected)}" for c in get("ray_sphere").cases(True) if c.group != "visible"}
    for test in report["tests"]:
        if test["visibility"] == "after_published":  # neither an expected value nor the answers given
            assert not any(v in test["output"] for v in hidden_values) and " gave " not in test["output"], test
    assert scale["output"] == "FAIL: 0/2 cases passed; FAIL far from the world's origin (1e5); FAIL a tiny scene (1e-4)"


def test_check_exercise_without_a_rubric(tmp_path: Path) -> None:
    folder = _class(tmp_path / "class")
    (folder / "loop.py").unlink()
    (folder / "reader.py").unlink()
    proc = glsandbox("check", str(folder), "--exercise", "ray_sphere", cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr
    table = proc.stdout.split("\n\n")[-1]
    assert "right.py" in table and "6/6" in table and "4/6" in table and "0/6" in table
    assert "1 failed, 1 broken" in table and "2 passed" in table


def test_check_one_file_exercise_exit_codes(tmp_path: Path) -> None:
    for name, text in (("right.py", RIGHT), ("wrong.py", WRONG), ("broken.py", BROKEN)):
        (tmp_path / name).write_text(text)
    right = glsandbox("check", "right.py", "--exercise", "ray_sphere", cwd=tmp_path)
    assert right.returncode == 0 and "right.py: 6/6 points" in right.stdout, right.stdout + right.stderr
    wrong = glsandbox("check", "wrong.py", "--exercise", "ray_sphere", cwd=tmp_path)
    assert wrong.returncode == 1 and "wrong.py: 4/6 points" in wrong.stdout and "far_root" in wrong.stdout
    broken = glsandbox("check", "broken.py", "--exercise", "ray_sphere", cwd=tmp_path)
    assert broken.returncode == 2 and broken.stderr.startswith("error: broken.py:1: syntax error")
    assert broken.stderr.count("\n") == 1
    unknown = glsandbox("check", "right.py", "--exercise", "ray_cube", cwd=tmp_path)
    assert unknown.returncode == 2 and "no exercise 'ray_cube'" in unknown.stderr
    both = glsandbox("check", "right.py", "--exercise", "ray_sphere", "--golden", "a.png", cwd=tmp_path)
    assert both.returncode == 2 and "drop --golden" in both.stderr


SCENE = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'

MIXED = """\
entry = "scene.toml"

[[check]]
name = "still"
golden = "goldens/still.png"
size = "64x48"
points = 1

[[check]]
exercise = "ray_sphere"
name = "sphere"
points = { visible = 2, hidden = 3 }
"""


def test_one_grading_file_mixes_pictures_and_exercises(tmp_path: Path, gl) -> None:
    """A student's folder holds the scene and the function: the picture checks render the rubric's
    entry, the exercise checks grade the file that defines the function; the points add up."""
    teacher = tmp_path / "teacher"
    teacher.mkdir()
    (teacher / "scene.toml").write_text(SCENE)
    (teacher / "sphere.py").write_text(RIGHT)
    rubric = teacher / "mixed.grading.toml"
    rubric.write_text(MIXED)
    made = glsandbox("check", str(teacher / "scene.toml"), "--rubric", str(rubric), "--update", cwd=tmp_path)
    assert made.returncode == 0 and (teacher / "goldens" / "still.png").is_file(), made.stdout + made.stderr
    folder = tmp_path / "class"
    for name, scene, function in (("right", SCENE, RIGHT), ("wrong_picture", SCENE.replace("cube\"\n", "sphere\"\n"), RIGHT),
                                  ("wrong_function", SCENE, WRONG), ("no_function", SCENE, None)):
        (folder / name).mkdir(parents=True)
        (folder / name / "scene.toml").write_text(scene)
        if function is not None:
            (folder / name / "sphere.py").write_text(function)
    (folder / "linked").symlink_to(folder / "right")
    data, gs = tmp_path / "marks.json", tmp_path / "results.json"
    proc = glsandbox("check", str(folder), "--rubric", str(rubric), "--jobs", "2", "--json", str(data),
                     "--gradescope", str(gs), cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    marks = {s["name"]: s for s in json.loads(data.read_text())["submissions"]}
    checks = {n: {c["check"]: c["status"] for c in s["checks"]} for n, s in marks.items()}
    assert list(checks["right"]) == ["still", *(f"sphere: {g}" for g in GROUPS)]  # the grading file's order
    assert set(checks["right"].values()) == {"PASS"} and marks["right"]["score"] == pytest.approx(6.0)
    assert checks["wrong_picture"]["still"] == "FAIL" and marks["wrong_picture"]["score"] == pytest.approx(5.0)
    assert checks["wrong_function"]["still"] == "PASS" and checks["wrong_function"]["sphere: visible"] == "FAIL"
    assert marks["wrong_function"]["score"] == pytest.approx(6.0 - 2.0 - 0.6)  # far_root, as graded alone
    assert checks["no_function"]["still"] == "PASS" and marks["no_function"]["score"] == pytest.approx(1.0)
    assert set(checks["linked"].values()) == {"BROKEN"} and marks["linked"]["score"] == 0
    tests = {t["name"]: t for t in json.loads(gs.read_text())["tests"]}
    assert tests["right: still"]["max_score"] == 1 and tests["right: sphere: inside"]["visibility"] == "after_published"
    one = glsandbox("check", str(folder / "right" / "scene.toml"), "--rubric", str(rubric), cwd=folder / "right")
    assert one.returncode == 0 and "PASS sphere: visible" in one.stdout, one.stdout + one.stderr
