"""``glsandbox bench --json`` figures as the docs' Markdown tables (glsandbox/measure/bench_tables.py):
a table per group under the run's header line, each cell from the data, and notes under them."""

from __future__ import annotations

import pytest

from glsandbox.measure.bench_tables import bench_tables

TIME = {"median": 1.25, "min": 1.0, "max": 2.5}


def _data(**extra) -> dict:
    cases = [
        {"group": "start-up", "name": "render", "baseline": "raw ModernGL", "subject": "glsandbox render",
         "unit": "s", "baseline_time": TIME, "subject_time": TIME, "ratio": 1.0, "goal": 1.2, "goal_met": True,
         "extra_cpu_us": 250000.0},
        {"group": "frames", "name": "a | b", "baseline": None, "subject": "phong", "unit": "ms",
         "baseline_time": None, "subject_time": TIME, "ratio": None, "extra_cpu_us": 12.0, "cpu_goal_us": 50,
         "cpu_goal_met": False},
    ]
    return {"cases": cases, "renderer": "llvmpipe", "rounds": 5, "date": "2026-01-02", "machine": "a laptop"} | extra


def test_a_table_per_group_with_each_cases_figures() -> None:
    text = bench_tables(_data())
    lines = text.splitlines()
    assert lines[0] == ("Measured 2026-01-02 on a laptop, llvmpipe; 5 alternating rounds; ratio = subject / "
                        "baseline (medians), spread min-max in brackets.")
    assert [line for line in lines if line.startswith("### ")] == ["### start-up", "### frames"]
    assert ("| render | raw ModernGL | glsandbox render | 1.250 s (1.000-2.500) | 1.250 s (1.000-2.500) | 1.00x | "
            "≤ 1.20x: met | +0.250 s |") in lines
    # A "|" in a name is escaped; a missing baseline, ratio and goal are "-"; CPU in µs for ms cases.
    assert r"| a \| b | - | phong | - | 1.250 ms (1.000-2.500) | - | - | +12 µs (≤ 50 µs: not met) |" in lines
    assert "Notes from the run" not in text


def test_quick_runs_and_notes_are_said() -> None:
    text = bench_tables(_data(quick=True, notes=["embree\nmissing"], date=None) | {"date": "today"})
    assert "5 alternating rounds, --quick;" in text and text.endswith("Notes from the run:\n\n- embree missing\n")


@pytest.mark.parametrize("key", ["cases", "renderer", "rounds"])
def test_json_not_written_by_bench_is_refused(key: str) -> None:
    data = _data()
    del data[key]
    with pytest.raises(ValueError, match=f"without '{key}'"):
        bench_tables(data)
