"""Benchmark: ``glsandbox exercise check`` of one function, with its pictures.

Subject: the whole command, from process start to the report, for a correct
``intersect_sphere`` (the ray_sphere exercise): the visible cases in the
student's confined process, the 256x256 probe picture (65,536 calls), the
lesson rendered with the function and the PNGs written. Baseline: ``glsandbox
exercise list`` (the same process start and imports, no check). Goal: the
check under 2 s on this machine, printed under the table from the subject's
median; the ratio shows what the check adds to a start.
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


def cases(env) -> list:
    from glsandbox.measure.bench import Case, Side, run_process

    mine = _TMP / "my_sphere.py"
    mine.write_text(SPHERE)
    command = [sys.executable, "-m", "glsandbox.cli", "exercise"]
    baseline = Side("exercise list", run_process([*command, "list"]))
    subject = Side("exercise check, pictures", run_process([*command, "check", "ray_sphere", str(mine),
                                                            "--pictures", str(_TMP / "pictures")]))
    return [Case(GROUP, "check ray_sphere: cases, 256x256 probe, lesson 160x90", baseline, subject,
                 repeat=1, unit="s", note=f"goal: the check under {GOAL_S:g} s")]


def summarize(results: Sequence[Any]) -> list[str]:
    """The check's median time against its goal."""
    lines = []
    for result in results:
        if result.case.group == GROUP and result.subject_s:
            median = statistics.median(result.subject_s)
            verdict = "met" if median < GOAL_S else "NOT met"
            lines.append(f"{GROUP}: exercise check with pictures {median:.2f} s (goal: under {GOAL_S:g} s: {verdict})")
    return lines
