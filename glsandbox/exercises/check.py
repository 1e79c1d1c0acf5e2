"""Checking a student's function: the cases, the probe picture, the named mistake.

:func:`check` runs an exercise's cases through a caller (an
:class:`~glsandbox.exercises.isolation.Isolated` file, or an
:class:`~glsandbox.exercises.isolation.InProcess` function in a notebook),
judges each answer in this process (the expected values never leave it),
draws the probe picture and matches the failures against the exercise's
named mistakes. The result, :class:`CheckResult`, is plain data: cases in
groups with their outcomes, ready to be given points and serialized
(:meth:`CheckResult.to_dict`).

Matching a mistake: each named mistake (trusted code, run here) answers the
same cases and a sample of the probe's field. Where the student's answer is
wrong, the mistake that gives the same wrong answers is the one named
(:func:`match_mistakes`).
"""

from __future__ import annotations

import ast
import gc
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from glsandbox.errors import SandboxError
from glsandbox.exercises import student_process
from glsandbox.exercises.compare import WrongType, describe, judge, matches, normalize
from glsandbox.exercises.definition import Case, Exercise, Mistake
from glsandbox.exercises.isolation import CRASHED, ERROR, TIMEOUT, VALUE, Answer, InProcess, Isolated, Limits
from glsandbox.exercises.probe import ProbeResult, probe_field, start_probe

__all__ = ["PASS", "FAIL", "BROKEN", "TIMEOUT_STATUS", "CaseResult", "CheckResult", "check", "check_file",
           "check_function", "static_check"]

PASS, FAIL, BROKEN, TIMEOUT_STATUS = "PASS", "FAIL", "BROKEN", "TIMEOUT"
#: A mistake is named when its wrong answers are the student's on at least this share of them.
HINT_SHARE = 0.8
#: The probe is sampled every this many pixels (each way) to match mistakes.
HINT_STRIDE = 8


@dataclass
class CaseResult:
    """One case's outcome: ``status`` is PASS, FAIL, BROKEN (it raised, its process ended, it
    printed too much) or TIMEOUT; ``note`` says why in words."""

    name: str
    group: str
    call: str
    expected: str
    got: str
    status: str
    note: str = ""

    @property
    def passed(self) -> bool:
        return self.status == PASS


@dataclass
class CheckResult:
    """A whole check: what a terminal, a notebook, an HTML page or a grader reads."""

    exercise: str
    function: str
    signature: str
    cases: list[CaseResult]
    mistakes: list[str] = field(default_factory=list)
    hints: list[str] = field(default_factory=list)
    load_error: str = ""
    probe: ProbeResult | None = None
    lesson: Any = None
    pictures: dict[str, str] = field(default_factory=dict)

    def group(self, name: str) -> list[CaseResult]:
        return [c for c in self.cases if c.group == name]

    def groups(self) -> dict[str, tuple[int, int]]:
        """Each case group (``visible``, then the hidden ones) with (passed, total)."""
        out: dict[str, tuple[int, int]] = {}
        for case in self.cases:
            passed, total = out.get(case.group, (0, 0))
            out[case.group] = (passed + case.passed, total + 1)
        return out

    @property
    def visible_passed(self) -> bool:
        visible = self.group("visible")
        return bool(visible) and all(c.passed for c in visible)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data: the cases, the groups' counts, the hint, the probe's figures, the pictures."""
        return {"exercise": self.exercise, "function": self.function, "signature": self.signature,
                "cases": [asdict(c) for c in self.cases],
                "groups": {k: {"passed": p, "total": t} for k, (p, t) in self.groups().items()},
                "visible_passed": self.visible_passed, "mistakes": list(self.mistakes), "hints": list(self.hints),
                "load_error": self.load_error,
                "probe": None if self.probe is None else self.probe.figures(),
                "pictures": dict(self.pictures)}


# --- before running anything: the file's shape -----------------------------------------------


def static_check(path: Path, exercise: Exercise) -> None:
    """Refuse a file that cannot be the exercise's answer, without running it: a syntax error,
    no function of the exercise's name, a different number of parameters. One line naming the
    file and line (:class:`SandboxError`)."""
    try:
        source = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SandboxError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SandboxError(f"{path}: cannot be read as a Python file ({exc})") from None
    try:
        tree = ast.parse(source, filename=str(path))
    except SyntaxError as exc:
        raise SandboxError(f"{path}:{exc.lineno}: syntax error: {exc.msg}") from None
    found = None
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name == exercise.function:
            found = node
        elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == exercise.function
                                                  for t in node.targets):
            return  # made by an assignment (a lambda, a wrapper): its parameters are seen when it runs
    if found is None:
        raise SandboxError(f"{path}:1: defines no function {exercise.function}() (the exercise {exercise.name} "
                           f"asks for {exercise.signature})")
    args = found.args
    if args.vararg is not None:
        return
    positional = len(args.posonlyargs) + len(args.args)
    required = positional - len(args.defaults)
    if not required <= len(exercise.params) <= positional:
        raise SandboxError(f"{path}:{found.lineno}: {exercise.function}() takes {positional} parameter"
                           f"{'s' if positional != 1 else ''}, the exercise asks for {exercise.signature}")


# --- running the cases -------------------------------------------------------------------


def _call_text(exercise: Exercise, args: Sequence[Any]) -> str:
    return f"{exercise.function}({', '.join(describe(a) for a in args)})"


def _plain(value: Any) -> Any:
    """A reference's or a mistake's answer as the student's would arrive (plain JSON data)."""
    return student_process._encode(value)


_GOT = {ERROR: "it raised", TIMEOUT: "no answer", CRASHED: "its process ended"}


def _outcome(case: Case, answer: Answer, exercise: Exercise) -> tuple[str, str]:
    if answer.status == TIMEOUT:
        return TIMEOUT_STATUS, answer.error
    if answer.status in (ERROR, CRASHED):
        return BROKEN, answer.error
    passed, note = judge(case, answer.value, exercise.returns)
    return (PASS if passed else FAIL), note


def _mistake_answer(mistake: Mistake, args: Sequence[Any]) -> Any:
    try:
        return _plain(mistake.function(*args))
    except Exception:  # noqa: BLE001 - a mistake may raise where the real function does not
        return {"__type__": "error", "repr": ""}


def _same(a: Any, b: Any, returns: str) -> bool:
    """Whether two answers are the same answer (both wrong the same way)."""
    try:
        x, y = normalize(a, returns), normalize(b, returns)
    except WrongType:
        return False
    return matches(x, y, 1e-6, 1e-9)


@dataclass(frozen=True)
class Evidence:
    """One input the student answered: the arguments, the answer, whether it is wrong, and how
    to tell a right answer there (the case's judgement, or the probe reference's value)."""

    args: tuple[Any, ...]
    answer: Any
    wrong: bool
    right: Callable[[Any], bool]


def match_mistakes(exercise: Exercise, evidence: list[Evidence]) -> list[Mistake]:
    """The named mistakes that answer as the student does where either of them is wrong.

    For each mistake, over the inputs where the student or the mistake is wrong, the share
    where the student gives the mistake's own answer (a mistake that is wrong where the
    student is right loses). The best is named when that share is at least half, then the
    same again on the student's wrong answers it leaves unexplained, so two mistakes made
    together are both named; a second one needs :data:`HINT_SHARE`."""
    named: list[Mistake] = []
    left = list(evidence)
    while any(e.wrong for e in left) and len(named) < 2:
        best, best_same, best_share = None, [], 0.0
        for mistake in exercise.mistakes:
            if mistake in named:
                continue
            answers = [_mistake_answer(mistake, e.args) for e in left]
            same = [e.wrong and _same(a, e.answer, exercise.returns) for a, e in zip(answers, left, strict=True)]
            union = sum(e.wrong or not e.right(a) for a, e in zip(answers, left, strict=True))
            share = sum(same) / union if union else 0.0
            if share > best_share:
                best, best_same, best_share = mistake, same, share
        if best is None or best_share < (HINT_SHARE if named else 0.5):
            break
        named.append(best)
        left = [e for e, explained in zip(left, best_same, strict=True) if not explained]
    return named


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cycle collector held off while a check runs, put back as it was after: the probe
    makes some 65,536 tuples of arguments and as many answers at once, none of them in a cycle,
    and each of the collector's passes would walk them all again (a quarter of its time)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def check(exercise: Exercise, caller: Isolated | InProcess, *, hidden: bool = False, probe: bool = True,
          probe_size: int = 256, lesson: bool = False) -> CheckResult:
    """Run ``exercise``'s cases (the hidden ones too with ``hidden``) through ``caller`` and
    judge them; draw the probe picture (``probe``) and, where the exercise has one and
    ``lesson`` is asked, the lesson rendered with the student's function."""
    with _collector_paused():
        return _check(exercise, caller, hidden, probe, probe_size, lesson)


def _check(exercise: Exercise, caller: Isolated | InProcess, hidden: bool, probe: bool, probe_size: int,
           lesson: bool) -> CheckResult:
    results: list[CaseResult] = []
    evidence: list[Evidence] = []
    start = getattr(caller, "start", None)
    if start is not None:
        start()  # the student's interpreter starts while this process makes the cases and the probe's field
    cases = exercise.cases(hidden)
    field = probe_field(exercise, probe_size) if probe else None
    for case in cases:
        answer = caller.call(case.args)
        status, note = _outcome(case, answer, exercise)
        got = describe(answer.value) if answer.status == VALUE else _GOT[answer.status]
        results.append(CaseResult(case.name, case.group, _call_text(exercise, case.args), describe(case.expected),
                                  got, status, note))
        if status in (PASS, FAIL) and not note:
            evidence.append(Evidence(case.args, answer.value, status == FAIL,
                                     lambda value, case=case: judge(case, value, exercise.returns)[0]))
    result = CheckResult(exercise.name, exercise.function, exercise.signature, results,
                         load_error=caller.load_error)
    lesson = lesson and exercise.lesson is not None and not caller.load_error
    prepared = None
    if probe and not caller.load_error:
        finish = start_probe(exercise, caller, probe_size, field)  # the student's process works on the field...
        if lesson:  # ...while this one renders the lesson's reference picture and the probe's reference
            from glsandbox.exercises.lesson_view import lesson_reference

            prepared = lesson_reference(exercise)
        result.probe = finish()
        evidence += [Evidence(args, answer, wrong, lambda value, ref=ref: _same(value, ref, exercise.returns))
                     for args, answer, ref, wrong in result.probe.sample(HINT_STRIDE)]
    for mistake in match_mistakes(exercise, evidence):
        result.mistakes.append(mistake.name)
        result.hints.append(mistake.hint)
    if lesson and not caller.load_error:
        from glsandbox.exercises.lesson_view import render_lesson

        result.lesson = render_lesson(exercise, caller, prepared)
    return result


def check_file(exercise: Exercise, path: str | os.PathLike[str], *, limits: Limits = Limits(),
               **options: Any) -> CheckResult:
    """:func:`check` of the file ``path``, its function run isolated (:class:`Isolated`)."""
    path = Path(path)
    static_check(path, exercise)
    with Isolated(path, exercise.function, limits) as caller:
        return check(exercise, caller, **options)


def check_function(exercise: Exercise, function: Any, **options: Any) -> CheckResult:
    """:func:`check` of a function object in this process (a notebook's own)."""
    if not callable(function):
        raise SandboxError(f"exercise {exercise.name}: expected a function, got {describe(function)}")
    return check(exercise, InProcess(function), **options)

