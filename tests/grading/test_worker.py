"""The supervisor's side of a submission's renderer (glsandbox/grading/worker.py): each picture
read off the pipe against the clock, a renderer that ends, hangs, lies about its picture or
finds no GL told as such, and its last output lines kept.
(The whole tree on hostile submissions: test_isolation.py.)"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from glsandbox.grading import worker
from glsandbox.grading.isolate import BROKEN, CRASHED, TAIL_LINES, TAIL_WIDTH, TIMEOUT, Job, Render

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="the tree's running side is POSIX only")

JOB = Job(0, None, "phong", (Render((), (4, 2)), Render((), (4, 2))), timeout=3.0)
IMAGE = np.arange(2 * 4 * 4, dtype=np.uint8).reshape(2, 4, 4)


def _collect(script: str, job: Job = JOB) -> list:
    """Run ``script`` as a stand-in renderer writing to fd ``out`` with ``send``; collect its pictures."""
    read_end, write_end = os.pipe()
    code = f"import os, sys, time\nfrom glsandbox.grading.isolate import send\nout = {write_end}\n" + script
    child = subprocess.Popen([sys.executable, "-c", code], pass_fds=(write_end,))
    os.close(write_end)
    try:
        return worker._collect(job, child.pid, read_end)
    finally:
        os.close(read_end)
        child.kill()
        try:
            child.wait(timeout=10)
        except ChildProcessError:  # reaped by _collect
            pass


IMAGE_OF = "bytes(range(32))"  # IMAGE, as the stand-in renderer writes it


def test_every_picture_sent_comes_back() -> None:
    pictures = _collect("for i in (0, 1):\n"
                        f"    send(out, {{'kind': 'image', 'index': i, 'shape': [2, 4, 4], 'seconds': 0.25}}, {IMAGE_OF})\n")
    assert all(np.array_equal(p.image, IMAGE) and p.seconds == 0.25 and p.status == "" for p in pictures)


def test_a_broken_lesson_breaks_every_picture_and_a_bad_one_only_its_own() -> None:
    pictures = _collect("send(out, {'kind': 'error', 'index': 0, 'error': 'x' * 900, 'all': True})\n")
    assert [p.status for p in pictures] == [BROKEN, BROKEN] and len(pictures[1].error) == 500
    pictures = _collect("send(out, {'kind': 'error', 'index': 0, 'error': 'NameError'})\n"
                        f"send(out, {{'kind': 'image', 'index': 1, 'shape': [2, 4, 4]}}, {IMAGE_OF})\n")
    assert pictures[0].status == BROKEN and pictures[1].image is not None


@pytest.mark.parametrize("script,error", [
    (f"send(out, {{'kind': 'image', 'index': 0, 'shape': [4, 2, 4]}}, {IMAGE_OF})\n",
     "sent a picture of shape (4, 2, 4) for a 4x2 render"),
    (f"send(out, {{'kind': 'image', 'index': 1, 'shape': [2, 4, 4]}}, {IMAGE_OF})\n",
     "sent a message out of order on the result pipe"),
    ("os.write(out, b'not a frame at all, long enough for a header')\n", "sent a malformed message on the result pipe"),
    ("sys.exit(3)\n", "exited with code 3 before its picture was sent"),
    ("os.kill(os.getpid(), 11)\n", "killed by signal SIGSEGV"),
])
def test_a_renderer_that_lies_or_ends_is_a_crash(script: str, error: str) -> None:
    pictures = _collect(script)
    assert [p.status for p in pictures] == [CRASHED, CRASHED] and pictures[0].error == error


def test_a_renderer_that_hangs_times_out_on_its_picture() -> None:
    # The limit is wide enough for the child Python to start and send its first picture on a
    # loaded machine; the second never comes.
    job = Job(0, None, "phong", (Render((), (4, 2)), Render((), (4, 2))), timeout=4.0)
    pictures = _collect(f"send(out, {{'kind': 'image', 'index': 0, 'shape': [2, 4, 4]}}, {IMAGE_OF})\n"
                        "time.sleep(30)\n", job)
    assert pictures[0].image is not None and pictures[1].status == TIMEOUT
    assert pictures[1].error == "timed out after 4 s" and pictures[1].seconds >= 4.0


def test_no_gl_is_the_machines_problem_not_the_submissions() -> None:
    with pytest.raises(worker._NoGL, match="no EGL display"):
        _collect("send(out, {'kind': 'nogl', 'error': 'no EGL display'})\n")


def test_the_cpu_limit_is_a_timeout() -> None:
    status = signal.SIGXCPU  # what the kernel's RLIMIT_CPU sends: a raw wait status of that signal
    assert worker._exit_reason(status, JOB) == (TIMEOUT, "timed out: the CPU time limit (16 s) reached")


def test_the_output_tail_is_its_last_lines_each_cut(tmp_path: Path) -> None:
    log = tmp_path / "out.log"
    log.write_bytes(b"\n".join([b"early"] * 50 + [b"y" * 500, b"last \xff"]))
    tail = worker._tail(str(log))
    assert len(tail) == TAIL_LINES and tail[-1] == "last \\xff" and tail[-2] == "y" * TAIL_WIDTH
    assert worker._tail(str(tmp_path / "missing.log")) == []


@pytest.mark.parametrize("root, python_readable, expected", [(True, False, 1), (True, True, 0), (False, False, 0)])
def test_the_zygote_works_out_the_readable_etc_once_where_renderers_need_it(
        monkeypatch: pytest.MonkeyPatch, root: bool, python_readable: bool, expected: int) -> None:
    """A renderer that keeps reading as root does is granted only what of /etc a user with no
    account may read: the zygote walks /etc before any fork, so no renderer walks it again."""
    from glsandbox.grading import layers, sandbox

    monkeypatch.setattr(layers, "submission_ids", lambda seed: (1_870_000_001, 1_870_000_001) if root else None)
    monkeypatch.setattr(worker, "_python_readable", lambda: python_readable)
    monkeypatch.setattr(sandbox, "landlock_abi", lambda: 1)
    sandbox.others_may_read.cache_clear()
    worker.prepare_confinement()
    walked = sandbox.others_may_read.cache_info()
    assert (walked.currsize > 0) == bool(expected)
    if expected:  # what confine asks for next is already there: a hit, no walk
        sandbox.others_may_read("/etc")
        assert sandbox.others_may_read.cache_info().hits == walked.hits + 1
        assert sandbox.others_may_read.cache_info().currsize == walked.currsize


def test_the_zygote_freezes_its_heap_before_it_serves() -> None:
    """Every object the zygote made while preloading is in the permanent generation by the time it
    forks: a renderer's collector never walks them (and copies their pages)."""
    code = ("import gc, os, sys; from glsandbox.grading import worker; "
            "worker.zygote = lambda fd, slots: (print(gc.get_freeze_count(), len(gc.get_objects()), flush=True), "
            "os._exit(0)); "
            "worker.zygote_main(-1)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True).stdout
    frozen, tracked = map(int, out.split())
    assert frozen > 10_000 and tracked < frozen // 10


#: A renderer's process: the submission prints, then its build raises; ``render_job`` sends why
#: there is no picture, and the process ends at once (no flush at exit), as a killed one would.
PRINTS_THEN_RAISES = """
import os, sys
from pathlib import Path
from glsandbox.grading.isolate import Job, Render
from glsandbox.grading.worker import render_job
root = Path(sys.argv[1])
(root / "spy.py").write_text("from glsandbox import Lesson\\n\\nclass Spy(Lesson):\\n    def build(self):\\n"
                             "        print('printed before it raised')\\n        raise RuntimeError('looked')\\n")
job = Job(0, str(root / "spy.py"), "spy.py", (Render((), (4, 2)),), copy=False)
class Renderer:  # draws nothing: builds the scene, as a frame does first
    def render(self, lesson, size, samples):
        return lesson.scene()
read_end, write_end = os.pipe()
render_job(job, Renderer(), str(root), "spy.py", write_end)
os.write(2, os.read(read_end, 1 << 16))  # what it sent, for the test to read
os._exit(0)
"""


def test_what_a_submission_printed_is_written_before_why_it_has_no_picture(tmp_path: Path) -> None:
    """The supervisor reads the output file as soon as the last picture's message arrives and then
    kills the renderer: every message, a BROKEN one too, goes after the prints are written out
    (stdout to a file is block-buffered: the line was lost when the grader was quicker)."""
    log = tmp_path / "output.txt"
    with log.open("wb") as out:
        # block-buffered, as in a renderer (whose environment has no PYTHONUNBUFFERED)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
        proc = subprocess.run([sys.executable, "-c", PRINTS_THEN_RAISES, str(tmp_path)], stdout=out,
                              stderr=subprocess.PIPE, check=True, timeout=60, env=env)
    assert b'"broken"' in proc.stderr and b"looked" in proc.stderr  # the message: why there is no picture
    assert "printed before it raised" in log.read_text()
