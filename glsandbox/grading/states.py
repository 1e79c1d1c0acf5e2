"""Grading a state exercise for a class: ``check DIR --exercise mirror_states``, or a rubric's
``exercise = "mirror_states"`` check with points per leak kind.

A state exercise's file is data (:mod:`glsandbox.exercises.states.tables`
reads it with :func:`ast.literal_eval` and never runs it), so it is graded in
the grader's own process, on one GL context for the whole run: the mirror
room is drawn with the tutorials' tables once, the known mistakes' leak
maps once (for the hints), and each student's tables once.

Each leak kind of the leak map (:data:`glsandbox.exercises.states.mirror.CLASSES`
but "as the reference") is a case group (named in
:data:`~glsandbox.exercises.states.STATE_EXERCISES`): PASS when no pixel of that kind
leaks, FAIL otherwise, worth the group's points; a file that is not the
tables (a statement, a name, a value the tables cannot hold) is BROKEN in
every group with its one ``error:`` line. The teacher's and the student's
lines are the same (the counts of leaking pixels and the named mistakes'
hints): the leak map is what the student's own ``exercise check`` shows.
"""

from __future__ import annotations

import ast
import atexit
import threading
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from glsandbox.errors import SandboxError
from glsandbox.exercises.states import STATE_EXERCISES

__all__ = ["is_state", "groups_of", "find_tables", "grade_tables", "close"]

def is_state(name: str) -> bool:
    """Whether ``name`` is a state exercise (its file is tables, not a function)."""
    return name in STATE_EXERCISES


def groups_of(name: str) -> dict[str, str]:
    """A state exercise's case group of each leak kind (by the kind's name in the leak map)."""
    from glsandbox.exercises.states.mirror import CLASSES

    return dict(zip((kind for kind, _ in CLASSES[1:]), STATE_EXERCISES[name].groups, strict=True))


def find_tables(source: Path) -> Path:
    """A student's tables file: ``source`` itself, or of a folder its only ``.py`` file or the one
    assigning ``MARK_MIRROR_DSS``; one error line when none or several."""
    if not source.is_dir():
        return source
    candidates = sorted(p for p in source.glob("*.py") if p.is_file() and not p.is_symlink())
    if len(candidates) == 1:
        return candidates[0]
    holding = [p for p in candidates if _assigns(p, "MARK_MIRROR_DSS")]
    if len(holding) == 1:
        return holding[0]
    raise SandboxError(f"{source}: {'no' if not holding else 'several'} .py file assigning MARK_MIRROR_DSS")


def _assigns(path: Path, name: str) -> bool:
    try:
        tree = ast.parse(path.read_bytes())
    except (OSError, SyntaxError, ValueError):
        return False
    return any(isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in node.targets)
               for node in tree.body)


@dataclass
class _Session:
    """The run's GL context and what every submission is measured against."""

    renderer: Any
    reference: Any
    mistakes: dict | None = None


_LOCK = threading.Lock()
_SESSION: list[_Session] = []


def _session() -> _Session:
    from glsandbox.exercises.states.mirror import render_with
    from glsandbox.frame import HeadlessRenderer

    if not _SESSION:
        renderer = HeadlessRenderer()
        _SESSION.append(_Session(renderer, render_with(renderer, None)))
    return _SESSION[0]


def close() -> None:
    """Close the run's GL context (the next state check opens a fresh one)."""
    with _LOCK:
        while _SESSION:
            _SESSION.pop().renderer.close()


atexit.register(close)


def grade_tables(check: Any, source: Path) -> list[Any]:
    """One state check of one submission: an :class:`~glsandbox.grading.check.Outcome` per leak kind."""
    import time

    from glsandbox.exercises.states import mirror
    from glsandbox.exercises.states.tables import load_tables
    from glsandbox.grading.check import BROKEN, FAIL, PASS, Outcome, shown

    def one(group: str, worth: float) -> Any:
        return replace(check, name=f"{check.name}: {group}", points=worth)

    started = time.perf_counter()
    try:
        if source.is_symlink():
            raise SandboxError(f"{source}: is a link (a submission is its own files)")
        path = find_tables(source)
        if path.is_symlink():
            raise SandboxError(f"{path}: is a link (a submission is its own files)")
        tables = load_tables(path)
    except SandboxError as exc:
        return [Outcome(one(g, p), BROKEN, error=shown(str(exc))) for g, p in check.group_points]
    with _LOCK:
        session = _session()
        leaks = mirror.leak_map(session.reference, mirror.render_with(session.renderer, tables))
        hints: list[str] = []
        if not leaks.empty:
            if session.mistakes is None:
                session.mistakes = mirror.mistake_maps(session.renderer, session.reference)
            hints = mirror.hints(leaks, session.mistakes)
    seconds = (time.perf_counter() - started) / max(len(check.group_points), 1)
    groups = groups_of(check.exercise)
    counts = {groups[kind]: count for kind, count in leaks.counts().items()}
    outcomes = []
    for group, worth in check.group_points:
        leaking = counts.get(group, 0)
        named = [h for h in hints if leaking and _shows(h, groups, group)] or (hints if leaking else [])
        line = f"{leaking} pixels leak" + "".join(f"; hint ({h})" for h in named)
        outcomes.append(Outcome(one(group, worth), FAIL if leaking else PASS, error=line, seconds=seconds,
                                student=line))
    return outcomes


def _shows(hint: str, groups: dict[str, str], group: str) -> bool:
    """Whether the named mistake of ``hint`` (``name: sentence``) shows as the leak kind ``group``."""
    from glsandbox.exercises.states.mirror import CLASSES, MISTAKES

    name = hint.split(":", 1)[0]
    kind = next((m.shows_as for m in MISTAKES if m.name == name), None)
    return kind is not None and groups.get(CLASSES[kind][0]) == group
