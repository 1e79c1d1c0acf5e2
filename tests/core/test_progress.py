"""Long commands show progress with the time left on a terminal, and nothing extra when stderr is not one."""

from __future__ import annotations

import io
import json
import re
import time
from pathlib import Path

import numpy as np
import pytest

from glsandbox import cli
from glsandbox.measure import bench, tradeoffs
from glsandbox.measure.knob import Knob, Setting
from glsandbox.progress import progress, say


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_terminal_gets_a_bar_with_the_count_and_the_time_left() -> None:
    screen = Terminal()
    with progress(3, "tour", "lesson", file=screen) as bar:
        for _ in range(3):
            time.sleep(0.3)  # longer than the bar's redraw interval
            bar.update(1)
    drawn = screen.getvalue()
    assert "tour:" in drawn and "0/3" in drawn and "2/3" in drawn
    assert re.search(r"2/3 \[00:00<00:00, +[\d.]+ lesson/s\]", drawn), drawn  # [elapsed<time left, rate]
    assert drawn.endswith("\r")  # the bar is wiped at the end: the command's own lines stay


def test_a_pipe_or_a_file_gets_no_bar_only_the_lines() -> None:
    piped = io.StringIO()
    with progress(3, "tour", "lesson", file=piped) as bar:
        say("[1/3] triangle: ok", file=piped)
        bar.update(3)
    assert piped.getvalue() == "[1/3] triangle: ok\n"


class Recorded:
    """Stands in for :func:`progress`: what each bar was made for and how far it got."""

    def __init__(self) -> None:
        self.bars: list[dict] = []

    def __call__(self, total: int, what: str, unit: str = "step", file=None):
        record = {"total": total, "what": what, "done": 0, "closed": False}
        self.bars.append(record)

        class Bar:
            def update(self, n: int = 1) -> None:
                record["done"] += n

            def close(self) -> None:
                record["closed"] = True

            def __enter__(self):
                return self

            def __exit__(self, *exc) -> None:
                self.close()

        return Bar()


@pytest.fixture
def recorded(monkeypatch) -> Recorded:
    bars = Recorded()
    for module in (cli, bench, tradeoffs):
        monkeypatch.setattr(module, "progress", bars)
    return bars


def test_tour_counts_every_lesson(recorded, tmp_path, gl, capsys) -> None:
    assert cli.main(["tour", "--out", str(tmp_path), "--size", "32x24"]) == 0
    (bar,) = recorded.bars
    lessons = json.loads((tmp_path / "tour.json").read_text())["lessons"]
    assert bar["what"] == "tour" and bar["total"] == bar["done"] == len(lessons) > 10
    assert bar["closed"]
    assert "[1/" in capsys.readouterr().err  # the lines are still there (say), above the bar


def test_compare_counts_each_tile_twice(recorded, tmp_path, gl, capsys) -> None:
    out = tmp_path / "c.png"
    assert cli.main(["compare", "phong", "--vary", "shading=phong,gouraud,blinn_phong", "--size", "90x30",
                     "--out", str(out)]) == 0
    (bar,) = recorded.bars
    assert bar == {"total": 6, "what": "compare", "done": 6, "closed": True}


def test_bench_counts_each_case_per_round_and_its_warm_up() -> None:
    calls: list[int] = []
    side = bench.Side("x", lambda k: calls.append(k))
    cases = [bench.Case("g", f"case {n}", side, side) for n in range(3)]
    steps: list[int] = []
    bench.measure(cases, rounds=4, advance=steps.append)
    assert steps == [1] * (3 * (4 + 1))


def test_tradeoffs_counts_every_render_of_a_knob(tmp_path) -> None:
    renders: list[str] = []

    def setting(label: str) -> Setting:
        def render(context) -> np.ndarray:
            renders.append(label)
            return np.full((8, 8, 4), 100 if label == "ref" else 90, np.uint8)
        return Setting(label, render)

    knob = Knob("fake", "a fake knob", "phong", (setting("a"), setting("b")), setting("ref"), "the reference")
    for folder in ("images", "error_maps"):
        (tmp_path / folder).mkdir()
    steps: list[int] = []
    tradeoffs.measure_knob(knob, context=None, out=tmp_path, quick=False, runs=5, advance=steps.append)
    # the bar counts the planned renders (each setting and the reference, once and 5 times in each of 3 passes) ...
    assert steps == [1] * tradeoffs.knob_renders(knob, quick=False, runs=5) == [1] * (3 * (1 + 5 * tradeoffs.PASSES))
    # ... and cheap settings whose median is not yet stable are timed again beyond them,
    # which no total can know in advance: only re-timings of the settings, never a new picture
    assert len(renders) >= len(steps) and set(renders[len(steps):]) <= {"a", "b", "ref"}


@pytest.mark.slow
def test_check_a_folder_counts_each_submission(recorded, tmp_path, gl, capsys) -> None:
    scene = 'name = "cube"\n[[nodes]]\nmesh = "cube"\n'
    ref = tmp_path / "ref.png"
    (tmp_path / "model.toml").write_text(scene)
    assert cli.main(["check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update",
                     "--size", "32x24"]) == 0
    subs = tmp_path / "subs"
    subs.mkdir()
    for name in ("alice", "bob", "carol"):
        (subs / f"{name}.toml").write_text(scene)
    capsys.readouterr()
    assert cli.main(["check", str(subs), "--golden", str(ref), "--size", "32x24", "--jobs", "1"]) == 0
    assert recorded.bars == [{"total": 3, "what": "check", "done": 3, "closed": True}]
    out = capsys.readouterr().out
    assert [f"[{n}/3]" in out for n in (1, 2, 3)] == [True] * 3  # the lines stay, on stdout


def test_ready_imports_the_bar_only_where_one_is_drawn() -> None:
    """On a terminal, tqdm is imported by ready(), before the first line; elsewhere never, and a
    bar there is one that draws nothing."""
    import subprocess
    import sys

    script = ("import io, sys\n"
              "from glsandbox import progress\n"
              "progress.ready()\n"
              "with progress.progress(3, 'check', 'submission') as bar:\n"
              "    bar.update(1)\n"
              "    progress.say('a line')\n"
              "piped = 'tqdm' in sys.modules\n"
              "class Terminal(io.StringIO):\n"
              "    def isatty(self):\n"
              "        return True\n"
              "sys.stderr = Terminal()\n"
              "progress.ready()\n"
              "print(piped, 'tqdm' in sys.modules)\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "True"]
    assert proc.stderr == "a line\n"
