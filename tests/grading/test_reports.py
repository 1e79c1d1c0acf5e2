"""The report writers on results made here: names with any bytes, every outcome, every format."""

from __future__ import annotations

import csv
import io
import json
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from glsandbox.files import save_png
from glsandbox.grading.check import CheckResult, Outcome, file_stem, shown, summary_table
from glsandbox.measure.golden import compare_images
from glsandbox.grading.reports import REPORTS, write_reports
from glsandbox.grading.rubric import Check

NASTY = os.fsdecode(b"<script>alert(1)</script>\xff\n\x1b[31m\"quote\",comma\u202e")


@pytest.fixture
def results(tmp_path: Path) -> list[CheckResult]:
    golden = tmp_path / "ref.png"
    image = np.zeros((6, 8, 4), np.uint8)
    image[..., 3] = 255
    save_png(image, golden)
    check = Check("still", golden, points=2.0)
    other = image.copy()
    other[:3] = 200
    made = []
    for name, status, actual, error in ((NASTY, "PASS", image, ""), ("bob", "FAIL", other, ""),
                                        ("cat", "BROKEN", None, "cat.py:3: NameError: x"),
                                        ("dan", "TIMEOUT", None, "after 3 s"),
                                        ("eve", "CRASHED", None, "killed by signal SIGSEGV"),
                                        ("fay", "OUT OF MEMORY", None, "MemoryError at fay.py:2")):
        match = compare_images(actual, image) if actual is not None else None
        made.append(CheckResult(name, tmp_path / name, [Outcome(check, status, match, error, 0.5, thumb=actual)],
                                output=["printed </pre><b>", "\x1b[2J"]))
    return made


def test_names_are_escaped_everywhere_and_every_writer_agrees(tmp_path: Path, results: list[CheckResult]) -> None:
    assert shown(NASTY) == '<script>alert(1)</script>\\xff\\n\\x1b[31m"quote",comma\\u202e'
    assert "\n" not in summary_table(results).splitlines()[2] and "\x1b" not in summary_table(results)
    assert file_stem(NASTY).replace("-", "").replace("_", "").replace(".", "").isalnum()
    targets = {kind: tmp_path / f"out.{kind}" for kind in REPORTS}
    assert write_reports(results, targets, "ref.png") == list(targets.values())
    statuses = [r.status for r in results]

    rows = list(csv.DictReader(io.StringIO(targets["csv"].read_text(encoding="utf-8"))))
    assert [r["status"] for r in rows] == statuses and rows[0]["name"] == shown(NASTY)
    report = json.loads(targets["json"].read_text())
    assert [s["status"] for s in report["submissions"]] == statuses
    assert (report["pass"], report["fail"], report["broken"], report["timeout"], report["crashed"],
            report["out_of_memory"]) == (1, 1, 1, 1, 1, 1)
    suite = ET.parse(targets["junit"]).getroot().find("testsuite")
    cases = suite.findall("testcase")
    assert [c.get("name") for c in cases][0] == shown(NASTY)
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("6", "1", "4")
    assert cases[2].find("error").get("type") == "BROKEN" and "NameError" in cases[2].find("error").get("message")
    gradescope = json.loads(targets["gradescope"].read_text())
    assert gradescope["score"] == 2.0 and [t["status"] for t in gradescope["tests"]].count("passed") == 1
    assert "killed by signal SIGSEGV" in gradescope["tests"][4]["output"]
    page = targets["html"].read_text()
    assert "<script>alert" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;\\xff\\n\\x1b[31m" in page
    assert "</pre><b>" not in page and "\x1b" not in page and page.count("<tr><td") == 6
    assert page.count('alt="submission"') == 2  # pictures for the two that rendered


def test_a_report_that_cannot_be_written_is_one_line(tmp_path: Path, results: list[CheckResult]) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    from glsandbox.errors import SandboxError

    with pytest.raises(SandboxError, match=r"^--junit .*cannot write"):
        write_reports(results, {"junit": blocker / "r.xml"}, "ref.png")

