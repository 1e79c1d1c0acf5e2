"""Peak memory of one step of work in this process: how far the resident size rose above where it was.

Linux: writing ``5`` to ``/proc/self/clear_refs`` starts the peak resident size
(``VmHWM`` in ``/proc/self/status``) again from the current one (``VmRSS``), so
:func:`peak_start` resets it and :func:`peak_growth` is the peak reached since,
less the resident size at the start. Elsewhere (no ``/proc``) the peak cannot be
reset: ``ru_maxrss`` (the process's peak so far; KiB on Linux, bytes on macOS) is
read before and after, so the growth is over the earlier *peak*, a lower bound
that equals the true figure only when the step peaks above everything before it
(which is why the benchmarks measure in a fresh process, after a small warm-up).
Run in the child processes of ``model_load.py`` and ``frame_memory.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

_STATUS = Path("/proc/self/status")
_CLEAR_REFS = Path("/proc/self/clear_refs")


def _status_bytes(key: str) -> int:
    """A ``kB`` line of ``/proc/self/status`` (``VmRSS``, ``VmHWM``) in bytes."""
    for line in _STATUS.read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(key)


def _maxrss_bytes() -> int:
    import resource

    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak if sys.platform == "darwin" else peak * 1024)


def uses_proc() -> bool:
    """Whether the peak can be reset here (Linux's ``/proc``), else ``ru_maxrss`` is read."""
    return _STATUS.exists() and _CLEAR_REFS.exists()


def peak_start() -> int:
    """Start a measurement: the peak reset to the current resident size (Linux), returned in bytes;
    elsewhere the peak so far (``ru_maxrss``)."""
    if uses_proc():
        _CLEAR_REFS.write_text("5")
        return _status_bytes("VmRSS")
    return _maxrss_bytes()


def peak_growth(start: int) -> int:
    """Bytes the peak resident size rose above ``start`` (:func:`peak_start`) since."""
    peak = _status_bytes("VmHWM") if uses_proc() else _maxrss_bytes()
    return max(0, peak - start)
