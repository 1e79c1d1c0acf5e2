"""The ``glsandbox`` command's first step: start early what a long command can start early, then run it.

``glsandbox check DIR`` grades a class through a zygote (a fresh Python that
imports glsandbox, numpy and moderngl once, :mod:`glsandbox.grading.zygote`):
about 0.3 s of a core before the first submission can be drawn. Started here,
before the command line's own modules are imported (:mod:`glsandbox.cli`:
numpy, the renderers; ``import glsandbox`` itself imports nothing), the two
starts overlap on two cores instead of following each other. Anything else
goes straight to :func:`glsandbox.cli.main`.

The console script and ``python -m glsandbox`` come here; ``python -m
glsandbox.cli`` runs the same commands without the early start.
"""

from __future__ import annotations

import os
import sys

__all__ = ["main", "grades_a_class", "start_early", "leave_quickly"]


def grades_a_class(words: list[str]) -> bool:
    """Whether the command line ``words`` (after the program's name) grades a folder of
    submissions: ``check`` given a folder, without ``--update`` (which renders the model answer
    in this process) and not ``check merge``. A guess before the options are parsed: a zygote
    started for a command that ends up not needing it (a mistake in the options, a rubric of
    exercises only) is closed at exit, its folder removed."""
    if words[:1] != ["check"] or words[1:2] == ["merge"] or "--update" in words:
        return False
    return any(not word.startswith("-") and os.path.isdir(word) for word in words[1:])


def start_early(words: list[str]) -> None:
    """For a command that grades a class (:func:`grades_a_class`): the zygote started now
    (:func:`glsandbox.grading.runner.prestart`), and numpy's BLAS kept to one thread in this
    process too, unless the user set it: the grader's arrays are pictures compared pixel by
    pixel, and BLAS threads would only spin on the cores the renderers want."""
    if not grades_a_class(words):
        return
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    from glsandbox.grading.runner import prestart

    prestart()


def main(argv: list[str] | None = None) -> int:
    """The ``glsandbox`` command: :func:`start_early`, then :func:`glsandbox.cli.main`, then
    :func:`leave_quickly`."""
    start_early(sys.argv[1:] if argv is None else list(argv))
    from glsandbox.cli import main as cli_main

    code = cli_main(argv)
    leave_quickly()
    return code


def leave_quickly() -> None:
    """Every object still alive moved to the collector's permanent generation, just before
    the interpreter exits: its last collections then walk none of them. With numpy, PIL and
    glsandbox's modules loaded, those walks were 40 to 90 ms of a command's exit here, for
    memory the system takes back at once anyway. Exit handlers and finalisers still run
    (temporary folders removed, the zygote closed); a cycle of objects left at exit is not
    collected, which an exiting interpreter never promised."""
    import gc

    gc.freeze()
