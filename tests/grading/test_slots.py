"""The grader's job slots (glsandbox/grading/slots.py), without a process tree: which jobs a slot
takes, at most ``--jobs`` slots, a result read and settled, a job handed back for a process of its
own, and a slot whose supervisor is gone. (The slots' supervisors and renderers: test_resident.py.)"""

from __future__ import annotations

import os
from collections import deque
from pathlib import Path

import numpy as np
import pytest

from glsandbox.grading.isolate import CRASHED, Job, JobResult, Render, send
from glsandbox.grading.slots import Slots, data_only

RENDERS = (Render((), (2, 1)),)


#: Where :func:`_job` writes its submissions (a fresh folder per test, :func:`subs`).
SUBS: list[Path] = []


@pytest.fixture(autouse=True)
def subs(tmp_path):
    SUBS[:] = [tmp_path]
    yield tmp_path
    SUBS.clear()


def _job(index: int, target: str = "scene.toml", **changes) -> Job:
    """Submission ``index``: a folder holding its one file ``target``, as a student hands it in."""
    folder = SUBS[0] / f"s{index}"
    folder.mkdir(exist_ok=True)
    if target:
        (folder / target).write_text('name = "x"\n')
    return Job(index, str(folder), target, RENDERS, **changes)


def test_only_a_copied_scene_file_that_is_not_the_model_answer_is_data_only(tmp_path) -> None:
    alone = tmp_path / "s0"
    alone.mkdir()
    (alone / "scene.toml").write_text('name = "x"\n')

    def job(target: str = "scene.toml", source=alone, **changes) -> Job:
        return Job(0, str(source), target, RENDERS, **changes)

    assert data_only(job()) and data_only(job(source=alone / "scene.toml"))  # a folder of one, or the file
    assert not data_only(job("lesson.py"))
    assert not data_only(job(""))  # a folder whose lesson the renderer finds
    assert not data_only(job(copy=False))  # a lesson checked by its author, where it is
    assert not data_only(job(writes_cache=True))  # the model answer fills Mesa's cache
    assert not data_only(Job(0, None, "scene.toml", RENDERS))  # a built-in lesson's name
    assert not data_only(job(source=tmp_path / "gone"))


@pytest.mark.parametrize("beside", ["rock.obj", "wood.png", "glow.frag", "models/"])
def test_a_scene_file_with_files_beside_it_gets_a_process_of_its_own(tmp_path, beside: str) -> None:
    """A model, a texture or a shader is decoded by C code: never in a renderer kept for others."""
    folder = tmp_path / "s1"
    folder.mkdir()
    (folder / "scene.toml").write_text('name = "x"\n')
    if beside.endswith("/"):
        (folder / beside).mkdir()
    else:
        (folder / beside).write_bytes(b"data")
    assert not data_only(Job(1, str(folder), "scene.toml", RENDERS))
    (folder / "link.toml").symlink_to(folder / "scene.toml")
    assert not data_only(Job(1, str(folder / "link.toml"), "link.toml", RENDERS))  # a link is never lone


class FakeZygote:
    """Keeps the ends of each slot's pipes the zygote would hand its supervisor."""

    def __init__(self) -> None:
        self.slots: list[tuple[int, int]] = []  # (jobs read end, results write end)

    def request(self, data: dict, fds: list[int]) -> None:
        assert data == {"slot": True} and len(fds) == 2
        self.slots.append((os.dup(fds[0]), os.dup(fds[1])))

    def close(self) -> None:
        for pair in self.slots:
            for fd in pair:
                try:
                    os.close(fd)
                except OSError:
                    pass


@pytest.fixture
def zygote():
    made = FakeZygote()
    yield made
    made.close()


def _collect(slots: Slots, pending: deque, results: dict, done: list) -> bool:
    return slots.collect(slots.fds(), pending, set(), results, done.append)


def test_at_most_jobs_slots_and_each_draws_one_job_at_a_time(zygote: FakeZygote) -> None:
    slots = Slots(2, zygote.request)
    assert [slots.take(_job(n)) for n in range(3)] == [True, True, False]
    assert slots.busy() == 2 and len(zygote.slots) == 2
    assert not slots.take(_job(3, "lesson.py"))  # a supervisor of its own, whatever the slots
    from glsandbox.grading.isolate import Reader

    reader = Reader(zygote.slots[0][0])
    reader.pump(5.0)
    assert [h["index"] for h, _ in reader.messages(0)] == [0]  # the job, as the zygote's JSON
    slots.close()


def test_a_busy_slot_holds_one_job_more_and_no_slot_more_is_opened(zygote: FakeZygote) -> None:
    """At ``--jobs`` the next scene file waits in a drawing slot's pipe (it starts there as soon
    as the first's result is sent), one per slot."""
    slots = Slots(2, zygote.request)
    assert [slots.take(_job(n)) for n in range(2)] == [True, True]
    assert [slots.queue(_job(n)) for n in range(2, 5)] == [True, True, False]
    assert [len(slot.queue) for slot in slots.open] == [2, 2] and len(zygote.slots) == 2
    assert not slots.queue(_job(5, "lesson.py"))
    slots.close()


def test_a_lost_slot_crashes_the_job_it_draws_and_gives_back_the_one_waiting(zygote: FakeZygote) -> None:
    slots = Slots(1, zygote.request)
    assert slots.take(_job(0)) and slots.queue(_job(1))
    jobs_end, results_end = zygote.slots[0]
    os.close(results_end)
    os.close(jobs_end)
    zygote.slots[0] = (-1, -1)
    pending, results, done = deque(), {}, []
    while not done:
        _collect(slots, pending, results, done)
    assert [p.status for p in done[0].pictures] == [CRASHED] and done[0].job.index == 0
    assert [job.index for job in pending] == [1]  # never started: graded again, not crashed
    slots.close()


def test_a_result_is_settled_and_the_slot_is_free_again(zygote: FakeZygote) -> None:
    slots = Slots(1, zygote.request)
    assert slots.take(_job(0))
    _, results_end = zygote.slots[0]
    send(results_end, {"kind": "pid", "pid": 0})
    pixels = np.arange(8, dtype=np.uint8)
    send(results_end, {"kind": "result", "pictures": [{"status": "", "error": "", "seconds": 0.5, "shape": [1, 2, 4]}],
                       "output": ["said"], "root": "", "meta": {}}, pixels.tobytes())
    pending, results, done = deque(), {}, []
    while not done:
        assert not _collect(slots, pending, results, done)
    (result,) = done
    assert isinstance(result, JobResult) and result.output == ["said"]
    assert np.array_equal(result.pictures[0].image.ravel(), pixels)
    assert slots.busy() == 0 and slots.take(_job(1))  # the same slot, not a new one
    assert len(zygote.slots) == 1
    slots.close()


def test_a_scene_file_handed_back_goes_to_a_process_of_its_own(zygote: FakeZygote) -> None:
    slots = Slots(1, zygote.request)
    job = _job(0)
    assert slots.take(job)
    send(zygote.slots[0][1], {"kind": "result", "pictures": None, "own_process": True})
    pending, results, done = deque(), {}, []
    while not pending:
        _collect(slots, pending, results, done)
    assert list(pending) == [job] and done == [] and results == {}
    assert not slots.take(job)  # now the one-process-each way
    slots.close()


def test_a_slot_whose_supervisor_is_gone_crashes_its_job_and_is_replaced(zygote: FakeZygote) -> None:
    slots = Slots(1, zygote.request)
    assert slots.take(_job(0))
    jobs_end, results_end = zygote.slots[0]
    os.close(results_end)  # the supervisor ended without a result
    os.close(jobs_end)
    zygote.slots[0] = (-1, -1)
    pending, results, done = deque(), {}, []
    while not done:
        _collect(slots, pending, results, done)
    assert [p.status for p in done[0].pictures] == [CRASHED]
    assert slots.open == [] and slots.take(_job(1)) and len(zygote.slots) == 2
    slots.close()


def test_once_every_job_is_handed_out_a_slot_ends_after_its_last_result(zygote: FakeZygote) -> None:
    """The supervisor reads the job it holds and then the end of its jobs' pipe (it cleans up
    while the grader settles the last results); a told slot takes no job, and its end is no crash."""
    from glsandbox.grading.isolate import Reader

    slots = Slots(1, zygote.request)
    assert slots.take(_job(0))
    slots.last_given()
    assert not slots.take(_job(1)) and not slots.queue(_job(1)) and len(zygote.slots) == 1
    jobs_end, results_end = zygote.slots[0]
    reader = Reader(jobs_end)
    while not reader.closed:
        reader.pump(5.0)
    assert [h["index"] for h, _ in reader.messages(0)] == [0]  # its job, then the pipe's end
    send(results_end, {"kind": "result", "pictures": [{"status": "", "error": "", "seconds": 0.1, "shape": [1, 2, 4]}],
                       "output": [], "root": "", "meta": {}}, bytes(8))
    os.close(results_end)  # the supervisor cleaned up and ended
    os.close(jobs_end)
    zygote.slots[0] = (-1, -1)
    pending, results, done = deque(), {}, []
    while slots.open:
        assert not _collect(slots, pending, results, done)
    assert [p.status for p in done[0].pictures] == [""] and not pending
    slots.last_given()  # nothing open: nothing to tell
    slots.close()
