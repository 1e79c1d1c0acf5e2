"""A process and everything it started: found through /proc, killed until none is left (Linux).

A process marked "child subreaper" (:func:`set_subreaper`) gets back every
orphan among its descendants, however they tried to leave (``fork``,
``setsid``, a parent that died), so :func:`kill_tree` on itself finds them all.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import time
from collections import deque
from collections.abc import Sequence

__all__ = ["descendants", "kill_tree", "killpg", "set_subreaper", "wait_briefly"]

_PR_SET_CHILD_SUBREAPER = 36


def _children_map() -> dict[int, list[int]]:
    """Every live process's children, from /proc."""
    children: dict[int, list[int]] = {}
    if not os.path.isdir("/proc"):  # not Linux: only the renderer's own session is killed (see _supervise)
        return children
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                fields = handle.read().rsplit(b")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != b"Z":
            children.setdefault(int(fields[1]), []).append(int(entry))
    return children


def descendants(pid: int) -> list[int]:
    """The live (not zombie) descendants of ``pid``."""
    children = _children_map()
    found, queue = [], deque(children.get(pid, []))
    while queue:
        child = queue.popleft()
        found.append(child)
        queue.extend(children.get(child, []))
    return found


def _reap() -> None:
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def kill_tree(pid: int, keep: Sequence[int] = ()) -> None:
    """SIGKILL every descendant of ``pid`` (except ``keep`` and theirs) until none is left.

    A process that forks while we look is found on the next pass; orphans come
    back to us as long as we are a subreaper. Reaps our own children.
    """
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        excluded = set(keep)
        for kept in keep:
            excluded.update(descendants(kept))
        alive = [p for p in descendants(pid) if p not in excluded]
        if not alive:
            break
        for victim in alive:
            try:
                os.kill(victim, signal.SIGKILL)
            except OSError:
                pass
        _reap() if pid == os.getpid() else None
        time.sleep(0.005)
    if pid == os.getpid():
        _reap()


def wait_briefly(pid: int, seconds: float = 0.05) -> None:
    """Reap ``pid`` if it ends within ``seconds``."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            done, _ = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            return
        if done:
            return
        time.sleep(0.001)


def set_subreaper(on: bool = True) -> None:
    """Mark this process as a child subreaper (or unmark it); nothing where the system has no such thing."""
    if sys.platform == "linux":
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0)


def killpg(group: int) -> None:
    try:
        os.killpg(group, signal.SIGKILL)
    except OSError:
        pass
