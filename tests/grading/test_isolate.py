"""The grader's side of the process tree (glsandbox/grading/isolate.py), without a tree: framed
messages on a pipe, a job through the zygote's JSON and back, a result read from a message (the
private folder's path said as the submission's own), and a job with no GL retried once.
(The whole tree on hostile submissions: test_isolation.py.)"""

from __future__ import annotations

import os
import sys
import time
from collections import deque
from pathlib import Path

import numpy as np
import pytest

from glsandbox.grading.isolate import (CRASHED, STORY_LIMIT, Job, JobResult, Picture, Reader, Render, _job_data,
                                       _result, job_from, send, settle, story_of, wide_pipe)

JOB = Job(3, "/subs/ann/spin.py", "spin.py", (Render(("time=1",), (4, 2)), Render((), (2, 2), 4, explain=(1, 0))),
          timeout=5.0, describe=True)


def _read_all(fd: int, limit: int = 1 << 20) -> list[tuple[dict, bytes]]:
    reader, found = Reader(fd), []
    while not reader.closed:
        reader.pump(5.0)
        found += list(reader.messages(limit))
    return found


def test_framed_messages_arrive_whole_and_in_order() -> None:
    read_end, write_end = os.pipe()
    try:
        send(write_end, {"kind": "pid", "pid": 7})
        send(write_end, {"kind": "result"}, b"\x00\x01" * 1000)
        os.close(write_end)
        assert _read_all(read_end) == [({"kind": "pid", "pid": 7}, b""), ({"kind": "result"}, b"\x00\x01" * 1000)]
    finally:
        os.close(read_end)


def test_a_half_message_waits_and_a_malformed_or_oversized_one_is_refused() -> None:
    read_end, write_end = os.pipe()
    try:
        send(write_end, {"kind": "image"}, b"x" * 100)
        reader = Reader(read_end)
        reader.pump(5.0)
        whole = bytes(reader.buffer)
        reader.buffer = bytearray(whole[:-1])  # one byte short
        assert list(reader.messages(1000)) == [] and len(reader.buffer) == len(whole) - 1
        reader.buffer = bytearray(whole)
        with pytest.raises(ValueError, match="malformed"):
            list(reader.messages(99))  # a payload past the limit
        reader.buffer = bytearray(b"XXXX" + whole[4:])
        with pytest.raises(ValueError, match="malformed"):
            list(reader.messages(1000))
    finally:
        os.close(read_end)
        os.close(write_end)


def test_a_picture_comes_whole_in_a_buffer_of_its_own_however_it_is_cut() -> None:
    import numpy as np
    import threading

    picture = np.arange(240 * 320 * 4, dtype=np.uint32).astype(np.uint8).reshape(240, 320, 4)
    read_end, write_end = os.pipe()
    whole: list[bytes] = []

    def framed(fd: int) -> None:
        send(fd, {"kind": "image", "shape": [240, 320, 4]}, [picture[:100], picture[100:]])
        send(fd, {"kind": "served"})
        os.close(fd)

    def write_in_pieces() -> None:  # the pipe's bytes passed on in uneven pieces
        first, second = os.pipe()
        sender = threading.Thread(target=framed, args=(second,))
        sender.start()
        while chunk := os.read(first, 70_001):
            whole.append(chunk)
            os.write(write_end, chunk)
        sender.join()
        os.close(first)
        os.close(write_end)

    writer = threading.Thread(target=write_in_pieces)
    writer.start()
    try:
        found = _read_all(read_end)
    finally:
        writer.join()
        os.close(read_end)
    assert [header["kind"] for header, _ in found] == ["image", "served"]
    assert isinstance(found[0][1], bytearray) and found[0][1] == picture.tobytes()
    # what a caller adds to the buffer itself (the portable path's reading thread) frames the same
    reader = Reader(-1)
    reader.buffer += b"".join(whole)
    assert [(h["kind"], bytes(p)) for h, p in reader.messages(1 << 20)] == [("image", picture.tobytes()), ("served", b"")]
    reader.buffer += b"".join(whole)
    with pytest.raises(ValueError, match="malformed"):  # past the limit, however big a buffer it would get
        list(reader.messages(picture.nbytes - 1))


def test_a_job_goes_to_the_zygote_and_back_unchanged() -> None:
    assert job_from(_job_data(JOB)) == JOB


def test_a_story_is_text_cut_to_its_limit() -> None:
    assert story_of({"story": "x" * (STORY_LIMIT + 10)}) == {"story": "x" * STORY_LIMIT}
    assert story_of({"story": ["not", "text"]}) == {} and story_of({}) == {}


def test_no_result_is_a_crash_of_every_picture() -> None:
    result = _result(JOB, None)
    assert [p.status for p in result.pictures] == [CRASHED, CRASHED]
    assert _result(JOB, ({"kind": "result"}, b"")).pictures[0].error == "its grading process ended without a result"
    assert _result(JOB, ({"no_gl": "no EGL"}, b"")).no_gl == "no EGL"


def test_a_result_reads_its_pictures_and_says_the_submissions_own_path(tmp_path: Path) -> None:
    folder = tmp_path / "ann"
    folder.mkdir()
    job = Job(0, str(folder), "spin.py", JOB.renders)
    image = np.arange(2 * 4 * 4, dtype=np.uint8).reshape(2, 4, 4)
    header = {"root": "/tmp/private-xyz", "output": ["loading /tmp/private-xyz/spin.py"],
              "meta": {"title": "T" * 3000, "description": "in /tmp/private-xyz"},
              "pictures": [{"shape": [2, 4, 4], "seconds": 0.5, "info": {"plan": "p"}},
                           {"status": "BROKEN", "error": "/tmp/private-xyz/spin.py:3: NameError"}]}
    result = _result(job, (header, image.tobytes()))
    first, second = result.pictures
    assert np.array_equal(first.image, image) and first.seconds == 0.5 and first.info == {"plan": "p"}
    assert second.image is None and second.error == f"{folder}/spin.py:3: NameError"
    assert result.output == [f"loading {folder}/spin.py"]
    assert len(result.meta["title"]) == 2000 and result.meta["description"] == f"in {folder}"
    assert result.meta["course_section"] == ""


def test_no_gl_is_retried_once_then_stops_the_run() -> None:
    pending, retried, results, done = deque(), set(), {}, []
    no_gl = JobResult(JOB, [], no_gl="no EGL")
    assert settle(JOB, no_gl, pending, retried, results, done.append) is False
    assert list(pending) == [JOB] and results == {}  # queued again, first in line
    pending.clear()
    assert settle(JOB, no_gl, pending, retried, results, done.append) is True  # the second time: stop
    assert results == {3: no_gl} and done == []
    fine = JobResult(Job(4, None, "phong", ()), [Picture()])
    assert settle(fine.job, fine, pending, retried, results, done.append) is False and done == [fine]


@pytest.mark.skipif(sys.platform != "linux", reason="F_SETPIPE_SZ is Linux's")
def test_a_wide_pipe_takes_a_whole_picture_in_one_write() -> None:
    """A 320x240 picture and its header go in one write that does not wait for the reader
    (a pipe of 64 KiB takes five)."""
    import fcntl

    read_end, write_end = os.pipe()
    try:
        os.set_blocking(write_end, False)
        wide_pipe(write_end)
        assert fcntl.fcntl(write_end, fcntl.F_GETPIPE_SZ) >= 1 << 20
        message = bytes(320 * 240 * 4 + 4096)
        assert os.write(write_end, message) == len(message)
    finally:
        os.close(read_end)
        os.close(write_end)


PRINTING_LESSON = """from glsandbox.geometry import builtin_mesh
from glsandbox.lesson import Lesson
from glsandbox.scene import Node, Scene


class Printer(Lesson):
    def build(self):
        print("built by {name}")
        return Scene("printer", nodes=[Node("cube", mesh=builtin_mesh("cube24"))])
"""


@pytest.mark.skipif(sys.platform != "linux", reason="the tree's processes are found through /proc")
def test_the_run_ends_with_every_supervisor_cleaned_up_and_every_output_kept(gl_renderer, tmp_path: Path) -> None:
    """Each supervisor sends its result before it cleans up (the grader starts the next
    submission meanwhile); the output printed before the picture still comes back, and when
    ``run_jobs`` returns no process it started and no private folder is left."""
    import tempfile

    from glsandbox.grading.isolate import run_jobs
    from glsandbox.grading.processes import descendants

    jobs = []
    for n in range(4):
        (tmp_path / f"s{n}.py").write_text(PRINTING_LESSON.format(name=f"student {n}"))
        jobs.append(Job(n, str(tmp_path / f"s{n}.py"), f"s{n}.py", (Render((), (32, 24)),), timeout=20.0))
    before = set(Path(tempfile.gettempdir()).glob("glsandbox-grade-*"))
    already = set(descendants(os.getpid()))  # this worker's own (another test's warm template)
    results = run_jobs(jobs, 2, lambda result: None)
    assert [r.pictures[0].image.shape for r in results] == [(24, 32, 4)] * 4
    assert [r.output for r in results] == [[f"built by student {n}"] for n in range(4)]
    # A supervisor that closed its pipe may still be exiting: gone within a few seconds.
    deadline = time.monotonic() + 5.0
    while (left := set(descendants(os.getpid())) - already) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert left == set()
    # the temp folder is the machine's: other runs' folders may come and go; none may hold ours
    for folder in set(Path(tempfile.gettempdir()).glob("glsandbox-grade-*")) - before:
        assert not any(f"student {n}" in _text_or_empty(folder / "submission" / f"s{n}.py") for n in range(4))


def _text_or_empty(path: Path) -> str:
    try:
        return path.read_text()
    except OSError:  # not there (another run's folder, or gone while looked at)
        return ""


SLOW_LESSON = """import time
from glsandbox.geometry import builtin_mesh
from glsandbox.lesson import Lesson
from glsandbox.scene import Node, Scene


class Slow(Lesson):
    def build(self):
        time.sleep({seconds})
        return Scene("slow", nodes=[Node("cube", mesh=builtin_mesh("cube24"))])
"""


@pytest.mark.skipif(sys.platform != "linux", reason="the tree's processes are found through /proc")
def test_a_run_stopped_midway_leaves_no_private_folder(gl_renderer, tmp_path: Path) -> None:
    """The run stops while a supervisor is still at work (here the grader's own callback raises
    on the first result; Ctrl-C does the same): that supervisor is killed before its clean-up,
    and still no private folder of the run is left in the temp folder (they are all made in one
    folder of the run's, which the grader removes once every process of the run is gone)."""
    import tempfile

    from glsandbox.grading.isolate import run_jobs

    (tmp_path / "quick.py").write_text(SLOW_LESSON.format(seconds=0))
    (tmp_path / "slow.py").write_text(SLOW_LESSON.format(seconds=30))
    jobs = [Job(0, str(tmp_path / "quick.py"), "quick.py", (Render((), (16, 12)),), timeout=60.0),
            Job(1, str(tmp_path / "slow.py"), "slow.py", (Render((), (16, 12)),), timeout=60.0)]
    temp = Path(tempfile.gettempdir())
    before = set(temp.glob("glsandbox-grade-*"))

    def stop(result: JobResult) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_jobs(jobs, 2, stop)
    # the temp folder is the machine's: other runs' folders may come and go; none may hold ours
    ours = [folder for folder in set(temp.glob("glsandbox-grade-*")) - before
            if any("time.sleep(30)" in _text_or_empty(p) for p in folder.rglob("slow.py"))]
    assert ours == []
