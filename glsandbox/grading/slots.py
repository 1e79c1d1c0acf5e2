"""The grader's job slots for data-only submissions: each a slot supervisor and its resident renderer.

:func:`glsandbox.grading.isolate.run_jobs`, given these slots by
:func:`glsandbox.grading.runner.run_jobs`, hands a scene-file submission
(:func:`data_only`) to an idle slot, or opens one while fewer than
``--jobs`` are open; every other submission gets a supervisor of its own,
as before. A slot is two pipes to a supervisor the zygote forked
(:mod:`glsandbox.grading.resident`): jobs go down one, one at a time, and
each job's result (the same message a one-shot supervisor sends) comes back
on the other. A slot whose supervisor hangs past the job's time and a
margin, or whose pipe closes without a result, is killed: its job is
CRASHED, as a one-shot supervisor's would be, and the next scene file
opens a fresh slot. A job the slot answers ``own_process`` (a scene file
with a shader of its own) goes back to the queue for a supervisor of its own.
Once the run has no job left to hand out, every slot is told so
(:meth:`Slots.last_given`: its jobs' pipe closed), and its supervisor
cleans up as soon as it sent its last result, while the grader still
settles the last ones.
"""

from __future__ import annotations

import os
from pathlib import Path
import time
from collections import deque
from collections.abc import Callable, Sequence

from glsandbox.grading.isolate import Job, JobResult, Reader, _job_data, _result, send, settle, wide_pipe
from glsandbox.grading.processes import kill_tree, killpg

__all__ = ["data_only", "lone_file", "Slot", "Slots"]

#: Seconds a slot supervisor may take past its job's time limits before it is given up.
MARGIN = 60.0


def data_only(job: Job) -> bool:
    """Whether ``job`` is a copied submission that is a scene file and nothing else (data, no code),
    and not the model answer (whose renderer fills Mesa's shader cache).

    Nothing else: a model file, a texture or a shader beside the scene file would be decoded by C
    code (trimesh's and PIL's readers, the driver's GLSL compiler) in a renderer that goes on to draw
    other students' submissions, where a crafted file that took that process over could change
    their pictures. Such a submission gets a process of its own, as a lesson does."""
    if not (job.copy and job.source is not None and job.target.endswith(".toml") and not job.writes_cache):
        return False
    return lone_file(Path(job.source), job.target)


def lone_file(source: Path, name: str) -> bool:
    """Whether ``source`` is a plain file, or a folder holding the plain file ``name`` and nothing else."""
    try:
        if source.is_symlink():
            return False
        if source.is_file():
            return True
        with os.scandir(source) as entries:
            found = [(entry.name, entry.is_file(follow_symlinks=False)) for entry in entries]
    except OSError:  # gone, unreadable: the one-shot path says what is wrong with it
        return False
    return found == [(name, True)]


class Slot:
    """One slot: the pipes to its supervisor, the supervisor's pid, and its jobs: the one it is
    drawing and at most one more, already sent (it starts on it as soon as it sent the first's
    result, without waiting for the grader to read that result)."""

    def __init__(self, request: Callable[[dict, list[int]], None]) -> None:
        jobs_read, self.jobs = os.pipe()
        results, results_write = os.pipe()
        wide_pipe(results_write)
        try:
            request({"slot": True}, [jobs_read, results_write])
        finally:
            os.close(jobs_read)
            os.close(results_write)
        self.reader = Reader(results)
        self.pid = 0
        self.queue: list[Job] = []
        self.deadline = 0.0
        #: Whether it was told it gets no more jobs (its jobs' pipe closed).
        self.told = False

    def tell_done(self) -> None:
        """No more jobs for it: its jobs' pipe closed, so the supervisor ends after those it holds."""
        if not self.told:
            self.told = True
            os.close(self.jobs)

    def give(self, job: Job) -> None:
        send(self.jobs, _job_data(job))
        self.queue.append(job)
        self._set_deadline()

    def _set_deadline(self) -> None:
        """Every job it holds may take its pictures' time limits; past them and a margin it is lost."""
        self.deadline = time.monotonic() + sum(j.timeout * len(j.renders) for j in self.queue) + MARGIN

    def finished(self) -> tuple[dict, bytes] | None | bool:
        """Its first job's result message if it came; False while it is still drawing; None when
        the slot is lost (its pipe closed or a bad message, or past its deadline)."""
        try:
            for header, payload in self.reader.messages(1 << 34):
                if header.get("kind") == "pid":
                    self.pid = int(header["pid"])
                elif header.get("kind") == "result":
                    return header, payload
        except (ValueError, KeyError, TypeError):
            return None
        if self.reader.closed or time.monotonic() > self.deadline:
            return None
        return False

    def kill(self) -> None:
        """End the supervisor's whole tree (its renderer's too) and close the pipes."""
        if self.pid:
            kill_tree(self.pid)
            killpg(self.pid)
        self.tell_done()
        os.close(self.reader.fd)


class Slots:
    """The run's slots, at most ``workers`` of them."""

    def __init__(self, workers: int, request: Callable[[dict, list[int]], None]) -> None:
        self.workers, self.request = max(1, workers), request
        self.open: list[Slot] = []
        #: Jobs a slot handed back (a scene file with a shader of its own): a supervisor each.
        self.own: set[int] = set()

    def busy(self) -> int:
        """The slots drawing (each counts as one of the run's ``workers``)."""
        return sum(1 for slot in self.open if slot.queue)

    def fds(self) -> list[int]:
        return [slot.reader.fd for slot in self.open]

    def _theirs(self, job: Job) -> bool:
        return data_only(job) and job.index not in self.own

    def take(self, job: Job) -> bool:
        """Give ``job`` to an idle slot (opened if need be); False: not a slot's job, or every slot busy."""
        if not self._theirs(job):
            return False
        slot = next((s for s in self.open if not s.queue and not s.told), None)
        if slot is None:
            if len(self.open) >= self.workers:
                return False
            slot = Slot(self.request)
            self.open.append(slot)
        try:
            slot.give(job)
        except OSError:  # its supervisor is gone: a fresh slot, once
            self.open.remove(slot)
            slot.kill()
            slot = Slot(self.request)
            self.open.append(slot)
            slot.give(job)
        return True

    def queue(self, job: Job) -> bool:
        """Send ``job`` to a slot drawing one job, to start when that one is done (no slot more
        is opened: the run is at ``workers``); False where none can take it."""
        slot = next((s for s in self.open if len(s.queue) == 1 and not s.told), None) if self._theirs(job) else None
        if slot is None:
            return False
        try:
            slot.give(job)
        except OSError:  # its supervisor is gone: collect() finds the pipe closed
            return False
        return True

    def last_given(self) -> None:
        """The run has no job left to hand out: every slot told (:meth:`Slot.tell_done`), so each
        supervisor removes its renderer and folder while the last results are settled, not after.
        A job that comes back later (a retry, a slot lost) is graded all the same: by a fresh slot,
        or a supervisor of its own."""
        for slot in self.open:
            slot.tell_done()

    def collect(self, ready: Sequence[int], pending: deque[Job], retried: set[int], results: dict[int, JobResult],
                done: Callable[[JobResult], object]) -> bool:
        """Read the slots that are ``ready`` and settle each job that finished (:func:`settle`);
        True when the run must stop (no GL)."""
        for slot in list(self.open):
            if slot.reader.fd in ready:
                slot.reader.pump(0.0)
            while slot in self.open and (settled := self._settled(slot, pending, retried, results, done)) is not None:
                if settled:
                    return True
        return False

    def _settled(self, slot: Slot, pending: deque[Job], retried: set[int], results: dict[int, JobResult],
                 done: Callable[[JobResult], object]) -> bool | None:
        """The first job of ``slot`` settled if its result came (True: the run must stop); None
        (and ``slot`` kept) when there is nothing more to settle now."""
        if not slot.queue:
            if slot.reader.closed:  # an idle supervisor that ended (told it is done, or lost): forgotten
                self.open.remove(slot)
                slot.kill()
            return None
        message = slot.finished()
        if message is False:
            return None
        job = slot.queue.pop(0)
        slot._set_deadline()
        if message is None:  # lost: its job crashed; the one behind it never started, it goes back
            self.open.remove(slot)
            slot.kill()
            pending.extendleft(reversed(slot.queue))
            slot.queue = []
            return settle(job, _result(job, None), pending, retried, results, done)
        if message[0].get("own_process"):
            self.own.add(job.index)
            pending.appendleft(job)
            return False
        return settle(job, _result(job, message), pending, retried, results, done)

    def close(self) -> None:
        """Tell every slot the run is over (its jobs' pipe closed: the supervisor cleans up and
        ends) and wait until each has ended; a slot still drawing is killed."""
        waiting = []
        for slot in self.open:
            if slot.queue:
                slot.kill()
                continue
            slot.tell_done()
            waiting.append((slot, time.monotonic() + 10))
        self.open = []
        _wait_closed(waiting)


def _wait_closed(waiting: list[tuple[Slot, float]]) -> None:
    """Wait until each slot's supervisor ended (its result pipe closed), killing one past its deadline."""
    import select

    while waiting:
        ready, _, _ = select.select([s.reader.fd for s, _ in waiting], [], [], 0.5)
        for slot, deadline in list(waiting):
            if slot.reader.fd in ready:
                slot.reader.pump(0.0)
                slot.reader.buffer.clear()
            if slot.reader.closed or time.monotonic() > deadline:
                if not slot.reader.closed and slot.pid:
                    kill_tree(slot.pid)
                    killpg(slot.pid)
                os.close(slot.reader.fd)
                waiting.remove((slot, deadline))
