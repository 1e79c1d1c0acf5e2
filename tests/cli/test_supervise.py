"""A lesson file's commands run supervised (glsandbox/supervise.py): a lesson that ends its process
before its picture (``sys.exit``, ``os._exit``, a crash) is one ``error:`` line naming it, exit 1
or 2, never a quiet exit 0; which command lines import user code; the child's word on its pipe."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from support import glsandbox

from glsandbox import supervise

LESSON = '''import glsandbox
from glsandbox import Lesson, Material, Node, Scene, geometry


class Ends(Lesson):
    name = "ends"

    def build(self):
        {in_build}
        return Scene("ends", nodes=(Node("c", geometry.cube(), material=Material((1, 1, 1, 1))),))


LESSON = Ends
{on_import}
'''

CASES = {
    "sys_exit_on_import": ("pass", "import sys; sys.exit(0)", (2,), "exited while importing"),
    "os_exit_on_import": ("pass", "import os; os._exit(0)", (1,), "ended the process (exit status 0"),
    "segfault_on_import": ("pass", "import ctypes; ctypes.string_at(0)", (1,), "died (SIGSEGV)"),
    "sys_exit_in_build": ("import sys; sys.exit(0)", "", (2,), "build() exited (SystemExit 0)"),
    "os_exit_in_build": ("import os; os._exit(0)", "", (1,), "ended the process"),
}


def _lesson(folder: Path, case: str) -> Path:
    in_build, on_import, _, _ = CASES[case]
    path = folder / f"{case}.py"
    path.write_text(LESSON.format(in_build=in_build, on_import=on_import))
    return path


def _assert_one_line(proc, codes: tuple[int, ...], name: str, says: str) -> None:
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode in codes, (proc.returncode, proc.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: ") and name in lines[0] and says in lines[0], proc.stderr


@pytest.mark.parametrize("case", sorted(CASES))
def test_render_of_a_lesson_that_ends_itself_says_so(tmp_path: Path, case: str, gl) -> None:
    path = _lesson(tmp_path, case)
    out = tmp_path / "out.png"
    proc = glsandbox("render", str(path), "--out", str(out), "--size", "32x24", cwd=tmp_path)
    _assert_one_line(proc, CASES[case][2], path.name, CASES[case][3])
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize("case", ["os_exit_on_import", "segfault_on_import"])
def test_tour_and_run_of_a_lesson_that_ends_itself_never_exit_0(tmp_path: Path, case: str, gl) -> None:
    folder = tmp_path / "lessons"
    folder.mkdir()
    path = _lesson(folder, case)
    proc = glsandbox("tour", "--lessons", str(folder), "--out", str(tmp_path / "tour"), "--size", "32x24",
                     cwd=tmp_path)
    # The tour renders each lesson isolated (as check does): the lesson's line says how it ended,
    # the last line names it, exit 1.
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 1 and lines[-1] == f"tour: failed: {path.stem}", proc.stderr
    assert any(f"{path.stem}: FAILED: CRASHED" in line for line in lines), proc.stderr
    proc = glsandbox("run", str(path), cwd=tmp_path, env={"DISPLAY": ""})
    assert proc.returncode in (1, 2) and "error: " in proc.stderr, proc.stderr


def test_a_lesson_that_renders_is_unchanged_by_the_supervision(tmp_path: Path, gl) -> None:
    path = tmp_path / "fine.py"
    path.write_text(LESSON.format(in_build="pass", on_import=""))
    out = tmp_path / "fine.png"
    proc = glsandbox("render", str(path), "--out", str(out), "--size", "32x24", cwd=tmp_path)
    assert proc.returncode == 0 and out.exists(), proc.stderr
    proc = glsandbox("render", str(tmp_path / "missing.py"), "--out", str(out), cwd=tmp_path)
    assert proc.returncode == 2 and proc.stderr.startswith("error: "), proc.stderr


def test_only_commands_that_import_a_lesson_file_are_supervised(tmp_path: Path) -> None:
    mine = tmp_path / "mine.py"
    mine.write_text("")
    assert supervise.user_code_in(["render", "--size", "32x24", str(mine)]) == str(mine)
    assert supervise.user_code_in(["run", str(mine)]) == str(mine)
    assert supervise.user_code_in(["render", "phong"]) is None  # a built-in lesson
    assert supervise.user_code_in(["render", str(tmp_path / "missing.py")]) is None  # the command says it is missing
    assert supervise.user_code_in(["plan", str(mine)]) is None and supervise.user_code_in([]) is None
    assert supervise.user_code_in(["tour", "--lessons", "folder"]) == "folder"
    assert supervise.user_code_in(["tour", "--lessons=folder"]) == "folder"
    assert supervise.user_code_in(["tour", "--out", "x"]) is None and supervise.user_code_in(["tour", "--lessons"]) is None


def test_the_child_says_done_once_on_its_pipe(monkeypatch) -> None:
    read_end, write_end = os.pipe()
    monkeypatch.setenv(supervise.CHILD_ENV, str(write_end))
    supervise.finished()
    assert os.read(read_end, 16) == b"done" and os.read(read_end, 16) == b""  # written, then closed
    assert supervise.CHILD_ENV not in os.environ  # a second call (or a grandchild) writes nothing
    supervise.finished()
    os.close(read_end)


def test_a_lesson_file_after_the_options_is_supervised_too(tmp_path: Path, gl) -> None:
    path = _lesson(tmp_path, "os_exit_on_import")
    out = tmp_path / "out.png"
    proc = glsandbox("render", "--size", "32x24", "--out", str(out), str(path), cwd=tmp_path)
    _assert_one_line(proc, (1,), path.name, "ended the process (exit status 0")
    assert not out.exists()
