"""How ``glsandbox tradeoffs`` times (glsandbox/measure/tradeoffs.py): rounds that take the
knobs in turn, and independent passes whose medians give each figure's run-to-run spread. Fake settings with a fake clock:
nothing is rendered and no time is measured."""

from __future__ import annotations

import numpy as np

from glsandbox.measure import tradeoffs
from glsandbox.measure.knob import Knob, Setting


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
