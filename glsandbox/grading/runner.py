"""Which way this machine grades: the fork-based process tree, or the portable one.

:func:`run_jobs` is what ``check`` and ``tour --lessons`` call: the tree of
:mod:`glsandbox.grading.isolate` where the system can fork, else (Windows) or
when ``GLSANDBOX_ISOLATION=portable`` asks (:func:`portable_wanted`), a fresh
Python per submission (:mod:`glsandbox.grading.portable`). Light to import
(neither way's modules until a run): the command line asks it to start the
zygote before it imports anything else (:mod:`glsandbox.launch`).
"""

from __future__ import annotations

import os

TYPE_CHECKING = False  # (typing's own is an import this early start does without)
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from glsandbox.grading.isolate import Job, JobResult

__all__ = ["run_jobs", "portable_wanted", "prestart"]


def portable_wanted() -> bool:
    """Whether ``check`` grades the portable way: asked for (``GLSANDBOX_ISOLATION=portable``), or no ``fork``."""
    return os.environ.get("GLSANDBOX_ISOLATION", "").strip().lower() == "portable" or not hasattr(os, "fork")


def prestart() -> None:
    """Where this machine grades the fork-based way, start the zygote now
    (:func:`glsandbox.grading.zygote.prestart`): the next run takes it."""
    if not portable_wanted():
        from glsandbox.grading import zygote

        zygote.prestart()


def run_jobs(jobs: Sequence[Job], workers: int, done: Callable[[JobResult], None]) -> list[JobResult]:
    """Run every job, ``workers`` at once, the way this machine grades; ``done`` hears each as it
    finishes; the results come back in job order."""
    if portable_wanted():
        from glsandbox.grading import portable

        return portable.run_jobs_portable(jobs, workers, done)
    from glsandbox.grading import isolate
    from glsandbox.grading.slots import Slots

    return isolate.run_jobs(jobs, workers, done, slots=Slots)  # scene files: a renderer kept per slot
