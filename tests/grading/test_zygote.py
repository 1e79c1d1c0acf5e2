"""The grader's handle on the zygote (glsandbox/grading/zygote.py): the one started ahead is taken
once by the next run, a dead one is replaced, and a request reaches it."""

from __future__ import annotations

import os
import shutil
import sys

import pytest

from glsandbox.grading import zygote

# No fork (Windows: the portable path grades there) is a machine without the zygote; on CI, a failure
pytestmark = pytest.mark.skipif(not hasattr(os, "fork") and not os.environ.get("CI"), reason="the zygote forks (POSIX)")


@pytest.fixture(autouse=True)
def no_zygote_left():
    yield
    zygote._discard_prestarted()


def _close(*made: zygote.Zygote) -> None:
    for z in made:
        z.close()
        shutil.rmtree(z.folder, ignore_errors=True)


def test_the_zygote_started_ahead_is_taken_once_then_a_fresh_one() -> None:
    zygote.prestart()
    ahead = zygote.ahead_pid()
    zygote.prestart()  # a second call starts no second one
    assert ahead is not None and zygote.ahead_pid() == ahead
    first = zygote.take()
    second = zygote.take()
    try:
        assert first.process.pid == ahead and zygote.ahead_pid() is None
        assert second.process.pid != ahead and second.process.poll() is None
    finally:
        _close(first, second)
    assert not os.path.exists(first.folder)


def test_a_zygote_that_died_before_its_run_is_replaced() -> None:
    zygote.prestart()
    dead = zygote._prestarted
    dead.process.kill()
    dead.process.wait(timeout=30)
    fresh = zygote.take()
    try:
        assert fresh is not dead and fresh.process.poll() is None
    finally:
        _close(fresh, dead)


def test_a_request_without_a_pipe_is_dropped_and_the_zygote_ends_when_told() -> None:
    """The zygote forks only for a request that hands it a pipe; closing the socket ends it."""
    made = zygote.Zygote()
    try:
        made.request({"slot": True}, [])
    finally:
        made.close()
        shutil.rmtree(made.folder, ignore_errors=True)
    assert made.process.returncode == 0, sys.executable
