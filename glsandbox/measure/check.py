"""``glsandbox check``: a lesson or scene file rendered and compared with a reference PNG.

The comparison is the project's golden rule (:func:`glsandbox.measure.golden.compare_images`:
a pixel is bad when a channel differs by more than ``threshold`` levels and no
pixel within one step matches, in both directions; the check fails when the
bad share exceeds ``max_bad_share``). On a failure the actual and expected
images and a diff picture are written (:func:`~glsandbox.measure.golden.write_artifacts`).

A folder of submissions (:func:`glsandbox.lesson.lesson_files`) is checked one
by one, each rendered in this process on a fresh headless context of its
own, so a submission that breaks GL state, or raises anywhere in its code,
is reported as BROKEN and the next one starts clean. A fresh context adds
about 20 ms on llvmpipe; a Python subprocess per submission 1.2 to 1.5 s (the
imports), so the context is the isolation used. What a context cannot
contain (a submission that calls ``os._exit``, crashes the interpreter or
never returns) stops the run.
"""

from __future__ import annotations

import csv
import io
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.frame import DEFAULT_SIZE, Frame, HeadlessRenderer
from glsandbox.lesson import Lesson, find_lesson, lesson_files, submission_lesson, user_code_error
from glsandbox.measure.golden import DEFAULT_MAX_BAD_SHARE, DEFAULT_THRESHOLD, ImageMatch, compare_images, write_artifacts

#: The tolerances ``--tolerance KEY=VALUE`` (and the pytest fixture's keywords) accept.
TOLERANCES = {"threshold": DEFAULT_THRESHOLD, "max_bad_share": DEFAULT_MAX_BAD_SHARE}


def parse_tolerances(items: Sequence[str]) -> dict[str, float]:
    """``threshold=4``, ``max_bad_share=0.01`` -> keywords of :func:`compare_images`, checked."""
    tolerances: dict[str, float] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or key not in TOLERANCES:
            raise SandboxError(f"--tolerance {item!r}: expected threshold=LEVELS or max_bad_share=FRACTION")
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if key == "threshold" and not (math.isfinite(value) and value == int(value) and 0 <= value <= 255):
            raise SandboxError(f"--tolerance {item!r}: threshold is a whole number of levels, 0..255")
        if key == "max_bad_share" and not 0.0 <= value <= 1.0:  # NaN fails this too
            raise SandboxError(f"--tolerance {item!r}: max_bad_share is a fraction, 0..1")
        tolerances[key] = int(value) if key == "threshold" else value
    return tolerances


def read_reference(path: Path) -> np.ndarray:
    """The reference PNG as RGBA, or a one-line error naming it."""
    data = files.read_user_file(path, "reference", "a .png file")
    try:
        return files.load_png(io.BytesIO(data))
    except OSError as exc:
        raise SandboxError(f"reference {path}: not a PNG image ({exc})") from None


def reference_size(path: Path, size: tuple[int, int] | None) -> tuple[int, int]:
    """The size to render at: the one asked for, else the reference's, else the default."""
    if size is not None:
        return size
    if path.exists():
        image = read_reference(path)
        return image.shape[1], image.shape[0]
    return DEFAULT_SIZE


def render_lesson(lesson: Lesson, size: tuple[int, int], samples: int = 0, backend: str | None = None,
                  renderer: HeadlessRenderer | None = None) -> Frame:
    """Render one lesson; the lesson's own exceptions become one-line errors.

    Without ``renderer`` a fresh context is opened and closed around it, so
    whatever one lesson leaves in GL state dies with its context.
    """
    try:
        if renderer is not None:
            return renderer.render(lesson, size, samples)
        with HeadlessRenderer(backend) as fresh:
            return fresh.render(lesson, size, samples)
    except SandboxError:
        raise
    except (Exception, SystemExit) as exc:  # the lesson's build(), or anything it reached
        raise user_code_error(exc) from exc


@dataclass
class CheckResult:
    """One submission's outcome: PASS, FAIL or BROKEN (it did not render)."""

    name: str
    path: Path
    status: str
    match: ImageMatch | None = None
    error: str = ""
    seconds: float = 0.0
    artifacts: dict[str, Path] = field(default_factory=dict)

    def line(self) -> str:
        if self.match is None:
            return f"{self.status:<6} {self.name}: {self.error}"
        return f"{self.status:<6} {self.name}: {self.match.summary().partition(': ')[2]}"

    def row(self) -> dict[str, object]:
        m = self.match
        return {"name": self.name, "path": str(self.path), "status": self.status,
                "bad_pixels": m.bad_pixels if m else None,
                "bad_share": round(m.bad_share, 6) if m else None,
                "max_diff": m.max_diff if m else None,
                "rmse": None if m is None or math.isnan(m.rmse) else round(m.rmse, 6),
                "threshold": m.threshold if m else None,
                "max_bad_share": m.max_bad_share if m else None,
                "seconds": round(self.seconds, 3), "error": self.error}


def judge(actual: np.ndarray, expected: np.ndarray, tolerances: dict[str, float], artifacts_dir: Path,
          artifact_name: str) -> tuple[ImageMatch, dict[str, Path]]:
    """Compare; on a failure write ``<name>-actual.png``, ``-expected.png``, ``-diff.png`` into ``artifacts_dir``."""
    match = compare_images(actual, expected, **tolerances)
    if match.passed:
        return match, {}
    try:
        paths = write_artifacts(actual, expected, artifacts_dir, artifact_name,
                                threshold=int(tolerances.get("threshold", DEFAULT_THRESHOLD)))
    except OSError as exc:
        raise SandboxError(f"{artifacts_dir}: cannot write the diff images ({exc.strerror or exc})") from None
    return match, paths


def check_folder(folder: Path, reference: Path, settings: Sequence[str], size: tuple[int, int] | None,
                 tolerances: dict[str, float], samples: int = 0, backend: str | None = None,
                 progress: Callable[[str], None] = lambda text: None) -> list[CheckResult]:
    """Check every submission in ``folder`` against ``reference``; never stops at a broken one.

    Failures leave their images in ``<reference stem>-results/`` beside the reference.
    """
    submissions = lesson_files(folder)
    if not submissions:
        raise SandboxError(f"{folder}: no .py or .toml lesson files (nor subfolders holding one)")
    if not reference.exists():
        raise SandboxError(f"reference {reference} not found; make it from the model answer first: "
                           f"glsandbox check ANSWER.py --golden {reference} --update")
    expected = read_reference(reference)
    size = size or (expected.shape[1], expected.shape[0])
    with HeadlessRenderer(backend):  # no GL at all is the machine's problem, not every submission's
        pass
    artifacts_dir = reference.with_name(f"{reference.stem}-results")
    results = []
    for number, (name, path) in enumerate(submissions, start=1):
        progress(f"[{number}/{len(submissions)}] {name} ...")
        started = time.perf_counter()
        try:
            lesson = submission_lesson(path).from_settings(settings)
            actual = render_lesson(lesson, size, samples, backend).image
            match, paths = judge(actual, expected, tolerances, artifacts_dir, name)
            result = CheckResult(name, path, "PASS" if match.passed else "FAIL", match, artifacts=paths)
        except SandboxError as exc:
            result = CheckResult(name, path, "BROKEN", error=str(exc))
        except (Exception, SystemExit) as exc:  # raised while loading, outside render_lesson's net
            result = CheckResult(name, path, "BROKEN", error=str(user_code_error(exc)))
        result.seconds = time.perf_counter() - started
        results.append(result)
    return results


def summary_table(results: Sequence[CheckResult]) -> str:
    """A fixed-width table of every submission's figures, and the counts."""
    header = f"{'submission':<24} {'status':<6} {'bad %':>8} {'max diff':>8} {'RMSE':>8} {'seconds':>7}"
    lines = [header, "-" * len(header)]
    for r in results:
        m = r.match
        figures = (f"{m.bad_share * 100:>8.3f} {m.max_diff:>8d} "
                   f"{'-' if math.isnan(m.rmse) else f'{m.rmse:.5f}':>8}") if m else f"{'-':>8} {'-':>8} {'-':>8}"
        lines.append(f"{r.name[:24]:<24} {r.status:<6} {figures} {r.seconds:>7.2f}")
    counts = {s: sum(r.status == s for r in results) for s in ("PASS", "FAIL", "BROKEN")}
    lines.append(f"{counts['PASS']} passed, {counts['FAIL']} failed, {counts['BROKEN']} broken "
                 f"of {len(results)}")
    return "\n".join(lines)


def write_reports(results: Sequence[CheckResult], csv_path: Path | None, json_path: Path | None,
                  reference: Path) -> list[Path]:
    """The figures as CSV and/or JSON, each written atomically."""
    rows = [r.row() for r in results]
    written = []
    for path, make in ((csv_path, _csv_text), (json_path, _json_text)):
        if path is None:
            continue
        try:
            files.write_text(path, make(rows, reference))
        except OSError as exc:
            raise SandboxError(f"{path}: cannot write ({exc.strerror or exc})") from None
        written.append(path)
    return written


def _csv_text(rows: list[dict[str, object]], reference: Path) -> str:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: "" if v is None else v for k, v in row.items()} for row in rows)
    return out.getvalue()


def _json_text(rows: list[dict[str, object]], reference: Path) -> str:
    counts = {s.lower(): sum(r["status"] == s for r in rows) for s in ("PASS", "FAIL", "BROKEN")}
    return json.dumps({"reference": str(reference), **counts, "submissions": rows}, indent=2) + "\n"


def check_one(spec: str, reference: Path, settings: Sequence[str], size: tuple[int, int] | None,
              tolerances: dict[str, float], update: bool, samples: int = 0,
              backend: str | None = None) -> tuple[ImageMatch | None, dict[str, Path], str]:
    """One lesson against one reference: (match, artifact paths, what happened to the reference).

    With ``update`` a missing or failing reference is (re)written, atomically,
    and a passing one is left as it is (the project's golden flow); the match
    is then against the old reference (None when there was none).
    """
    lesson = find_lesson(spec).from_settings(settings)  # the lesson's own mistakes first
    if not update and not reference.exists():
        raise SandboxError(f"reference {reference} not found; write it with --update")
    expected = read_reference(reference) if reference.exists() else None
    size = size or ((expected.shape[1], expected.shape[0]) if expected is not None else DEFAULT_SIZE)
    actual = render_lesson(lesson, size, samples, backend).image
    if expected is None:
        _write_reference(actual, reference)
        return None, {}, "written"
    if update:
        match = compare_images(actual, expected, **tolerances)
        if match.passed:
            return match, {}, "unchanged"
        _write_reference(actual, reference)
        return match, {}, "rewritten"
    match, paths = judge(actual, expected, tolerances, reference.parent, reference.stem)
    return match, paths, ""


def _write_reference(image: np.ndarray, path: Path) -> None:
    try:
        files.save_png(image, path)
    except OSError as exc:
        raise SandboxError(f"reference {path}: cannot write ({exc.strerror or exc})") from None
