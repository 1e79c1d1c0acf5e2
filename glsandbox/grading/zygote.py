"""The grader's handle on the zygote: started (ahead of its run where it can be), asked, closed.

The zygote (:func:`glsandbox.grading.worker.zygote_main`) is a fresh Python
that imports glsandbox, numpy and moderngl once and forks a supervisor, or a
job slot, on the grader's word over a socket pair no other process can find.
Its start is the longest wait before a class's first picture, so
:func:`prestart` starts it as early as the command line knows it will grade a
class (:mod:`glsandbox.launch`): this module imports only the standard
library's process and socket modules, and :mod:`glsandbox.grading.layers` for
the environment the zygote starts with. :func:`take` hands the next run
(:func:`glsandbox.grading.isolate.run_jobs`) the one started ahead, or a
fresh one.
"""

from __future__ import annotations

import os
import struct
import sys

__all__ = ["Zygote", "prestart", "take", "ahead_pid"]


class Zygote:
    """The zygote process and the grader's end of its socket pair."""

    def __init__(self) -> None:
        import socket
        import subprocess
        import tempfile

        # Every private folder of the run is made in this one (the zygote's temporary folder),
        # removed by the grader when the run ends: none is left by a supervisor killed before
        # its own clean-up (past its deadline, or the run stopped). Others may pass through it
        # to the folders a submission's user owns, not list it.
        self.folder = tempfile.mkdtemp(prefix="glsandbox-grade-run-")
        os.chmod(self.folder, 0o711)
        self.channel, theirs = socket.socketpair()
        code = ("import sys; from glsandbox.grading.resident import zygote_main; "
                "zygote_main(int(sys.argv[1]), sys.argv[2])")
        # a fresh program with only what rendering reads: every fork's /proc/self/environ is this one
        from glsandbox.grading.layers import renderer_environment

        package_parent = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
        code = f"import sys; sys.path.insert(0, {package_parent!r}); " + code
        self.process = subprocess.Popen([sys.executable, "-c", code, str(theirs.fileno()), self.folder],
                                        pass_fds=[theirs.fileno()],
                                        # never the grader's stdout
                                        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                        env=renderer_environment())
        theirs.close()

    def request(self, data: dict, fds: list[int]) -> None:
        """Send the zygote ``data`` (a job, or a slot's request) and ``fds`` (the caller keeps its copies)."""
        import json
        import socket

        encoded = json.dumps(data).encode()
        self.channel.sendall(struct.pack("!I", len(encoded)))
        socket.send_fds(self.channel, [encoded], fds)

    def close(self) -> None:
        self.channel.close()
        try:
            self.process.wait(timeout=10)
        except Exception:  # noqa: BLE001 - it is killed with the rest of the run
            pass


#: A zygote started ahead of its run (:func:`prestart`), taken by the next run (:func:`take`).
_prestarted: Zygote | None = None


def prestart() -> None:
    """Start the zygote now, so that its start (a fresh Python importing glsandbox, numpy and
    moderngl: about a third of a second) overlaps the grader's own preparation (its modules
    imported, the references read, the submissions listed); the next run takes it. Nothing
    where the system cannot fork."""
    global _prestarted
    if _prestarted is None and hasattr(os, "fork"):
        import atexit

        _prestarted = Zygote()
        atexit.register(_discard_prestarted)


def ahead_pid() -> int | None:
    """The process id of the zygote started ahead, if one waits to be taken."""
    return _prestarted.process.pid if _prestarted is not None else None


def _discard_prestarted() -> None:
    """At exit: a prestarted zygote no run took (the command stopped first: a missing reference,
    a rubric of exercises only) is closed and its folder removed."""
    import shutil

    global _prestarted
    found, _prestarted = _prestarted, None
    if found is not None:
        found.close()
        shutil.rmtree(found.folder, ignore_errors=True)


def take() -> Zygote:
    """The prestarted zygote if there is one (and it lives), else a fresh one."""
    global _prestarted
    found, _prestarted = _prestarted, None
    if found is not None and found.process.poll() is None:
        return found
    if found is not None:
        found.close()
    return Zygote()
