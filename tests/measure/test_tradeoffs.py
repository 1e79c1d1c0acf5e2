"""How ``glsandbox tradeoffs`` times (glsandbox/measure/tradeoffs.py): rounds that take the
knobs in turn, independent passes whose medians give each figure's run-to-run spread, and a
report that gives no figure where the passes disagree or the machine was too busy. Fake settings with a fake clock:
nothing is rendered and no time is measured."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from glsandbox.measure import tradeoffs
from glsandbox.measure.knob import Knob, Row, Setting, machine_busy, run_spread
from glsandbox.measure.tradeoffs_report import time_cell, write_report


def test_interleave_takes_the_knobs_in_turn() -> None:
    assert tradeoffs.interleave([["a1", "a2", "a3"], ["b1"], ["c1", "c2"]]) == ["a1", "b1", "c1", "a2", "c2", "a3"]
    assert tradeoffs.interleave([]) == []


def test_a_pass_times_every_render_each_round_and_reverses_every_other_round() -> None:
    calls: list[int] = []
    clock = iter(range(10_000))
    renders = [lambda i=i: calls.append(i) for i in range(3)]
    times = tradeoffs.time_pass(renders, 4, clock=lambda: next(clock) * 1.0)  # 1000 ms a render: not cheap
    assert calls == [0, 1, 2, 2, 1, 0, 0, 1, 2, 2, 1, 0]
    assert all(t == [1000.0] * 4 for t in times)


def test_a_cheap_render_with_an_unstable_median_runs_again_within_its_pass() -> None:
    steps = iter([0.3, 3.0] * 40)  # alternately fast and slow: odd and even runs' medians disagree
    now = [0.0]

    def clock() -> float:
        return now[0]

    def render() -> None:
        now[0] += next(steps) / 1e3

    times = tradeoffs.time_pass([render], 5, clock=clock)
    assert len(times[0]) == tradeoffs.MAX_RUNS or tradeoffs.median_spread(times[0]) < tradeoffs.STABLE_SPREAD
    assert len(times[0]) > 5


def test_measure_knobs_alternates_rounds_across_knobs_and_keeps_each_pass_median(tmp_path) -> None:
    renders: list[str] = []

    def setting(label: str) -> Setting:
        def render(context) -> np.ndarray:
            renders.append(label)
            return np.full((8, 8, 4), 100 if label.endswith("ref") else 90, np.uint8)
        return Setting(label, render)

    knobs = [Knob(name, name, "phong", (setting(f"{name}1"),), setting(f"{name}ref"), "ref") for name in "ab"]
    for folder in ("images", "error_maps"):
        (tmp_path / folder).mkdir()
    results = tradeoffs.measure_knobs(knobs, None, tmp_path, quick=False, runs=5, passes=2)
    first_round = renders[4:8]  # after the four warm-up pictures
    assert first_round == ["a1", "b1", "aref", "bref"]  # the knobs in turn
    for result in results:
        for row in result.rows:
            assert len(row.pass_medians) == 2 and len(row.times_ms) >= 10


def test_run_spread_is_the_passes_medians_apart() -> None:
    assert math.isclose(run_spread([1.66, 8.37]), (8.37 - 1.66) / 5.015)
    assert math.isclose(run_spread([2.0, 2.1, 2.0]), 0.1 / 2.0)
    assert math.isinf(run_spread([2.0]))


def row(medians: list[float], busy: str | None = None) -> Row:
    return Row("k", "MSAA 4x", False, [m for m in medians for _ in range(5)], 0.01, 40.0, 0.02,
               "images/a.png", "error_maps/a.png", None, medians, busy)


def test_the_machine_is_busy_above_two_runnable_threads_a_cpu() -> None:
    assert machine_busy([3.9, 4.0], 2) is None  # this run's own threads on an idle 2-CPU machine
    assert machine_busy([3.9, 12.11], 2) == "machine busy: load 12.1 on 2 CPUs"  # any pass's start or end
    assert machine_busy([2.5], 1) == "machine busy: load 2.5 on 1 CPU"
    assert machine_busy([], 2) is None  # no load average (Windows): the passes' spread alone decides


def test_passes_that_agree_on_a_busy_machine_give_no_figure(tmp_path) -> None:
    busy = row([36.6, 36.8], "machine busy: load 12.1 on 2 CPUs")
    assert row([36.6, 36.8]).trusted and not busy.trusted
    assert time_cell(busy) == "too noisy (machine busy: load 12.1 on 2 CPUs; passes 36.60, 36.80 ms: ±1%)"
    knob = Knob("k", "A knob", "phong", (Setting("MSAA 4x", lambda c: None),), Setting("ref", lambda c: None), "r")
    from glsandbox.measure.knob import KnobResult

    info = {"renderer": "llvmpipe", "backend": "egl", "size": "128x96", "runs": "5", "passes": "2", "quick": "yes"}
    write_report([KnobResult(knob, [busy])], info, tmp_path / "report.md")
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert ("Too noisy to give a time: machine busy: load 12.1 on 2 CPUs, more than 2 runnable threads a CPU "
            "while it was timed") in report


def test_measure_knobs_reads_the_load_at_each_pass_and_marks_a_busy_run(tmp_path, monkeypatch) -> None:
    loads = iter([1.0, 1.5, 9.0, 1.0])  # the second pass started on a busy machine
    monkeypatch.setattr(tradeoffs, "one_minute_load", lambda: [next(loads)])
    monkeypatch.setattr(tradeoffs.os, "cpu_count", lambda: 2)
    setting = Setting("s", lambda context: np.zeros((4, 4, 4), np.uint8))
    knob = Knob("k", "k", "phong", (setting,), Setting("ref", lambda context: np.zeros((4, 4, 4), np.uint8)), "r")
    for folder in ("images", "error_maps"):
        (tmp_path / folder).mkdir()
    [result] = tradeoffs.measure_knobs([knob], None, tmp_path, quick=False, runs=5, passes=2, flip=False)
    assert {r.busy for r in result.rows} == {"machine busy: load 9.0 on 2 CPUs"}
    assert not any(r.trusted for r in result.rows)


@given(st.lists(st.floats(0.05, 500.0), min_size=2, max_size=6))
def test_the_stated_range_holds_every_pass_median(medians) -> None:
    """A figure is the median ± the whole spread of the passes' medians: each pass, a run of its own,
    lands inside the range the report states (± half the spread would leave the extreme passes out)."""
    r = row(medians)
    if not r.trusted:
        return
    figure, stated = time_cell(r).split(" ±")
    assert figure == f"{r.median_ms:.2f}"
    percent = int(stated.removesuffix("%"))
    assert all(abs(m - r.median_ms) <= percent / 100 * r.median_ms * (1 + 1e-9) for m in medians), (medians, percent)


def test_the_stated_spread_is_never_narrower_than_whole_runs_move() -> None:
    """Passes that agree closely still get ± the drift of whole runs (RUN_DRIFT), and a sub-millisecond
    frame ± its noise (FRAME_NOISE_MS); passes further apart than that get their own range."""
    from glsandbox.measure.knob import FRAME_NOISE_MS, RUN_DRIFT

    assert row([18.9, 18.95, 19.0]).stated_spread == RUN_DRIFT
    assert row([0.20, 0.201]).stated_spread == FRAME_NOISE_MS / row([0.20, 0.201]).median_ms
    assert row([10.0, 11.5]).stated_spread == row([10.0, 11.5]).run_spread > RUN_DRIFT
    assert time_cell(row([0.20, 0.201])) == "0.20 ±25%"


def test_a_time_whose_passes_disagree_gets_no_figure(tmp_path) -> None:
    assert time_cell(row([1.66, 1.70])) == "1.68 ±10%"  # passes within 3%: the runs' drift
    assert time_cell(row([1.66, 8.37])) == "too noisy (passes 1.66, 8.37 ms: ±134%)"
    knob = Knob("k", "A knob", "phong", (Setting("MSAA 4x", lambda c: None),), Setting("ref", lambda c: None), "r")
    from glsandbox.measure.knob import KnobResult

    info = {"renderer": "llvmpipe", "backend": "egl", "size": "128x96", "runs": "5", "passes": "2", "quick": "yes",
            "load": "3.10, 2.50, 2.00 before, 3.20, 2.60, 2.00 after", "cpus": "2"}
    write_report([KnobResult(knob, [row([1.66, 8.37])])], info, tmp_path / "report.md")
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "| MSAA 4x | too noisy (passes 1.66, 8.37 ms: ±134%) |" in report
    assert "Too noisy to give a time (1 of 1 settings)" in report
    assert "Load average (1, 5, 15 min) on 2 CPUs: 3.10, 2.50, 2.00 before, 3.20, 2.60, 2.00 after." in report
