"""``glsandbox bench``: every benchmark in ``benchmarks/``, one table of ratios.

A benchmark module in ``benchmarks/`` (any ``*.py`` not starting with ``_``)
defines ``cases(env: BenchEnv) -> list[Case]``, and may define
``summarize(results: list[Result]) -> list[str]``: lines printed under the
table from its measured rows (e.g. how a time grows across rows). A :class:`Case` pairs a
*baseline* side with a *subject* side (e.g. raw ModernGL vs glsandbox, or the
on-demand plan vs ``effects=all``). All cases run together in alternating
rounds, in one process and on one GL context: every round times each
case's two sides back to back, the order swapped every other round, so the
noise of a shared machine hits both alike. The figure per case is the ratio
of the two medians (subject / baseline). Each sample also records the main
thread's CPU time (``time.thread_time``) and that of the child processes it
waited for (``RUSAGE_CHILDREN``: a process side's whole run, all its threads):
the subject's extra CPU per repetition is a column of its own, steadier than
wall time on a shared machine (GL drivers' worker threads in this process are
not in it). Speed goals are printed, never
asserted: no test depends on a timing, which a busy machine would fail
(docs/benchmarks.md).

The same harness drives ``python benchmarks/cube_frame.py`` on its own.
"""

from __future__ import annotations

import importlib.util
import datetime
import json
import os
import platform
import statistics
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

try:
    import resource
except ImportError:  # Windows: no child process CPU (a process side's column shows only the waiting)
    resource = None  # type: ignore[assignment]

from glsandbox.errors import SandboxError
from glsandbox.progress import progress, say
from glsandbox.files import write_text
from glsandbox.frame import HeadlessRenderer, LazyRenderer
from glsandbox.gl.context import headless_order

#: The frame size of the frame benchmarks (the course's 800x600 window).
FRAME_SIZE = (800, 600)
#: Goals of a lesson frame against its raw-ModernGL baseline: at most this ratio
#: of the raw frame's wall time, and at most this much extra main-thread CPU (µs) per frame.
LESSON_FRAME_GOAL = 1.05
LESSON_FRAME_CPU_GOAL_US = 50.0


@dataclass(frozen=True)
class Side:
    """One side of a comparison: a label and a callable doing one unit of work.

    ``run(k)`` does the k-th repetition (frames pass ``k`` on as an animation
    step); what it returns is kept from the first call for the picture check.
    """

    label: str
    run: Callable[[int], Any]


#: Units of cases whose sides return what is measured (:class:`Case`) instead of being timed.
QUANTITY_UNITS = ("MiB",)


@dataclass(frozen=True)
class Case:
    """Two sides measured side by side; the ratio is subject / baseline.

    ``repeat`` is how many repetitions make one timed sample (many cheap
    frames, one process start); ``unit`` is how the per-repetition time is
    printed ("ms" or "s"), or a quantity's unit (:data:`QUANTITY_UNITS`, e.g.
    "MiB"): then each side's ``run`` returns the figure itself (e.g. a fresh
    process's peak memory), which is the sample in place of the time, and
    there is no warm-up call; ``goal`` is the ratio aimed for (printed, never
    asserted); ``cpu_goal_us`` the most extra main-thread CPU per repetition
    aimed for, in microseconds (printed likewise); ``compare`` decides whether the two sides show the same
    picture from their first results (None: nothing to compare).
    """

    group: str
    name: str
    baseline: Side | None
    subject: Side
    repeat: int = 30
    unit: str = "ms"
    goal: float | None = None
    cpu_goal_us: float | None = None
    note: str = ""
    compare: Callable[[Any, Any], str] | None = None


@dataclass
class BenchEnv:
    """What benchmark modules get: a shared headless renderer, the frame size and the mode."""

    quick: bool = False
    size: tuple[int, int] = FRAME_SIZE
    root: Path = field(default_factory=lambda: Path.cwd())
    #: Lines printed under the table (and written to the JSON): what a module skipped and why.
    notes: list[str] = field(default_factory=list)
    #: The one headless context every case draws on (EGL on Linux, the standalone WGL/CGL one on
    #: Windows and macOS), opened by the first case that asks for it.
    gl: LazyRenderer = field(default_factory=lambda: LazyRenderer(headless_order()[0]))

    def note(self, text: str) -> None:
        """Print ``text`` under the table, e.g. ``skipped: embreex not installed``."""
        if text not in self.notes:
            self.notes.append(text)

    @property
    def renderer(self) -> HeadlessRenderer:
        """One :class:`~glsandbox.frame.HeadlessRenderer` for every case (one context)."""
        return self.gl.renderer

    def renderer_name(self) -> str:
        """The GL renderer the cases ran on; ``?`` when none of them opened it."""
        return str(self.renderer.host.renderer) if self.gl.opened else "?"

    def close(self) -> None:
        self.gl.close()


@dataclass
class Result:
    """The timings of one case: per-repetition seconds of each sample, both sides (a quantity
    case's figures instead: :data:`QUANTITY_UNITS`)."""

    case: Case
    baseline_s: list[float]
    subject_s: list[float]
    same: str = ""
    #: Main-thread CPU seconds per repetition (with the child processes waited for: :func:`cpu_seconds`),
    #: sample for sample with the wall times.
    baseline_cpu_s: list[float] = field(default_factory=list)
    subject_cpu_s: list[float] = field(default_factory=list)

    @property
    def ratio(self) -> float | None:
        if not self.baseline_s:
            return None
        return statistics.median(self.subject_s) / statistics.median(self.baseline_s)

    @property
    def extra_cpu_us(self) -> float | None:
        """The subject's CPU per repetition beyond the baseline's (medians, :func:`cpu_seconds`), in µs."""
        if not self.baseline_cpu_s or not self.subject_cpu_s:
            return None
        return (statistics.median(self.subject_cpu_s) - statistics.median(self.baseline_cpu_s)) * 1e6

    def to_dict(self) -> dict[str, Any]:
        c = self.case
        scale = 1e3 if c.unit == "ms" else 1.0

        def summary(samples: list[float]) -> dict[str, float] | None:
            if not samples:
                return None
            return {"median": round(statistics.median(samples) * scale, 4),
                    "min": round(min(samples) * scale, 4), "max": round(max(samples) * scale, 4)}

        return {"group": c.group, "name": c.name, "unit": c.unit,
                "baseline": c.baseline.label if c.baseline else None, "subject": c.subject.label,
                "baseline_time": summary(self.baseline_s), "subject_time": summary(self.subject_s),
                "ratio": None if self.ratio is None else round(self.ratio, 4), "goal": c.goal,
                "goal_met": None if c.goal is None or self.ratio is None else self.ratio <= c.goal,
                "extra_cpu_us": None if self.extra_cpu_us is None else round(self.extra_cpu_us, 1),
                "cpu_goal_us": c.cpu_goal_us,
                "cpu_goal_met": None if c.cpu_goal_us is None or self.extra_cpu_us is None
                else self.extra_cpu_us <= c.cpu_goal_us,
                "same_picture": self.same or None, "note": c.note or None}


# --- measuring ----------------------------------------------------------------


def cpu_seconds() -> float:
    """This thread's CPU time plus that of every child process waited for so far (user and
    system, all their threads): a side that starts a process (:func:`run_process`) costs what
    the process cost, not only the wait (its own time would be near zero)."""
    cpu = time.thread_time()
    if resource is not None:
        children = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu += children.ru_utime + children.ru_stime
    return cpu


def _sample(side: Side, repeat: int, start: int) -> tuple[float, float, Any]:
    """Wall and CPU seconds (:func:`cpu_seconds`) per repetition, and what the last one returned."""
    cpu0, t0 = cpu_seconds(), time.perf_counter()
    value = None
    for k in range(repeat):
        value = side.run(start + k)
    return (time.perf_counter() - t0) / repeat, (cpu_seconds() - cpu0) / repeat, value


def measure(cases: Sequence[Case], rounds: int, log: Callable[[str], None] = lambda s: None,
            advance: Callable[[int], object] = lambda n: None) -> list[Result]:
    """Alternating rounds over every case; the first call of each side is a warm-up and the picture check.

    ``advance(1)`` follows each case's warm-up and each case in each round:
    ``len(cases) * (rounds + 1)`` steps (a progress bar's ``update``).
    """
    results = []
    for case in cases:
        if case.unit in QUANTITY_UNITS:  # each call measures anew: nothing to warm up
            results.append(Result(case, [], []))
            advance(1)
            continue
        first_base = case.baseline.run(0) if case.baseline else None
        first_subject = case.subject.run(0)
        same = case.compare(first_base, first_subject) if case.compare and case.baseline else ""
        results.append(Result(case, [], [], same))
        advance(1)
    for r in range(rounds):
        log(f"bench: round {r + 1}/{rounds}")
        for result in results:
            case = result.case
            sides = [(case.baseline, result.baseline_s, result.baseline_cpu_s),
                     (case.subject, result.subject_s, result.subject_cpu_s)]
            if r % 2:
                sides.reverse()
            for side, samples, cpu_samples in sides:
                if side is not None:
                    wall, cpu, value = _sample(side, case.repeat, r * case.repeat)
                    samples.append(float(value) if case.unit in QUANTITY_UNITS else wall)
                    cpu_samples.append(cpu)
            advance(1)
    return results


def same_pixels(a: Any, b: Any) -> str:
    """``identical``, or how far two RGBA frames are apart (largest level difference, share of pixels)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return f"NO (shapes {a.shape} vs {b.shape})"
    if np.array_equal(a, b):
        return "identical"
    diff = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=-1)
    return f"max {int(diff.max())} levels, {np.count_nonzero(diff) / diff.size:.2%} px"


#: Seconds an interrupted side's process gets to clean up after its own Ctrl-C before it is killed.
CHILD_GRACE_S = 1.0


def interrupt_child(proc: subprocess.Popen) -> None:
    """Pass Ctrl-C on to a case's process that is still running (a ``glsandbox`` command then
    removes its temporary folders) and kill it if it has not ended :data:`CHILD_GRACE_S` later."""
    if proc.poll() is not None:
        return
    try:
        proc.send_signal(signal.SIGINT)
    except (ValueError, OSError):  # Windows takes no SIGINT for a process: killed below
        pass
    try:
        proc.wait(timeout=CHILD_GRACE_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def run_process(command: list[str]) -> Callable[[int], None]:
    """A side that starts a process and waits for it (cold start, tour); its CPU is the process's.
    Ctrl-C while it runs is passed on to it (:func:`interrupt_child`)."""

    def side(_: int) -> None:
        with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
            try:
                _, errors = proc.communicate()
            except KeyboardInterrupt:
                interrupt_child(proc)
                raise
        if proc.returncode != 0:
            raise SandboxError(f"bench: {' '.join(command[:4])}... failed: "
                               f"{(errors.strip().splitlines() or ['?'])[-1]}")

    return side


# --- discovery and the table ------------------------------------------------------


def benchmarks_dir() -> Path:
    """The ``benchmarks/`` folder of the source tree (next to the ``glsandbox`` package), else of the working folder."""
    for root in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (root / "benchmarks").is_dir():
            return root / "benchmarks"
    raise SandboxError("no benchmarks/ folder: run glsandbox bench from a clone of the repository")


def load_modules(folder: Path) -> list[ModuleType]:
    """Import every benchmark module (``*.py`` not starting with ``_``) that defines ``cases``."""
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))  # so modules can share helpers in _*.py
    modules = []
    for path in sorted(folder.glob("*.py")):
        if path.name.startswith("_"):
            continue
        spec = importlib.util.spec_from_file_location(f"benchmarks_{path.stem}", path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        if hasattr(module, "cases"):
            modules.append(module)
    return modules


def format_table(results: Sequence[Result]) -> str:
    """One table: every case, both medians with spread, the ratio, the goal, the subject's extra
    CPU per repetition (main thread, or the whole process of a process side) with its goal, and
    the picture check."""
    header = ("benchmark", "baseline", "subject", "baseline", "subject", "ratio", "goal", "extra CPU",
              "CPU goal", "same picture")
    rows = []
    for res in results:
        c = res.case
        scale = 1e3 if c.unit == "ms" else 1.0

        def cell(samples: list[float]) -> str:
            if not samples:
                return "-"
            return (f"{statistics.median(samples) * scale:.3f} {c.unit} "
                    f"({min(samples) * scale:.3f}-{max(samples) * scale:.3f})")

        ratio = res.ratio
        goal = "-" if c.goal is None or ratio is None else f"<={c.goal:.2f}x {'met' if ratio <= c.goal else 'NOT met'}"
        extra = res.extra_cpu_us
        cpu_goal = "-" if c.cpu_goal_us is None or extra is None else \
            f"<={c.cpu_goal_us:g} us {'met' if extra <= c.cpu_goal_us else 'NOT met'}"
        rows.append((f"{c.group}: {c.name}", c.baseline.label if c.baseline else "-", c.subject.label,
                     cell(res.baseline_s), cell(res.subject_s), "-" if ratio is None else f"{ratio:.2f}x",
                     goal, "-" if extra is None else _cpu_cell(extra, c.unit), cpu_goal, res.same or "-"))
    widths = [max(len(str(r[i])) for r in (header, *rows)) for i in range(len(header))]
    lines = ["  ".join(str(v).ljust(w) for v, w in zip(header, widths)).rstrip(),
             "  ".join("-" * w for w in widths)]
    lines += ["  ".join(str(v).ljust(w) for v, w in zip(r, widths)).rstrip() for r in rows]
    return "\n".join(lines)


def _cpu_cell(extra_us: float, unit: str) -> str:
    """Extra CPU per repetition: microseconds for frames, seconds for whole runs."""
    return f"{extra_us:+.0f} us" if unit == "ms" else f"{extra_us / 1e6:+.3f} s"


def run_all(json_path: Path | None = None, quick: bool = False, only: Sequence[str] = (),
            rounds: int | None = None) -> int:
    """Collect the cases of every benchmark module, measure them together, print one table."""
    if json_path is not None and (json_path.is_dir() or not json_path.parent.is_dir()):
        raise SandboxError(f"--json {json_path}: not a file in an existing folder")
    folder = benchmarks_dir()
    env = BenchEnv(quick=quick, root=folder.parent)
    log = say  # lines above the progress bar (only a terminal gets the bar)
    try:
        cases: list[Case] = []
        found_lines = []
        summaries = []
        skipped: list[str] = []  # notes of modules with no case at all here (e.g. no display for a window)
        for module in load_modules(folder):
            noted = len(env.notes)
            found = module.cases(env)
            matched = [c for c in found if not only or any(o in f"{c.group}: {c.name}" for o in only)]
            if not found:
                skipped += env.notes[noted:]
            if not matched:  # a module left out by --only: its notes (what it skipped) do not apply
                del env.notes[noted:]
            cases += matched
            if matched and hasattr(module, "summarize"):
                summaries.append(module.summarize)
            found_lines.append(f"bench: {Path(module.__file__ or '').name}: {len(matched)} of {len(found)} cases")
        if not cases:  # said before any progress line: a mistake is one line
            why = "".join(f"; {text}" for text in skipped if any(o in text for o in only))  # the rows asked for
            raise SandboxError(f"--only {' '.join(only)}: no benchmark case matched (see glsandbox bench){why}")
        for line in found_lines:
            log(line)
        groups = list(dict.fromkeys(c.group for c in cases))
        cases.sort(key=lambda c: groups.index(c.group))  # stable: one group's rows together
        rounds = rounds or (3 if quick else 7)
        if quick:
            cases = [_quick(c) for c in cases]
        started = time.perf_counter()
        with progress(len(cases) * (rounds + 1), "bench", "case") as bar:
            results = measure(cases, rounds, log, bar.update)
        for summarize in summaries:
            for line in summarize(results):
                env.note(line)
        renderer = env.renderer_name()
    finally:
        env.close()
    title = (f"glsandbox bench: {len(results)} cases, {rounds} alternating rounds, frames {env.size[0]}x"
             f"{env.size[1]}, {renderer}; ratio = subject / baseline (medians), spread min-max")
    print(title)
    print(format_table(results))
    for text in env.notes:
        print(text)
    if json_path is not None:
        data = {"title": title, "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                "machine": machine(), "renderer": renderer, "rounds": rounds, "quick": quick,
                "seconds": round(time.perf_counter() - started, 2), "cases": [r.to_dict() for r in results],
                "notes": list(env.notes)}
        write_text(json_path, json.dumps(data, indent=2) + "\n")
        print(f"wrote {json_path}")
    return 0


def machine() -> str:
    """The machine a run measured on, in one line: system, processor and cores, Python."""
    cpu = platform.processor() or platform.machine()
    return (f"{platform.system()} {platform.release()}, {cpu}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}")


def _quick(case: Case) -> Case:
    return replace(case, repeat=max(1, min(case.repeat, 5)))
