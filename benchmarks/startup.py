"""Benchmark: cold start (process start to the first PNG) and the full ``tour``.

Cold start: ``glsandbox render indexed_cube`` at 800x600 vs the raw ModernGL
script path of ``cube_frame.py --raw-once`` (context, resources, one frame,
one PNG). The "extra CPU" column is the glsandbox process's CPU beyond the
raw script's (user and system, all threads: the child processes' rusage),
steadier than wall time on a busy machine. The tour renders every lesson in
one process; it has no baseline, its time is printed on its own.
"""

from __future__ import annotations

import sys
from pathlib import Path

from _scratch import scratch_folder

_TMP = scratch_folder("glsandbox-bench-")

#: The goal: cold start (with bytecode compiled) at most this ratio of the raw script's.
COLD_START_GOAL = 1.2


def cases(env) -> list:
    from glsandbox.measure.bench import Case, Side, run_process

    tmp = _TMP
    here = Path(__file__).resolve().parent
    ours = [sys.executable, "-m", "glsandbox.cli", "render", "indexed_cube", "--size", "800x600",
            "--backend", "egl", "--out", str(tmp / "ours.png")]
    raw = [sys.executable, str(here / "cube_frame.py"), "--raw-once", str(tmp / "raw.png")]
    tour = [sys.executable, "-m", "glsandbox.cli", "tour", "--backend", "egl", "--out", str(tmp / "tour")]
    return [
        Case("startup", "cold start to first PNG", Side("raw ModernGL script", run_process(raw)),
             Side("glsandbox render", run_process(ours)), repeat=1, unit="s",
             goal=COLD_START_GOAL),
        Case("startup", "full tour (every lesson, 640x480)", None, Side("glsandbox tour", run_process(tour)),
             repeat=1, unit="s"),
    ]
