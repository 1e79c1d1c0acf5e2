"""Ctrl-C ends a command within a bound, even when its main thread cannot unwind.

Python turns SIGINT into ``KeyboardInterrupt`` only when the main thread next runs
Python code: a frame that llvmpipe is still drawing, a GL call that waits on the
driver's threads, or a library that catches the exception and carries on, can keep
the command going long after the key was pressed. :func:`watch_interrupts` gives
the command a second way out: the C-level signal handler writes every signal it
catches to a pipe (``signal.set_wakeup_fd``), and a daemon thread reading that pipe
ends the process with exit 130 if it is still there :data:`GRACE_S` seconds after
the first SIGINT. The normal path (the command unwinds, its ``finally`` blocks
remove what it half-wrote, :func:`glsandbox.cli.end_interrupted` exits) is never
cut short while it is within its grace; the watch is the bound, not the way out.

It is installed only where it cannot take anything from someone else: in the main
thread, with Python's own SIGINT handler in place (not ignored, not replaced), and
with no wakeup descriptor set already (asyncio sets one). A process forked from
the command (the grader's probes and zygote) drops the descriptor: its signals are
its own.
"""

from __future__ import annotations

import os
import signal
import threading
import time

__all__ = ["EXIT_INTERRUPTED", "GRACE_S", "watch_interrupts"]

#: Seconds from the first SIGINT to the forced exit: the command's own unwinding
#: (a timing child killed, temporary files removed) takes milliseconds.
GRACE_S = 1.5
#: What a Unix tool exits with on Ctrl-C (128 + SIGINT): every glsandbox command's status then.
EXIT_INTERRUPTED = 130

_installed: list[int] = []  # the pipe's two ends, once installed


def watch_interrupts(grace_s: float = GRACE_S) -> bool:
    """Start the watch for this process; whether it was installed (see the module's rules)."""
    if _installed or threading.current_thread() is not threading.main_thread():
        return bool(_installed)
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return False  # ignored (a background job's Ctrl-C is not its own) or someone else's handler
    read_end, write_end = os.pipe()
    os.set_blocking(write_end, False)  # the handler never blocks; a full pipe just drops bytes
    try:
        previous = signal.set_wakeup_fd(write_end, warn_on_full_buffer=False)
    except ValueError:
        previous = None
    if previous != -1:  # not ours to take (or not allowed here): leave it as it was
        if previous is not None:
            signal.set_wakeup_fd(previous)
        os.close(read_end)
        os.close(write_end)
        return False
    _installed[:] = [read_end, write_end]
    os.register_at_fork(after_in_child=_forget_in_child)
    threading.Thread(target=_watch, args=(read_end, grace_s), name="glsandbox-interrupt-watch",
                     daemon=True).start()
    return True


def _forget_in_child() -> None:
    """In a forked child: no watch thread came along, and its signals must not reach ours."""
    if not _installed:
        return
    try:
        signal.set_wakeup_fd(-1)
    except ValueError:  # forked from a thread other than the main one: Python keeps no handlers there
        pass
    for fd in _installed:
        try:
            os.close(fd)
        except OSError:
            pass
    _installed.clear()


def _watch(read_end: int, grace_s: float) -> None:
    while True:
        try:
            caught = os.read(read_end, 64)
        except OSError:
            return
        if not caught:
            return
        if signal.SIGINT in caught:
            break
    time.sleep(grace_s)
    # Straight to the descriptor: the main thread may be stuck holding sys.stderr's lock.
    line = f"interrupted: the command did not end within {grace_s:g} s of Ctrl-C; ended it\n"
    try:
        os.write(2, line.encode())
    except OSError:
        pass
    os._exit(EXIT_INTERRUPTED)
