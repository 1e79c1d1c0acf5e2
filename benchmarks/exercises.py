"""Benchmark: ``glsandbox exercise check`` of one function, with its pictures; and a class of
100 submissions of one exercise graded isolated against the same checks in one process.

Subject: the whole command, from process start to the report, for a correct
``intersect_sphere`` (the ray_sphere exercise): the visible cases in the
student's confined process, the 256x256 probe picture (65,536 calls), the
lesson rendered with the function and the PNGs written. Baseline: ``glsandbox
exercise list`` (the same process start and imports, no check). Goal: the
check under 2 s on this machine, printed under the table from the subject's
median; the ratio shows what the check adds to a start.

The class row (:func:`class_cases`): 100 right ``intersect_sphere`` files (a
comment apart), every case group graded as ``check DIR --exercise
ray_sphere`` grades them. Anchor, "the same checks in one process": one
Python process imports glsandbox, then for each file reads it
(:func:`~glsandbox.exercises.check.static_check`), runs it in its own
namespace and runs :func:`~glsandbox.exercises.check.check` through
:class:`~glsandbox.exercises.isolation.InProcess` with the hidden cases and
the 256x256 probe, as the grader does (no lesson picture, no reports,
one submission after another). Subject: ``glsandbox check DIR --exercise
ray_sphere --jobs 2``, each function in its own confined process (a fresh
interpreter per submission). Both are whole commands. Goal: at most 1.5x.
"""

from __future__ import annotations

import statistics
import sys
from collections.abc import Sequence
from typing import Any

from _scratch import scratch_folder

_TMP = scratch_folder("glsandbox-bench-exercises-")
GROUP = "exercises"
#: The goal for the subject's median, in seconds.
GOAL_S = 2.0

SPHERE = '''import math


def intersect_sphere(origin, direction, center, radius):
    l = [c - o for c, o in zip(center, origin)]
    s = sum(a * b for a, b in zip(l, direction))
    l2 = sum(a * a for a in l)
    m2 = l2 - s * s
    if m2 > radius * radius:
        return None
    q = math.sqrt(radius * radius - m2)
    if l2 > radius * radius:
        return None if s < 0 else s - q
    t = s + q
    return t if t > 0 else None
'''


#: The anchor: the same checks as the grader's, every function in this one process.
IN_PROCESS = """
import sys
from pathlib import Path
from glsandbox.exercises.catalogue import get
from glsandbox.exercises.check import check, static_check
from glsandbox.exercises.isolation import InProcess

exercise = get("ray_sphere")
for path in sorted(Path(sys.argv[1]).glob("*.py")):
    static_check(path, exercise)
    namespace = {"__name__": "submission", "__file__": str(path)}
    exec(compile(path.read_text(), str(path), "exec"), namespace)
    result = check(exercise, InProcess(namespace[exercise.function]), hidden=True, probe=True)
    assert all(case.passed for case in result.cases), path
"""


def class_cases(env) -> list:
    """100 submissions (``--quick``: 20) graded isolated ``--jobs 2`` against one process."""
    from glsandbox.measure.bench import Case, Side, run_process

    count = 20 if env.quick else 100
    folder = _TMP / "class"
    folder.mkdir(parents=True, exist_ok=True)
    for n in range(count):
        (folder / f"student_{n:03d}.py").write_text(f"# student {n}\n{SPHERE}")
    baseline = Side("one process", run_process([sys.executable, "-c", IN_PROCESS, str(folder)]))
    subject = Side("isolated --jobs 2", run_process([sys.executable, "-m", "glsandbox.cli", "check", str(folder),
                                                     "--exercise", "ray_sphere", "--jobs", "2"]))
    return [Case(GROUP, f"{count} submissions of ray_sphere, isolated --jobs 2", baseline, subject, repeat=1,
                 unit="s", goal=1.5, note="every case group and the probe; a confined process per submission")]


def cases(env) -> list:
    from glsandbox.measure.bench import Case, Side, run_process

    mine = _TMP / "my_sphere.py"
    mine.write_text(SPHERE)
    command = [sys.executable, "-m", "glsandbox.cli", "exercise"]
    baseline = Side("exercise list", run_process([*command, "list"]))
    subject = Side("exercise check, pictures", run_process([*command, "check", "ray_sphere", str(mine),
                                                            "--pictures", str(_TMP / "pictures")]))
    return [Case(GROUP, "check ray_sphere: cases, 256x256 probe, lesson 160x90", baseline, subject,
                 repeat=1, unit="s", note=f"goal: the check under {GOAL_S:g} s"), *class_cases(env)]


def summarize(results: Sequence[Any]) -> list[str]:
    """The check's median time against its goal."""
    lines = []
    for result in results:
        if result.case.group == GROUP and result.case.name.startswith("check ") and result.subject_s:
            median = statistics.median(result.subject_s)
            verdict = "met" if median < GOAL_S else "NOT met"
            lines.append(f"{GROUP}: exercise check with pictures {median:.2f} s (goal: under {GOAL_S:g} s: {verdict})")
    return lines
