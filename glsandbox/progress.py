"""Progress with a time left for long commands, on stderr, drawn only for a person.

``tour``, ``tradeoffs``, ``bench``, ``compare`` and ``check DIR`` run for
seconds to minutes. :func:`progress` is a tqdm bar (steps done, rate and the
estimated time left) that draws only when stderr is a terminal: piped into a
file or read by a test, stderr holds just the command's own lines, as before.
:func:`say` prints such a line above a bar without breaking it.

Use::

    with progress(len(items), "check", unit="submission") as bar:
        for item in items:
            say(f"{item}: ok")
            bar.update(1)
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:
    from tqdm import tqdm

# tqdm is imported where a bar is drawn, not with this module: the CLI imports this module for
# every command, and tqdm's import (importlib.metadata) is a fifth of a cold start.

__all__ = ["progress", "say", "ready"]


def _terminal(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # no such method, or closed
        return False


def ready() -> None:
    """Where a bar will be drawn (stderr a terminal), import tqdm now, for a command whose first
    line waits on other processes (a class's first submission drawn): it is imported while they
    start, not when the first result is in and the next ones queue behind the import (30 to 45
    ms here). Elsewhere tqdm is never imported: no bar is drawn there."""
    if _terminal(sys.stderr):
        import tqdm  # noqa: F401 - imported for what follows


class _NoBar:
    """The bar of a stream that is not a terminal: nothing drawn (as tqdm draws nothing there)."""

    def update(self, n: float = 1) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> _NoBar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def progress(total: int, what: str, unit: str = "step", file: TextIO | None = None) -> tqdm | _NoBar:
    """A bar for ``total`` steps of ``what`` on ``file`` (stderr); nothing at all unless it is a terminal."""
    stream = file or sys.stderr
    if not _terminal(stream):
        return _NoBar()
    from tqdm import tqdm

    return tqdm(total=total, desc=what, unit=f" {unit}", file=stream, disable=None, leave=False,
                dynamic_ncols=True, mininterval=0.25, smoothing=0.1)


def say(text: str, file: TextIO | None = None) -> None:
    """One line on ``file`` (stderr), above any bar there (which is drawn again below it)."""
    stream = file or sys.stderr
    module = sys.modules.get("tqdm")  # never imported: no bar was made, none to keep clear of
    if module is not None and getattr(module.tqdm, "_instances", None):  # a bar drawn: the line goes above it
        module.tqdm.write(text, file=stream)
    else:  # no bar (not a terminal, or none made): the plain line, without tqdm's locks
        stream.write(text + "\n")
    stream.flush()
