"""The portable way of grading (a teacher's Mac or Windows laptop), forced on Linux.

``GLSANDBOX_ISOLATION=portable`` grades each submission in a fresh Python,
its process tree killed with psutil: the core hostile kinds end as on the
full path (an endless loop TIMEOUT, ``os._exit`` CRASHED, a memory hog OUT
OF MEMORY, reading the reference BROKEN), a wrong answer FAILs, a right one
PASSes, the first line says the confinement is weaker, and no process of the
run is left.
"""

from __future__ import annotations

import json
from pathlib import Path

import psutil
import pytest
from support import run_cli

RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'
WRONG = RIGHT.replace('mesh = "cube"', 'mesh = "sphere"')
LESSON = "import os\nfrom glsandbox import Lesson\n\n\nclass Student(Lesson):\n    def build(self):\n        {body}\n"
SECRET = "tok-portable-5521"


@pytest.mark.slow
def test_the_portable_path_holds_the_core_hostile_kinds(tmp_path: Path, gl) -> None:
    (tmp_path / "model.toml").write_text(RIGHT)
    ref = tmp_path / "ref.png"
    assert run_cli("check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size",
                   "64x48").returncode == 0
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "right.toml").write_text(RIGHT)
    (subs / "wrong.toml").write_text(WRONG)
    bodies = {"endless": "while True:\n            pass", "exits": "os._exit(3)",
              "hog": "self.hoard = bytearray(16 << 30)",
              "reader": f"print(open({str(ref)!r}, 'rb').read())",
              "spy": "print(dict(os.environ))\n        raise RuntimeError('looked')"}
    for name, body in bodies.items():
        (subs / f"{name}.py").write_text(LESSON.format(body=body))
    before = {p.pid for p in psutil.Process().children(recursive=True)}
    proc = run_cli("check", str(subs), "--golden", str(ref), "--timeout", "3", "--memory", "1024", "--jobs", "2",
                   "--json", str(tmp_path / "r.json"), env={"GLSANDBOX_ISOLATION": "portable", "GRADER_TOKEN": SECRET})
    assert proc.returncode == 1, proc.stderr
    assert proc.stdout.startswith("isolation: portable") and "weaker" in proc.stdout.splitlines()[0]
    report = {s["name"]: s for s in json.loads((tmp_path / "r.json").read_text())["submissions"]}
    outcomes = {name: (s["status"], s["error"]) for name, s in report.items()}
    assert outcomes["right"][0] == "PASS" and outcomes["wrong"][0] == "FAIL"
    assert outcomes["endless"] == ("TIMEOUT", "timed out after 3 s")
    assert outcomes["exits"][0] == "CRASHED" and "exited with code 3" in outcomes["exits"][1]
    assert outcomes["hog"][0] == "OUT OF MEMORY"
    assert outcomes["reader"][0] == "BROKEN" and "outside the submission" in outcomes["reader"][1]
    assert outcomes["spy"][0] == "BROKEN" and report["spy"]["output"]  # it printed its environment: not the grader's
    assert SECRET not in proc.stdout + (tmp_path / "r.json").read_text()
    assert {p.pid for p in psutil.Process().children(recursive=True)} <= before  # every tree killed


@pytest.mark.slow
def test_tour_lessons_takes_the_portable_path_too(tmp_path: Path, gl) -> None:
    lessons = tmp_path / "lessons"
    lessons.mkdir()
    (lessons / "room.toml").write_text(RIGHT)
    (lessons / "endless.py").write_text(LESSON.format(body="while True:\n            pass"))
    out = tmp_path / "tour"
    proc = run_cli("tour", "--lessons", str(lessons), "--out", str(out), "--size", "64x48", "--timeout", "2",
                   env={"GLSANDBOX_ISOLATION": "portable"})
    assert proc.returncode == 1, proc.stderr
    cards = {entry["lesson"]: entry for entry in json.loads((out / "tour.json").read_text())["lessons"]}
    assert cards["endless"]["ok"] is False and cards["endless"]["error"] == "TIMEOUT: timed out after 2 s"
    assert cards["room"]["ok"] and cards["room"]["title"]  # its card, sent back as on the full path
