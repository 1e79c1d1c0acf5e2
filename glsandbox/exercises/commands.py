"""``glsandbox exercise list | start | check``: the command line's bodies.

Exit codes of ``check``: 0 when every visible case passes (a state exercise:
when its leak map is empty), 1 otherwise, 2 for bad input (no such exercise, a file that is not the exercise's function:
one ``error:`` line naming the file and line).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from glsandbox.errors import SandboxError
from glsandbox.exercises.catalogue import all_exercises, get
from glsandbox.files import write_text

__all__ = ["cmd_exercise", "add_arguments"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The ``exercise`` command's own subcommands."""
    sub = parser.add_subparsers(dest="action", required=True, metavar="ACTION")
    sub.add_parser("list", help="a line per exercise: its name, course section and signature")
    p = sub.add_parser("start", help="write the starting file of an exercise (signature, docstring, example)")
    p.add_argument("name", metavar="NAME", help="the exercise (glsandbox exercise list)")
    p.add_argument("--out", type=Path, default=None, metavar="FILE", help="the file to write (default NAME.py)")
    p = sub.add_parser("check", help="run an exercise's cases on your file: a table, a hint, probe pictures")
    p.add_argument("name", metavar="NAME", help="the exercise (glsandbox exercise list)")
    p.add_argument("file", type=Path, metavar="FILE.py", help="your file, defining the exercise's function")
    p.add_argument("--html", type=Path, default=None, metavar="FILE",
                   help="also write the report as a page; its pictures go beside it")
    p.add_argument("--pictures", type=Path, default=None, metavar="DIR",
                   help="the folder for the pictures (default: FILE_check/ beside your file)")
    p.add_argument("--no-lesson", action="store_true", help="skip rendering the lesson with your function")
    p.add_argument("--timeout", type=float, default=2.0, metavar="SECONDS",
                   help="time for each call of your function (default 2)")


def cmd_exercise(args: argparse.Namespace) -> int:
    from glsandbox.exercises.states import STATE_EXERCISES

    if args.action == "list":
        return _list()
    if args.action == "start":
        return _start(args.name, args.out)
    if args.name in STATE_EXERCISES:
        from glsandbox.exercises.states.command import check_states

        return check_states(args)
    return _check(args)


def _list() -> int:
    from glsandbox.exercises.states import STATE_EXERCISES

    lines = [(e.name, e.section, e.signature) for e in all_exercises()]
    lines += [(e.name, e.section, e.holds) for e in STATE_EXERCISES.values()]
    name_w = max(len(n) for n, _, _ in lines)
    section_w = max(len(s) for _, s, _ in lines)
    for name, section, what in lines:
        print(f"{name:<{name_w}}  {section:<{section_w}}  {what}")
    return 0


def _start(name: str, out: Path | None) -> int:
    from glsandbox.exercises.starter import starter
    from glsandbox.exercises.states import STATE_EXERCISES

    exercise = get(name) if name not in STATE_EXERCISES else None
    path = out or Path(f"{name}.py")
    _check_out(path)
    if exercise is None:
        from glsandbox.exercises.states.mirror import starter as state_starter

        write_text(path, state_starter())
        print(f"wrote {path}: fill in its tables, then: glsandbox exercise check {name} {path}")
        return 0
    write_text(path, starter(exercise))
    print(f"wrote {path}: write {exercise.signature} in it, then: glsandbox exercise check {exercise.name} {path}")
    return 0


def _check_out(path: Path) -> None:
    """A starter's file: a new .py file in a folder that exists."""
    if path.exists():
        raise SandboxError(f"{path}: already exists; not overwritten (remove it, or name another with --out)")
    if path.suffix != ".py":
        raise SandboxError(f"--out {path}: the starter is a Python file, name it .py")
    if not (path.parent if str(path.parent) else Path(".")).is_dir():
        raise SandboxError(f"--out {path}: folder {path.parent} does not exist")


def _check(args: argparse.Namespace) -> int:
    from glsandbox.exercises.check import check_file
    from glsandbox.exercises.isolation import Limits
    from glsandbox.exercises.report import text, write_html, write_pictures

    exercise = get(args.name)
    if args.html is not None and not (args.html.parent if str(args.html.parent) else Path(".")).is_dir():
        raise SandboxError(f"--html {args.html}: folder {args.html.parent} does not exist")
    if not args.timeout > 0:
        raise SandboxError(f"--timeout {args.timeout}: must be a positive number of seconds")
    result = check_file(exercise, args.file, limits=Limits(call_seconds=args.timeout), hidden=False,
                        lesson=not args.no_lesson)
    if args.pictures is not None:
        folder = args.pictures
    elif args.html is not None:
        folder = args.html.parent / f"{args.html.stem}_pictures"
    else:
        folder = args.file.parent / f"{args.file.stem}_check"
    write_pictures(result, folder)
    if args.html is not None:
        write_html(result, args.html)
        result.pictures["report"] = str(args.html)
    print(text(result, hidden_shown=False))
    return 0 if result.visible_passed else 1
