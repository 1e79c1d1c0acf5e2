"""A knob of ``glsandbox tradeoffs`` (glsandbox/measure/knob.py): the registry, what a setting's
row says about its timing (stable, trusted) and whether errors fall along the knob's order."""

from __future__ import annotations

import math

import pytest

from glsandbox.measure import knob as knob_module
from glsandbox.measure.knob import Knob, KnobResult, Row, Setting, all_knobs, median_spread, register_knob


def test_median_spread_is_the_odd_and_even_runs_medians_apart() -> None:
    assert median_spread([1.0, 3.0, 1.0, 3.0]) == pytest.approx(2.0 / 2.0)  # odd runs 1, even runs 3, median 2
    assert median_spread([2.0, 2.0, 2.0, 2.0]) == 0.0
    assert math.isinf(median_spread([2.0]))


@pytest.mark.parametrize("times, stable", [([1.0, 1.0, 1.02, 0.99, 1.0, 1.01], True),
                                           ([0.5, 3.0, 0.5, 3.1, 0.6, 2.9], False)])
def test_median_spread_tells_a_stable_median(times, stable) -> None:
    assert (median_spread(times) < 0.05) is stable


def _row(setting: str, rmse: float, medians: list[float]) -> Row:
    return Row("k", setting, False, [1.0, 1.0], rmse, 30.0, None, pass_medians=medians)


def test_a_row_is_trusted_while_its_passes_agree_within_the_wide_spread() -> None:
    assert _row("a", 0.1, [1.0, 1.0 + knob_module.WIDE_SPREAD * 0.99]).trusted
    assert not _row("a", 0.1, [1.0, 1.3]).trusted
    assert not _row("a", 0.1, [1.0]).trusted  # one pass: no spread to give


def _knob(*monotone: str) -> Knob:
    settings = tuple(Setting(label, lambda c: None) for label in ("low", "mid", "high"))
    return Knob("k", "A knob", "phong", settings, Setting("ref", lambda c: None), "r", monotone=monotone)


def test_errors_must_not_grow_along_the_knobs_order() -> None:
    rows = [_row("low", 0.3, []), _row("mid", 0.2, []), _row("high", 0.25, [])]
    assert KnobResult(_knob("low", "mid"), rows).monotone_ok() is True
    assert KnobResult(_knob("low", "mid", "high"), rows).monotone_ok() is False
    assert KnobResult(_knob("low"), rows).monotone_ok() is None  # one setting: nothing to compare
    assert KnobResult(_knob(), rows).row("mid").rmse == 0.2


def test_every_knob_module_registers_its_knob_and_they_come_in_order(monkeypatch) -> None:
    knobs = all_knobs()
    assert len({k.name for k in knobs}) == len(knobs) >= 10
    assert [k.order for k in knobs] == sorted(k.order for k in knobs)
    monkeypatch.setattr(knob_module, "_KNOBS", dict(knob_module._KNOBS))
    first = _knob()
    register_knob(Knob("k", "A knob", "phong", first.settings, first.reference, "r", order=-1))
    assert all_knobs()[0].name == "k"


def test_quick_keeps_the_knobs_quick_settings() -> None:
    knob = _knob()
    assert [s.label for s in knob.chosen(quick=True)] == ["low", "mid", "high"]  # no quick list: all
    quick = Knob("k", "A knob", "phong", knob.settings, knob.reference, "r", quick=("high", "low"))
    assert [s.label for s in quick.chosen(quick=True)] == ["low", "high"]  # in the knob's order
    assert len(quick.chosen(quick=False)) == 3
