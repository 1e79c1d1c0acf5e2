"""What accuracy costs in time: ``glsandbox tradeoffs [--out DIR] [--quick]``.

For each accuracy knob (:mod:`glsandbox.measure.knob`; the built-in ones in
:mod:`glsandbox.measure.knobs`) the same scene is rendered at every setting
of the knob and at a reference setting, and its picture is compared with the
reference by RMSE, PSNR and FLIP (NVIDIA's perceptual error, the
``flip-evaluator`` package of the optional ``measure`` extra,
:mod:`glsandbox.measure.extra`).

Timing. A load on a shared machine that comes and goes moves a median by
several times (the same frame measured 1.66 ms, then 8.37 ms a run later),
so every figure is given with its run-to-run spread:

- :data:`PASSES` independent passes (at least two), each of ``runs`` rounds
  (at least five) in a fresh process of its own
  (:mod:`glsandbox.measure.timing_pass`: two passes in one process agree
  better than two runs of the command, so only passes in processes of their
  own give the run-to-run spread); a round renders every setting of every
  knob once, the knobs taken in turn (:func:`interleave`) and the order
  reversed every other round, so a burst of load falls on many knobs'
  settings, not on one knob;
- in each pass a cheap setting (under :data:`CHEAP_MS`) runs again until its
  median is stable within the pass (odd and even runs' medians within
  :data:`STABLE_SPREAD`);
- the figure is the median of all runs; its spread is how far apart the
  passes' medians lie (:attr:`~glsandbox.measure.knob.Row.run_spread`), and
  a setting whose passes differ by more than
  :data:`~glsandbox.measure.knob.WIDE_SPREAD` gets no figure in the report,
  only the passes' medians and "too noisy";
- the machine's load average is printed before and after, and at each pass;
  where it passes :data:`~glsandbox.measure.knob.BUSY_LOAD_PER_CPU` runnable
  threads per CPU at a pass's start or end, no time is a figure ("too noisy:
  machine busy"): passes that agree within such a run still disagree with the
  next run.

:func:`run` then writes the report
(:mod:`glsandbox.measure.tradeoffs_report`): ``report.md``,
``tradeoffs.csv``, ``tradeoffs.png``, and the pictures compared in
``images/`` and their FLIP error maps in ``error_maps/``.

A knob whose ``unavailable`` says why it cannot be measured here is skipped
and listed in the report under "Not measured yet".
"""

from __future__ import annotations

import functools
import os
import statistics
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.files import save_png
from glsandbox.measure import extra, metrics
from glsandbox.measure.knob import Knob, KnobResult, Row, Setting, all_knobs, machine_busy, median_spread
from glsandbox.measure.render_context import RenderContext
from glsandbox.measure.timing_pass import CHEAP_MS, MAX_RUNS, STABLE_SPREAD, time_in_process, time_pass
from glsandbox.measure.tradeoffs_report import write_csv, write_plot, write_report
from glsandbox.progress import progress
from glsandbox.progress import say as progress_line

__all__ = ["CHEAP_MS", "MAX_RUNS", "STABLE_SPREAD", "FULL_SIZE", "median_spread", "PASSES", "QUICK_SIZE", "RUNS", "KnobResult", "Row", "flip_error", "interleave",
           "load_average", "measure_knob", "measure_knobs", "run", "time_pass", "PassTimer"]

#: Runs per setting for the timing (the issue asks for at least five).
RUNS = 5
#: Independent passes of the timing rounds, each in a process of its own: each figure's
#: run-to-run spread is how far apart the passes' medians lie
#: (:attr:`~glsandbox.measure.knob.Row.run_spread`), and the report gives the median ± that
#: whole range (never less than :data:`~glsandbox.measure.knob.RUN_DRIFT`). For medians that
#: scatter alike from run to run, two runs' ranges so stated overlap 98.6% of the time with
#: three passes and 99.9% with four (± half the range: 88% and 97%).
PASSES = 4
#: Frame size of the full report, and of ``--quick``.
FULL_SIZE = (320, 240)
QUICK_SIZE = (128, 96)


def flip_error(reference: np.ndarray, test: np.ndarray) -> tuple[float, np.ndarray]:
    """Mean FLIP error (0: identical; LDR, 67 pixels per degree) and its magma error map as ``uint8`` RGB."""
    flip_evaluator = extra.require("flip_evaluator")
    ref = np.ascontiguousarray(reference[..., :3], dtype=np.float32) / 255.0
    tst = np.ascontiguousarray(test[..., :3], dtype=np.float32) / 255.0
    error_map, mean, _ = flip_evaluator.evaluate(ref, tst, "LDR")
    return float(mean), np.rint(np.clip(error_map, 0.0, 1.0) * 255.0).astype(np.uint8)


def _slug(text: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in text.lower()).strip("_").replace("__", "_")


def knob_renders(knob: Knob, quick: bool, runs: int, passes: int = PASSES) -> int:
    """How many renders :func:`measure_knob` makes: each setting and the reference, once
    and ``runs`` times in each of ``passes`` passes."""
    return (len(knob.chosen(quick)) + 1) * (runs * passes + 1)


T = TypeVar("T")

#: How a pass is timed: ``(the (knob, setting) entries in order, rounds, advance)`` -> milliseconds
#: per entry. :func:`run` times each pass in a process of its own (:func:`processes_timer`).
PassTimer = Callable[[Sequence[tuple[Knob, Setting]], int, Callable[[int], object]], list[list[float]]]


def in_process_timer(context: RenderContext) -> PassTimer:
    """Time each pass here, on ``context`` (what :func:`measure_knobs` does unless told otherwise:
    for knobs no other process can find by name, such as the tests' own)."""

    def timer(entries: Sequence[tuple[Knob, Setting]], rounds: int,
              advance: Callable[[int], object]) -> list[list[float]]:
        return time_pass([functools.partial(setting.render, context) for _, setting in entries], rounds, advance)

    return timer


def processes_timer(size: tuple[int, int], backend: str | None, quick: bool) -> PassTimer:
    """Time each pass in a fresh process (:func:`~glsandbox.measure.timing_pass.time_in_process`)
    that finds the registered knobs by name, renders at ``size`` on ``backend``."""

    def timer(entries: Sequence[tuple[Knob, Setting]], rounds: int,
              advance: Callable[[int], object]) -> list[list[float]]:
        return time_in_process([(knob.name, setting.label) for knob, setting in entries], size, backend, quick,
                               rounds, advance)

    return timer


def interleave(groups: Sequence[Sequence[T]]) -> list[T]:
    """The groups' items taken in turn (``[[a1, a2], [b1]]`` -> ``[a1, b1, a2]``): a timing
    round visits the knobs alternately, so a burst of load on the machine falls on
    settings of several knobs, not on one knob's settings all together."""
    out: list[T] = []
    for depth in range(max((len(g) for g in groups), default=0)):
        out += [g[depth] for g in groups if depth < len(g)]
    return out


def load_average() -> str:
    """The machine's load average over 1, 5 and 15 minutes (``n/a`` where the system has none)."""
    try:
        return ", ".join(f"{value:.2f}" for value in os.getloadavg())
    except (AttributeError, OSError):  # Windows
        return "n/a"


def one_minute_load() -> list[float]:
    """``[the 1-minute load average]``, or ``[]`` where the system has none (Windows)."""
    try:
        return [os.getloadavg()[0]]
    except (AttributeError, OSError):
        return []


def measure_knobs(knobs: Sequence[Knob], context: RenderContext, out: Path, quick: bool, runs: int = RUNS,
                  passes: int = PASSES, log: Callable[[str], None] = lambda s: None,
                  advance: Callable[[int], object] = lambda n: None, flip: bool = True,
                  timer: PassTimer | None = None) -> list[KnobResult]:
    """Render every knob's settings and reference, time them in ``passes`` independent
    passes of ``runs`` rounds that alternate across the knobs (:func:`interleave`,
    :func:`time_pass`), and compare each picture with its knob's reference.

    ``timer`` times one pass (default: here, on ``context``, :func:`in_process_timer`).
    ``advance(1)`` is called after each of the :func:`knob_renders` renders (a progress bar's ``update``).
    ``flip=False`` (flip-evaluator missing) leaves FLIP and the error maps out.
    """
    timer = timer or in_process_timer(context)
    groups = [[(knob, setting) for setting in (*knob.chosen(quick), knob.reference)] for knob in knobs]
    pictures: dict[tuple[str, str], np.ndarray] = {}
    for knob, setting in (entry for group in groups for entry in group):
        log(f"  render {knob.name}: {setting.label}")  # the first render warms caches (programs, targets)
        pictures[knob.name, setting.label] = setting.render(context)
        advance(1)
    entries = interleave(groups)
    passes_times, loads = [], []
    for number in range(passes):
        log(f"  timing pass {number + 1}/{passes}: {runs} rounds over {len(knobs)} knob(s), "
            f"load average {load_average()}")
        loads += one_minute_load()
        passes_times.append(timer(entries, runs, advance))
        loads += one_minute_load()
    busy = machine_busy(loads, os.cpu_count() or 1)
    times = {(k.name, s.label): [t for taken in passes_times for t in taken[i]] for i, (k, s) in enumerate(entries)}
    medians = {(k.name, s.label): [statistics.median(taken[i]) for taken in passes_times]
               for i, (k, s) in enumerate(entries)}
    results = []
    for knob, group in zip(knobs, groups):
        reference = pictures[knob.name, knob.reference.label]
        rows = []
        for _, setting in group:
            key = (knob.name, setting.label)
            picture = pictures[key]
            stem = f"{knob.name}-{_slug(setting.label)}"
            image_path, map_path = Path("images") / f"{stem}.png", Path("error_maps") / f"{stem}.png"
            save_png(np.ascontiguousarray(picture), out / image_path)
            flip_mean: float | None = None
            if flip:
                flip_mean, error_map = flip_error(reference, picture)
                save_png(np.ascontiguousarray(error_map), out / map_path)
            count = None
            if setting.count is not None:
                log(f"  count {knob.count_label} of {setting.label}")
                count = setting.count(context)
            rows.append(Row(knob.name, setting.label, setting is knob.reference, times[key],
                            metrics.rmse(reference, picture), metrics.psnr(reference, picture), flip_mean,
                            str(image_path), str(map_path) if flip else "", count, medians[key], busy))
        results.append(KnobResult(knob, rows))
    return results


def measure_knob(knob: Knob, context: RenderContext, out: Path, quick: bool, runs: int = RUNS,
                 log: Callable[[str], None] = lambda s: None,
                 advance: Callable[[int], object] = lambda n: None, passes: int = PASSES,
                 flip: bool = True) -> KnobResult:
    """:func:`measure_knobs` of one knob."""
    return measure_knobs([knob], context, out, quick, runs, passes, log, advance, flip)[0]


def run(out: Path, quick: bool = False, backend: str | None = None, runs: int = RUNS,
        only: Sequence[str] = (), log: Callable[[str], None] | None = None, passes: int = PASSES) -> list[KnobResult]:
    """Measure every available knob (or the ``only`` ones) and write the report into ``out``."""
    if runs < 5:
        raise SandboxError(f"--runs {runs}: the timing needs at least 5 runs")
    if passes < 2:
        raise SandboxError(f"--passes {passes}: a run-to-run spread needs at least 2 passes")
    say = log or progress_line
    knobs = all_knobs()
    if only:
        unknown = [name for name in only if name not in {k.name for k in knobs}]
        if unknown:
            raise SandboxError(f"unknown knob {unknown[0]!r}; knobs: {', '.join(k.name for k in knobs)}")
        knobs = [k for k in knobs if k.name in only]
    extra.require_all()  # before anything is rendered or written
    flip = extra.has_flip()
    if not flip:
        say(extra.FLIP_MISSING)
    try:
        for folder in (out, out / "images", out / "error_maps"):
            folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot create folder ({exc.strerror})") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise SandboxError(f"--out {out}: folder is not writable")
    size = QUICK_SIZE if quick else FULL_SIZE
    context = RenderContext(size, backend)
    skipped: dict[str, str] = {}
    measured = []
    for number, knob in enumerate(knobs, start=1):
        reason = knob.unavailable()
        if reason:
            say(f"[{number}/{len(knobs)}] {knob.name}: skipped ({reason})")
            skipped[knob.name] = reason
        else:
            say(f"[{number}/{len(knobs)}] {knob.name}: {len(knob.chosen(quick))} settings + reference")
            measured.append(knob)
    load_before = load_average()
    bar = progress(sum(knob_renders(knob, quick, runs, passes) for knob in measured), "tradeoffs", "render")
    try:
        try:
            results = measure_knobs(measured, context, out, quick, runs, passes, lambda text: say(text), bar.update,
                                    flip, processes_timer(size, context.renderer.host.backend, quick))
        except OSError as exc:  # its images could not be written
            raise SandboxError(f"--out {out}: cannot write ({exc.strerror or exc})") from None
        host = context.renderer.host
        info = {"renderer": str(host.renderer), "backend": str(host.backend), "size": f"{size[0]}x{size[1]}",
                "runs": str(runs), "passes": str(passes), "quick": "yes" if quick else "no",
                "load": f"{load_before} before, {load_average()} after", "cpus": str(os.cpu_count() or "?")}
    finally:
        bar.close()
        context.close()
    say(f"tradeoffs: load average (1, 5, 15 min) {info['load']}")
    try:  # a full disk or a folder made read-only meanwhile: one line, no half-written file
        write_csv(results, size, out / "tradeoffs.csv")
        write_report(results, info, out / "report.md", skipped)
        write_plot(results, out / "tradeoffs.png")
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot write ({exc.strerror or exc})") from None
    say(f"tradeoffs: {len(results)} knobs -> {out / 'report.md'}, {out / 'tradeoffs.csv'}, {out / 'tradeoffs.png'}")
    return results
