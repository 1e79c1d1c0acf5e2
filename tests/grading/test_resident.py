"""Scene files graded by a renderer kept per job slot (glsandbox/grading/resident.py): the same
verdicts and pictures as a process each, a fresh renderer after a TIMEOUT, crash or OUT OF
MEMORY, nothing carried from one submission to the next, and no submission's files readable by
another. (The grader's side of the slots: test_slots.py.)"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from glsandbox.grading import slots
from glsandbox.grading.isolate import BROKEN, CRASHED, TIMEOUT, Job, Render
from glsandbox.grading.resident import names_own_shader, start_afresh
from glsandbox.grading.runner import run_jobs  # the slots' way: scene files to a renderer kept per slot
from glsandbox.grading.warm import _WARM_SCENE
from glsandbox.lesson import find_lesson

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the slots' process tree is Linux's (fork, /proc)")

SIZE = (64, 48)
#: The warm template's scene (a camera and a light) with one node.
SCENE = _WARM_SCENE + '[[nodes]]\nmesh = "{mesh}"\nshading = "{shading}"\ncolor = [0.8, 0.4, 0.2]\n'
#: A triangle in an OBJ file; two of them, the same length, differ only in where the corners lie.
TRIANGLE = "v {a} 0.000 0.000\nv 0.000 {a} 0.000\nv 0.000 0.000 {a}\nf 1 2 3\n"


def _scene(folder: Path, name: str, text: str) -> Job:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.toml").write_text(text)
    return Job(0, str(folder), f"{name}.toml", (Render((), SIZE),), timeout=20.0)  # a student's folder


def _numbered(jobs: list[Job]) -> list[Job]:
    from dataclasses import replace

    return [replace(job, index=n) for n, job in enumerate(jobs)]


def _slow_scene(count: int = 6000) -> str:
    """A scene file that takes seconds to load and draw (many spheres): past a short time limit
    however fast the machine (a warm process loads and draws 1,500 of them in about 0.4 s, so
    6,000 take about four times the 0.5 s limit)."""
    nodes = "".join(f'[[nodes]]\nname = "n{i}"\nmesh = "sphere"\ntranslate = [{i % 20 * 0.1:.1f}, 0, 0]\n'
                    for i in range(count))
    return _WARM_SCENE + nodes


def _one_process_each(monkeypatch: pytest.MonkeyPatch, jobs: list[Job], workers: int = 2) -> list:
    with monkeypatch.context() as patch:
        patch.setattr(slots, "data_only", lambda job: False)
        return run_jobs(jobs, workers, lambda result: None)


def _summary(results: list) -> list[list[tuple[str, str, bytes | None]]]:
    return [[(p.status, p.error, None if p.image is None else p.image.tobytes()) for p in r.pictures] for r in results]


def test_a_class_of_scene_files_gets_the_verdicts_and_pictures_of_a_process_each(
        gl, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Right, different, broken and textured scene files, a model file and one with a shader
    of its own (handed back to a process of its own): the slots' results equal, picture for
    picture and line for line, those of a supervisor and renderer each."""
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "tri.obj").write_text(TRIANGLE.format(a="1.500"))
    (tmp_path / "t").mkdir()
    from glsandbox.files import save_png

    checker = np.kron(np.array([[0, 255], [255, 0]], dtype=np.uint8), np.ones((8, 8), dtype=np.uint8))
    save_png(np.repeat(checker[..., None], 3, axis=2), tmp_path / "t" / "checker.png")
    (tmp_path / "g").mkdir()
    (tmp_path / "g" / "toon.glsl").write_text("not GLSL at all\n")
    jobs = _numbered([
        _scene(tmp_path / "a", "cube", SCENE.format(mesh="cube24", shading="phong")),
        _scene(tmp_path / "b", "sphere", SCENE.format(mesh="sphere", shading="gouraud")),
        _scene(tmp_path / "c", "typo", SCENE.format(mesh="cube24", shading="phong").replace("[camera]", "[camra]")),
        _scene(tmp_path / "m", "model", SCENE.format(mesh="tri.obj", shading="solid")),
        _scene(tmp_path / "t", "textured", SCENE.format(mesh="cube24", shading="phong") + 'texture = "checker.png"\n'),
        _scene(tmp_path / "u", "missing", SCENE.format(mesh="cube24", shading="phong") + 'texture = "none.png"\n'),
        _scene(tmp_path / "g", "shader", SCENE.format(mesh="cube24", shading="phong") + 'shader = "toon.glsl"\n'),
        _scene(tmp_path / "a2", "cube", SCENE.format(mesh="cube24", shading="phong")),
    ])
    resident = run_jobs(jobs, 2, lambda result: None)
    alone = _one_process_each(monkeypatch, jobs)
    assert _summary(resident) == _summary(alone)
    statuses = [[p.status for p in r.pictures] for r in resident]
    assert statuses == [[""], [""], [BROKEN], [""], [""], [BROKEN], [BROKEN], [""]]
    assert "camra" in resident[2].pictures[0].error and "toon.glsl" in resident[6].pictures[0].error
    assert str(tmp_path / "c") in resident[2].pictures[0].error  # the submission's own path, not the copy's
    assert not np.array_equal(resident[0].pictures[0].image, resident[1].pictures[0].image)
    assert np.array_equal(resident[0].pictures[0].image, resident[7].pictures[0].image)


def test_a_timeout_mid_batch_replaces_the_renderer_and_the_next_one_passes(
        gl, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A scene file past its time limit is TIMEOUT, as in a process of its own; the same slot's
    next submission is drawn by a fresh renderer, and right."""
    right = SCENE.format(mesh="cube24", shading="phong")
    jobs = _numbered([_scene(tmp_path / "a", "first", right), _scene(tmp_path / "slow", "slow", _slow_scene()),
                      _scene(tmp_path / "b", "after", right)])
    from dataclasses import replace

    jobs = [replace(job, timeout=0.5) if job.target == "slow.toml" else job for job in jobs]
    resident = run_jobs(jobs, 1, lambda result: None)
    assert [r.pictures[0].status for r in resident] == ["", TIMEOUT, ""]
    assert resident[1].pictures[0].error == "timed out after 0.5 s"
    assert np.array_equal(resident[0].pictures[0].image, resident[2].pictures[0].image)
    expected = gl.render(find_lesson(str(tmp_path / "b" / "after.toml")).from_settings(()), SIZE).image
    assert np.array_equal(resident[2].pictures[0].image, expected)
    alone = _one_process_each(monkeypatch, jobs[1:2], workers=1)
    assert (alone[0].pictures[0].status, alone[0].pictures[0].error) == (TIMEOUT, "timed out after 0.5 s")


def _resident_renderers() -> list[int]:
    """This process's descendants working in a slot's inbox (``.../in/<n>``): resident renderers drawing."""
    from glsandbox.grading.processes import descendants

    found = []
    for pid in descendants(os.getpid()):
        try:
            if os.sep + "in" + os.sep in os.readlink(f"/proc/{pid}/cwd"):
                found.append(pid)
        except OSError:
            continue
    return found


def test_a_renderer_killed_mid_batch_is_a_crash_and_the_next_one_passes(gl, tmp_path: Path) -> None:
    """The resident renderer killed while it draws (SIGKILL: what the kernel's OOM killer sends):
    that submission is CRASHED with the signal named; the next one gets a fresh renderer and passes."""
    right = SCENE.format(mesh="cube24", shading="phong")
    jobs = _numbered([_scene(tmp_path / "a", "first", right), _scene(tmp_path / "slow", "slow", _slow_scene(4000)),
                      _scene(tmp_path / "b", "after", right)])
    killed: list[int] = []

    def kill_the_slow_ones_renderer() -> None:
        deadline = time.monotonic() + 60
        while not killed and time.monotonic() < deadline:
            for pid in _resident_renderers():
                if os.readlink(f"/proc/{pid}/cwd").endswith(os.sep + "2"):  # the slot's second submission
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)
            time.sleep(0.02)

    killer = threading.Thread(target=kill_the_slow_ones_renderer, daemon=True)
    killer.start()
    resident = run_jobs(jobs, 1, lambda result: None)
    killer.join()
    assert killed
    assert [r.pictures[0].status for r in resident] == ["", CRASHED, ""]
    assert resident[1].pictures[0].error == "killed by signal SIGKILL"
    assert np.array_equal(resident[0].pictures[0].image, resident[2].pictures[0].image)


def test_a_resident_renderer_is_one_thread_under_seccomp(gl, tmp_path: Path) -> None:
    """Landlock and seccomp bind the thread that enters them and the threads it starts later, not
    one already running: so a resident renderer, confined after its context opened, runs no
    thread of the driver's (no rasterizer threads, no Mesa shader-cache thread), and its one
    thread is under seccomp's filter."""
    from glsandbox.grading.layers import install_seccomp

    probe_read, probe_write = os.pipe()
    if os.fork() == 0:  # does this kernel have seccomp at all? (a throw-away child)
        os.write(probe_write, b"1" if install_seccomp() else b"0")
        os._exit(0)
    os.close(probe_write)
    has_seccomp = os.read(probe_read, 1) == b"1"
    os.close(probe_read)
    os.wait()
    jobs = _numbered([_scene(tmp_path / "a", "first", SCENE.format(mesh="cube24", shading="phong")),
                      _scene(tmp_path / "slow", "slow", _slow_scene(4000))])
    seen: list[list[str]] = []

    def look_at_the_slow_ones_renderer() -> None:
        deadline = time.monotonic() + 60
        while not seen and time.monotonic() < deadline:
            for pid in _resident_renderers():
                try:
                    if not os.readlink(f"/proc/{pid}/cwd").endswith(os.sep + "2"):
                        continue
                    seen.append([Path(f"/proc/{pid}/task/{tid}/status").read_text()
                                 for tid in os.listdir(f"/proc/{pid}/task")])
                except OSError:
                    continue
            time.sleep(0.02)

    watcher = threading.Thread(target=look_at_the_slow_ones_renderer, daemon=True)
    watcher.start()
    run_jobs(jobs, 1, lambda result: None)
    watcher.join()
    assert seen, "the renderer drawing the slow scene was found"
    (statuses,) = seen[:1]
    assert len(statuses) == 1, [line for status in statuses for line in status.splitlines() if line.startswith("Name")]
    if has_seccomp:
        assert "Seccomp:\t2" in statuses[0]  # 2: a filter


@pytest.mark.slow
def test_out_of_memory_mid_batch_replaces_the_renderer_and_the_next_one_passes(gl, tmp_path: Path) -> None:
    """A scene file too big for the memory limit to read (nine million numbers, under 460 MB: out
    of memory within seconds, well inside its time limit even on a slow machine): OUT OF MEMORY;
    the next submission, right, gets a fresh renderer and passes. (Near the limit a verdict may
    differ from a process of its own by what the process already holds: a resident renderer
    holds the programs of the scenes it drew, a renderer forked from the warm template those of
    every shading, so the resident one has the more room.)"""
    from dataclasses import replace

    from glsandbox.grading.isolate import OOM

    right = SCENE.format(mesh="cube24", shading="phong")
    numbers = ", ".join(["0.5"] * 9_000_000)
    jobs = _numbered([_scene(tmp_path / "a", "first", right),
                      _scene(tmp_path / "big", "big", right + f"uniforms = {{ big = [{numbers}] }}\n"),
                      _scene(tmp_path / "b", "after", right)])
    resident = run_jobs([replace(job, memory_mb=460) for job in jobs], 1, lambda result: None)
    assert [r.pictures[0].status for r in resident] == ["", OOM, ""]
    assert np.array_equal(resident[0].pictures[0].image, resident[2].pictures[0].image)


def test_no_model_is_carried_from_one_submission_to_the_next(gl, tmp_path: Path) -> None:
    """Two submissions whose model files have the same name, size and modification time but
    other corners, drawn one after the other by the same renderer: each picture is its own
    scene's (as drawn in this process), and they differ."""
    jobs = []
    for n, corner in enumerate(("1.500", "0.500")):
        folder = tmp_path / f"s{n}"
        folder.mkdir()
        (folder / "tri.obj").write_text(TRIANGLE.format(a=corner))
        os.utime(folder / "tri.obj", ns=(1_700_000_000_000_000_000,) * 2)
        jobs.append(_scene(folder, "model", SCENE.format(mesh="tri.obj", shading="solid")))
    assert (tmp_path / "s0" / "tri.obj").stat().st_size == (tmp_path / "s1" / "tri.obj").stat().st_size
    results = run_jobs(_numbered(jobs), 1, lambda result: None)
    pictures = [r.pictures[0].image for r in results]
    assert not np.array_equal(pictures[0], pictures[1])
    for n, picture in enumerate(pictures):
        expected = gl.render(find_lesson(str(tmp_path / f"s{n}" / "model.toml")).from_settings(()), SIZE).image
        assert np.array_equal(picture, expected)


def test_a_scene_file_cannot_read_another_submissions_files(gl, tmp_path: Path) -> None:
    """A scene file naming a neighbour's model (where it was handed in, and where the slot kept
    the neighbour's copy) is BROKEN, the path said: only its own files are read."""
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "tri.obj").write_text(TRIANGLE.format(a="1.500"))
    own = _scene(tmp_path / "a", "own", SCENE.format(mesh="tri.obj", shading="solid"))
    theirs = _scene(tmp_path / "b", "theirs", SCENE.format(mesh=str(tmp_path / "a" / "tri.obj"), shading="solid"))
    copy = _scene(tmp_path / "c", "copy", SCENE.format(mesh="../1/tri.obj", shading="solid"))
    results = run_jobs(_numbered([own, theirs, copy]), 1, lambda result: None)
    assert results[0].pictures[0].status == ""
    for result in results[1:]:
        assert result.pictures[0].status == BROKEN
    assert "outside the submission" in results[1].pictures[0].error
    assert "tri.obj" in results[2].pictures[0].error


def test_a_scene_file_with_a_shader_of_its_own_is_told_apart(tmp_path: Path) -> None:
    (tmp_path / "plain.toml").write_text(SCENE.format(mesh="cube", shading="phong"))
    (tmp_path / "shaded.toml").write_text(SCENE.format(mesh="cube", shading="phong") + 'shader = "x.glsl"\n')
    (tmp_path / "broken.toml").write_text("[[nodes]\n")
    assert [names_own_shader(tmp_path / f"{n}.toml") for n in ("plain", "shaded", "broken", "gone")] == [
        False, True, False, False]


def test_starting_afresh_keeps_the_built_in_programs_and_forgets_the_rest(gl, tmp_path: Path) -> None:
    """After :func:`start_afresh` the renderer has no target, mesh or plan of the last scene and
    no model in the cache, but its compiled built-in programs are the same objects."""
    from glsandbox.mesh import load

    (tmp_path / "tri.obj").write_text(TRIANGLE.format(a="1.500"))
    (tmp_path / "model.toml").write_text(SCENE.format(mesh="tri.obj", shading="solid"))
    lesson = find_lesson(str(tmp_path / "model.toml")).from_settings(())
    before = gl.render(lesson, SIZE).image
    programs = dict(gl.executor._programs)
    assert programs and load._CACHE and gl._targets
    start_afresh(gl)
    assert not load._CACHE and not gl._targets and not gl.executor._meshes and not gl._noted
    # The shared context may hold other tests' own-shader programs (keyed by their file's path): gone.
    built_in = {k: p for k, (_, p) in programs.items() if not Path(k.split("[")[0]).is_absolute()}
    assert built_in and {k: p for k, (_, p) in gl.executor._programs.items()} == built_in
    assert np.array_equal(gl.render(lesson, SIZE).image, before)
