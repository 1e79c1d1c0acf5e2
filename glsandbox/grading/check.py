"""``glsandbox check``: lessons and scene files rendered and compared with reference PNGs.

The comparison is the project's golden rule (:func:`glsandbox.measure.golden.compare_images`:
a pixel is bad when a channel differs by more than ``threshold`` levels and no
pixel within one step matches, in both directions; the check fails when the
bad share exceeds ``max_bad_share``). On a failure the actual and expected
images and a diff picture are written (:func:`~glsandbox.measure.golden.write_artifacts`).

A folder of submissions (:func:`glsandbox.lesson.lesson_files`) is graded
with each submission in a process of its own (:mod:`glsandbox.grading.isolate`),
under a time and memory limit, reading only its own files
(:mod:`glsandbox.grading.sandbox`), sending back only pixels. This process
reads the references, compares and writes every verdict and report: nothing
a submission does reaches another's verdict, the references, the reports or
the exit code. Each submission gets one picture per :class:`Check` (one, or
a rubric's several, :mod:`glsandbox.grading.rubric`) and an outcome per
picture: PASS, FAIL, BROKEN (its error line), TIMEOUT, CRASHED or OUT OF MEMORY.
"""

from __future__ import annotations

import hashlib
import io
import math
import os
import re
import sys
import time
import unicodedata
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from PIL import Image

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.frame import DEFAULT_SIZE, Frame, HeadlessRenderer
from glsandbox.lesson import Lesson, entry_point, lesson_files, user_code_error
from glsandbox.measure.golden import DEFAULT_THRESHOLD, ImageMatch, compare_images, write_artifacts
from glsandbox.measure.margin import NUDGES, inside_share, margin_from, margin_path, read_margin, save_margin
from glsandbox.grading.isolate import BROKEN, CRASHED, OOM, TIMEOUT, Job, JobResult, Picture, Render
from glsandbox.grading.runner import run_jobs
from glsandbox.grading.kinds import kind_of
from glsandbox.grading.rubric import Check

PASS, FAIL = "PASS", "FAIL"
#: Every outcome, in the order the summary counts them.
OUTCOMES = (PASS, FAIL, BROKEN, TIMEOUT, CRASHED, OOM)
#: The defaults of ``--timeout`` (seconds per picture) and ``--memory`` (MB per submission).
DEFAULT_TIMEOUT, DEFAULT_MEMORY = 30.0, 2048
#: Thumbnails kept for the HTML report: at most this wide.
THUMB_WIDTH = 160


def shown(text: str) -> str:
    """A name as it may be printed or written anywhere: bytes that are not UTF-8 as ``\\xNN``,
    control and format characters (newlines, escape sequences) as ``\\n``, ``\\x1b``, ``\\u202e``."""
    try:
        raw = os.fsencode(text) if isinstance(text, str) else bytes(text)
    except UnicodeEncodeError:  # a surrogate no file name gives
        raw = text.encode("utf-8", "backslashreplace")
    decoded = raw.decode("utf-8", "backslashreplace")
    out = []
    for char in decoded:
        if unicodedata.category(char)[0] in "CZ" and char != " ":
            out.append(char.encode("unicode_escape").decode("ascii"))
        else:
            out.append(char)
    return "".join(out)


def file_stem(name: str) -> str:
    """A file name for a submission's artefacts: letters, digits, ``._-`` (and a hash when changed)."""
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", shown(name))[:80].lstrip(".") or "_"
    if safe != name:
        safe += "-" + hashlib.sha1(os.fsencode(name)).hexdigest()[:8]
    return safe


def read_reference(path: Path) -> np.ndarray:
    """The reference PNG as RGBA, or a one-line error naming it."""
    data = files.read_user_file(path, "reference", "a .png file")
    if not data:
        raise SandboxError(f"reference {path}: an empty file, not a PNG image; write it from the model answer "
                           "with --update")
    try:
        with warnings.catch_warnings():
            # A decompression bomb (a small file that decodes to gigabytes): refused, past
            # Pillow's warning size too, before its pixels are decoded.
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            return files.load_png(io.BytesIO(data))
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        raise SandboxError(f"reference {path}: too large to decode safely ({' '.join(str(exc).split())})") from None
    except (OSError, ValueError, SyntaxError):  # Pillow's reason names its buffer object, no use to a reader
        raise SandboxError(f"reference {path}: not a PNG image ({len(data)} bytes that PNG cannot read)") from None


def render_lesson(lesson: Lesson, size: tuple[int, int], samples: int = 0, backend: str | None = None,
                  renderer: HeadlessRenderer | None = None) -> Frame:
    """Render one lesson in this process; the lesson's own exceptions become one-line errors.

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
class Outcome:
    """One check of one submission."""

    check: Check
    status: str
    match: ImageMatch | None = None
    error: str = ""
    seconds: float = 0.0
    artifacts: dict[str, Path] = field(default_factory=dict)
    thumb: np.ndarray | None = None
    #: An exercise check's cases (the teacher's reports), and what a student may read (None: :meth:`detail`).
    cases: list[dict] = field(default_factory=list)
    student: str | None = None
    #: A failed picture's first differing pixel (x, y from the top; row by row), and its story in the
    #: submission's own frame (``check --explain``: told in the submission's confined renderer).
    first_difference: tuple[int, int] | None = None
    story: str = ""

    @property
    def points(self) -> float:
        return self.check.points if self.status == PASS else 0.0

    def detail(self) -> str:
        """The figures of a comparison, or the error line."""
        if self.match is None:
            return shown(self.error)
        return self.match.summary().partition(": ")[2]


@dataclass
class CheckResult:
    """One submission: its outcome for each check, and the last lines it printed."""

    name: str
    path: Path
    outcomes: list[Outcome]
    output: list[str] = field(default_factory=list)
    #: A hash of the submission's files (:func:`submission_digest`), and the others with the same.
    digest: str = ""
    same_as: list[str] = field(default_factory=list)

    @property
    def shown(self) -> str:
        return shown(self.name)

    @property
    def status(self) -> str:
        """PASS when every check passed, else the first check's outcome that did not."""
        return next((o.status for o in self.outcomes if o.status != PASS), PASS)

    @property
    def score(self) -> float:
        return sum(o.points for o in self.outcomes)

    @property
    def total(self) -> float:
        return sum(o.check.points for o in self.outcomes)

    @property
    def seconds(self) -> float:
        return sum(o.seconds for o in self.outcomes)

    @property
    def match(self) -> ImageMatch | None:
        return self.outcomes[0].match if len(self.outcomes) == 1 else None

    def line(self) -> str:
        """One line: the outcome, the name and (one check) the figures or error, (several) the score."""
        if len(self.outcomes) == 1:
            return f"{self.status:<6} {self.shown}: {self.outcomes[0].detail()}"
        first = self.outcomes[0]
        if first.status != PASS and all((o.status, o.error) == (first.status, first.error) for o in self.outcomes):
            parts = f"every check {first.status} ({first.detail()})"  # it did not load: said once
        else:
            parts = "; ".join(f"{o.check.name} {o.status}" + ("" if o.status == PASS else f" ({o.detail()})")
                              for o in self.outcomes)
        return f"{self.status:<6} {self.shown}: {points(self.score)}/{points(self.total)} points: {parts}"


def points(value: float) -> str:
    return f"{value:g}"


def _thumbnail(image: np.ndarray) -> np.ndarray:
    step = max(1, math.ceil(image.shape[1] / THUMB_WIDTH))
    return np.ascontiguousarray(image[::step, ::step])


def judge(actual: np.ndarray, expected: np.ndarray, tolerances: dict[str, float], artifacts_dir: Path,
          artifact_name: str, margin: np.ndarray | None = None) -> tuple[ImageMatch, dict[str, Path]]:
    """Compare (with the reference's ``margin`` when it has one); on a failure write
    ``<name>-actual.png``, ``-expected.png``, ``-diff.png`` into ``artifacts_dir``."""
    match = compare_images(actual, expected, **tolerances, margin=margin)
    if match.passed:
        return match, {}
    return match, _artifacts(actual, expected, tolerances, artifacts_dir, artifact_name, margin)


def _artifacts(actual: np.ndarray, expected: np.ndarray, tolerances: dict[str, float], artifacts_dir: Path,
               artifact_name: str, margin: np.ndarray | None = None) -> dict[str, Path]:
    try:
        return write_artifacts(actual, expected, artifacts_dir, artifact_name,
                               threshold=int(tolerances.get("threshold", DEFAULT_THRESHOLD)), margin=margin)
    except OSError as exc:
        raise SandboxError(f"{artifacts_dir}: cannot write the diff images ({exc.strerror or exc})") from None


def results_dir(check: Check) -> Path:
    """Where a check's failing pictures go: ``<golden stem>-results/`` beside the golden."""
    return check.golden.with_name(f"{check.golden.stem}-results")


@dataclass(frozen=True)
class Limits:
    """What each submission may use: seconds for each picture, MB of memory, submissions at once."""

    timeout: float = DEFAULT_TIMEOUT
    memory: int = DEFAULT_MEMORY
    jobs: int = 1


def cgroup_cpus(root: Path = Path("/sys/fs/cgroup"), membership: Path = Path("/proc/self/cgroup")) -> float | None:
    """The CPUs this process's cgroup quota allows (``cpu.max``, the smallest along its cgroup's path;
    cgroup v1's ``cpu.cfs_quota_us`` where there is no v2); None when there is no quota."""
    try:
        lines = membership.read_text().splitlines()
    except OSError:
        return None
    quotas = []
    for line in lines:
        number, _, rest = line.partition(":")
        controllers, _, path = rest.partition(":")
        if number == "0" and controllers == "":  # v2: every cgroup from this one up to the root
            folder = root / path.lstrip("/")
            while True:
                try:
                    quota, period = (folder / "cpu.max").read_text().split()[:2]
                    if quota != "max":
                        quotas.append(int(quota) / int(period))
                except (OSError, ValueError):
                    pass
                if folder == root or root not in folder.parents:
                    break
                folder = folder.parent
        elif "cpu" in controllers.split(","):
            for base in (root / "cpu,cpuacct", root / "cpu"):
                try:
                    quota_us = int((base / path.lstrip("/") / "cpu.cfs_quota_us").read_text())
                    period_us = int((base / path.lstrip("/") / "cpu.cfs_period_us").read_text())
                except (OSError, ValueError):
                    continue
                if quota_us > 0 and period_us > 0:
                    quotas.append(quota_us / period_us)
                break
    return min(quotas) if quotas else None


def default_jobs() -> int:
    """``--jobs`` when not given: the CPUs this process may run on (its affinity) and, in a
    container, its cgroup's quota allows (a 2-CPU quota on a 64-core machine is 2)."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    quota = cgroup_cpus() if sys.platform == "linux" else None
    if quota is not None:
        cpus = min(cpus, math.ceil(quota))
    return max(1, cpus)


def _renders(checks: Sequence[Check], references: dict[Path, np.ndarray]) -> tuple[Render, ...]:
    out = []
    for check in checks:
        expected = references.get(check.golden)
        size = check.size or ((expected.shape[1], expected.shape[0]) if expected is not None else DEFAULT_SIZE)
        out.append(Render(check.settings, size, check.samples))
    return tuple(out)


def submission_jobs(entries: Sequence[tuple[str, Path, Path]], renders: tuple[Render, ...], backend: str | None,
                    limits: Limits, entry: str | None = None) -> list[tuple[str, Path, Job]]:
    """(name, path, job) for each submission (name, its file or folder, its lesson file or the
    folder when none can be told): a file alone, or the whole of its folder."""
    out = []
    for index, (name, source, lesson) in enumerate(entries):
        target = "" if lesson.is_dir() else lesson.relative_to(source).as_posix() if source.is_dir() else source.name
        job = Job(index, str(source), target, renders, backend, limits.timeout, limits.memory, entry=entry)
        out.append((name, lesson, job))
    return out


def submissions(folder: Path, entry: str | None = None, one: bool = False) -> list[tuple[str, Path, Path]]:
    """(name, submission, lesson file) for each student's submission in ``folder``; ``one``: the
    folder is one student's (a flat folder of a lesson and its helpers, as Gradescope gives it)."""
    if one:
        if folder.is_symlink():
            return [(folder.name or "submission", folder, folder)]
        return [(folder.resolve().name or "submission", folder, entry_point(folder, entry))]
    out = []
    for name, path in lesson_files(folder, entry):
        source = path if path.parent == folder else path.parent
        out.append((name, source, path))
    return out


def submission_digest(source: Path) -> str:
    """A hash of a submission's files (their paths inside it and their bytes; a link by its text):
    two submissions with the same digest are the same files."""
    digest = hashlib.sha256()
    if source.is_symlink():
        return ""
    paths = sorted(source.rglob("*")) if source.is_dir() else [source]
    for path in paths:
        relative = path.relative_to(source).as_posix() if source.is_dir() else ""
        if path.is_symlink():
            digest.update(b"L" + os.fsencode(relative) + b"\0" + os.fsencode(os.readlink(path)) + b"\0")
        elif path.is_file():
            digest.update(b"F" + os.fsencode(relative) + b"\0")
            try:
                with path.open("rb") as handle:
                    for chunk in iter(lambda: handle.read(1 << 20), b""):
                        digest.update(chunk)
            except OSError:
                digest.update(b"?")
            digest.update(b"\0")
    return digest.hexdigest()


def mark_duplicates(results: Sequence[CheckResult]) -> None:
    """Give each result the names of the others whose files are the same (:attr:`CheckResult.same_as`)."""
    by_digest: dict[str, list[CheckResult]] = {}
    for result in results:
        if result.digest:
            by_digest.setdefault(result.digest, []).append(result)
    for group in by_digest.values():
        for result in group:
            result.same_as = [other.name for other in group if other is not result]


LINK_ERROR = "is a link (a submission is its own files, not a link to others')"


def _outcomes(result: JobResult, checks: Sequence[Check], references: dict[Path, np.ndarray],
              name: str, margins: dict[Path, np.ndarray | None] | None = None) -> list[Outcome]:
    outcomes = []
    for check, picture in zip(checks, result.pictures):
        outcomes.append(_outcome(check, picture, references[check.golden], name,
                                 (margins or {}).get(check.golden)))
    return outcomes


def _outcome(check: Check, picture: Picture, expected: np.ndarray, name: str,
             margin: np.ndarray | None = None) -> Outcome:
    """What came back for ``check``, judged by its kind (:mod:`glsandbox.grading.kinds`; a picture
    with its reference's ``margin`` when there is one); a failed comparison's pictures go into
    :func:`results_dir`."""
    if picture.image is None:
        return Outcome(check, picture.status or CRASHED, error=shown(picture.error), seconds=picture.seconds)
    extra = {"margin": margin} if margin is not None else {}
    verdict = kind_of(check.kind).judge(check, picture.image, expected, **extra)
    paths: dict[str, Path] = {}
    if not verdict.passed and verdict.match is not None:
        paths = _artifacts(picture.image, expected, check.tolerances, results_dir(check), file_stem(name), margin)
    return Outcome(check, PASS if verdict.passed else FAIL, verdict.match, error=verdict.detail,
                   seconds=picture.seconds, artifacts=paths, thumb=_thumbnail(picture.image),
                   first_difference=None if verdict.passed else first_difference(picture.image, expected, check))


def first_difference(actual: np.ndarray, expected: np.ndarray, check: Check) -> tuple[int, int] | None:
    """The first pixel, row by row from the top, whose largest channel differs by more than the
    check's threshold (None when the shapes differ or none does)."""
    if actual.shape != expected.shape:
        return None
    threshold = int(check.tolerances.get("threshold", DEFAULT_THRESHOLD))
    delta = np.abs(actual[..., :3].astype(np.int16) - expected[..., :3].astype(np.int16)).max(axis=2)
    rows, cols = np.nonzero(delta > threshold)
    return (int(cols[0]), int(rows[0])) if rows.size else None


def explain_failures(entries: Sequence[tuple[str, Path, Job]], finished: dict[str, CheckResult],
                     checks: Sequence[Check], jobs: int) -> None:
    """``check --explain``: each failed picture's first differing pixel told in the submission's own
    frame, by a second confined run of it that renders the failed checks again with their pixel
    (:attr:`Render.explain`); the story is the submission's output, kept as text (:attr:`Outcome.story`)."""
    again, wanted = [], {}
    for name, _, job in entries:
        result = finished.get(name)
        failed = [(k, o) for k, o in enumerate(result.outcomes) if o.first_difference is not None] if result else []
        if failed:
            renders = tuple(replace(job.renders[k], explain=o.first_difference) for k, o in failed)
            again.append(replace(job, renders=renders))
            wanted[job.index] = (name, [k for k, _ in failed])
    if not again:
        return

    def done(result: JobResult) -> None:
        name, indices = wanted[result.job.index]
        for k, picture in zip(indices, result.pictures, strict=True):
            story = picture.info.get("story") if picture.image is not None else None
            finished[name].outcomes[k].story = story if isinstance(story, str) else \
                f"(no story: {shown(picture.error) or 'the second run sent none'})"

    run_jobs(again, jobs, done)


def read_references(checks: Sequence[Check]) -> dict[Path, np.ndarray]:
    """Every check's golden, read by the grader (never by a submission); a missing one is one line."""
    references = {}
    for check in checks:
        if not check.golden.exists() and not check.golden.is_symlink():
            raise SandboxError(f"reference {check.golden} not found; make it from the model answer first: "
                               f"glsandbox check ANSWER.py --golden {check.golden} --update "
                               "(or --rubric FILE --update)")
        references[check.golden] = read_reference(check.golden)
    return references


def read_margins(references: dict[Path, np.ndarray]) -> dict[Path, np.ndarray | None]:
    """Each reference's margin (``NAME.margin.png`` beside it, :mod:`glsandbox.measure.margin`),
    None where it has none; read by the grader, like the references."""
    return {path: read_margin(path, image.shape) for path, image in references.items()}


def check_folder(folder: Path, checks: Sequence[Check], backend: str | None = None, limits: Limits = Limits(),
                 progress: Callable[[int, int, CheckResult], None] = lambda done, total, result: None,
                 entry: str | None = None, one: bool = False,
                 keep: Callable[[str], bool] = lambda name: True, explain: bool = False) -> list[CheckResult]:
    """Grade every submission in ``folder`` against ``checks``; never stops at a broken one.

    ``progress`` hears each submission as it finishes (in the order they
    finish); the results come back in folder order. Failures leave their
    images in ``<golden stem>-results/`` beside each golden. ``entry``: the
    lesson file's name in a student's folder (the rubric's); ``one``: the
    folder is one student's. A submission that is a symbolic link is BROKEN
    without running; submissions that are the same files are marked
    (:func:`mark_duplicates`). ``keep``: which submissions (by name) this run grades (a shard,
    :mod:`glsandbox.grading.shards`). ``explain``: each failed picture's first differing pixel is
    told (:func:`explain_failures`).
    """
    found = submissions(folder, entry, one)
    if not found or (one and not folder.is_dir()):
        raise SandboxError(f"{folder}: no .py or .toml lesson files (nor subfolders holding one)")
    found = [e for e in found if keep(e[0])]
    references = read_references(checks)
    margins = read_margins(references)
    renders = _renders(checks, references)
    links = [(name, source) for name, source, _ in found if source.is_symlink()]
    entries = submission_jobs([e for e in found if not e[1].is_symlink()], renders, backend, limits, entry)
    digests = {name: submission_digest(source) for name, source, _ in found}
    total = len(found)
    finished: dict[str, CheckResult] = {}

    def record(result: CheckResult) -> None:
        result.digest = digests.get(result.name, "")
        finished[result.name] = result
        progress(len(finished), total, result)

    for name, source in links:
        record(CheckResult(name, source, [Outcome(c, BROKEN, error=f"{shown(str(source))}: {LINK_ERROR}")
                                          for c in checks]))
    by_index = {job.index: (name, path) for name, path, job in entries}

    def done(result: JobResult) -> None:
        name, path = by_index[result.job.index]
        record(CheckResult(name, path, _outcomes(result, checks, references, name, margins),
                           [shown(line) for line in result.output]))

    results = run_jobs([job for _, _, job in entries], limits.jobs, done) if entries else []
    no_gl = next((r.no_gl for r in results if r.no_gl), "")
    if no_gl:  # the machine's problem, not every submission's
        raise SandboxError(no_gl)
    if explain:
        explain_failures(entries, finished, checks, limits.jobs)
    ordered = [finished[name] for name, _, _ in found]
    mark_duplicates(ordered)
    return ordered


def render_submissions(folder: Path, size: tuple[int, int], samples: int, backend: str | None, limits: Limits,
                       progress: Callable[[str, Path, JobResult], None] = lambda name, path, result: None,
                       ) -> list[tuple[str, Path, JobResult]]:
    """Each lesson of ``folder`` (:func:`submissions`: students' files and folders) rendered once,
    isolated and limited as ``check`` grades them, with what the tour's page shows
    (:attr:`~glsandbox.grading.isolate.Job.describe`); a link is BROKEN without running."""
    found = submissions(folder)
    render = (Render((), size, samples),)
    live = [e for e in found if not e[1].is_symlink()]
    entries = submission_jobs(live, render, backend, limits)
    jobs = [replace(job, describe=True) for _, _, job in entries]
    by_index = {job.index: (name, path) for name, path, job in entries}
    finished: dict[str, tuple[str, Path, JobResult]] = {}

    def done(result: JobResult) -> None:
        name, path = by_index[result.job.index]
        finished[name] = (name, path, result)
        progress(name, path, result)

    for name, source, _ in found:
        if source.is_symlink():
            broken = JobResult(Job(-1, str(source), "", render), [Picture(status=BROKEN,
                                                                          error=f"{shown(str(source))}: {LINK_ERROR}")])
            finished[name] = (name, source, broken)
            progress(name, source, broken)
    results = run_jobs(jobs, limits.jobs, done) if jobs else []
    no_gl = next((r.no_gl for r in results if r.no_gl), "")
    if no_gl:
        raise SandboxError(no_gl)
    return [finished[name] for name, _, _ in found]


def render_isolated(spec: str, checks: Sequence[Check], sizes: Sequence[tuple[int, int]],
                    backend: str | None, limits: Limits, model_answer: bool = False) -> JobResult:
    """One lesson (a name or a file) rendered once per check in an isolated child, its folder as its root
    (``model_answer``: its compiled shaders are kept in Mesa's cache, for the submissions, and each
    check's picture is followed, after all of them, by its :data:`~glsandbox.measure.margin.NUDGES`
    pictures, for the margins)."""
    renders = tuple(Render(c.settings, size, c.samples) for c, size in zip(checks, sizes))
    if model_answer:
        renders += tuple(Render(c.settings, size, c.samples, nudge=nudge) for c, size in zip(checks, sizes)
                         for nudge in NUDGES)
    path = Path(spec)
    if spec.endswith((".py", ".toml")):
        job = Job(0, str(path.resolve()), path.name, renders, backend, limits.timeout, limits.memory, copy=False,
                  writes_cache=model_answer)
    else:
        job = Job(0, None, spec, renders, backend, limits.timeout, limits.memory, copy=False,
                  writes_cache=model_answer)
    (result,) = run_jobs([job], 1, lambda r: None)
    if result.no_gl:
        raise SandboxError(result.no_gl)
    if path.resolve() != path and job.source:  # errors name the file as the user wrote it
        for picture in result.pictures:
            picture.error = picture.error.replace(str(path.resolve()), spec)
    return result


@dataclass
class OneCheck:
    """One lesson against one check: the match (None when the reference was just written),
    the artefacts, what happened to the reference, or the outcome when it did not render."""

    check: Check
    match: ImageMatch | None = None
    artifacts: dict[str, Path] = field(default_factory=dict)
    updated: str = ""
    status: str = ""
    error: str = ""
    #: With ``--update``: the share of the reference's pixels inside the margin written beside it.
    margin_share: float | None = None


def check_one(spec: str, checks: Sequence[Check], update: bool, backend: str | None = None,
              limits: Limits = Limits()) -> list[OneCheck]:
    """One lesson against each check's reference, isolated as a submission is.

    The lesson's own mistakes are said first (a :class:`SandboxError`,
    before a missing reference); a time-out, crash or memory limit is an
    outcome (exit 1), never a pass. With ``update`` a missing or failing
    reference is (re)written, atomically, and a passing one is left as it is
    (the project's golden flow); the match is then against the old reference.
    """
    existing = {c.golden: read_reference(c.golden) for c in checks if c.golden.exists()}
    sizes = [c.size or ((existing[c.golden].shape[1], existing[c.golden].shape[0]) if c.golden in existing
                        else DEFAULT_SIZE) for c in checks]
    result = render_isolated(spec, checks, sizes, backend, limits, model_answer=update)
    broken = next((p for p in result.pictures if p.status == BROKEN), None)
    if broken is not None:
        raise SandboxError(shown(broken.error))
    if not update:
        missing = next((c for c in checks if c.golden not in existing), None)
        if missing is not None:
            raise SandboxError(f"reference {missing.golden} not found; write it with --update")
    out = []
    for index, (check, picture) in enumerate(zip(checks, result.pictures)):
        if picture.image is None:
            out.append(OneCheck(check, status=picture.status, error=shown(picture.error)))
            continue
        expected = existing.get(check.golden)
        if expected is None:
            _write_reference(picture.image, check.golden)
            one = OneCheck(check, updated="written")
        elif update:
            match = compare_images(picture.image, expected, **check.tolerances)
            if not match.passed:
                _write_reference(picture.image, check.golden)
            one = OneCheck(check, match, updated="unchanged" if match.passed else "rewritten")
        else:
            margin = read_margin(check.golden, expected.shape)
            match, paths = judge(picture.image, expected, check.tolerances, check.golden.parent, check.golden.stem,
                                 margin)
            out.append(OneCheck(check, match, paths))
            continue
        reference = picture.image if one.updated != "unchanged" else expected
        nudged = result.pictures[len(checks) + index * len(NUDGES):len(checks) + (index + 1) * len(NUDGES)]
        one.margin_share = _write_margin(check, reference, nudged)
        out.append(one)
    return out


def _write_margin(check: Check, reference: np.ndarray, nudged: Sequence[Picture]) -> float:
    """The margin of a reference just written or kept, from the model answer's nudged pictures,
    written beside it (:mod:`glsandbox.measure.margin`); the share of its pixels inside."""
    failed = next((p for p in nudged if p.image is None), None)
    if failed is not None:
        raise SandboxError(f"margin {margin_path(check.golden)}: a nudged picture of the model answer did not "
                           f"render ({failed.status}: {shown(failed.error)})")
    threshold = int(check.tolerances.get("threshold", DEFAULT_THRESHOLD))
    margin = margin_from(reference, [p.image for p in nudged], threshold)
    save_margin(margin, margin_path(check.golden))
    return inside_share(margin)


def _write_reference(image: np.ndarray, path: Path) -> None:
    try:
        files.save_png(image, path)
    except OSError as exc:
        raise SandboxError(f"reference {path}: cannot write ({exc.strerror or exc})") from None


def counts(results: Sequence[CheckResult]) -> dict[str, int]:
    """How many submissions ended with each outcome."""
    return {status: sum(r.status == status for r in results) for status in OUTCOMES}


def counts_line(results: Sequence[CheckResult]) -> str:
    """``2 passed, 1 failed, 1 broken, 0 timed out, 0 crashed, 0 out of memory of 4``."""
    c = counts(results)
    return (f"{c[PASS]} passed, {c[FAIL]} failed, {c[BROKEN]} broken, {c[TIMEOUT]} timed out, "
            f"{c[CRASHED]} crashed, {c[OOM]} out of memory of {len(results)}")


def summary_table(results: Sequence[CheckResult]) -> str:
    """A fixed-width table of every submission's figures (or score), and the counts."""
    several = any(len(r.outcomes) > 1 for r in results)
    last = f"{'score':>9}" if several else f"{'bad %':>8} {'max diff':>8} {'RMSE':>8}"
    header = f"{'submission':<24} {'status':<13} {last} {'seconds':>7}"
    lines = [header, "-" * len(header)]
    for r in results:
        m = r.match
        if several:
            figures = f"{points(r.score) + '/' + points(r.total):>9}"
        elif m is not None:
            figures = (f"{m.bad_share * 100:>8.3f} {m.max_diff:>8d} "
                       f"{'-' if math.isnan(m.rmse) else f'{m.rmse:.5f}':>8}")
        else:
            figures = f"{'-':>8} {'-':>8} {'-':>8}"
        lines.append(f"{r.shown[:24]:<24} {r.status:<13} {figures} {r.seconds:>7.2f}")
    lines.append(counts_line(results))
    lines += [f"same files: {' = '.join(group)}" for group in duplicate_groups(results)]
    return "\n".join(lines)


def duplicate_groups(results: Sequence[CheckResult]) -> list[list[str]]:
    """The names (shown) of each group of submissions that are the same files, in folder order."""
    groups, seen = [], set()
    for r in results:
        if r.same_as and r.name not in seen:
            group = [r.name, *r.same_as]
            seen.update(group)
            groups.append([shown(n) for n in group])
    return groups


def time_in_process(folder: Path, checks: Sequence[Check], backend: str | None = None,
                    shared_context: bool = False) -> float:
    """Seconds to grade ``folder`` in this process, with no isolation (the benchmark's baselines).

    Without ``shared_context``: a fresh GL context per submission (how ``check``
    graded before each submission had a process of its own). With it: one
    context for every submission, opened before the clock starts, the
    cheapest honest way to grade in one process (what it saves, each
    isolated renderer must pay or inherit from the zygote's warm template)."""
    from glsandbox.lesson import submission_lesson

    references = read_references(checks)
    renders = _renders(checks, references)
    shared = HeadlessRenderer(backend) if shared_context else None
    started = time.perf_counter()
    try:
        for _name, path in lesson_files(folder):
            try:
                cls = submission_lesson(path)
                for check, render in zip(checks, renders):
                    image = render_lesson(cls.from_settings(render.settings), render.size, render.samples, backend,
                                          renderer=shared).image
                    compare_images(image, references[check.golden], **check.tolerances)
            except SandboxError:
                pass
        return time.perf_counter() - started
    finally:
        if shared is not None:
            shared.close()
