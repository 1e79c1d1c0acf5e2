"""Grading students' functions: a rubric's ``exercise`` checks, or ``check DIR --exercise NAME``.

Each submission is a ``.py`` file, or a folder holding it (the rubric's
``entry``, else its only ``.py`` file, else the one defining the exercise's
function). Its function runs in the exercises' isolation
(:class:`~glsandbox.exercises.isolation.Isolated`: its own confined process,
only inputs in and JSON answers out) and every case, the hidden groups too,
is judged in this process (:func:`glsandbox.exercises.check.check`).

Each case group becomes one :class:`~glsandbox.grading.check.Outcome` worth
the group's points, all or nothing: PASS when every case of the group
passes, FAIL when one is wrong, else TIMEOUT or BROKEN. The teacher's
reports carry the cases (call, expected, got) and the named mistake's hint;
what a student may read (:attr:`Outcome.student`) of a hidden group is its
counts and case names, never an expected value.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, replace
from pathlib import Path

from glsandbox.errors import SandboxError
from glsandbox.exercises import check as exercise_check
from glsandbox.exercises.catalogue import get
from glsandbox.exercises.isolation import Limits as ExerciseLimits
from glsandbox.grading.check import (BROKEN, FAIL, PASS, TIMEOUT, CheckResult, Limits, Outcome, mark_duplicates,
                                     shown, submission_digest)
from glsandbox.grading import states
from glsandbox.grading.rubric import Check, exercise_groups, group_points

__all__ = ["default_check", "grade_file", "grade_folder", "exercise_submissions", "check_command", "with_exercises"]

#: The wrong cases a group's line names (its report's cases list every one).
SHOWN = 2


def default_check(name: str, where: str = "--exercise") -> Check:
    """The check ``check DIR --exercise NAME`` grades by: every case group, one point each."""
    groups = exercise_groups(name)
    split = group_points(float(len(groups)), groups, where)
    return Check(name, Path(f"{name}.exercise"), points=float(len(groups)), kind="exercise", exercise=name,
                 group_points=split)


def _defines(path: Path, function: str) -> bool:
    try:
        tree = ast.parse(path.read_bytes())
    except (OSError, SyntaxError, ValueError):
        return False
    return any(isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name == function
               for node in tree.body)


def entry_file(folder: Path, function: str, entry: str | None) -> Path:
    """The file of a student's folder that holds the function: ``entry`` where it defines it (else the
    one file that does), its only ``.py`` file, or the one defining it; a one-line error when none or several."""
    candidates = sorted(p for p in folder.glob("*.py") if p.is_file() and not p.is_symlink())
    if entry is not None:  # the rubric's (a lesson's, in a grading file of pictures and exercises too)
        chosen = folder / entry
        defining = [p for p in candidates if _defines(p, function)]
        return defining[0] if not _defines(chosen, function) and len(defining) == 1 else chosen
    if len(candidates) == 1:
        return candidates[0]
    defining = [p for p in candidates if _defines(p, function)]
    if len(defining) == 1:
        return defining[0]
    raise SandboxError(f"{shown(str(folder))}: {'no' if not defining else 'several'} .py file defining "
                       f"{function}() (name it with entry = \"FILE.py\" in the grading file)")


def exercise_submissions(folder: Path, one: bool = False) -> list[tuple[str, Path]]:
    """The students of ``folder``: each ``.py`` file and each subfolder, by name (``one``: the folder is one)."""
    if one or folder.is_file():
        return [(folder.resolve().name or "submission", folder)]
    return sorted((p.name, p) for p in folder.iterdir()
                  if (p.is_dir() or p.suffix == ".py") and not p.name.startswith((".", "__")))


def _limits(limits: Limits) -> ExerciseLimits:
    """The exercises' limits under the grader's: ``--timeout`` bounds each batch, ``--memory`` the process."""
    return replace(ExerciseLimits(), batch_seconds=min(limits.timeout, ExerciseLimits.batch_seconds),
                   call_seconds=min(limits.timeout, ExerciseLimits.call_seconds), memory_mb=limits.memory)


def _group_status(cases: Sequence[exercise_check.CaseResult]) -> str:
    if all(c.passed for c in cases):
        return PASS
    if any(c.status == exercise_check.FAIL for c in cases):
        return FAIL
    return TIMEOUT if any(c.status == exercise_check.TIMEOUT_STATUS for c in cases) else BROKEN


def _outcomes(check: Check, result: exercise_check.CheckResult, seconds: float) -> list[Outcome]:
    """One outcome per case group: the teacher's line names the wrong cases and the hint, the
    student's (a hidden group) only the counts and the cases' names."""
    outcomes = []
    groups = dict(check.group_points)
    hint = "; ".join(f"hint ({m}): {h}" for m, h in zip(result.mistakes, result.hints, strict=True))
    for group, worth in groups.items():
        cases = result.group(group)
        hidden = check.hidden or group != "visible"
        one = replace(check, name=f"{check.name}: {group}", points=worth, hidden=hidden)
        status = _group_status(cases)
        passed = sum(c.passed for c in cases)
        wrong = [c for c in cases if not c.passed]
        counts = f"{passed}/{len(cases)} cases passed"
        more = [f"and {len(wrong) - SHOWN} more"] if len(wrong) > SHOWN else []
        teacher = "; ".join([counts, *(f"{c.status} {c.name}: {c.call} gave {c.got}, expected {c.expected}"
                                       + (f" ({c.note})" if c.note else "") for c in wrong[:SHOWN]),
                             *more, *([hint] if hint and wrong else [])])
        if hidden:
            student = "; ".join([counts, *(f"{c.status} {c.name}" for c in wrong)])
        else:
            student = teacher
        outcomes.append(Outcome(one, status, error=teacher, seconds=seconds / max(len(groups), 1),
                                cases=[asdict(c) for c in cases], student=student))
    return outcomes


def grade_file(checks: Sequence[Check], source: Path, limits: Limits = Limits(), entry: str | None = None,
               ) -> list[Outcome]:
    """Every exercise check of one submission (a file or a student's folder); a file that cannot be the
    answer (a syntax error, no such function) is BROKEN in every group with its error line."""
    import time

    outcomes: list[Outcome] = []
    for check in checks:
        if states.is_state(check.exercise):  # tables, never run: drawn on the grader's context
            outcomes += states.grade_tables(check, source)
            continue
        exercise = get(check.exercise)
        started = time.perf_counter()
        try:
            path = entry_file(source, exercise.function, entry) if source.is_dir() else source
            if path.is_symlink():
                raise SandboxError(f"{shown(str(path))}: is a link (a submission is its own files)")
            result = exercise_check.check_file(exercise, path, limits=_limits(limits), hidden=True, probe=True)
        except SandboxError as exc:
            line = shown(str(exc))
            outcomes += [Outcome(replace(check, name=f"{check.name}: {g}", points=p,
                                         hidden=check.hidden or g != "visible"), BROKEN, error=line)
                         for g, p in check.group_points]
            continue
        if result.load_error:
            line = shown(result.load_error)
            outcomes += [Outcome(replace(check, name=f"{check.name}: {g}", points=p,
                                         hidden=check.hidden or g != "visible"), BROKEN, error=line)
                         for g, p in check.group_points]
            continue
        outcomes += _outcomes(check, result, time.perf_counter() - started)
    return outcomes


def grade_folder(folder: Path, checks: Sequence[Check], limits: Limits = Limits(), entry: str | None = None,
                 one: bool = False, progress: Callable[[int, int, CheckResult], None] = lambda d, t, r: None,
                 ) -> list[CheckResult]:
    """Every submission of ``folder`` graded on ``checks`` (all ``exercise``), ``limits.jobs`` at once;
    the results in folder order, the same files marked."""
    found = exercise_submissions(folder, one)
    if not found:
        raise SandboxError(f"{shown(str(folder))}: no .py files (nor subfolders holding one)")
    done: list[CheckResult] = []

    def grade(item: tuple[str, Path]) -> CheckResult:
        name, source = item
        result = CheckResult(name, source, grade_file(checks, source, limits, entry),
                             digest=submission_digest(source))
        done.append(result)
        progress(len(done), len(found), result)
        return result

    if any(states.is_state(c.exercise) for c in checks):  # one GL context: this thread only
        results = [grade(item) for item in found]
        states.close()
    else:
        with ThreadPoolExecutor(max(1, limits.jobs)) as pool:
            results = list(pool.map(grade, found))
    mark_duplicates(results)
    return results


def _source(folder: Path, path: Path, one: bool) -> Path:
    """A picture result's submission (its file, link or subfolder of ``folder``) from its lesson's path."""
    if one or path == folder:
        return folder
    try:
        relative = path.relative_to(folder)
    except ValueError:
        return path
    return folder / relative.parts[0]


def with_exercises(result: CheckResult, folder: Path, checks: Sequence[Check], limits: Limits = Limits(),
                   entry: str | None = None, one: bool = False) -> CheckResult:
    """A grading file of pictures and exercises: ``result`` (graded on its picture checks) given
    the outcomes of its exercise checks too, every outcome in the grading file's order. The
    submission is the same file or folder (in a folder, the exercise's function is the file
    that defines it, the lesson the rubric's ``entry`` or the one no other imports)."""
    source = _source(folder, result.path, one)
    outcomes: list[Outcome] = []
    for check in checks:
        if check.kind != "exercise":
            outcomes += [o for o in result.outcomes if o.check is check]
        elif source.is_symlink():
            outcomes += [Outcome(replace(check, name=f"{check.name}: {g}", points=p,
                                         hidden=check.hidden or g != "visible"), BROKEN,
                                 error=f"{shown(str(source))}: is a link (a submission is its own files)")
                         for g, p in check.group_points]
        else:
            outcomes += grade_file([check], source, limits, entry)
    result.outcomes = outcomes
    return result


def check_command(target: Path, checks: Sequence[Check], limits: Limits, reports: dict[str, Path | None],
                  title: str, entry: str | None = None, one: bool = False, update: bool = False) -> int:
    """``glsandbox check DIR|FILE.py --exercise NAME`` (or a rubric of ``exercise`` checks): a line per
    submission, the table and the reports; 0 when every submission passes every group, 1 otherwise.
    One file (no folder) that cannot be the answer is bad input: one ``error:`` line (exit 2)."""
    from glsandbox.grading.check import summary_table
    from glsandbox.grading.reports import REPORTS, write_reports

    if any(c.kind != "exercise" for c in checks):
        raise SandboxError(f"{title}: check_command grades exercise checks only (glsandbox check grades a "
                           "grading file of both: its pictures, then with_exercises)")
    if update:
        raise SandboxError("--update writes picture references; an exercise's references are its own cases")
    if not target.exists():
        raise SandboxError(f"{shown(str(target))}: no such file or folder")
    if target.is_dir():
        def report(done: int, total: int, result: CheckResult) -> None:
            print(f"[{done}/{total}] {result.line()}", flush=True)

        results = grade_folder(target, checks, limits, entry, one, report)
        print()
        print(summary_table(results))
        for path in write_reports(results, reports, title):
            print(f"wrote {path}")
        return 0 if all(r.status == PASS for r in results) else 1
    if any(path is not None for path in reports.values()):
        raise SandboxError(f"--{', --'.join(k.replace('_', '-') for k in REPORTS)} report a folder of submissions; "
                           "give a folder (--one for one student's)")
    if target.suffix != ".py":
        raise SandboxError(f"{shown(str(target))}: expected a .py file holding the exercise's function")
    outcomes = grade_file(checks, target, limits, entry)
    broken = next((o for o in outcomes if o.status == BROKEN), None)
    if broken is not None and all(o.error == broken.error for o in outcomes if o.status == BROKEN) \
            and all(o.status == BROKEN for o in outcomes):
        raise SandboxError(broken.error)
    for o in outcomes:
        print(f"{o.status:<7} {o.check.name} ({o.points:g}/{o.check.points:g}): {o.detail()}")
    score, total = sum(o.points for o in outcomes), sum(o.check.points for o in outcomes)
    print(f"{shown(str(target))}: {score:g}/{total:g} points")
    return 0 if all(o.status == PASS for o in outcomes) else 1
