"""Benchmark: grading a class of 100 scene-file submissions at 320x240, in one process vs isolated;
and a class of right, wrong and hostile submissions graded whole: throughput, peak memory, what is left.

Anchors (both whole commands, from process start to the last verdict, all
submissions right so every run exits 0):

- **one shared context** (the honest anchor, the goal's): every submission
  loaded and rendered in the grader's own process on ONE GL context, opened
  before the clock starts and kept for the whole class
  (:func:`glsandbox.grading.check.time_in_process` with ``shared_context``):
  the cheapest way to grade in one process, as a grader with no isolation
  at all would. Its choices: the same lesson loading, the same 320x240
  render and the same comparison as ``check``; no reports written; a
  broken submission skipped.
- **a fresh context each**: the same with a context opened and closed per
  submission (how ``glsandbox check DIR`` graded before isolation); it
  pays a context start per submission, as the isolated renderers would
  without the zygote's warm template, so a ratio against it flatters the
  isolation (shown, not a goal).

Subject: ``glsandbox check DIR`` as it is (``python -m glsandbox``, the console
script's way in: :mod:`glsandbox.launch` starts the zygote before the
command line's modules are imported), with ``--jobs 1`` and ``--jobs 2``:
scene files, which run no code, are drawn by one confined renderer kept
per job slot (its supervisor copies each submission into a fresh folder
and replaces the renderer after any TIMEOUT, crash or OUT OF MEMORY:
:mod:`glsandbox.grading.resident`); a lesson file gets a supervisor and a
renderer of its own, forked by the zygote that imported glsandbox once.
Goal on a 2-core machine: isolated ``--jobs 2`` within 1.5x of the
shared-context anchor.

The class row (:func:`class_case`) grades generated submissions, one in 20
hostile (an endless loop, ``os._exit``, a memory hog, a reader of secrets
and ``/proc``), one in 4 of the rest wrong, ``--jobs 2 --timeout 2``; its
notes give the submissions per second, the peak resident memory of the
grader's whole process tree (RSS summed over it, sampled every 50 ms: pages
shared by forks count once per process, so an upper bound), and the
processes (found by a mark in their environment) and the supervisors'
private folders (``glsandbox-grade-*`` in the temp folder) the run left
(none is the goal). ``glsandbox
bench`` grades 40 (``--quick``: 20); ``python benchmarks/grading.py --class
1000`` grades a class of 1,000 once and prints the same figures.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable
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
              "time_in_process(Path(sys.argv[1]), [Check('ref', Path(sys.argv[2]))], backend='egl', "
              "shared_context=sys.argv[3] == 'shared')")


def _made_first(ready: Callable[[], object], run: Callable[[int], None]) -> Callable[[int], None]:
    """``run`` once ``ready()`` has made what it reads (a cached maker: the first call makes it)."""

    def side(k: int) -> None:
        ready()
        run(k)

    return side


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
    ready = functools.cache(lambda: make_class(folder, count))  # by the first run: rows left out cost nothing
    ref = folder.parent / "ref.png"
    shared = Side("one process, one context", _made_first(ready, run_process(
        [sys.executable, "-c", IN_PROCESS, str(folder), str(ref), "shared"])))
    fresh = Side("one process, a context each", _made_first(ready, run_process(
        [sys.executable, "-c", IN_PROCESS, str(folder), str(ref), "fresh"])))

    def isolated(jobs: int) -> Side:
        return Side(f"isolated --jobs {jobs}", _made_first(ready, run_process([
            sys.executable, "-m", "glsandbox", "check", str(folder), "--golden", str(ref), "--backend", "egl",
            "--jobs", str(jobs)])))

    name = f"{count} scene files {SIZE}"
    return [*class_case(env),
        Case("grading", f"{name}, isolated --jobs 1 vs one shared context", shared, isolated(1), repeat=1, unit="s"),
        Case("grading", f"{name}, isolated --jobs 2 vs one shared context", shared, isolated(2), repeat=1, unit="s",
             goal=1.5, note="the honest anchor: one GL context for the whole class, in one process"),
        Case("grading", f"{name}, isolated --jobs 2 vs a fresh context each", fresh, isolated(2), repeat=1, unit="s",
             note="the old anchor: a context per submission (flatters the isolation)"),
    ]


#: The hostile kinds of the class row, in turn: what each does instead of building a scene.
HOSTILE = {
    "endless": "while True:\n            pass",
    "exits": "import os\n        os._exit(3)",
    "hog": "self.hoard = bytearray(8 << 30)",
    "spy": ("import os\n        print(open('/proc/self/environ').read(), os.listdir('/proc'))\n"
            "        return None"),
}
LESSON = "from glsandbox import Lesson\n\n\nclass Student(Lesson):\n    def build(self):\n        {body}\n"
WRONG_SCENE = SCENE.replace('mesh = "cube24"', 'mesh = "sphere"')


def make_mixed_class(folder: Path, count: int) -> Path:
    """``count`` submissions, one in 20 hostile, a quarter of the rest wrong, and the reference."""
    folder.mkdir(parents=True, exist_ok=True)
    kinds = list(HOSTILE)
    for n in range(count):
        if n % 20 == 19:
            body = HOSTILE[kinds[(n // 20) % len(kinds)]]
            (folder / f"student_{n:04d}.py").write_text(LESSON.format(body=body))
        else:
            (folder / f"student_{n:04d}.toml").write_text((WRONG_SCENE if n % 4 == 3 else SCENE).format(n=n))
    (folder.parent / "model.toml").write_text(SCENE.format(n="model"))
    ref = folder.parent / "ref.png"
    subprocess.run([sys.executable, "-m", "glsandbox.cli", "check", str(folder.parent / "model.toml"), "--golden",
                    str(ref), "--update", "--size", SIZE, "--backend", "egl"], check=True, capture_output=True)
    return ref


def _marked(mark: str) -> list[int]:
    """The live processes whose environment holds ``GLSANDBOX_BENCH_MARK=mark`` (every process of the run:
    the renderers' fresh environment keeps ``GLSANDBOX_*``)."""
    import psutil

    found = []
    for proc in psutil.process_iter():
        try:
            if proc.environ().get("GLSANDBOX_BENCH_MARK") == mark:
                found.append(proc.pid)
        except (psutil.Error, OSError):
            continue
    return found


def grade_class(folder: Path, ref: Path, jobs: int = 2) -> dict[str, object]:
    """Grade ``folder`` once with ``check``: seconds, submissions per second, peak RSS of the process
    tree (MiB), and the processes and temporary files left after it ended."""
    import psutil

    from glsandbox.grading.portable import tree_rss
    from glsandbox.measure.bench import interrupt_child

    mark = uuid.uuid4().hex
    tmp = Path(tempfile.gettempdir())
    before = {p.name for p in tmp.iterdir()}
    env = {**os.environ, "GLSANDBOX_BENCH_MARK": mark}
    started = time.perf_counter()
    proc = psutil.Popen([sys.executable, "-m", "glsandbox", "check", str(folder), "--golden", str(ref),
                         "--backend", "egl", "--jobs", str(jobs), "--timeout", "2", "--memory", "1024"],
                        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    peak = [0]
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], tree_rss(proc.pid))
            done.wait(0.05)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    try:
        _, errors = proc.communicate()
    finally:  # also on Ctrl-C: no sampler left running into the interpreter's exit, no check left behind
        done.set()
        sampler.join()
        interrupt_child(proc)  # interrupted: the check's own Ctrl-C removes its run folder, then it ends
    seconds = time.perf_counter() - started
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"check ended with {proc.returncode}: {errors.decode(errors='replace')[-400:]}")
    time.sleep(0.5)  # a process being reaped is not one left behind
    left = _marked(mark)
    # the supervisors' private folders (on a shared machine, another's grading run at the same time shows too)
    new_tmp = sorted(name for name in {p.name for p in tmp.iterdir()} - before if name.startswith("glsandbox-grade-"))
    count = sum(1 for _ in folder.iterdir())
    return {"seconds": seconds, "per_second": count / seconds, "peak_mib": peak[0] / 2**20,
            "processes_left": left, "temp_left": new_tmp, "count": count}


def _class_note(figures: dict[str, object]) -> str:
    left = figures["processes_left"] or "none"
    temp = figures["temp_left"] or "none"
    return (f"class of {figures['count']} (1 in 20 hostile, a quarter of the rest wrong), --jobs 2: "
            f"{figures['per_second']:.1f} submissions/s, peak RSS of the process tree {figures['peak_mib']:.0f} MiB, "
            f"processes left: {left}, temporary files left: {temp}")


def class_case(env) -> list:
    from glsandbox.measure.bench import Case, Side

    count = 20 if env.quick else 40
    folder = _TMP / "mixed" / "class"
    ready = functools.cache(lambda: make_mixed_class(folder, count))  # by the first run, as in cases()

    def graded(_: int) -> None:
        text = _class_note(grade_class(folder, ready()))
        env.notes[:] = [n for n in env.notes if not n.startswith(f"class of {count} ")]  # the last run's figures
        env.note(text)

    return [Case("grading", f"class of {count}: right, wrong, hostile, --jobs 2", None, Side("check", graded),
                 repeat=1, unit="s", note="python benchmarks/grading.py --class 1000: a class of 1,000")]


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description="Grade a generated class once: throughput, peak memory, leftovers.")
    parser.add_argument("--class", dest="count", type=int, default=1000, help="submissions (default 1000)")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    reference = make_mixed_class(_TMP / "mixed" / "class", args.count)
    print(_class_note(grade_class(_TMP / "mixed" / "class", reference, args.jobs)))
