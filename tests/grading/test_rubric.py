"""Grading files (``--rubric``): checks with settings and points, scores, ``new --assignment``."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from support import glsandbox

from glsandbox.errors import SandboxError
from glsandbox.grading.rubric import load_rubric


def run(*args: str, cwd: Path):
    return glsandbox(*args, cwd=cwd)


GOOD = '''timeout = 5
[[check]]
golden = "g/still.png"
set = ["time=0"]
[[check]]
name = "late"
golden = "g/late.png"
set = ["time=2", "speed=1"]
size = "32x24"
renderer = "ray_numpy"
points = 2.5
tolerance = { threshold = 4, max_bad_share = 0.01 }
hidden = true
'''


def test_a_rubric_is_read_with_every_key(tmp_path: Path) -> None:
    path = tmp_path / "grading.toml"
    path.write_text(GOOD)
    rubric = load_rubric(path)
    still, late = rubric.checks
    assert (still.name, still.golden, still.settings, still.points, still.size) == (
        "still", tmp_path / "g" / "still.png", ("time=0",), 1.0, None)
    assert late.settings == ("time=2", "speed=1", "renderer=ray_numpy") and late.size == (32, 24)
    assert late.tolerances == {"threshold": 4, "max_bad_share": 0.01} and late.hidden and late.points == 2.5
    assert rubric.total == 3.5 and rubric.timeout == 5.0 and rubric.memory is None


@pytest.mark.parametrize("text, fragment", [
    ("", "expected one or more [[check]] tables"),
    ("[[check]]\ngolden = 3\n", "check 1: golden = 3: expected the path of a .png file"),
    ("[[check]]\ngolden = 'a.jpg'\n", "expected the path of a .png file"),
    ("[[check]]\ngolden = 'a.png'\npoints = -1\n", "check 'a': points = -1"),
    ("[[check]]\ngolden = 'a.png'\npoints = true\n", "points = True"),
    ("[[check]]\ngolden = 'a.png'\nset = 'time=1'\n", "set = 'time=1': expected a list"),
    ("[[check]]\ngolden = 'a.png'\nsize = '0x3'\n", "size '0x3': expected WIDTHxHEIGHT"),
    ("[[check]]\ngolden = 'a.png'\nsamples = 3\n", "samples = 3"),
    ("[[check]]\ngolden = 'a.png'\ntolerance = { threshold = 1.5 }\n", "threshold is a whole number"),
    ("[[check]]\ngolden = 'a.png'\ntolerance = { fuzz = 1 }\n", "expected threshold=LEVELS"),
    ("[[check]]\ngolden = 'a.png'\nhidden = 'yes'\n", "hidden = 'yes': expected true or false"),
    ("[[check]]\ngolden = 'a.png'\ncolour = 1\n", "unknown key 'colour'"),
    ("[[check]]\ngolden = 'a.png'\n[[check]]\ngolden = 'b/a.png'\n", "two checks are named 'a'"),
    ("timeout = 0\n[[check]]\ngolden = 'a.png'\n", "timeout = 0"),
    ("memory = 'lots'\n[[check]]\ngolden = 'a.png'\n", "memory = 'lots'"),
    ("jobs = 2\n[[check]]\ngolden = 'a.png'\n", "unknown key 'jobs'"),
    ("[[check]\n", "not valid TOML"),
    ("[[check]]\nkind = 'sound'\ngolden = 'a.png'\n", "check 1: kind = 'sound': expected one of exercise, picture"),
])
def test_every_rubric_mistake_is_one_line_naming_the_file(tmp_path: Path, text: str, fragment: str) -> None:
    path = tmp_path / "grading.toml"
    path.write_text(text)
    with pytest.raises(SandboxError) as error:
        load_rubric(path)
    message = str(error.value)
    assert message.startswith(str(path)) and fragment in message and "\n" not in message, message


def test_rubric_on_the_command_line_refuses_mixed_flags(tmp_path: Path) -> None:
    path = tmp_path / "grading.toml"
    path.write_text(GOOD)
    for extra, fragment in ((["--set", "time=1"], "drop --set"), (["--golden", "x.png"], "one of the two"),
                            ([], None)):
        args = ["check", str(tmp_path), "--rubric", str(path), *extra] if fragment else ["check", str(tmp_path)]
        proc = run(*args, cwd=tmp_path)
        assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and proc.stderr.startswith("error: ")
        assert (fragment or "one of the two") in proc.stderr


@pytest.mark.slow
def test_an_assignment_from_new_to_scores_and_every_report(tmp_path: Path, gl) -> None:
    proc = run("new", "--assignment", "spin", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "spin.py").exists() and (tmp_path / "spin.grading.toml").exists()
    again = run("new", "--assignment", "spin", cwd=tmp_path)
    assert again.returncode == 2 and "already exist" in again.stderr
    rubric = load_rubric(tmp_path / "spin.grading.toml")
    names = [c.name for c in rubric.checks]
    proc = run("check", "spin.py", "--rubric", "spin.grading.toml", "--update", cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout.count("wrote reference") == len(names), proc.stdout + proc.stderr
    goldens = {c.name: c.golden.read_bytes() for c in rubric.checks}

    subs = tmp_path / "subs"
    (subs / "ann").mkdir(parents=True)
    (subs / "ann" / "spin.py").write_text((tmp_path / "spin.py").read_text())  # the model answer: full marks
    slow = (tmp_path / "spin.py").read_text().replace('Param("speed", 0.8', 'Param("speed", 0.3')
    assert slow != (tmp_path / "spin.py").read_text()
    (subs / "bob.py").write_text(slow)  # right at time 0 only
    (subs / "cat.py").write_text("def oops(:\n")
    out = {kind: tmp_path / f"report.{kind}" for kind in ("html", "junit", "gradescope", "json")}
    proc = run("check", "subs", "--rubric", "spin.grading.toml", "--jobs", "2",
               *[f"--{kind}={path}" for kind, path in out.items()], cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    lines = {m.group(2): m.group(0) for m in re.finditer(r"\[\d/3\] (\S+) +(\w+): .*", proc.stdout)}
    assert "PASS   ann: 4/4 points" in lines["ann"]
    assert "FAIL   bob: 2/4 points: still PASS; moving FAIL (" in lines["bob"] and "traced PASS" in lines["bob"]
    assert "BROKEN cat: 0/4 points: every check BROKEN (subs/cat.py:1: syntax error" in lines["cat"]
    assert {c.name: c.golden.read_bytes() for c in rubric.checks} == goldens  # the goldens untouched

    report = json.loads(out["json"].read_text())
    assert [(s["name"], s["score"], s["total"]) for s in report["submissions"]] == [
        ("ann", 4.0, 4.0), ("bob", 2.0, 4.0), ("cat", 0.0, 4.0)]
    assert [c["status"] for c in report["submissions"][1]["checks"]] == ["PASS", "FAIL", "PASS"]
    gradescope = json.loads(out["gradescope"].read_text())
    assert gradescope["score"] == 6.0 and len(gradescope["tests"]) == 9
    traced = [t for t in gradescope["tests"] if t["name"].endswith("traced")]
    assert {t["visibility"] for t in traced} == {"after_published"}  # the hidden check
    bob_moving = next(t for t in gradescope["tests"] if t["name"] == "bob: moving")
    assert (bob_moving["score"], bob_moving["max_score"], bob_moving["status"]) == (0.0, 2.0, "failed")
    suite = ET.parse(out["junit"]).getroot().find("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("9", "1", "3")
    page = out["html"].read_text()
    assert page.count("<tr><td") == 3 and page.count("data:image/png;base64") >= 3 * 3 + 2 * 3
    assert "subs/cat.py:1: syntax error" in page and "4/4" in page and "2/4" in page

    # Gradescope runs one student's folder at a time: the tests are named by check alone
    proc = run("check", "subs/ann", "--rubric", "spin.grading.toml", "--gradescope", "one.json", cwd=tmp_path)
    one = json.loads((tmp_path / "one.json").read_text())
    assert proc.returncode == 0 and one["score"] == 4.0 and [t["name"] for t in one["tests"]] == names


def test_a_new_kind_of_check_is_one_registry_entry(tmp_path: Path) -> None:
    """A kind registered once is read from a rubric (its own keys only) and judges what comes back."""
    import numpy as np

    from glsandbox.grading.check import PASS, _outcome
    from glsandbox.grading.isolate import Picture
    from glsandbox.grading.kinds import KINDS, CheckKind, Verdict, register_kind

    seen = []

    def judge(check, image, expected):
        seen.append((check.kind, image.shape, expected))
        return Verdict(True)

    register_kind(CheckKind("always", frozenset({"golden"}), judge))
    try:
        path = tmp_path / "grading.toml"
        path.write_text("[[check]]\nkind = 'always'\ngolden = 'a.png'\n")
        (check,) = load_rubric(path).checks
        assert check.kind == "always"
        outcome = _outcome(check, Picture(image=np.zeros((2, 2, 4), "uint8")), "the reference", "ann")
        assert outcome.status == PASS and seen == [("always", (2, 2, 4), "the reference")]
        path.write_text("[[check]]\nkind = 'always'\ngolden = 'a.png'\nsize = '4x4'\n")
        with pytest.raises(SandboxError, match="unknown key 'size'"):
            load_rubric(path)
    finally:
        del KINDS["always"]
