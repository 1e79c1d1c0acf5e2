"""One timing pass of ``glsandbox tradeoffs`` in a process of its own.

Two passes timed in one process agree with each other better than two runs
of the command do: three quick runs on a quiet machine (load under 1) put
one run's medians 8-10% above the others' across every knob, while each
run's own two passes agreed within 2-5%. What moves between runs is what a
process fixes once: where the interpreter, llvmpipe's compiled shaders and
the frame buffers land in memory, which core the process starts on. A pass
in a fresh process samples those as a fresh run does, so the passes' spread
is the run-to-run spread the report promises.

The parent (:func:`glsandbox.measure.tradeoffs.measure_knobs`) calls
:func:`time_in_process` once per pass. It starts ``python -m
glsandbox.measure.timing_pass``, writes the request (the knobs' names,
the settings in the order to time them, the frame size, the backend, the
rounds) as one JSON line on its stdin, and reads back one ``rendered`` line
per timed render of the rounds (the progress bar's steps) and a last line
``times`` with the milliseconds of every render. The child renders every
setting once before its clock starts (its own programs compiled, its
targets made: the first frame of a process is not a figure), then runs
:func:`glsandbox.measure.tradeoffs.time_pass`.

A failing child ends the run with its last error line; Ctrl-C (or any
exception in the parent) kills it before the exception goes on.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence

from glsandbox.errors import SandboxError
from glsandbox.measure.knob import median_spread

__all__ = ["CHEAP_MS", "MAX_RUNS", "RENDERED", "STABLE_SPREAD", "TIMES", "time_in_process", "time_pass"]

#: A setting faster than this is "cheap": its runs repeat (interleaved) until its
#: median is stable, :func:`~glsandbox.measure.knob.median_spread` under
#: :data:`STABLE_SPREAD`, or it has :data:`MAX_RUNS` runs. A 0.6 ms frame's
#: 5-run median measured anywhere in 0.47-3.09 ms: noise, not a figure.
CHEAP_MS = 100.0
STABLE_SPREAD = 0.05
MAX_RUNS = 61

#: The child's line after each timed render of the rounds, and the prefix of its last line.
RENDERED, TIMES = "rendered", "times "


def time_pass(renders: Sequence[Callable[[], object]], rounds: int, advance: Callable[[int], object] = lambda n: None,
              clock: Callable[[], float] = time.perf_counter) -> list[list[float]]:
    """One pass: ``rounds`` rounds, each calling every render once (in the given order,
    reversed every other round so no render always follows the same one), then more
    rounds of the cheap ones (median under :data:`CHEAP_MS`) until their median is stable
    (:func:`~glsandbox.measure.knob.median_spread` under :data:`STABLE_SPREAD`) or they have
    :data:`MAX_RUNS` runs. Milliseconds per render."""
    times: list[list[float]] = [[] for _ in renders]

    def timed(index: int) -> None:
        start = clock()
        renders[index]()
        times[index].append((clock() - start) * 1e3)

    for number in range(rounds):
        order = range(len(renders)) if number % 2 == 0 else reversed(range(len(renders)))
        for index in order:
            timed(index)
            advance(1)
    while True:
        unstable = [i for i, taken in enumerate(times) if statistics.median(taken) < CHEAP_MS
                    and len(taken) < MAX_RUNS and median_spread(taken) >= STABLE_SPREAD]
        if not unstable:
            return times
        for index in unstable:
            timed(index)


def time_in_process(entries: Sequence[tuple[str, str]], size: tuple[int, int], backend: str | None, quick: bool,
                    rounds: int, advance: Callable[[int], object] = lambda n: None) -> list[list[float]]:
    """Milliseconds of each ``(knob name, setting label)`` of ``entries`` (a list per entry), timed
    over ``rounds`` rounds by a fresh ``glsandbox.measure.timing_pass``."""
    request = {"entries": [list(e) for e in entries], "size": list(size), "backend": backend, "quick": quick,
               "rounds": rounds}
    child = subprocess.Popen([sys.executable, "-m", "glsandbox.measure.timing_pass"], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, encoding="utf-8")
    try:
        assert child.stdin is not None and child.stdout is not None and child.stderr is not None
        child.stdin.write(json.dumps(request) + "\n")
        child.stdin.close()
        times = None
        for line in child.stdout:
            if line.startswith(TIMES):
                times = json.loads(line[len(TIMES):])
            elif line.strip() == RENDERED:
                advance(1)
        errors = child.stderr.read()
        code = child.wait()
    finally:
        if child.poll() is None:  # Ctrl-C or an error here: the child goes with the run
            child.kill()
            child.wait()
    if code != 0 or times is None or len(times) != len(entries):
        last = (errors.strip().splitlines() or [f"exit status {code}"])[-1]
        raise SandboxError(f"tradeoffs: a timing pass failed: {last}")
    return times


def _serve(request: dict) -> list[list[float]]:
    """The child's side: find the knobs' settings, render each once, then time the rounds."""
    import functools

    from glsandbox.measure.knob import all_knobs
    from glsandbox.measure.render_context import RenderContext

    knobs = {knob.name: knob for knob in all_knobs()}
    settings = []
    for name, label in request["entries"]:
        if name not in knobs:
            raise SandboxError(f"unknown knob {name!r}")
        knob = knobs[name]
        found = [s for s in (*knob.chosen(request["quick"]), knob.reference) if s.label == label]
        if not found:
            raise SandboxError(f"knob {name!r} has no setting {label!r}")
        settings.append(found[0])
    context = RenderContext(tuple(request["size"]), request["backend"])
    try:
        renders = [functools.partial(setting.render, context) for setting in settings]
        for render in renders:  # untimed: this process's programs, targets and caches made
            render()

        def rendered(n: int) -> None:
            print(RENDERED, flush=True)

        return time_pass(renders, request["rounds"], rendered)
    finally:
        context.close()


def main() -> int:
    try:
        times = _serve(json.loads(sys.stdin.readline()))
    except KeyboardInterrupt:  # Ctrl-C reached the whole process group: the parent says so
        return 130
    except Exception as exc:  # one line for the parent's error (a SandboxError names what failed)
        print(str(exc) or type(exc).__name__, file=sys.stderr)
        return 1
    print(TIMES + json.dumps(times), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
