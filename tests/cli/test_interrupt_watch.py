"""Ctrl-C's bound (glsandbox/interrupt_watch.py): a command whose main thread does not unwind
still ends with 130 soon after the key, and the watch takes nothing that is not its own."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from support import REPO_ROOT

from glsandbox.interrupt_watch import GRACE_S

#: A command that swallows every KeyboardInterrupt and carries on (as a library may); it says
#: "ready" once the watch is installed (or "not installed").
SWALLOWS = textwrap.dedent("""
    import signal, sys, time
    from glsandbox.interrupt_watch import watch_interrupts
    # Python's own handler, as in a terminal's foreground command (a test run started as a
    # background job hands its children SIGINT ignored, and then the watch stays out)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    {before}
    said = "ready" if watch_interrupts() else "not installed"
    while True:
        try:  # the line said inside: a key pressed as soon as it is read is swallowed too
            if said:
                line, said = said, ""
                print(line, flush=True)
            time.sleep(10)
        except KeyboardInterrupt:
            pass
""")


def _start(before: str = "") -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen([sys.executable, "-c", SWALLOWS.format(before=before)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=REPO_ROOT)
    assert proc.stdout is not None
    return proc, proc.stdout.readline().strip()


def _ended_within(proc: subprocess.Popen, seconds: float) -> bool:
    try:
        proc.wait(timeout=seconds)
        return True
    except subprocess.TimeoutExpired:
        return False


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a process is POSIX")
def test_a_command_that_does_not_unwind_ends_with_130_after_the_grace() -> None:
    proc, said = _start()
    assert said == "ready"
    start = time.monotonic()
    proc.send_signal(signal.SIGINT)
    ended = _ended_within(proc, 10)
    seconds = time.monotonic() - start
    if not ended:
        proc.kill()
    _, err = proc.communicate()
    assert ended and proc.returncode == 130, (proc.returncode, err)
    assert GRACE_S - 0.05 <= seconds < GRACE_S + 1.5, seconds  # not before the grace: the normal path's time
    assert f"did not end within {GRACE_S:g} s of Ctrl-C" in err


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a process is POSIX")
def test_other_signals_do_not_end_it() -> None:
    proc, said = _start("signal.signal(signal.SIGUSR1, lambda *a: None)")
    assert said == "ready"
    proc.send_signal(signal.SIGUSR1)  # caught by a Python handler: written to the pipe as well
    assert not _ended_within(proc, GRACE_S + 1.0)
    proc.kill()
    proc.communicate()


@pytest.mark.parametrize("before", [
    "signal.signal(signal.SIGINT, signal.SIG_IGN)",  # a background job's: Ctrl-C is not for it
    "signal.signal(signal.SIGINT, lambda *a: None)",  # a handler of someone else's
    "import os; r, w = os.pipe(); os.set_blocking(w, False); signal.set_wakeup_fd(w)",  # asyncio's, say
], ids=["ignored", "own_handler", "wakeup_fd_taken"])
def test_the_watch_takes_nothing_that_is_not_its_own(before) -> None:
    proc, said = _start(before)
    proc.kill()
    proc.communicate()
    assert said == "not installed"


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork is POSIX")
def test_a_forked_childs_interrupt_does_not_end_the_parent() -> None:
    script = textwrap.dedent("""
        import os, signal, sys, time
        from glsandbox.interrupt_watch import watch_interrupts
        signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a foreground command
        assert watch_interrupts()
        pid = os.fork()
        if pid == 0:
            try:
                time.sleep(30)
            except KeyboardInterrupt:
                os._exit(7)
            os._exit(0)
        time.sleep(0.2)
        os.kill(pid, signal.SIGINT)
        _, status = os.waitpid(pid, 0)
        time.sleep(%r)  # the parent's watch would have fired by now had it read the child's byte
        print("child", os.waitstatus_to_exitcode(status), "parent alive", flush=True)
    """ % (GRACE_S + 0.7))
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT, timeout=30)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "child 7 parent alive"
