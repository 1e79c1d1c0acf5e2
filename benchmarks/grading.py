"""Benchmark: grading a class of 100 scene-file submissions at 320x240, in one process vs isolated.

Baseline: every submission loaded and rendered in the grader's own process on
a fresh context each (how ``glsandbox check DIR`` graded before isolation:
:func:`glsandbox.grading.check.time_in_process`). Subject: ``glsandbox check
DIR`` as it is, each submission in a process of its own (a zygote that
imported glsandbox once forks a supervisor and a renderer per submission),
with ``--jobs 1`` and ``--jobs 2``. Both sides are whole commands, from
process start to the last verdict. Goal on a 2-core machine: isolated
``--jobs 2`` within 1.5x of the in-process time.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from _scratch import scratch_folder

_TMP = scratch_folder("glsandbox-bench-grading-")
SIZE = "320x240"
SCENE = """name = "cube"
[camera]
eye = [2.5, 2.0, 3.5]
[[lights]]
position = [2, 3, 4]
[[nodes]]
mesh = "cube24"
shading = "phong"
color = [0.8, 0.4, 0.2]
# submission {n}
"""

IN_PROCESS = ("import sys; from pathlib import Path; from glsandbox.grading.check import Check, time_in_process; "
              "time_in_process(Path(sys.argv[1]), [Check('ref', Path(sys.argv[2]))], backend='egl')")


def make_class(folder: Path, count: int) -> Path:
    """``count`` submissions (all right, so every run exits 0) and the reference from the first."""
    folder.mkdir(parents=True, exist_ok=True)
    for n in range(count):
        (folder / f"student_{n:03d}.toml").write_text(SCENE.format(n=n))
    ref = folder.parent / "ref.png"
    subprocess.run([sys.executable, "-m", "glsandbox.cli", "check", str(folder / "student_000.toml"), "--golden",
                    str(ref), "--update", "--size", SIZE, "--backend", "egl"], check=True, capture_output=True)
    return ref


def cases(env) -> list:
    from glsandbox.measure.bench import Case, Side, run_process

    count = 20 if env.quick else 100
    folder = _TMP / "class"
    ref = make_class(folder, count)
    baseline = Side("in one process", run_process([sys.executable, "-c", IN_PROCESS, str(folder), str(ref)]))

    def isolated(jobs: int) -> Side:
        return Side(f"isolated --jobs {jobs}", run_process([
            sys.executable, "-m", "glsandbox.cli", "check", str(folder), "--golden", str(ref), "--backend", "egl",
            "--jobs", str(jobs)]))

    name = f"{count} scene files {SIZE}"
    return [
        Case("grading", f"{name}, isolated --jobs 1", baseline, isolated(1), repeat=1, unit="s"),
        Case("grading", f"{name}, isolated --jobs 2", baseline, isolated(2), repeat=1, unit="s", goal=1.5,
             note="a process per submission: time, memory and file limits"),
    ]
