"""What ``glsandbox tradeoffs`` writes (glsandbox/measure/tradeoffs_report.py): a time cell with its
run-to-run spread, or no figure where the passes disagree; the CSV's columns. Hand-made rows:
nothing is rendered and no time is measured."""

from __future__ import annotations

import csv

from glsandbox.measure.knob import Knob, KnobResult, Row, Setting
from glsandbox.measure.tradeoffs_report import CSV_COLUMNS, time_cell, write_csv, write_report


def row(medians: list[float]) -> Row:
    return Row("k", "MSAA 4x", False, [m for m in medians for _ in range(5)], 0.01, 40.0, 0.02,
               "images/a.png", "error_maps/a.png", None, medians)


def test_a_time_whose_passes_disagree_gets_no_figure(tmp_path) -> None:
    assert time_cell(row([1.66, 1.70])) == "1.68 ±1%"
    assert time_cell(row([1.66, 8.37])) == "too noisy (passes 1.66, 8.37 ms: ±67%)"
    knob = Knob("k", "A knob", "phong", (Setting("MSAA 4x", lambda c: None),), Setting("ref", lambda c: None), "r")
    info = {"renderer": "llvmpipe", "backend": "egl", "size": "128x96", "runs": "5", "passes": "2", "quick": "yes",
            "load": "3.10, 2.50, 2.00 before, 3.20, 2.60, 2.00 after", "cpus": "2"}
    write_report([KnobResult(knob, [row([1.66, 8.37])])], info, tmp_path / "report.md")
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "| MSAA 4x | too noisy (passes 1.66, 8.37 ms: ±67%) |" in report
    assert "Too noisy to give a time (1 of 1 settings)" in report
    assert "Load average (1, 5, 15 min) on 2 CPUs: 3.10, 2.50, 2.00 before, 3.20, 2.60, 2.00 after." in report


def test_the_csv_has_a_row_per_setting_in_its_columns(tmp_path) -> None:
    knob = Knob("k", "A knob", "phong", (Setting("MSAA 4x", lambda c: None),), Setting("ref", lambda c: None), "r")
    reference = Row("k", "ref", True, [2.0, 2.0, 2.0], 0.0, float("inf"), None, pass_medians=[2.0, 2.0])
    write_csv([KnobResult(knob, [row([1.66, 1.70]), reference])], (128, 96), tmp_path / "t.csv")
    with (tmp_path / "t.csv").open(encoding="utf-8", newline="") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == CSV_COLUMNS and [r["setting"] for r in rows] == ["MSAA 4x", "ref"]
    assert (rows[0]["width"], rows[0]["height"], rows[0]["reference"]) == ("128", "96", "0")
    assert rows[1]["flip"] == "" and rows[1]["reference"] == "1"  # no FLIP figure: flip-evaluator was missing
