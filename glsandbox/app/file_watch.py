"""Watching the files a window shows: saving one tells the window to reload it
(a node's own shader, docs/your-own.md "Your own shader"; a lesson file, "Your own lesson").

A cheap modification-time poll, not a file-system notifier (``watchdog``):
no extra dependency, the files are a handful (a node's own shader and its
includes, the lesson's file), and :meth:`FileWatch.changed` stats them at most a few times a
second, a few microseconds each, from the window's loop. Editors that save by
writing a new file and renaming it over the old one are seen the same way.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path

#: What a file looked like: (modification time in ns, size), or None while it is missing
#: (an editor between deleting and writing it). Size too: a coarse file-system clock may
#: give two saves within one tick the same time.
Stamp = tuple[int, int] | None


def stamp(path: Path) -> Stamp:
    try:
        info = os.stat(path)
    except OSError:
        return None
    return info.st_mtime_ns, info.st_size


class FileWatch:
    """Polls the files ``files()`` lists; :meth:`changed` says whether one changed since the last poll.

    A file seen for the first time is recorded, not reported (it was just
    compiled). ``interval`` seconds pass between two looks at the disk.
    """

    def __init__(self, files: Callable[[], Iterable[Path]], interval: float = 0.25) -> None:
        self.files = files
        self.interval = interval
        self._stamps: dict[Path, Stamp] = {}
        self._next = 0.0

    def changed(self, now: float | None = None) -> bool:
        now = time.monotonic() if now is None else now
        if now < self._next:
            return False
        self._next = now + self.interval
        changed = False
        for path in self.files():
            current = stamp(path)
            if path in self._stamps and self._stamps[path] != current:
                changed = True
            self._stamps[path] = current
        return changed
