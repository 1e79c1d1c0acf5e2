"""Which way this machine grades (glsandbox/grading/runner.py): the fork-based tree, or a fresh
Python per submission when ``GLSANDBOX_ISOLATION=portable`` asks or the system cannot fork.
(Each way end to end: test_isolation.py and test_portable.py.)"""

from __future__ import annotations

import pytest

from glsandbox.grading import isolate, portable, runner
from glsandbox.grading.slots import Slots


@pytest.fixture
def calls(monkeypatch) -> list[tuple]:
    found: list[tuple] = []
    monkeypatch.setattr(isolate, "run_jobs",
                        lambda jobs, workers, done, slots=None: found.append(("tree", jobs, workers, slots)) or ["t"])
    monkeypatch.setattr(portable, "run_jobs_portable",
                        lambda jobs, workers, done: found.append(("portable", jobs, workers)) or ["p"])
    return found


@pytest.mark.parametrize("value,way", [("", "tree"), ("portable", "portable"), (" Portable ", "portable"),
                                       ("tree", "tree")])
def test_the_environment_chooses_the_way(monkeypatch, calls, value: str, way: str) -> None:
    monkeypatch.setenv("GLSANDBOX_ISOLATION", value)
    jobs = ["a job"]
    assert runner.run_jobs(jobs, 3, print) == (["p"] if way == "portable" else ["t"])
    # the tree's way gives scene files their job slots (glsandbox.grading.slots)
    assert calls == [(way, jobs, 3, *((Slots,) if way == "tree" else ()))]


def test_a_system_that_cannot_fork_grades_the_portable_way(monkeypatch, calls) -> None:
    monkeypatch.delenv("GLSANDBOX_ISOLATION", raising=False)
    monkeypatch.delattr(portable.os, "fork", raising=False)
    runner.run_jobs([], 1, print)
    assert [way for way, *_ in calls] == ["portable"]
