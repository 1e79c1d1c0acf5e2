"""Which way this machine grades: the fork-based process tree, or the portable one.

:func:`run_jobs` is what ``check`` and ``tour --lessons`` call: the tree of
:mod:`glsandbox.grading.isolate` where the system can fork, else (Windows) or
when ``GLSANDBOX_ISOLATION=portable`` asks, a fresh Python per submission
(:mod:`glsandbox.grading.portable`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from glsandbox.grading import isolate, portable
from glsandbox.grading.isolate import Job, JobResult
from glsandbox.grading.slots import Slots

__all__ = ["run_jobs"]


def run_jobs(jobs: Sequence[Job], workers: int, done: Callable[[JobResult], None]) -> list[JobResult]:
    """Run every job, ``workers`` at once, the way this machine grades; ``done`` hears each as it
    finishes; the results come back in job order."""
    if portable.wanted():
        return portable.run_jobs_portable(jobs, workers, done)
    return isolate.run_jobs(jobs, workers, done, slots=Slots)  # scene files: a renderer kept per slot
