"""A class graded in shards: ``check DIR --shard K/N`` and ``glsandbox check merge REPORTS...``.

A Kubernetes Job array or a CI matrix of N machines grades one class: each
grades the submissions of its shard and writes its JSON report; the merge
reads the N reports and writes the full reports, as one run would have.

A submission's shard is a stable hash of its name (SHA-256 of the name's
bytes, modulo N): the same on every machine and Python, whatever order a
file system lists the folder in, and a late submission moves no other.
Submissions that are the same files (their digest) are found again over the
whole class on merging, also when they fell into different shards.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.grading.check import OUTCOMES, PASS, CheckResult, Outcome, mark_duplicates
from glsandbox.grading.rubric import Check
from glsandbox.measure.golden import ImageMatch

__all__ = ["parse_shard", "shard_of", "in_shard", "read_shard", "merge_reports", "MergedOutcome"]


def parse_shard(text: str) -> tuple[int, int]:
    """``K/N`` (1 <= K <= N <= 10000) -> (K, N), or a one-line error naming the value."""
    found = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not found or not 1 <= int(found[1]) <= int(found[2]) <= 10_000:
        raise SandboxError(f"--shard {text!r}: expected K/N, this machine's share K of N (1 <= K <= N), e.g. 2/8")
    return int(found[1]), int(found[2])


def shard_of(name: str, count: int) -> int:
    """The shard (1..count) of the submission named ``name``: SHA-256 of its bytes, modulo ``count``."""
    digest = hashlib.sha256(os.fsencode(name)).digest()
    return int.from_bytes(digest[:8], "big") % count + 1


def in_shard(name: str, shard: tuple[int, int] | None) -> bool:
    """Whether ``name`` is graded by ``shard`` (None: every submission is)."""
    return shard is None or shard_of(name, shard[1]) == shard[0]


class MergedOutcome(Outcome):
    """An outcome read back from a shard's JSON: its figures and its one-line detail as written."""

    text: str = ""

    def detail(self) -> str:
        return self.text


def _match(figures: dict, passed: bool) -> ImageMatch | None:
    if figures.get("bad_pixels") is None:
        return None
    rmse = figures.get("rmse")
    return ImageMatch(passed, False, int(figures["bad_pixels"]), 0, float(figures["bad_share"]),
                      int(figures["max_diff"]), math.nan if rmse is None else float(rmse),
                      int(figures["threshold"]), float(figures["max_bad_share"]))


def _outcome(check: Check, figures: dict, where: str) -> MergedOutcome:
    status = figures.get("status")
    if status not in OUTCOMES:
        raise SandboxError(f"{where}: status {status!r}: expected one of {', '.join(OUTCOMES)}")
    outcome = MergedOutcome(check, status, _match(figures, status == PASS), error=str(figures.get("error") or ""),
                            seconds=float(figures.get("seconds") or 0.0))
    outcome.text = str(figures.get("detail", outcome.error))
    return outcome


def read_shard(path: Path, checks: Sequence[Check]) -> list[CheckResult]:
    """One shard's ``--json`` report as results, each outcome matched to ``checks`` by name."""
    raw = files.read_user_file(path, "report", "a JSON report of glsandbox check --json")
    try:
        data = json.loads(raw.decode("utf-8"))
        entries = data["submissions"]
        assert isinstance(entries, list)
    except (UnicodeDecodeError, ValueError, KeyError, TypeError, AssertionError):
        raise SandboxError(f"{path}: not a report of glsandbox check --json (no \"submissions\" list)") from None
    by_name = {c.name: c for c in checks}
    results = []
    for number, entry in enumerate(entries, start=1):
        where = f"{path}: submission {number}"
        try:
            if "checks" in entry:
                unknown = next((c["check"] for c in entry["checks"] if c["check"] not in by_name), None)
                if unknown is not None or len(entry["checks"]) != len(checks):
                    raise SandboxError(f"{where}: checks {[c['check'] for c in entry['checks']]} are not the "
                                       f"grading file's {list(by_name)}; merge with the file the shards were graded with")
                outcomes = [_outcome(by_name[c["check"]], c, where) for c in entry["checks"]]
            else:
                if len(checks) != 1:
                    raise SandboxError(f"{where}: graded with one check, the grading file has {len(checks)}")
                outcomes = [_outcome(checks[0], entry, where)]
            result = CheckResult(str(entry["name"]), Path(str(entry["path"])), outcomes,
                                 [str(line) for line in entry.get("output", [])], str(entry.get("digest", "")))
        except (KeyError, TypeError, ValueError) as exc:
            raise SandboxError(f"{where}: not as glsandbox check --json writes it ({type(exc).__name__}: {exc})") from None
        results.append(result)
    return results


def merge_reports(paths: Sequence[Path], checks: Sequence[Check]) -> list[CheckResult]:
    """Every shard's results, in the order one run lists them (by name and path), the same files
    found again across the shards; a submission in two reports is one line naming both."""
    if not paths:
        raise SandboxError("check merge: give the shards' JSON reports (glsandbox check DIR --shard K/N --json FILE)")
    merged: dict[tuple[str, str], tuple[CheckResult, Path]] = {}
    for path in paths:
        for result in read_shard(path, checks):
            key = (result.name, str(result.path))
            if key in merged:
                raise SandboxError(f"{path}: submission {result.name} is in {merged[key][1]} too; "
                                   "each shard's report once, of the same --shard N")
            merged[key] = (result, path)
    results = [merged[key][0] for key in sorted(merged)]
    mark_duplicates(results)
    return results
