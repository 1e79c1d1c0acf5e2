"""The portable way of grading: a fresh Python per submission, its process tree killed with psutil.

Where the fork-based tree of :mod:`glsandbox.grading.isolate` cannot run (a
teacher's Windows laptop: no ``fork``), or when ``GLSANDBOX_ISOLATION=portable``
asks for it, each submission is a new interpreter started with
:mod:`subprocess` in a private copy of its folder, with only the environment
rendering needs (:func:`glsandbox.grading.layers.renderer_environment`). It
reads its job on stdin, sends its pictures framed on stdout (what it prints
goes to a log file instead) and loads the lesson under the same audit hook
(and, on Linux, Landlock) as the full path (:func:`glsandbox.grading.sandbox.confine`).

Limits: each picture's time is watched by the grader, which kills the whole
process tree (psutil finds the descendants on every system); memory is the
address-space limit where the system has one (``RLIMIT_AS``: Linux; macOS
accepts but does not enforce it) and, everywhere, the tree's resident size
watched by the grader. Weaker than the full path: no other user, no network
namespace or seccomp filter, and a process that leaves the tree (a daemon that
re-parents itself) is found only through its process group on POSIX.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from glsandbox.grading.isolate import (BROKEN, CRASHED, OOM, TIMEOUT, Job, JobResult, Picture, Reader, _job_data,
                                       job_from, send, settle, story_of)

__all__ = ["describe", "run_jobs_portable", "child_main", "tree_rss"]

#: Seconds a new interpreter may take to import glsandbox and open its context before its clock starts.
STARTUP_SECONDS = 60.0
#: How often the grader looks at each running submission (its messages, clock and memory).
POLL_SECONDS = 0.02


def describe() -> str:
    """The one line ``check`` starts with on this path."""
    memory = "address space and resident size" if sys.platform == "linux" else "resident size, watched"
    return ("isolation: portable (a fresh Python per submission, its process tree killed with psutil; memory: "
            f"{memory}; files: the audit hook{', Landlock' if sys.platform == 'linux' else ''}; "
            "weaker: no other user, the network open)")


# --- the submission's side --------------------------------------------------------------------


def _limit_memory(job: Job) -> None:
    try:
        import resource
    except ImportError:  # Windows: the grader watches the resident size
        return
    memory = job.memory_mb * 1024 * 1024
    for limit, value in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CORE, 0)):
        try:
            resource.setrlimit(limit, (value, value))
        except (ValueError, OSError):
            pass


def child_main() -> None:
    """A submission's interpreter: its job on stdin, its pictures framed on stdout; it ends with
    ``os._exit`` (no atexit handler or finaliser of the submission runs)."""
    try:
        _child()
    finally:
        for stream in (sys.stdout, sys.__stdout__, sys.__stderr__):
            try:
                stream.flush()
            except BaseException:  # noqa: BLE001 - replaced or closed by the submission
                pass
        os._exit(0)


def _child() -> None:
    out = os.dup(1)  # the result pipe; the submission's prints go to the log (stderr) from here on
    os.dup2(2, 1)
    if sys.platform == "win32":
        import msvcrt

        msvcrt.setmode(out, os.O_BINARY)
    data = json.loads(sys.stdin.readline())
    sys.stdin = open(os.devnull)  # noqa: SIM115 - the submission's, for its life
    sys.argv = ["submission"]
    job, root, cwd = job_from(data["job"]), data["root"], data["cwd"]
    from glsandbox.errors import SandboxError
    from glsandbox.frame import HeadlessRenderer
    from glsandbox.grading.sandbox import confine
    from glsandbox.grading.worker import render_job

    _limit_memory(job)
    try:
        renderer = HeadlessRenderer(job.backend)
    except SandboxError as exc:
        send(out, {"kind": "nogl", "error": str(exc)})
        return
    confine(root, [root, cwd], cache_writable=job.writes_cache)
    send(out, {"kind": "ready"})
    render_job(job, renderer, root, job.target, out)


# --- the grader's side ------------------------------------------------------------------------


def tree_rss(pid: int) -> int:
    """Bytes resident in the process ``pid`` and every descendant psutil finds (shared pages once per process)."""
    import psutil

    total = 0
    try:
        top = psutil.Process(pid)
        for proc in [top, *top.children(recursive=True)]:
            try:
                total += proc.memory_info().rss
            except psutil.Error:
                pass
    except psutil.Error:
        pass
    return total


def _kill_tree(pid: int) -> None:
    """The process, every descendant psutil finds, and (POSIX) its process group: killed, waited for."""
    import psutil

    try:
        top = psutil.Process(pid)
        procs = [top, *top.children(recursive=True)]
    except psutil.Error:
        procs = []
    for proc in procs:
        try:
            proc.kill()
        except psutil.Error:
            pass
    if hasattr(os, "killpg"):
        try:
            os.killpg(pid, signal.SIGKILL)
        except OSError:
            pass
    psutil.wait_procs(procs, timeout=5)


class _Submission:
    """One running submission: its interpreter, the bytes it sent, its clock and its pictures."""

    def __init__(self, job: Job) -> None:
        from glsandbox.grading.layers import renderer_environment
        from glsandbox.grading.worker import _copy_submission

        self.job, self.work = job, tempfile.mkdtemp(prefix="glsandbox-grade-")
        cwd = os.path.join(self.work, "cwd")
        os.mkdir(cwd)
        self.original = ""
        if job.source is None:
            root = cwd
        elif job.copy:
            root = str(_copy_submission(Path(job.source), Path(self.work) / "submission"))
            self.original = job.source if Path(job.source).is_dir() else str(Path(job.source).parent)
        else:
            root = str(Path(job.source).parent)
        self.root = root
        self.log = open(os.path.join(self.work, "output.txt"), "wb")  # noqa: SIM115 - closed in close()
        package_parent = str(Path(__file__).resolve().parents[2])
        code = (f"import sys; sys.path.insert(0, {package_parent!r}); "
                "from glsandbox.grading.portable import child_main; child_main()")
        flags = getattr(subprocess, "CREATE_NEW_PROCESS_GROUP", 0)
        self.process = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=self.log, cwd=root if job.copy else cwd, env=renderer_environment(),
                                        start_new_session=hasattr(os, "setsid"), creationflags=flags)
        self.process.stdin.write(json.dumps({"job": _job_data(job), "root": root, "cwd": cwd}).encode() + b"\n")
        self.process.stdin.close()
        self.reader, self.lock, self.eof = Reader(-1), threading.Lock(), False
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()
        self.pictures = [Picture() for _ in job.renders]
        self.current, self.started, self.ready = 0, time.monotonic(), False
        self.no_gl = ""
        self.output: list[str] = []
        self.meta: dict[str, str] = {}

    def _read(self) -> None:
        while True:
            chunk = self.process.stdout.read1(1 << 20) if hasattr(self.process.stdout, "read1") else b""
            with self.lock:
                if not chunk:
                    self.eof = True
                    return
                self.reader.buffer += chunk

    def _finish(self, kind: str, error: str) -> bool:
        for picture in self.pictures[self.current:]:
            if not picture.status and picture.image is None:
                picture.status, picture.error = kind, error
        self.current = len(self.pictures)
        return True


    def poll(self) -> bool:
        """Read what arrived, watch the clock and memory; True once this submission is done."""
        with self.lock:
            eof = self.eof
            try:
                messages = list(self.reader.messages(1 << 34))
            except ValueError as exc:
                return self._finish(CRASHED, f"sent {exc}")
        for header, payload in messages:
            kind = header.get("kind")
            if kind == "nogl":
                self.no_gl = str(header.get("error", ""))
                return self._finish(CRASHED, self.no_gl)
            if kind == "ready":
                self.ready, self.started = True, time.monotonic()
                continue
            if kind == "meta":  # the tour's card (tour --lessons)
                self.meta = {k: str(header.get(k, ""))[:2000] for k in ("title", "course_section", "description")}
                continue
            index = int(header.get("index", -1))
            if index != self.current:
                return self._finish(CRASHED, "sent a message out of order")
            picture = self.pictures[index]
            if kind == "image":
                w, h = self.job.renders[index].size
                if tuple(header.get("shape", ())) != (h, w, 4) or len(payload) != w * h * 4:
                    return self._finish(CRASHED, f"sent a picture of shape {header.get('shape')} for a {w}x{h} render")
                picture.image = np.frombuffer(payload, dtype=np.uint8).reshape(h, w, 4)
                picture.seconds = float(header.get("seconds", 0.0))
                if self.job.describe and isinstance(header.get("info"), dict):
                    picture.info = header["info"]
                picture.info = {**picture.info, **story_of(header)}
            else:
                picture.status = OOM if kind == "oom" else BROKEN
                picture.error = str(header.get("error", ""))[:500]
                if header.get("all"):
                    return self._finish(picture.status, picture.error)
            self.current, self.started = self.current + 1, time.monotonic()
        if self.current >= len(self.pictures):
            return True
        elapsed = time.monotonic() - self.started
        if not self.ready and elapsed > STARTUP_SECONDS:
            return self._finish(TIMEOUT, f"did not start within {STARTUP_SECONDS:g} s")
        if self.ready and elapsed > self.job.timeout:
            self.pictures[self.current].seconds = elapsed
            return self._finish(TIMEOUT, f"timed out after {self.job.timeout:g} s")
        if tree_rss(self.process.pid) > self.job.memory_mb * 1024 * 1024:
            return self._finish(OOM, f"out of memory: its processes held more than {self.job.memory_mb} MB")
        code = self.process.poll()
        if code is not None and eof:
            with self.lock:
                left = len(self.reader.buffer)
            if not left:
                reason = (f"killed by signal {signal.Signals(-code).name}" if code < 0 and -code in
                          signal.Signals._value2member_map_ else f"exited with code {code} before its picture was sent")
                return self._finish(CRASHED, reason)
        return False

    def result(self) -> JobResult:
        if self.no_gl:
            return JobResult(self.job, [], no_gl=self.no_gl)
        output = self.output
        if self.original:  # the private copy's path, said as the submission's own
            for picture in self.pictures:
                picture.error = picture.error.replace(self.root, self.original)
            output = [line.replace(self.root, self.original) for line in output]
        meta = {k: v.replace(self.root, self.original) if self.original else v for k, v in self.meta.items()}
        return JobResult(self.job, self.pictures, output, meta=meta)

    def close(self) -> None:
        """Kill its tree, keep its last printed lines (:attr:`output`), remove its private folder."""
        from glsandbox.grading.worker import _tail

        _kill_tree(self.process.pid)
        self.process.wait()
        self.thread.join(timeout=5)
        self.process.stdout.close()
        self.log.close()
        self.output = _tail(os.path.join(self.work, "output.txt"))
        shutil.rmtree(self.work, ignore_errors=True)


def run_jobs_portable(jobs: Sequence[Job], workers: int, done: Callable[[JobResult], None]) -> list[JobResult]:
    """:func:`glsandbox.grading.isolate.run_jobs` the portable way: ``workers`` interpreters at once."""
    pending: deque[Job] = deque(jobs)
    running: list[_Submission] = []
    results: dict[int, JobResult] = {}
    retried: set[int] = set()
    try:
        while pending or running:
            while pending and len(running) < max(1, workers):
                running.append(_Submission(pending.popleft()))
            time.sleep(POLL_SECONDS)
            for entry in list(running):
                if not entry.poll():
                    continue
                running.remove(entry)
                entry.close()
                if settle(entry.job, entry.result(), pending, retried, results, done):
                    return [results[j.index] for j in jobs if j.index in results]
    finally:
        for entry in running:
            entry.close()
    return [results[j.index] for j in jobs]
