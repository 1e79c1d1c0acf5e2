"""Submissions as students hand them in, and the reports' two readers.

A submission is one file or one folder with its helper modules; a link is
BROKEN; two submissions with the same files are flagged; ``--one DIR`` grades
one student's flat folder (Gradescope's ``/autograder/submission``); ``tour
--lessons`` renders through the same isolation; the student's report shows
nothing of a hidden check.
"""

from __future__ import annotations

import base64
import csv
import json
from pathlib import Path

import numpy as np
import pytest
from support import assert_user_error, run_cli

from glsandbox.files import load_png, png_bytes, save_png
from glsandbox.grading.check import cgroup_cpus, default_jobs

RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'
WRONG = RIGHT.replace('mesh = "cube"', 'mesh = "sphere"')

#: A lesson whose scene comes from a helper module beside it.
HELPED = '''
from pathlib import Path
from glsandbox import Lesson
from glsandbox.scene_file import load_scene
import helpers


class Helped(Lesson):
    def build(self):
        here = Path("scene.toml")
        here.write_text(helpers.SCENE)
        return load_scene(here)
'''
HELPERS = f"SCENE = {RIGHT!r}\n"
ENDLESS = "from glsandbox import Lesson\n\n\nclass Endless(Lesson):\n    def build(self):\n        while True:\n            pass\n"


def reference(tmp_path: Path) -> Path:
    (tmp_path / "model.toml").write_text(RIGHT)
    ref = tmp_path / "ref.png"
    made = run_cli("check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size", "64x48")
    assert made.returncode == 0, made.stderr
    return ref


def helped_folder(folder: Path) -> Path:
    folder.mkdir(parents=True)
    (folder / "spin.py").write_text(HELPED)
    (folder / "helpers.py").write_text(HELPERS)
    return folder


@pytest.mark.slow
def test_links_are_broken_and_the_same_files_are_flagged(tmp_path: Path, gl) -> None:
    ref = reference(tmp_path)
    teacher = tmp_path / "teacher"
    teacher.mkdir()
    (teacher / "model.toml").write_text(RIGHT)
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "ann.toml").write_text(RIGHT)
    (subs / "bob.toml").write_text(RIGHT)  # the same file as ann's
    (subs / "cat.toml").write_text(WRONG)
    (subs / "m_link").symlink_to(teacher)  # the model answer, through a link
    (subs / "f_link.toml").symlink_to(teacher / "model.toml")
    out = tmp_path / "out"
    proc = run_cli("check", str(subs), "--golden", str(ref), "--json", str(out / "r.json"), "--csv", str(out / "r.csv"),
                   "--html", str(out / "r.html"))
    assert proc.returncode == 1, proc.stdout
    report = {s["name"]: s for s in json.loads((out / "r.json").read_text())["submissions"]}
    for name in ("m_link", "f_link"):
        assert report[name]["status"] == "BROKEN" and "is a link" in report[name]["error"], report[name]
        assert f"BROKEN {name}: {subs / name}" in proc.stdout
    assert report["ann"]["same_as"] == ["bob"] and report["bob"]["same_as"] == ["ann"]
    assert report["cat"]["same_as"] == [] and report["ann"]["digest"] == report["bob"]["digest"]
    assert "same files: ann = bob" in proc.stdout
    rows = {r["name"]: r for r in csv.DictReader((out / "r.csv").open())}
    assert rows["ann"]["same_as"] == "bob" and rows["cat"]["same_as"] == ""
    assert "same files as bob" in (out / "r.html").read_text()


@pytest.mark.slow
def test_a_student_with_helper_modules_passes_in_both_layouts(tmp_path: Path, gl) -> None:
    ref = reference(tmp_path)
    subs = tmp_path / "subs"
    helped_folder(subs / "dana")  # a subfolder: the lesson and helpers.py
    (subs / "eve.toml").write_text(RIGHT)
    proc = run_cli("check", str(subs), "--golden", str(ref))
    assert proc.returncode == 0 and "PASS   dana: identical" in proc.stdout, proc.stdout
    flat = helped_folder(tmp_path / "submission")  # Gradescope's flat /autograder/submission
    proc = run_cli("check", "--one", str(flat), "--golden", str(ref))
    assert proc.returncode == 0 and "[1/1] PASS   submission: identical" in proc.stdout, proc.stdout
    # without --one, each file of the flat folder would be a student of its own
    proc = run_cli("check", str(flat), "--golden", str(ref))
    assert proc.returncode == 1 and "[2/2]" in proc.stdout


@pytest.mark.slow
def test_the_rubrics_entry_names_the_lesson_among_several(tmp_path: Path, gl) -> None:
    ref = reference(tmp_path)
    flat = helped_folder(tmp_path / "submission")
    (flat / "other.py").write_text(HELPED.replace("Helped", "Other"))  # two lessons, neither imported
    rubric = tmp_path / "grading.toml"
    rubric.write_text(f'[[check]]\ngolden = "{ref.name}"\n')
    proc = run_cli("check", "--one", str(flat), "--rubric", str(rubric))
    assert proc.returncode == 1 and "none stands out as the lesson" in proc.stdout, proc.stdout
    rubric.write_text(f'entry = "spin.py"\n[[check]]\ngolden = "{ref.name}"\n')
    proc = run_cli("check", "--one", str(flat), "--rubric", str(rubric))
    assert proc.returncode == 0 and "PASS" in proc.stdout, proc.stdout
    rubric.write_text(f'entry = "gone.py"\n[[check]]\ngolden = "{ref.name}"\n')
    proc = run_cli("check", "--one", str(flat), "--rubric", str(rubric))
    assert proc.returncode == 1 and "no gone.py in this folder (the rubric's entry point)" in proc.stdout
    rubric.write_text(f'entry = "../x.py"\n[[check]]\ngolden = "{ref.name}"\n')
    assert_user_error(run_cli("check", "--one", str(flat), "--rubric", str(rubric)), "entry = '../x.py'")


@pytest.mark.slow
def test_tour_lessons_is_isolated_and_an_endless_lesson_is_timeout_on_its_card(tmp_path: Path, gl) -> None:
    lessons = tmp_path / "lessons"
    lessons.mkdir()
    (lessons / "endless.py").write_text(ENDLESS)
    (lessons / "room.toml").write_text(RIGHT)
    helped_folder(lessons / "helped")
    (tmp_path / "secret.txt").write_text("the teacher's")
    (lessons / "spy.py").write_text(HELPED.replace("import helpers", f"open({str(tmp_path / 'secret.txt')!r}).read()"))
    out = tmp_path / "tour"
    proc = run_cli("tour", "--lessons", str(lessons), "--out", str(out), "--size", "64x48", "--timeout", "2")
    assert proc.returncode == 1, proc.stderr
    cards = {entry["lesson"]: entry for entry in json.loads((out / "tour.json").read_text())["lessons"]}
    assert cards["endless"]["ok"] is False and cards["endless"]["error"] == "TIMEOUT: timed out after 2 s"
    assert cards["room"]["ok"] and cards["helped"]["ok"] and load_png(out / "helped.png").shape == (48, 64, 4)
    assert "outside the submission" in cards["spy"]["error"]  # confined as check confines it
    assert cards["helped"]["title"] == f"lesson file {lessons / 'helped' / 'spin.py'}"
    assert "TIMEOUT: timed out after 2 s" in (out / "index.html").read_text()


HIDDEN_RUBRIC = '''
[[check]]
name = "shown"
golden = "ref.png"
[[check]]
name = "secret"
golden = "hidden.png"
points = 3
hidden = true
'''


@pytest.mark.slow
def test_the_students_report_shows_nothing_of_a_hidden_check(tmp_path: Path, gl) -> None:
    ref = reference(tmp_path)
    hidden = tmp_path / "hidden.png"
    image = load_png(ref).copy()
    image[:8, :8] = (255, 0, 255, 255)  # a reference the student's picture misses
    save_png(image, hidden)
    (tmp_path / "grading.toml").write_text(HIDDEN_RUBRIC)
    flat = helped_folder(tmp_path / "submission")
    student, teacher, gradescope = tmp_path / "student.html", tmp_path / "teacher.html", tmp_path / "results.json"
    proc = run_cli("check", "--one", str(flat), "--rubric", str(tmp_path / "grading.toml"), "--student-report",
                   str(student), "--html", str(teacher), "--gradescope", str(gradescope))
    assert proc.returncode == 1, proc.stdout
    page, teachers = student.read_text(), teacher.read_text()
    from glsandbox.grading.check import _thumbnail

    hidden_thumb = base64.b64encode(png_bytes(_thumbnail(load_png(hidden)))).decode()
    shown_thumb = base64.b64encode(png_bytes(_thumbnail(load_png(ref)))).decode()
    assert hidden_thumb in teachers and hidden_thumb not in page  # the teacher's page has it; the student's not
    assert shown_thumb in page and "1 / 1" in page and "- / 3" in page
    assert "bad of" not in page.split("secret", 1)[1].split("</tr>", 1)[0]  # no figures of the hidden check
    assert "shown after the grades are published" in page and "FAIL" not in page
    results = json.loads(gradescope.read_text())
    secret = next(t for t in results["tests"] if t["name"] == "secret")
    assert secret["visibility"] == "after_published" and results["score"] == 1
    assert results["output"].startswith("glsandbox check: 1/1 points on the checks shown now")


def test_an_empty_reference_is_one_line_without_python_object_text(tmp_path: Path) -> None:
    (tmp_path / "a.toml").write_text(RIGHT)
    (tmp_path / "ref.png").write_bytes(b"")
    proc = run_cli("check", str(tmp_path / "a.toml"), "--golden", str(tmp_path / "ref.png"))
    assert_user_error(proc, "an empty file, not a PNG image")
    (tmp_path / "ref.png").write_bytes(b"not a png at all")
    proc = run_cli("check", str(tmp_path / "a.toml"), "--golden", str(tmp_path / "ref.png"))
    assert_user_error(proc, "not a PNG image (16 bytes that PNG cannot read)")
    assert "object at 0x" not in proc.stderr


def test_jobs_default_to_the_cgroup_quota_and_affinity(tmp_path: Path) -> None:
    root = tmp_path / "cgroup"
    (root / "kubepods" / "pod1").mkdir(parents=True)
    membership = tmp_path / "self-cgroup"
    membership.write_text("0::/kubepods/pod1\n")
    assert cgroup_cpus(root, membership) is None  # no cpu.max anywhere: no quota
    (root / "kubepods" / "pod1" / "cpu.max").write_text("max 100000\n")
    assert cgroup_cpus(root, membership) is None
    (root / "kubepods" / "cpu.max").write_text("150000 100000\n")  # a parent's quota bounds its children
    assert cgroup_cpus(root, membership) == 1.5
    (root / "kubepods" / "pod1" / "cpu.max").write_text("100000 100000\n")
    assert cgroup_cpus(root, membership) == 1.0
    v1 = tmp_path / "v1"
    (v1 / "cpu,cpuacct" / "job").mkdir(parents=True)
    (v1 / "cpu,cpuacct" / "job" / "cpu.cfs_quota_us").write_text("200000\n")
    (v1 / "cpu,cpuacct" / "job" / "cpu.cfs_period_us").write_text("100000\n")
    membership.write_text("4:cpu,cpuacct:/job\n")
    assert cgroup_cpus(v1, membership) == 2.0
    import os

    assert 1 <= default_jobs() <= len(os.sched_getaffinity(0))
    quota = cgroup_cpus()
    if quota is not None:
        assert default_jobs() <= max(1, int(np.ceil(quota)))
