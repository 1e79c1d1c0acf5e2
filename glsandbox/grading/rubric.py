"""A grading file: the checks each submission gets, with their settings, tolerances and points.

``glsandbox check DIR --rubric grading.toml`` renders every submission once
per check and gives each student a score out of the total. The file::

    # every key below [[check]] is optional except golden
    timeout = 30            # seconds for each picture (the command line's --timeout wins)
    memory = 2048           # MB of address space for each submission
    entry = "spin.py"       # the lesson file in a student's folder (default: the one no other file imports)

    [[check]]
    kind = "picture"        # the default; the kinds are glsandbox.grading.kinds.KINDS
    name = "still"          # default: the golden's stem
    golden = "goldens/still.png"   # relative to this file; may be a hidden one only the teacher has
    points = 2              # default 1
    set = ["time=0"]        # any --set values: time, a Param, renderer, camera, u.NAME
    size = "320x240"        # default: the golden's size
    samples = 0
    renderer = "raster"     # a short way of writing set = ["renderer=..."]
    tolerance = { threshold = 2, max_bad_share = 0.0005 }
    hidden = false          # true: Gradescope shows it to the student only after publishing

    [[check]]
    exercise = "ray_sphere" # a student's function (glsandbox exercise list); kind = "exercise" inferred
    points = { visible = 2, hidden = 3 }   # per case group; "hidden": the hidden groups not named, split evenly
                                           # (one number: split evenly over every group)

    [[check]]
    exercise = "mirror_states"             # a state exercise: points per leak kind
    points = { reflection_outside = 2, shadow_twice = 1 }

Every mistake in the file is one line naming the file, the check and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from glsandbox.errors import SandboxError, parse_size_text
from glsandbox.files import read_user_file, written_path
from glsandbox.grading.kinds import COMMON_KEYS, kind_of, known
from glsandbox.measure.golden import DEFAULT_MAX_BAD_SHARE, DEFAULT_THRESHOLD

__all__ = ["Check", "Rubric", "load_rubric", "parse_tolerances", "TOLERANCES", "parse_size_text", "STARTER"]

#: The tolerances ``--tolerance KEY=VALUE`` (and the pytest fixture's keywords) accept.
TOLERANCES = {"threshold": DEFAULT_THRESHOLD, "max_bad_share": DEFAULT_MAX_BAD_SHARE}


@dataclass(frozen=True)
class Check:
    """One picture every submission must match, and what it is worth."""

    name: str
    golden: Path
    settings: tuple[str, ...] = ()
    size: tuple[int, int] | None = None
    samples: int = 0
    tolerances: dict[str, float] = field(default_factory=dict)
    points: float = 1.0
    hidden: bool = False
    #: The kind of check (:mod:`glsandbox.grading.kinds`): how what comes back is judged.
    kind: str = "picture"
    #: An ``exercise`` check's exercise name, and its points per case group (in the exercise's order).
    exercise: str = ""
    group_points: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class Rubric:
    """The checks, and the limits the file asks for (None: the command line's or the default)."""

    checks: tuple[Check, ...]
    timeout: float | None = None
    memory: int | None = None
    #: The lesson file's name in a student's folder (None: the one no other file imports).
    entry: str | None = None

    @property
    def total(self) -> float:
        return sum(check.points for check in self.checks)


def tolerance_value(key: str, value: Any, where: str) -> float:
    """One tolerance checked: ``threshold`` a whole number of levels 0..255, ``max_bad_share`` 0..1."""
    if key not in TOLERANCES:
        raise SandboxError(f"{where}: expected threshold=LEVELS or max_bad_share=FRACTION")
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if key == "threshold" and not (math.isfinite(number) and number == int(number) and 0 <= number <= 255):
        raise SandboxError(f"{where}: threshold is a whole number of levels, 0..255")
    if key == "max_bad_share" and not 0.0 <= number <= 1.0:  # NaN fails this too
        raise SandboxError(f"{where}: max_bad_share is a fraction, 0..1")
    return int(number) if key == "threshold" else number


def parse_tolerances(items: list[str] | tuple[str, ...]) -> dict[str, float]:
    """``threshold=4``, ``max_bad_share=0.01`` -> keywords of :func:`compare_images`, checked."""
    tolerances: dict[str, float] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            key = ""
        tolerances[key] = tolerance_value(key, text, f"--tolerance {item!r}")
    return tolerances


_TOP_KEYS = {"timeout", "memory", "entry", "check"}


def load_rubric(path: Path) -> Rubric:
    """Read and check a grading file; every mistake is one :class:`SandboxError` naming the file and key."""
    import tomllib  # only grading reads TOML

    raw = read_user_file(path, "rubric", "a .toml grading file")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise SandboxError(f"{path}: not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise SandboxError(f"{path}: not valid TOML ({exc})") from None
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise SandboxError(f"{path}: unknown key {unknown[0]!r} (expected {', '.join(sorted(_TOP_KEYS))})")
    entries = data.get("check")
    if not isinstance(entries, list) or not entries or not all(isinstance(e, dict) for e in entries):
        raise SandboxError(f"{path}: expected one or more [[check]] tables")
    checks = [_check(entry, number, path) for number, entry in enumerate(entries, start=1)]
    names = [c.name for c in checks]
    twice = next((n for n in names if names.count(n) > 1), None)
    if twice is not None:
        raise SandboxError(f"{path}: two checks are named {twice!r}; give each its own name")
    timeout = data.get("timeout")
    if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                or not 0 < timeout <= 3600):
        raise SandboxError(f"{path}: timeout = {timeout!r}: expected seconds, more than 0 and at most 3600")
    memory = data.get("memory")
    if memory is not None and (isinstance(memory, bool) or not isinstance(memory, int) or not 64 <= memory <= 1 << 20):
        raise SandboxError(f"{path}: memory = {memory!r}: expected a whole number of MB, at least 64")
    entry = data.get("entry")
    if entry is not None and (not isinstance(entry, str) or not entry.endswith((".py", ".toml")) or "/" in entry
                              or "\\" in entry or entry.startswith(".")):
        raise SandboxError(f"{path}: entry = {entry!r}: expected a lesson file's name, e.g. \"spin.py\"")
    return Rubric(tuple(checks), None if timeout is None else float(timeout), memory, entry)


def _check(entry: dict[str, Any], number: int, path: Path) -> Check:
    where = f"{path}: check {number}"
    kind_name = entry.get("kind", "exercise" if "exercise" in entry else "picture")
    try:
        kind = kind_of(kind_name) if isinstance(kind_name, str) else None
    except KeyError:
        kind = None
    if kind is None:
        raise SandboxError(f"{where}: kind = {kind_name!r}: expected one of {', '.join(known())}")
    allowed = COMMON_KEYS | kind.keys
    unknown = sorted(set(entry) - allowed)
    if unknown:
        raise SandboxError(f"{where}: unknown key {unknown[0]!r} (expected {', '.join(sorted(allowed))})")
    if kind.name == "exercise":
        return exercise_check(entry, where, path)
    golden = entry.get("golden")
    if not isinstance(golden, str) or not golden.lower().endswith(".png"):
        raise SandboxError(f"{where}: golden = {golden!r}: expected the path of a .png file")
    try:
        golden_path = written_path(golden, path.parent)  # relative to this file; / or \\ between folders
    except SandboxError as exc:
        raise SandboxError(f"{where}: golden: {exc}") from None
    name = entry.get("name", golden_path.stem)
    if not isinstance(name, str) or not name.strip() or not name.isprintable():
        raise SandboxError(f"{where}: name = {name!r}: expected a short printable text")
    where = f"{path}: check {name!r}"
    points = entry.get("points", 1)
    if isinstance(points, bool) or not isinstance(points, (int, float)) or not (0 <= points <= 1e6):
        raise SandboxError(f"{where}: points = {points!r}: expected a number, 0 or more")
    settings = entry.get("set", [])
    if not isinstance(settings, list) or not all(isinstance(s, str) and "=" in s for s in settings):
        raise SandboxError(f"{where}: set = {settings!r}: expected a list of \"key=value\" texts")
    renderer = entry.get("renderer")
    if renderer is not None:
        if not isinstance(renderer, str):
            raise SandboxError(f"{where}: renderer = {renderer!r}: expected a text")
        settings = [*settings, f"renderer={renderer}"]
    size = entry.get("size")
    size_value = None if size is None else parse_size_text(size, f"{where}: size")
    samples = entry.get("samples", 0)
    if isinstance(samples, bool) or samples not in (0, 1, 2, 4, 8, 16):
        raise SandboxError(f"{where}: samples = {samples!r}: expected 0, 1, 2, 4, 8 or 16")
    tolerance = entry.get("tolerance", {})
    if not isinstance(tolerance, dict):
        raise SandboxError(f"{where}: tolerance: expected a table, e.g. {{ threshold = 2, max_bad_share = 0.0005 }}")
    tolerances = {key: tolerance_value(key, value, f"{where}: tolerance {key} = {value!r}")
                  for key, value in tolerance.items()}
    hidden = entry.get("hidden", False)
    if not isinstance(hidden, bool):
        raise SandboxError(f"{where}: hidden = {hidden!r}: expected true or false")
    return Check(name.strip(), golden_path, tuple(settings), size_value, samples, tolerances, float(points), hidden,
                 kind.name)


def group_points(points: Any, groups: list[str], where: str) -> tuple[tuple[str, float], ...]:
    """An exercise check's points per case group: one number split evenly over ``groups``, or a table
    of group names (``hidden``: the hidden groups not named, split evenly; a group not named and no
    ``hidden``: 0 points)."""
    def number(value: Any, key: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= 1e6:
            raise SandboxError(f"{where}: {key} = {value!r}: expected a number, 0 or more")
        return float(value)

    if not isinstance(points, dict):
        total = number(points, "points")
        return tuple((g, total / len(groups)) for g in groups)
    for key in points:
        if key not in groups and key != "hidden":
            raise SandboxError(f"{where}: points.{key}: no case group {key!r} (the groups: {', '.join(groups)}, "
                               "or hidden for the hidden ones not named)")
    named = {key: number(value, f"points.{key}") for key, value in points.items()}
    rest = [g for g in groups if g not in named and g != "visible"]
    share = named.get("hidden", 0.0) / len(rest) if rest else 0.0
    return tuple((g, named[g] if g in named else 0.0 if g == "visible" else share) for g in groups)


def exercise_groups(name: str) -> list[str]:
    """An exercise's case groups, in its order: a function exercise's (``visible`` first), or a
    state exercise's leak kinds."""
    from glsandbox.exercises.catalogue import get
    from glsandbox.exercises.states import STATE_EXERCISES

    if name in STATE_EXERCISES:
        return list(STATE_EXERCISES[name].groups)
    return list(dict.fromkeys(case.group for case in get(name).cases(True)))


def exercise_check(entry: dict[str, Any], where: str, path: Path) -> Check:
    """A ``[[check]]`` of kind ``exercise``: the exercise (checked against the catalogue), its name,
    its points per case group and ``hidden``."""
    from glsandbox.exercises.catalogue import MODULES, get
    from glsandbox.exercises.states import STATE_EXERCISES

    name = entry.get("exercise")
    if not isinstance(name, str) or (name not in MODULES and name not in STATE_EXERCISES):
        raise SandboxError(f"{where}: exercise = {name!r}: expected one of {', '.join([*MODULES, *STATE_EXERCISES])}")
    title = entry.get("name", name)
    if not isinstance(title, str) or not title.strip() or not title.isprintable():
        raise SandboxError(f"{where}: name = {title!r}: expected a short printable text")
    where = f"{path}: check {title!r}"
    groups = exercise_groups(name)
    split = group_points(entry.get("points", len(groups)), groups, where)
    hidden = entry.get("hidden", False)
    if not isinstance(hidden, bool):
        raise SandboxError(f"{where}: hidden = {hidden!r}: expected true or false")
    return Check(title.strip(), path.parent / f"{name}.exercise", points=sum(p for _, p in split), hidden=hidden,
                 kind="exercise", exercise=name, group_points=split)


#: The starting rubric ``glsandbox new --assignment NAME`` writes beside the model answer.
STARTER = """\
# Grading file for the assignment "$name" (see the manual, docs/grading-a-class.md).
#   1. write the goldens from the model answer:
#        glsandbox check $name.py --rubric $name.grading.toml --update
#   2. grade a folder of submissions (one .py/.toml file or one folder per student):
#        glsandbox check submissions/ --rubric $name.grading.toml --html report.html
# Each [[check]] renders every submission once; its golden may be kept from students.

timeout = 30     # seconds for each picture
memory = 2048    # MB of memory for each submission

[[check]]
name = "still"
golden = "$name-goldens/still.png"
set = ["time=0"]
size = "320x240"
points = 1

[[check]]
name = "moving"
golden = "$name-goldens/moving.png"
set = ["time=1.5"]
size = "320x240"
points = 2
tolerance = { threshold = 2, max_bad_share = 0.0005 }

[[check]]
name = "traced"
golden = "$name-goldens/traced.png"
set = ["time=0"]
renderer = "ray_numpy"
size = "160x120"
points = 1
hidden = true
"""
