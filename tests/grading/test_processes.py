"""A process and everything it started (glsandbox/grading/processes.py): found through /proc and
killed until none is left, what is kept left alone, and orphans brought back by a subreaper.
Every tree here is one this test starts: never this process's own."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from glsandbox.grading import processes

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="/proc and the subreaper are Linux's")


def _tree(sleepers: int) -> subprocess.Popen:
    """A shell with ``sleepers`` sleeping children, once they are all there."""
    shell = subprocess.Popen(["sh", "-c", " ".join(["sleep 30 &"] * sleepers) + " wait"])
    deadline = time.monotonic() + 10
    while len(processes.descendants(shell.pid)) < sleepers and time.monotonic() < deadline:
        time.sleep(0.01)
    return shell


def test_kill_tree_kills_every_descendant_and_leaves_the_kept_ones() -> None:
    shell = _tree(3)
    try:
        found = processes.descendants(shell.pid)
        assert len(found) == 3
        processes.kill_tree(shell.pid, keep=found[:1])
        assert processes.descendants(shell.pid) == found[:1]  # the kept one lives on
        processes.kill_tree(shell.pid)
        assert processes.descendants(shell.pid) == []
        assert shell.wait(timeout=10) is not None  # its children gone, its `wait` returns
    finally:
        shell.kill()
        shell.wait()


def test_wait_briefly_reaps_a_child_that_ends() -> None:
    child = subprocess.Popen(["true"])
    processes.wait_briefly(child.pid, 5.0)
    with pytest.raises(ChildProcessError):  # reaped: nothing left to wait for
        os.waitpid(child.pid, 0)
    processes.wait_briefly(child.pid)  # a pid no longer ours: no error
    processes.killpg(2**22 + 12345)  # a group that does not exist: no error


ORPHAN = """
import os, signal, subprocess, sys
from glsandbox.grading.processes import descendants, kill_tree, set_subreaper
set_subreaper(sys.argv[1] == "on")
# The sh ends at once, leaving its sleep an orphan (its output elsewhere: the pipe closes with sh).
sh = subprocess.run(["sh", "-c", "sleep 30 >/dev/null 2>&1 & echo $!"], stdout=subprocess.PIPE, text=True, check=True)
found = descendants(os.getpid())
kill_tree(os.getpid())
print(len(found), len(descendants(os.getpid())))
try:
    os.kill(int(sh.stdout), signal.SIGKILL)  # not ours without the subreaper: ended here all the same
except ProcessLookupError:
    pass
"""


@pytest.mark.parametrize("subreaper,found", [("on", "1 0"), ("off", "0 0")])
def test_a_subreaper_gets_back_the_orphans_of_its_descendants(subreaper: str, found: str) -> None:
    proc = subprocess.run([sys.executable, "-c", ORPHAN, subreaper], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == found.split()
