"""The ``glsandbox`` command's first step (glsandbox/launch.py): a class's zygote started before numpy."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from glsandbox import launch
from glsandbox.grading import runner, zygote

REPO = Path(__file__).resolve().parents[2]


def test_only_a_command_that_grades_a_folder_starts_early(tmp_path: Path) -> None:
    folder, file = tmp_path / "subs", tmp_path / "ref.png"
    folder.mkdir()
    file.write_bytes(b"")
    assert launch.grades_a_class(["check", str(folder), "--golden", str(file)])
    assert launch.grades_a_class(["check", "--golden", str(file), "--jobs", "2", str(folder)])
    assert not launch.grades_a_class(["check", str(file), "--golden", str(file)])  # one lesson: no zygote
    assert not launch.grades_a_class(["check", str(folder), "--update"])  # the model answer, in this process
    assert not launch.grades_a_class(["check", "merge", str(folder)])
    assert not launch.grades_a_class(["render", str(folder)]) and not launch.grades_a_class([])


def test_the_zygote_starts_before_numpy_and_a_run_that_takes_none_leaves_nothing(tmp_path: Path) -> None:
    (tmp_path / "subs").mkdir()
    script = ("import json, os, sys\n"
              "from glsandbox import launch\n"
              "from glsandbox.grading import zygote\n"
              f"launch.start_early(['check', {str(tmp_path / 'subs')!r}])\n"
              "z = zygote._prestarted\n"
              "print(json.dumps({'started': z is not None and z.process.poll() is None, 'folder': z.folder,\n"
              "                  'numpy': 'numpy' in sys.modules, 'blas': os.environ.get('OPENBLAS_NUM_THREADS'),\n"
              "                  'isolate': 'glsandbox.grading.isolate' in sys.modules}))\n")
    env = {"PATH": "/usr/bin:/bin", "GLSANDBOX_ISOLATION": ""}
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    seen = json.loads(proc.stdout)
    assert seen["started"] and not seen["numpy"] and seen["blas"] == "1"
    assert not seen["isolate"]  # started with the standard library's process modules, before the grader's own
    assert not Path(seen["folder"]).exists()  # closed at exit, its folder removed


def test_the_portable_way_starts_no_zygote_and_the_user_keeps_their_blas_threads(monkeypatch, tmp_path) -> None:
    started: list[str] = []
    monkeypatch.setattr(zygote, "prestart", lambda: started.append("zygote"))
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    monkeypatch.setenv("GLSANDBOX_ISOLATION", "portable")
    launch.start_early(["check", str(tmp_path)])
    assert started == []
    monkeypatch.setenv("GLSANDBOX_ISOLATION", "")
    launch.start_early(["check", str(tmp_path)])
    assert started == ["zygote"] and runner.portable_wanted() is False
    import os

    assert os.environ["OPENBLAS_NUM_THREADS"] == "4"


@pytest.mark.parametrize("entry", [["-m", "glsandbox"], ["-m", "glsandbox.cli"]])
def test_both_ways_in_run_the_same_command(entry: list[str]) -> None:
    proc = subprocess.run([sys.executable, *entry, "--version"], capture_output=True, text=True, cwd=REPO, timeout=120)
    assert proc.returncode == 0 and proc.stdout.split()[-1] == __import__("glsandbox").__version__


def test_the_command_leaves_its_objects_to_the_system_and_still_runs_its_exit_handlers() -> None:
    script = ("import atexit, gc, json, sys, tempfile\n"
              "import glsandbox.cli\n"
              "glsandbox.cli.main = lambda argv=None: 3\n"
              "from glsandbox import launch\n"
              "folder = tempfile.TemporaryDirectory()\n"
              "path = folder.name\n"
              "atexit.register(lambda: print(json.dumps({'frozen': gc.get_freeze_count(), 'folder': path})))\n"
              "sys.exit(launch.main(['render', 'x']))\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO, timeout=120)
    assert proc.returncode == 3, proc.stderr
    seen = json.loads(proc.stdout)
    assert seen["frozen"] > 1000  # the interpreter's last collections walk none of them
    assert not Path(seen["folder"]).exists()  # a temporary folder's finaliser still ran
