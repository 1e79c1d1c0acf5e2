"""``glsandbox gradescope``: the autograder zip, unpacked as Gradescope lays out ``/autograder`` and run.

The bundle is unpacked into a folder with ``source/``, ``submission/`` and
``results/`` (the root given by ``GLSANDBOX_AUTOGRADER_ROOT``) and its
``run_autograder`` run, with this environment's glsandbox on PATH (setup.sh's
apt and uv installs are not run here), on a right, a wrong and a hostile
submission; each ``results.json`` is checked against the fields Gradescope's
"Autograder Specifications" document.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from support import assert_user_error, run_cli

RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'
WRONG = RIGHT.replace('mesh = "cube"', 'mesh = "sphere"')
SECRET = "tok-3f9a1c77e2"

RUBRIC = """timeout = 4
[[check]]
name = "still"
golden = "goldens/still.png"
size = "64x48"
points = 1

[[check]]
name = "secret"
golden = "goldens/secret.png"
set = ["time=1"]
size = "48x36"
points = 2
hidden = true
"""

#: Tries to read the hidden golden, the environment and another process's, to forge the results,
#: then never ends.
HOSTILE = '''
import os
from glsandbox import Lesson

ROOT = {root!r}


class Hostile(Lesson):
    def build(self):
        for attempt in (lambda: open(ROOT + "/source/goldens/2-secret.png", "rb").read(),
                        lambda: open("/proc/self/environ").read(), lambda: open("/proc/1/environ").read(),
                        lambda: open(ROOT + "/results/results.json", "w").write('{{"score": 100}}')):
            try:
                print("got", attempt())
            except Exception as exc:
                print("refused", type(exc).__name__)
        while True:
            pass
'''

#: Gradescope's results.json, as its "Autograder Specifications" page documents it.
FORMATS = {"text", "html", "simple_format", "md", "ansi"}
VISIBILITIES = {"hidden", "after_due_date", "after_published", "visible"}
TOP = {"score": (int, float), "execution_time": (int, float), "output": str, "output_format": FORMATS,
       "test_output_format": FORMATS, "test_name_format": FORMATS, "visibility": VISIBILITIES,
       "stdout_visibility": VISIBILITIES, "extra_data": dict, "tests": list, "leaderboard": list}
TEST = {"score": (int, float), "max_score": (int, float), "status": {"passed", "failed"}, "name": str,
        "name_format": FORMATS, "number": str, "output": str, "output_format": FORMATS, "tags": list,
        "visibility": VISIBILITIES, "extra_data": dict}


def _field_ok(value, rule) -> bool:
    if isinstance(rule, set):
        return value in rule
    return isinstance(value, rule) and not isinstance(value, bool)


def validate_results(results: dict) -> None:
    """Every key documented and of its type; a score on the whole or on every test."""
    assert isinstance(results, dict)
    for key, value in results.items():
        assert key in TOP and _field_ok(value, TOP[key]), (key, value)
    for test in results.get("tests", []):
        for key, value in test.items():
            assert key in TEST and _field_ok(value, TEST[key]), (key, value)
        if "score" not in results:
            assert "score" in test
    assert "score" in results or results.get("tests")


def make_assignment(folder: Path) -> Path:
    folder.mkdir()
    (folder / "model.toml").write_text(RIGHT)
    rubric = folder / "shading.grading.toml"
    rubric.write_text(RUBRIC)
    made = run_cli("check", str(folder / "model.toml"), "--rubric", str(rubric), "--update")
    assert made.returncode == 0, made.stderr
    return rubric


def unpack(bundle: Path, root: Path) -> None:
    """The zip into ``root/source`` as ``unzip`` would (its modes kept), and the empty folders."""
    for name in ("source", "submission", "results"):
        (root / name).mkdir(parents=True)
    with zipfile.ZipFile(bundle) as z:
        for info in z.infolist():
            target = root / "source" / info.filename
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(z.read(info))
            target.chmod((info.external_attr >> 16) & 0o777)


def run_autograder(root: Path) -> dict:
    env = {**os.environ, "GLSANDBOX_AUTOGRADER_ROOT": str(root), "GRADER_TOKEN": SECRET,
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run([str(root / "source" / "run_autograder")], env=env, cwd=root, capture_output=True,
                          text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    results = json.loads((root / "results" / "results.json").read_text())
    validate_results(results)
    return results


@pytest.mark.slow
def test_the_bundle_grades_a_right_a_wrong_and_a_hostile_submission(tmp_path: Path, gl) -> None:
    rubric = make_assignment(tmp_path / "teacher")
    bundle = tmp_path / "autograder.zip"
    proc = run_cli("gradescope", str(rubric), "--out", str(bundle))
    assert proc.returncode == 0, proc.stderr
    with zipfile.ZipFile(bundle) as z:
        names = z.namelist()
        modes = {i.filename: (i.external_attr >> 16) & 0o777 for i in z.infolist()}
        setup = z.read("setup.sh").decode()
    assert {"setup.sh", "run_autograder", "assignment.grading.toml", "goldens/1-still.png",
            "goldens/2-secret.png", "goldens/1-still.margin.png", "goldens/2-secret.margin.png"} <= set(names)
    assert any(n.startswith("glsandbox-") and n.endswith(".whl") for n in names)
    assert modes["setup.sh"] & stat.S_IXUSR and modes["run_autograder"] & stat.S_IXUSR
    assert "uv\" python install 3.12" in setup and "libegl1" in setup and "apt-get update" in setup
    assert setup.index("apt-get update") < setup.index("apt-get install") < setup.index("pip install --upgrade uv")
    secret_golden = (tmp_path / "teacher" / "goldens" / "secret.png").read_bytes()

    outcomes = {}
    for name, files in (("right", {"shading.toml": RIGHT}), ("wrong", {"shading.toml": WRONG}),
                        ("hostile", {"spin.py": HOSTILE.format(root=str(tmp_path / "hostile"))})):
        root = tmp_path / name
        unpack(bundle, root)
        for file, text in files.items():
            (root / "submission" / file).write_text(text)
        outcomes[name] = run_autograder(root)
        assert (root / "source" / "goldens" / "2-secret.png").read_bytes() == secret_golden
    print(json.dumps(outcomes, indent=2))  # the report's record of the three results.json

    right, wrong, hostile = outcomes["right"], outcomes["wrong"], outcomes["hostile"]
    assert right["score"] == 3 and [t["status"] for t in right["tests"]] == ["passed", "passed"]
    assert wrong["score"] == 0 and [t["status"] for t in wrong["tests"]] == ["failed", "failed"]
    assert hostile["score"] == 0 and all(t["status"] == "failed" for t in hostile["tests"])
    for results in outcomes.values():
        assert results["stdout_visibility"] == "hidden"
        still, secret = results["tests"]
        assert (still["name"], still["visibility"], still["max_score"]) == ("still", "visible", 1)
        assert (secret["name"], secret["visibility"], secret["max_score"]) == ("secret", "after_published", 2)
        assert secret["output"] in ("PASS", "FAIL", "TIMEOUT")  # its outcome only: no figures, diff or output
    assert "bad of" in wrong["tests"][0]["output"] or "differ" in wrong["tests"][0]["output"]
    assert hostile["tests"][0]["output"].startswith("TIMEOUT")
    text = json.dumps(hostile)
    assert SECRET not in text and "got" not in text  # nothing read; the forged results.json never landed


@pytest.mark.slow
def test_a_submission_with_no_lesson_or_none_at_all_gets_a_results_json_that_says_why(tmp_path: Path, gl) -> None:
    rubric = make_assignment(tmp_path / "teacher")
    bundle = tmp_path / "autograder.zip"
    assert run_cli("gradescope", str(rubric), "--out", str(bundle)).returncode == 0
    root = tmp_path / "root"
    unpack(bundle, root)
    (root / "submission" / "notes.txt").write_text("no lesson here")
    results = run_autograder(root)
    assert results["score"] == 0 and [t["output"][:7] for t in results["tests"]] == ["BROKEN:", "BROKEN"]
    assert "no .py or .toml lesson file" in results["tests"][0]["output"]
    (root / "submission" / "notes.txt").unlink()
    (root / "submission").rmdir()  # glsandbox refuses before grading: run_autograder writes why
    results = run_autograder(root)
    assert results["score"] == 0 and results["tests"] == []
    assert results["output"].startswith("error: ") and "submission" in results["output"], results


def test_bad_input_is_one_line_and_no_zip(tmp_path: Path) -> None:
    rubric = tmp_path / "a.grading.toml"
    rubric.write_text('[[check]]\ngolden = "gone.png"\n')
    out = tmp_path / "out"
    out.mkdir()
    assert_user_error(run_cli("gradescope", str(rubric), "--out", str(out / "a.zip"), unchanged=out),
                      "gone.png", "not found")
    assert_user_error(run_cli("gradescope", str(rubric), "--out", str(out / "a.tar")), "--out", "expected a .zip")
    assert_user_error(run_cli("gradescope", str(tmp_path / "model.py"), "--out", str(out / "a.zip")),
                      "expected a grading file")
    assert_user_error(run_cli("gradescope", str(rubric), "--out", str(tmp_path / "no" / "a.zip")),
                      "does not exist")
    rubric.write_text("[[check]\n")
    assert_user_error(run_cli("gradescope", str(rubric), "--out", str(out / "a.zip"), unchanged=out), "not valid TOML")
    assert list(out.iterdir()) == []


def test_an_installed_glsandbox_is_packed_back_into_the_same_wheel(tmp_path: Path) -> None:
    import importlib.metadata

    from glsandbox.grading.gradescope import _build_from_checkout, _project_root, _wheel_from_installed

    root = _project_root()
    assert root is not None  # the tests run from the checkout
    built = _build_from_checkout(root, tmp_path / "built")
    installed = tmp_path / "site"
    with zipfile.ZipFile(built) as z:
        z.extractall(installed)
        original = {n: z.read(n) for n in z.namelist() if not n.endswith("/RECORD")}
    dist = importlib.metadata.PathDistribution(next(installed.glob("glsandbox-*.dist-info")))
    (tmp_path / "packed").mkdir()
    packed = _wheel_from_installed(dist, tmp_path / "packed")
    assert packed.name == built.name
    with zipfile.ZipFile(packed) as z:
        again = {n: z.read(n) for n in z.namelist() if not n.endswith("/RECORD")}
        record = z.read(next(n for n in z.namelist() if n.endswith("/RECORD"))).decode()
    assert again == original  # every file of the package, its lessons and shaders, byte for byte
    assert all(f"{name},sha256=" in record for name in again)


EXERCISE_RUBRIC = """timeout = 4
[[check]]
exercise = "ray_sphere"
name = "sphere"
points = { visible = 2, hidden = 3 }
"""

#: An exercise's hostile student: forges the results, reads the grader's environment and the
#: bundle, then never answers.
HOSTILE_FUNCTION = '''
import os

ROOT = {root!r}


def intersect_sphere(origin, direction, center, radius):
    for attempt in (lambda: open(ROOT + "/results/results.json", "w").write('{{"score": 100}}'),
                    lambda: open(ROOT + "/results/forged.txt", "w").write("x"),
                    lambda: open("/proc/self/environ").read(), lambda: open("/proc/1/environ").read(),
                    lambda: open(ROOT + "/source/assignment.grading.toml").read()):
        try:
            text = str(attempt())
            if "tok-" in text or "ray_sphere" in text:  # the grader's secret, or the bundle's grading file
                return 35.0
        except Exception:
            pass
    if any("tok-" in v for v in os.environ.values()):
        return 35.0
    while True:
        pass
'''


@pytest.mark.slow
def test_the_bundle_grades_an_exercise_rubric(tmp_path: Path) -> None:
    """An exercise rubric's bundle (no goldens: the cases are the wheel's), run on a right, a wrong
    (the far root) and a hostile function: results.json valid, one test per case group."""
    from support import SPHERE_ANSWER

    teacher = tmp_path / "teacher"
    teacher.mkdir()
    rubric = teacher / "sphere.grading.toml"
    rubric.write_text(EXERCISE_RUBRIC)
    bundle = tmp_path / "autograder.zip"
    proc = run_cli("gradescope", str(rubric), "--out", str(bundle))
    assert proc.returncode == 0, proc.stderr
    with zipfile.ZipFile(bundle) as z:
        names = z.namelist()
        bundled = z.read("assignment.grading.toml").decode()
    assert not any(n.startswith("goldens/") for n in names) and 'exercise = "ray_sphere"' in bundled
    wrong = SPHERE_ANSWER.replace("return None if s < 0 else s - q", "return None if s < 0 else s + q")
    assert wrong != SPHERE_ANSWER
    outcomes = {}
    for name, text in (("right", SPHERE_ANSWER), ("wrong", wrong), ("hostile", None)):
        root = tmp_path / name
        unpack(bundle, root)
        body = text if text is not None else HOSTILE_FUNCTION.format(root=str(root))
        (root / "submission" / "sphere.py").write_text(body)
        outcomes[name] = run_autograder(root)
        assert not (root / "results" / "forged.txt").exists()
    print(json.dumps(outcomes, indent=2))  # the report's record of the three results.json
    groups = ["visible", "inside", "behind", "edge", "surface", "scale"]
    for results in outcomes.values():
        tests = results["tests"]
        assert [t["name"] for t in tests] == [f"sphere: {g}" for g in groups]
        assert [t["visibility"] for t in tests] == ["visible"] + ["after_published"] * 5
        assert sum(t["max_score"] for t in tests) == pytest.approx(5.0)
    assert outcomes["right"]["score"] == pytest.approx(5.0)
    assert outcomes["wrong"]["score"] == pytest.approx(5.0 - 2.0 - 0.6)  # far_root: the notes' examples and scale
    assert "far_root" in outcomes["wrong"]["tests"][0]["output"]
    hostile = outcomes["hostile"]
    assert hostile["score"] == 0 and all(t["status"] == "failed" for t in hostile["tests"])
    assert SECRET not in json.dumps(hostile)
