"""``glsandbox exercise check mirror_states FILE.py``: the tables read (exit 2 for a file that is
not the tables), the room rendered with them, the leak map printed and pictured (exit 0 when it
is empty, 1 otherwise)."""

from __future__ import annotations

import argparse
from pathlib import Path

from glsandbox.errors import SandboxError

__all__ = ["check_states"]


def check_states(args: argparse.Namespace) -> int:
    """The ``check`` action for a state exercise (``--pictures`` as for the function exercises;
    ``--html``, ``--no-lesson`` and ``--timeout`` have nothing to do here: the file is never run)."""
    from glsandbox.exercises.states.mirror import check_tables, report, write_picture
    from glsandbox.exercises.states.tables import load_tables
    from glsandbox.frame import HeadlessRenderer

    if args.html is not None:
        raise SandboxError("--html: a state exercise's report is its text and its leak map picture (--pictures)")
    tables = load_tables(args.file)
    folder = args.pictures if args.pictures is not None else args.file.parent / f"{args.file.stem}_check"
    renderer = HeadlessRenderer()
    try:
        result = check_tables(renderer, tables)
    finally:
        renderer.close()
    picture: Path = write_picture(result.leaks, folder)
    print(report(result, picture))
    return 0 if result.passed else 1
