"""Rendering each graded submission in a process of its own, under limits, and getting back only pixels.

The process tree of one grading run::

    grader (never opens a GL context; reads the reference, compares, writes every report)
     └─ zygote (imported glsandbox, numpy and moderngl once; forks on the grader's word)
         ├─ warm template, one per backend where safe (:mod:`glsandbox.grading.warm`):
         │   a single-threaded software context drawn with once; forks the supervisors
         └─ supervisor, one per submission (own session; a "child subreaper": every process
            │  the submission leaves behind is re-parented to it, and it kills them all)
            └─ renderer (own session; stdin /dev/null, stdout and stderr into a file;
               address-space, CPU-time and file-size limits; working folder a private
               copy of the submission; confined by :mod:`glsandbox.grading.sandbox`)

The renderer opens its GL context, or uses its copy of the warm template's
(a fork of a process with llvmpipe's rasterizer threads would deadlock on
them, so only a template without them, checked, is forked from), then
loads the submission and renders each requested picture, writing each as a
framed message on a pipe: raw RGBA pixels, or an error line. It knows no
reference. The supervisor reads the pipe against the clock, kills the
renderer's whole tree when it is done, times out or dies, and sends the
grader one plain result per picture (JSON and raw pixels on a pipe of its
own: the grader never unpickles what a child sends). The zygote is
Python's "forkserver" idea without its named socket: the grader talks to it
over a socket pair no other process can find. Nothing the submission does in its
own process (``os._exit``, a signal, ``atexit``, threads, ``fork``,
replacing ``sys.stdout`` or glsandbox's functions) reaches the grader: the
worst it can do is lose its own pictures.

This module is the grader's side and what both sides share (the jobs, the
framed messages); :mod:`glsandbox.grading.zygote` starts the zygote and asks
it; :mod:`glsandbox.grading.worker` is the zygote, supervisor and renderer;
:mod:`glsandbox.grading.processes` finds and kills a tree.
A scene file (data, no code) goes instead to a job slot: a supervisor and a
renderer kept for many scene files, confined as these are
(:mod:`glsandbox.grading.slots`, :mod:`glsandbox.grading.resident`).
"""

from __future__ import annotations

import json
import os
import select
import shutil
import struct
import sys
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from glsandbox.grading.processes import descendants, kill_tree, killpg, set_subreaper

__all__ = ["Render", "Job", "Picture", "JobResult", "run_jobs", "wide_pipe"]

#: Outcomes of one picture, besides the grader's PASS and FAIL.
BROKEN, TIMEOUT, CRASHED, OOM = "BROKEN", "TIMEOUT", "CRASHED", "OUT OF MEMORY"
#: The renderer's output kept for the report: its last lines, each cut.
TAIL_LINES, TAIL_WIDTH = 8, 200

_MAGIC = b"GLSB"
_HEADER = struct.Struct("!4sIQ")  # magic, JSON header length, payload length


@dataclass(frozen=True)
class Render:
    """One picture to render: the lesson's ``--set`` values, the size and MSAA samples, and a
    nudge of the camera (a reference's margin, :data:`glsandbox.measure.margin.NUDGES`; none: ``()``)."""

    settings: tuple[str, ...]
    size: tuple[int, int]
    samples: int = 0
    #: A pixel (x, y from the top) whose story (``glsandbox explain``) comes back with the picture:
    #: told in the renderer, of the submission's own scene, as text (a failed picture's first difference).
    explain: tuple[int, int] | None = None
    nudge: tuple[float, ...] = ()


@dataclass(frozen=True)
class Job:
    """One submission: where it is, what to render, and the limits.

    ``source`` is the submission's file or folder, copied into the private
    folder (``copy=True``, grading) or read where it is (``copy=False``: one
    lesson checked by its author, whose folder is its root); ``target`` is
    the lesson file to load inside it (relative), or a built-in lesson's
    name when ``source`` is None.
    """

    index: int
    source: str | None
    target: str
    renders: tuple[Render, ...]
    backend: str | None = None
    timeout: float = 30.0
    memory_mb: int = 2048
    copy: bool = True
    #: The model answer (``--update``): its compiled shaders may go into Mesa's cache for the submissions.
    writes_cache: bool = False
    #: The rubric's name for the lesson file in a student's folder (for the error when it is missing).
    entry: str | None = None
    #: Send back what the tour's page shows too: the lesson's title, section and description, each frame's plan.
    describe: bool = False


@dataclass
class Picture:
    """What came back for one :class:`Render`: the pixels, or an outcome and its line."""

    image: np.ndarray | None = None
    status: str = ""
    error: str = ""
    seconds: float = 0.0
    #: With :attr:`Job.describe`: the frame's plan (``plan``, its dict, and ``plan_text``).
    info: dict = field(default_factory=dict)


@dataclass
class JobResult:
    """Every picture of one job, the renderer's last output lines, and whether GL was there at all."""

    job: Job
    pictures: list[Picture]
    output: list[str] = field(default_factory=list)
    no_gl: str = ""
    #: With :attr:`Job.describe`: the lesson's ``title``, ``course_section`` and ``description``.
    meta: dict = field(default_factory=dict)


# --- the framed messages of a pipe: a JSON header and raw bytes ---------------------------------


def wide_pipe(fd: int) -> None:
    """Let the pipe at ``fd`` hold a whole 320x240 picture and more (Linux: 1 MiB, the most an
    unprivileged process may ask by default, against 64 KiB): the sender writes a picture in one
    call instead of waking the reader for each 64 KiB. Where refused, the pipe stays as it was."""
    import fcntl

    try:
        fcntl.fcntl(fd, getattr(fcntl, "F_SETPIPE_SZ"), 1 << 20)
    except (AttributeError, OSError):
        pass


def send(fd: int, header: dict, payload: bytes | memoryview | Sequence[bytes | memoryview] = b"") -> None:
    """Frame ``header`` and ``payload`` (raw bytes, or several buffers sent one after another:
    each picture's pixels as they lie, never joined) on ``fd``, in one gathered write where the
    pipe has room. A 320x240 picture is 300 KiB: every copy of it is fresh memory to fault in, so
    the pixels go from the array to the pipe with no copy of their own."""
    pieces = [memoryview(piece).cast("B") for piece in (payload if isinstance(payload, (list, tuple)) else [payload])]
    data = json.dumps(header).encode()
    pending = [_HEADER.pack(_MAGIC, len(data), sum(len(piece) for piece in pieces)) + data,
               *[piece for piece in pieces if len(piece)]]
    while pending:
        written = os.writev(fd, pending)
        while pending and written >= len(pending[0]):
            written -= len(pending[0])
            pending.pop(0)
        if written:
            pending[0] = memoryview(pending[0])[written:]


#: The most of a pixel's story a submission's renderer may send back (characters).
STORY_LIMIT = 6000


def story_of(header: dict) -> dict:
    """A picture message's story (``Render.explain``), as the grader keeps it: text, cut to
    :data:`STORY_LIMIT` (it comes from the submission's process: untrusted, shown escaped)."""
    story = header.get("story")
    return {"story": story[:STORY_LIMIT]} if isinstance(story, str) else {}


class Reader:
    """The framed messages of the renderer's pipe, read as they arrive.

    A big payload (a picture) is read straight into a buffer of its own size once its header
    has come: the pipe's bytes are copied once, into the bytes the pixels are read from, not
    gathered in :attr:`buffer` and cut out of it. What arrives otherwise (and what a caller
    adds to :attr:`buffer` itself) is framed from :attr:`buffer`."""

    #: Payloads of these sizes are read into a buffer of their own (a bigger claim is read as it comes).
    DIRECT = (1 << 16, 1 << 28)

    def __init__(self, fd: int) -> None:
        self.fd, self.buffer, self.closed = fd, bytearray(), False
        #: A big payload being filled: its header, its buffer and how much of it has come.
        self._pending: tuple[dict, bytearray] | None = None
        self._filled = 0
        #: The biggest payload the last :meth:`messages` call allowed: none bigger gets a buffer.
        self._limit = 0

    def pump(self, timeout: float) -> None:
        """Read what has come within ``timeout`` seconds: while no picture is pending, at most a
        header's worth (:attr:`DIRECT`), so that a picture behind it is read into its own buffer."""
        ready, _, _ = select.select([self.fd], [], [], max(timeout, 0.0))
        if not ready:
            return
        if self._pending is None:
            chunk = os.read(self.fd, self.DIRECT[0])
            self.closed = not chunk
            self.buffer += chunk
            self._begin_payload()
            if self._pending is None or self.buffer or not select.select([self.fd], [], [], 0)[0]:
                return
        got = os.readv(self.fd, [memoryview(self._pending[1])[self._filled:]])
        self.closed = not got
        self._filled += got

    def _begin_payload(self) -> None:
        """Where :attr:`buffer` starts with the header of a big payload: that payload's own buffer,
        what came of it moved there. (A malformed header is left for :meth:`messages` to refuse.)"""
        if self._pending is not None or len(self.buffer) < _HEADER.size:
            return
        magic, head, size = _HEADER.unpack_from(self.buffer)
        start = _HEADER.size + head
        direct = self.DIRECT[0] <= size <= min(self.DIRECT[1], self._limit)
        if magic != _MAGIC or head > 1 << 16 or not direct or len(self.buffer) < start:
            return
        header = json.loads(bytes(self.buffer[_HEADER.size:start]))
        payload = bytearray(size)
        taken = min(len(self.buffer) - start, size)
        payload[:taken] = memoryview(self.buffer)[start:start + taken]
        del self.buffer[:start + taken]
        self._pending, self._filled = (header, payload), taken

    def messages(self, limit: int) -> Iterator[tuple[dict, bytes | bytearray]]:
        """Each whole message that has come, with payloads of at most ``limit`` bytes; a
        ValueError for a malformed one, or one past the limit."""
        self._limit = limit
        while True:
            if self._pending is not None:
                header, payload = self._pending
                if len(payload) > limit:
                    raise ValueError("a malformed message on the result pipe")
                taken = min(len(self.buffer), len(payload) - self._filled)
                if taken:  # (bytes a caller added to the buffer itself)
                    payload[self._filled:self._filled + taken] = memoryview(self.buffer)[:taken]
                    del self.buffer[:taken]
                    self._filled += taken
                if self._filled < len(payload):
                    return
                self._pending, self._filled = None, 0
                yield header, payload
                continue
            if len(self.buffer) < _HEADER.size:
                return
            magic, head, size = _HEADER.unpack_from(self.buffer)
            if magic != _MAGIC or head > 1 << 16 or size > limit:
                raise ValueError("a malformed message on the result pipe")
            self._begin_payload()
            if self._pending is not None:
                continue
            end = _HEADER.size + head + size
            if len(self.buffer) < end:
                return
            header = json.loads(bytes(self.buffer[_HEADER.size:_HEADER.size + head]))
            payload = bytes(self.buffer[_HEADER.size + head:end])
            del self.buffer[:end]
            yield header, payload


def _job_data(job: Job) -> dict:
    return {"index": job.index, "source": job.source, "target": job.target, "backend": job.backend,
            "timeout": job.timeout, "memory_mb": job.memory_mb, "copy": job.copy, "writes_cache": job.writes_cache,
            "entry": job.entry, "describe": job.describe,
            "renders": [{"settings": list(r.settings), "size": list(r.size), "samples": r.samples,
                         "explain": None if r.explain is None else list(r.explain),
                         "nudge": list(r.nudge)} for r in job.renders]}


def job_from(data: dict) -> Job:
    renders = tuple(Render(tuple(r["settings"]), tuple(r["size"]), r["samples"],
                           None if r.get("explain") is None else (int(r["explain"][0]), int(r["explain"][1])),
                           nudge=tuple(r.get("nudge", ())))
                    for r in data.pop("renders"))
    return Job(renders=renders, **data)


# --- the grader's side -----------------------------------------------------------------------


@dataclass
class _Running:
    job: Job
    reader: Reader
    deadline: float
    pid: int = 0


def settle(job: Job, result: JobResult, pending: deque[Job], retried: set[int], results: dict[int, JobResult],
           done: Callable[[JobResult], object]) -> bool:
    """A finished job's result, in either isolation path: queued once more when it found no GL
    (a driver can fail now and then), else kept and handed to ``done``. True when the run must
    stop: no GL the second time either."""
    if result.no_gl and job.index not in retried:
        retried.add(job.index)
        pending.appendleft(job)
        return False
    results[job.index] = result
    if result.no_gl:
        return True
    done(result)
    return False


class _NoSlots:
    """No job slots: every job gets a supervisor of its own (:func:`run_jobs` without ``slots``)."""

    def take(self, job: Job) -> bool:
        return False

    def queue(self, job: Job) -> bool:
        return False

    def busy(self) -> int:
        return 0

    def fds(self) -> list[int]:
        return []

    def collect(self, *_: object) -> bool:
        return False

    def last_given(self) -> None:
        pass

    def close(self) -> None:
        pass


def _supervised(zygote_process, job: Job) -> int:  # noqa: ANN001 - a glsandbox.grading.zygote.Zygote
    """Ask the zygote for a supervisor for ``job``; the read end of its result pipe."""
    read_end, write_end = os.pipe()
    wide_pipe(write_end)
    try:
        zygote_process.request(_job_data(job), [write_end])
    finally:
        os.close(write_end)
    return read_end


def run_jobs(jobs: Sequence[Job], workers: int, done: Callable[[JobResult], None],
             slots: Callable[[int, Callable[[dict, list[int]], None]], object] | None = None) -> list[JobResult]:
    """Run every job, ``workers`` at once; ``done`` is called as each finishes; results in job order.
    ``slots(workers, request)``: the job slots that take the jobs they can (scene files,
    :class:`glsandbox.grading.slots.Slots`, given a way to ask the zygote); else none.

    The grader becomes a subreaper for the run, so a process a submission
    leaves behind whose supervisor was killed still comes back here, and is
    killed at the end with everything else the run started. (:func:`glsandbox.grading.runner.run_jobs`
    chooses between this and :mod:`glsandbox.grading.portable`.)
    """
    if not hasattr(os, "fork"):
        from glsandbox.errors import SandboxError

        raise SandboxError("glsandbox check runs each submission in a process of its own, which needs a POSIX "
                           "system (Linux, macOS); on Windows run it in WSL or a container")
    from glsandbox.grading import zygote

    ahead = zygote.ahead_pid()
    before = set(descendants(os.getpid())) - {ahead}
    set_subreaper()
    pending = deque(jobs)
    running: dict[int, _Running] = {}
    results: dict[int, JobResult] = {}
    retried: set[int] = set()
    # Supervisors that sent their result and are cleaning up (killing their renderer's tree,
    # removing their private folder): their pipes close when they end; the run waits for that.
    closing: dict[int, _Running] = {}
    zygote_process = zygote.take()
    folders = [zygote_process.folder]
    # Scene files go to job slots, each a supervisor with a renderer kept for many (glsandbox.grading.slots).
    slots = _NoSlots() if slots is None else slots(workers, lambda data, fds: zygote_process.request(data, fds))
    try:
        while pending or running or slots.busy():
            while pending and (len(running) + slots.busy() < max(1, workers) or slots.queue(pending[0])):
                job = pending.popleft()
                if len(running) + slots.busy() >= max(1, workers) or slots.take(job):
                    continue  # (queued behind a slot's job, or taken by an idle slot)
                try:
                    fd = _supervised(zygote_process, job)
                except OSError:  # the zygote is gone (it should not be): a fresh one, once
                    zygote_process.close()
                    zygote_process = zygote.Zygote()
                    folders.append(zygote_process.folder)
                    fd = _supervised(zygote_process, job)
                # a supervisor that hangs (it should not) is given up after every picture's time and a margin
                running[fd] = _Running(job, Reader(fd), time.monotonic() + job.timeout * len(job.renders) + 60)
            if not pending:  # every job handed out: the slots clean up as they finish theirs
                slots.last_given()
            ready, _, _ = select.select([*running, *closing, *slots.fds()], [], [], 1.0)
            _drain(closing, ready)
            if slots.collect(ready, pending, retried, results, done):
                return [results[j.index] for j in jobs if j.index in results]
            for fd in list(running):
                entry = running[fd]
                if fd in ready:
                    entry.reader.pump(0.0)
                message = None
                try:
                    for header, payload in entry.reader.messages(1 << 34):
                        if header.get("kind") == "pid":
                            entry.pid = int(header["pid"])
                        elif header.get("kind") == "result":
                            message = (header, payload)
                except (ValueError, KeyError, TypeError):
                    entry.reader.closed = True
                late = time.monotonic() > entry.deadline
                if message is None and not entry.reader.closed and not late:
                    continue
                if entry.pid and message is None:
                    kill_tree(entry.pid)
                    killpg(entry.pid)
                del running[fd]
                if message is not None and not entry.reader.closed:
                    closing[fd] = _Running(entry.job, entry.reader, time.monotonic() + 10, entry.pid)
                else:
                    os.close(fd)
                if settle(entry.job, _result(entry.job, message), pending, retried, results, done):
                    return [results[j.index] for j in jobs if j.index in results]
    finally:
        for fd, entry in running.items():
            if entry.pid:
                killpg(entry.pid)
            os.close(fd)
        slots.close()
        while closing:
            ready, _, _ = select.select(list(closing), [], [], 0.5)
            _drain(closing, ready)
        zygote_process.close()
        kill_tree(os.getpid(), keep=sorted(before))
        set_subreaper(False)
        for folder in folders:  # every process of the run is gone: what they left goes too
            shutil.rmtree(folder, ignore_errors=True)
    return [results[j.index] for j in jobs]


def _drain(closing: dict[int, _Running], ready: Sequence[int]) -> None:
    """Read the pipes of the supervisors cleaning up; forget each that closed (its supervisor
    ended) and kill the tree of one that is still at it past its deadline."""
    for fd in [fd for fd in closing if fd in ready or time.monotonic() > closing[fd].deadline]:
        entry = closing[fd]
        if fd in ready:
            entry.reader.pump(0.0)
            entry.reader.buffer.clear()  # nothing more is expected: whatever came is dropped
        if entry.reader.closed or time.monotonic() > entry.deadline:
            if not entry.reader.closed and entry.pid:
                kill_tree(entry.pid)
                killpg(entry.pid)
            del closing[fd]
            os.close(fd)


def _result(job: Job, message: tuple[dict, bytes] | None) -> JobResult:
    import numpy as np  # (not at the top: this module is light, for the zygote's early start)

    if message is None or (message[0].get("pictures") is None and not message[0].get("no_gl")):
        pictures = [Picture(status=CRASHED, error="its grading process ended without a result") for _ in job.renders]
        return JobResult(job, pictures)
    header, payload = message
    if header.get("no_gl"):
        return JobResult(job, [], no_gl=str(header["no_gl"]))
    pictures, offset = [], 0
    for entry in header["pictures"]:
        image = None
        if entry.get("shape"):
            h, w, c = entry["shape"]
            image = np.frombuffer(payload, dtype=np.uint8, count=h * w * c, offset=offset).reshape(h, w, c)
            offset += h * w * c
        info = entry.get("info") if isinstance(entry.get("info"), dict) else {}
        pictures.append(Picture(image, str(entry.get("status", "")), str(entry.get("error", "")),
                                float(entry.get("seconds", 0.0)), info))
    output = [str(line) for line in header.get("output", [])]
    root = str(header.get("root") or "")
    original = ""
    if root and job.source:  # the private copy's path, said as the submission's own
        original = job.source if Path(job.source).is_dir() else str(Path(job.source).parent)
        for picture in pictures:
            picture.error = picture.error.replace(root, original)
        output = [line.replace(root, original) for line in output]
    raw = header.get("meta") if isinstance(header.get("meta"), dict) else {}
    meta = {k: str(raw.get(k, ""))[:2000] for k in ("title", "course_section", "description")}
    if root and job.source:
        meta = {k: v.replace(root, original) for k, v in meta.items()}
    return JobResult(job, pictures, output, meta=meta)
