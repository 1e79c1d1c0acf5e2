"""What ``glsandbox tradeoffs`` writes (glsandbox/measure/tradeoffs_report.py): whether a knob's
errors fall along its order, the knobs not measured and why, the CSV's columns. Hand-made rows:
nothing is rendered and no time is measured. (A time cell and its spread: test_tradeoffs.py.)"""

from __future__ import annotations

import csv

from glsandbox.measure.knob import Knob, KnobResult, Row, Setting
from glsandbox.measure.tradeoffs_report import CSV_COLUMNS, write_csv, write_report


def row(setting: str, rmse: float, reference: bool = False) -> Row:
    return Row("k", setting, reference, [2.0] * 5, rmse, 40.0, None, pass_medians=[2.0, 2.0])


KNOB = Knob("k", "A knob", "phong", tuple(Setting(s, lambda c: None) for s in ("low", "a | b", "high")),
            Setting("ref", lambda c: None), "r", monotone=("low", "high"))
INFO = {"renderer": "llvmpipe", "backend": "egl", "size": "128x96", "runs": "5", "passes": "2", "quick": "yes"}


def test_the_report_says_whether_errors_fall_along_the_knobs_order(tmp_path) -> None:
    falls = KnobResult(KNOB, [row("low", 0.3), row("a | b", 0.2), row("high", 0.1), row("ref", 0.0, True)])
    grows = KnobResult(KNOB, [row("low", 0.1), row("high", 0.3), row("ref", 0.0, True)])
    write_report([falls], INFO, tmp_path / "falls.md")
    write_report([grows], INFO, tmp_path / "grows.md", skipped={"k": "x", "other": "needs embree"})
    falls_text, grows_text = ((tmp_path / f"{n}.md").read_text(encoding="utf-8") for n in ("falls", "grows"))
    assert "Error order low >= high (RMSE): holds." in falls_text
    assert "Error order low >= high (RMSE): DOES NOT HOLD." in grows_text
    assert "| a \\| b | " in falls_text and "| ref (reference) | " in falls_text  # a "|" in a label is escaped
    assert "## Not measured yet\n\n- `other`: needs embree" in grows_text and "`k`: x" not in grows_text
    assert "Not measured yet" not in falls_text


def test_the_report_says_how_its_times_were_taken_with_every_figure_filled_in(tmp_path) -> None:
    write_report([KnobResult(KNOB, [row("low", 0.1), row("ref", 0.0, True)])], INFO, tmp_path / "r.md")
    text = (tmp_path / "r.md").read_text(encoding="utf-8")
    assert "2 independent passes of 5 timed rounds, each pass in a process of its own" in text
    assert "where the passes differ by more than 20%, or the load average passed 2 runnable threads" in text
    assert "{" not in text and "}" not in text  # no placeholder left unformatted


def test_the_csv_has_a_row_per_setting_in_its_columns(tmp_path) -> None:
    knob = Knob("k", "A knob", "phong", (Setting("MSAA 4x", lambda c: None),), Setting("ref", lambda c: None), "r")
    reference = Row("k", "ref", True, [2.0, 2.0, 2.0], 0.0, float("inf"), None, pass_medians=[2.0, 2.0])
    write_csv([KnobResult(knob, [row("MSAA 4x", 0.01), reference])], (128, 96), tmp_path / "t.csv")
    with (tmp_path / "t.csv").open(encoding="utf-8", newline="") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == CSV_COLUMNS and [r["setting"] for r in rows] == ["MSAA 4x", "ref"]
    assert (rows[0]["width"], rows[0]["height"], rows[0]["reference"]) == ("128", "96", "0")
    assert rows[1]["flip"] == "" and rows[1]["reference"] == "1"  # no FLIP figure: flip-evaluator was missing
