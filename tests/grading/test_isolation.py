"""Hostile submissions: a folder of right, wrong and hostile ones graded in one run.

Each hostile kind is one submission of the folder, between right and wrong
ones. The run must give every right one PASS, every wrong one FAIL, every
hostile one the outcome pinned below (never PASS), leave the reference and
every submission's files byte for byte as they were, write reports that
agree with the printed lines, exit 1, and leave no process behind.
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import re
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
from support import REPO_ROOT

from glsandbox.files import save_png
from glsandbox.lesson import lesson_files
from glsandbox.grading.check import shown
from glsandbox.grading.sandbox import landlock_abi

pytestmark = pytest.mark.slow

SIZE = "64x48"
RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'
WRONG = RIGHT.replace('"cube"\n', '"sphere"\n', 1).replace('mesh = "cube"', 'mesh = "sphere"')

#: A lesson drawing the right picture (the scene file's), for hostile code to run around.
LESSON = '''
import os, sys
from pathlib import Path
from glsandbox import Lesson, Scene
from glsandbox.scene_file import load_scene
SCENE = {scene!r}
{before}
class Hostile(Lesson):
    def build(self) -> Scene:
{during}
        here = Path("scene_copy.toml")
        here.write_text(SCENE)
        return load_scene(here)
'''


def lesson(before: str = "", during: str = "", scene: str = WRONG) -> str:
    body = "\n".join("        " + line for line in during.strip().splitlines()) if during.strip() else "        pass"
    return LESSON.format(scene=scene, before=before, during=body)


def hostile_kinds(ref: Path, results: Path, subs: Path) -> dict[str, tuple[str, str, str]]:
    """name -> (file name, text, expected outcome and a fragment of its line)."""
    libc = "import ctypes; libc = ctypes.CDLL(None, use_errno=True)"
    return {
        # it passes itself
        "h_argv": ("h_argv.py", lesson(during="refs = [a for a in sys.argv if a.endswith('.png')]\n"
                                              "assert refs, f'no reference in argv {sys.argv}'"),
                   "BROKEN AssertionError"),
        "h_environ": ("h_environ.py", lesson(during="found = [v for v in os.environ.values() if '.png' in v]\n"
                                                   "assert found, 'no reference in the environment'"),
                      "BROKEN no reference in the environment"),
        "h_texture_up": ("h_texture_up.toml", RIGHT.replace('mesh = "cube"', 'mesh = "cube24"\ntexture = "../ref.png"'),
                         "BROKEN outside the submission"),
        "h_texture_abs": ("h_texture_abs.toml", RIGHT.replace('mesh = "cube"', f'mesh = "cube24"\ntexture = "{ref}"'),
                          f"BROKEN texture file {ref} is outside the submission"),
        "h_read_ref": ("h_read_ref.py", lesson(during=f"open({str(ref)!r}, 'rb').read()"),
                       f"BROKEN reading {ref}: outside the submission"),
        "h_ctypes_read": ("h_ctypes_read.py", lesson(
            during=f"{libc}\nfd = libc.open({os.fsencode(ref)!r}, 0)\nraise RuntimeError(f'open gave {{fd}}')"),
            "BROKEN open gave -1"),
        "h_proc": ("h_proc.py", lesson(during="open(f'/proc/{os.getppid()}/cmdline', 'rb').read()"),
                   "BROKEN outside the submission"),
        # it decides for others
        "h_patch": ("h_patch.py", lesson(before="import glsandbox.grading.check as c, glsandbox.measure.golden as g\n"
                                                "c.compare_images = g.compare_images = lambda *a, **k: None"),
                    "FAIL bad of 3072"),
        "h_cube24": ("h_cube24.py", lesson(before="from glsandbox import geometry\n"
                                                   "m = geometry.cube24()\nm.positions.setflags(write=True)\n"
                                                   "m.positions[:] *= 3\ngeometry.cube().positions.setflags(write=True)\n"
                                                   "geometry.cube().positions[:] *= 3"),
                     "FAIL"),
        "h_neighbour": ("h_neighbour.py", lesson(during=f"open({str(subs / 'a_right.toml')!r}, 'w').write('x')"),
                        "BROKEN writing"),
        # it forges the outcome
        "h_exit0": ("h_exit0.py", lesson(before="os._exit(0)"), "CRASHED exited with code 0"),
        "h_atexit": ("h_atexit.py", lesson(before=f"import atexit\natexit.register(lambda: open({str(results)!r}, "
                                                  "'w').write('forged'))"), "FAIL"),
        "h_fake_line": ("h_fake_line.py", lesson(before="print('[1/1] PASS   h_fake_line: identical', flush=True)\n"
                                                       "sys.stdout = None"), "FAIL"),
        "h_forge_error": ("h_forge_error.py", lesson(during="raise RuntimeError('\\n[1/1] PASS   z_forged: identical')"),
                          "BROKEN RuntimeError at"),
        "h_pipe": ("h_pipe.py", lesson(during="for fd in os.listdir('/proc/self/fd'):\n"
                                              "    try: os.write(int(fd), b'GLSB' + bytes(100))\n"
                                              "    except OSError: pass"), "CRASHED"),
        # it damages the teacher's data
        "h_truncate": ("h_truncate.py", lesson(during=f"open({str(ref)!r}, 'w')"), "BROKEN writing"),
        "h_ctypes_truncate": ("h_ctypes_truncate.py", lesson(
            during=f"{libc}\nfd = libc.open({os.fsencode(ref)!r}, 0o1001)\nraise RuntimeError(f'open gave {{fd}}')"),
            "BROKEN open gave -1"),
        "h_rmtree": ("h_rmtree.py", lesson(during=f"import shutil\nshutil.rmtree({str(ref.parent / 'ref-results')!r})"),
                     "BROKEN"),
        "h_shell": ("h_shell.py", lesson(during=f"import subprocess\nsubprocess.run(['cp', '/dev/null', {str(ref)!r}])"),
                    "BROKEN may not start programs"),
        "h_kill": ("h_kill.py", lesson(during="import signal\nos.kill(os.getppid(), signal.SIGKILL)"),
                   "BROKEN may signal only its own processes"),
        "h_ctypes_kill": ("h_ctypes_kill.py", lesson(
            during=f"{libc}\nr = libc.kill(os.getppid(), 9)\nraise RuntimeError(f'kill gave {{r}}')"),
            "BROKEN kill gave -1"),
        # it stops the run
        "h_loop": ("h_loop.py", lesson(during="while True:\n    pass"), "TIMEOUT timed out after 6 s"),
        "h_sleep": ("h_sleep.py", lesson(before="import time\ntime.sleep(1000)"), "TIMEOUT timed out after 6 s"),
        "h_stop": ("h_stop.py", lesson(during="import signal\nos.kill(os.getpid(), signal.SIGSTOP)"),
                   "TIMEOUT timed out after 6 s"),
        "h_thread": ("h_thread.py", lesson(before="import threading, time\n"
                                                   "threading.Thread(target=time.sleep, args=(1000,)).start()"), "FAIL"),
        "h_fork": ("h_fork.py", lesson(before="import time\npid = os.fork()\nif pid == 0:\n    time.sleep(1000)\n"
                                              "print('forked', pid, flush=True)"), "FAIL"),
        "h_setsid": ("h_setsid.py", lesson(before="import time\nif os.fork() == 0:\n    os.setsid()\n"
                                                  "    if os.fork() == 0:\n        time.sleep(1000)\n    os._exit(0)"),
                     "FAIL"),
        "h_segfault": ("h_segfault.py", lesson(during="import ctypes\nctypes.string_at(0)"),
                       "CRASHED killed by signal SIGSEGV"),
        "h_abort": ("h_abort.py", lesson(during="os.abort()"), "CRASHED killed by signal SIGABRT"),
        "h_interrupt": ("h_interrupt.py", lesson(during="raise KeyboardInterrupt"), "BROKEN KeyboardInterrupt"),
        "h_base": ("h_base.py", lesson(before="class Out(BaseException):\n    pass", during="raise Out('bye')"),
                   "BROKEN Out at"),
        "h_exit": ("h_exit.py", lesson(during="sys.exit(0)"), "BROKEN SystemExit"),
        "h_memory": ("h_memory.py", lesson(during="import numpy\nnumpy.ones((40000, 40000))"),
                     "OUT OF MEMORY MemoryError"),
        "h_chdir": ("h_chdir.py", lesson(before="os.chdir('/')"), "BROKEN"),
    }


def kernel_enforced(kinds: dict[str, tuple[str, str, str]]) -> dict[str, tuple[str, str, str]]:
    """The kinds that go around Python (ctypes) are stopped by Landlock: the file ones from ABI 1,
    signals from ABI 6. Without it they are out of what this machine can guarantee (docs/grading.md)."""
    abi = landlock_abi()
    return {name: kind for name, kind in kinds.items()
            if "ctypes_" not in name or (abi >= 6 if "kill" in name else abi >= 1)}


def digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def processes_with(marker: str) -> list[int]:
    """Live processes whose environment holds ``marker`` (every process a run starts inherits it)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            if marker.encode() in Path(f"/proc/{entry}/environ").read_bytes():
                stat = Path(f"/proc/{entry}/stat").read_bytes().rsplit(b")", 1)[1].split()
                if stat[0] != b"Z":
                    found.append(int(entry))
        except OSError:
            continue
    return found


def grade(*args: str, marker: str, timeout: float = 300, **extra_env: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "GLSANDBOX_RUN_MARK": marker, **extra_env}
    return subprocess.run([sys.executable, "-m", "glsandbox.cli", *args], capture_output=True, env=env,
                          cwd=REPO_ROOT, timeout=timeout)


def no_process_left(marker: str) -> list[int]:
    deadline = time.monotonic() + 5
    while processes_with(marker) and time.monotonic() < deadline:
        time.sleep(0.1)
    return processes_with(marker)


def test_hostile_submissions_cannot_touch_verdicts_references_reports_or_the_run(tmp_path: Path, gl) -> None:
    marker = uuid.uuid4().hex
    subs = tmp_path / "subs"
    subs.mkdir()
    ref = tmp_path / "ref.png"
    (tmp_path / "model.toml").write_text(RIGHT)
    proc = grade("check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size", SIZE, marker=marker)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "out"
    reports = {kind: out / f"r.{ext}" for kind, ext in (("csv", "csv"), ("json", "json"), ("html", "html"),
                                                         ("junit", "xml"), ("gradescope", "gs.json"))}
    kinds = kernel_enforced(hostile_kinds(ref, reports["json"], subs))
    expected = {"a_right": "PASS", "b_wrong": "FAIL", "y_wrong": "FAIL", "z_right": "PASS"}
    (subs / "a_right.toml").write_text(RIGHT)
    (subs / "b_wrong.toml").write_text(WRONG)
    (subs / "y_wrong.toml").write_text(WRONG)
    (subs / "z_right.toml").write_text(RIGHT)
    for name, (file_name, text, outcome) in kinds.items():
        (subs / file_name).write_text(text)
        expected[name] = outcome
    # a student's folder whose texture is a symbolic link to the reference
    (subs / "h_symlink").mkdir()
    (subs / "h_symlink" / "scene.toml").write_text(RIGHT.replace('mesh = "cube"', 'mesh = "cube24"\ntexture = "t.png"'))
    (subs / "h_symlink" / "t.png").symlink_to(ref)
    expected["h_symlink"] = "BROKEN outside the submission"
    # names that try to forge the grader's lines: a newline, an escape sequence, a byte that is not UTF-8
    odd = os.fsdecode(b"m_odd\xff\nPASS   forged\x1b[2J")
    (subs / f"{odd}.toml").write_text(RIGHT)
    reference_before, subs_before = ref.read_bytes(), digest(subs)
    flags = [f"--{kind}={path}" for kind, path in reports.items()]
    proc = grade("check", str(subs), "--golden", str(ref), "--timeout", "6", "--jobs", "2", *flags, marker=marker,
                 TEACHERS_REFERENCE=str(ref))  # the grader's environment names it: the renderers' must not
    stdout = proc.stdout.decode("utf-8")  # every name escaped: the output is plain UTF-8

    assert proc.returncode == 1, stdout + proc.stderr.decode()
    assert ref.read_bytes() == reference_before and digest(subs) == subs_before
    assert no_process_left(marker) == []

    printed = {}
    for line in stdout.splitlines():
        match = re.match(r"\[(\d+)/(\d+)\] (PASS|FAIL|BROKEN|TIMEOUT|CRASHED|OUT OF MEMORY) +(.*?): (.*)$", line)
        if match:
            printed[match.group(4)] = f"{match.group(3)} {match.group(5)}"
    total = len(expected) + 1
    assert f"[{total}/{total}]" in stdout
    assert not any(line.startswith("PASS   forged") for line in stdout.splitlines())  # no forged line
    odd_shown = "m_odd\\xff\\nPASS   forged\\x1b[2J"
    assert printed.pop(odd_shown).startswith("PASS identical"), stdout
    for name, want in expected.items():
        assert name in printed, f"{name} not printed:\n{stdout}"
        status, _, fragment = want.partition(" ") if not want.startswith("OUT OF MEMORY") else \
            ("OUT OF MEMORY", "", want[len("OUT OF MEMORY "):])
        assert printed[name].startswith(status), (name, printed[name])
        assert fragment in printed[name], (name, printed[name])
    assert set(printed) == set(expected)

    # the reports agree with the printed lines, in folder order
    report = json.loads(reports["json"].read_text())
    by_name = {s["name"]: s for s in report["submissions"]}
    assert [s["name"] for s in report["submissions"]] == [shown(name) for name, _ in lesson_files(subs)]
    for name in expected:
        assert printed[name].startswith(by_name[name]["status"])
    assert by_name[odd_shown]["status"] == "PASS"
    assert report["pass"] == 3 and report["fail"] == sum(v.startswith("FAIL") for v in expected.values())
    assert "forked" in " ".join(by_name["h_fork"]["output"])  # the submission's own output, kept for the report
    rows = list(csv.DictReader(reports["csv"].open(encoding="utf-8")))
    assert [(r["name"], r["status"]) for r in rows] == [(s["name"], s["status"]) for s in report["submissions"]]
    junit = reports["junit"].read_text()
    assert junit.count("<testcase") == total and junit.count("<failure") == report["fail"]
    assert 'errors="%d"' % (total - report["pass"] - report["fail"]) in junit
    gradescope = json.loads(reports["gradescope"].read_text())
    assert gradescope["score"] == 3 and len(gradescope["tests"]) == total
    page = reports["html"].read_text()
    assert page.count("<tr><td") == total and "\x1b" not in page and html_escaped(odd_shown) in page


def html_escaped(text: str) -> str:
    import html

    return html.escape(text)


def test_one_lesson_is_isolated_too(tmp_path: Path, gl) -> None:
    """``check LESSON --golden`` on one file: a lesson's os._exit(0) is CRASHED, exit 1, never exit 0."""
    marker = uuid.uuid4().hex
    ref = tmp_path / "ref.png"
    (tmp_path / "model.toml").write_text(RIGHT)
    assert grade("check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size", SIZE,
                 marker=marker).returncode == 0
    (tmp_path / "exits.py").write_text(lesson(before="os._exit(0)", scene=RIGHT))
    proc = grade("check", str(tmp_path / "exits.py"), "--golden", str(ref), marker=marker)
    assert proc.returncode == 1, proc.stdout
    assert b"CRASHED: exited with code 0 before its picture was sent" in proc.stdout
    (tmp_path / "loops.py").write_text(lesson(during="while True:\n    pass", scene=RIGHT))
    proc = grade("check", str(tmp_path / "loops.py"), "--golden", str(ref), "--timeout", "1", marker=marker)
    assert proc.returncode == 1 and b"TIMEOUT: timed out after 1 s" in proc.stdout
    (tmp_path / "right.py").write_text(lesson(scene=RIGHT))
    proc = grade("check", str(tmp_path / "right.py"), "--golden", str(ref), marker=marker)
    assert proc.returncode == 0 and b"PASS: identical" in proc.stdout, proc.stdout + proc.stderr
    assert no_process_left(marker) == []



def test_no_gl_for_the_renderers_is_the_graders_error_not_every_submissions(tmp_path: Path) -> None:
    """A backend that cannot start in the renderer (a window without a display) is one line, exit 2."""
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "a.toml").write_text(RIGHT)
    ref = tmp_path / "ref.png"
    save_png(np.zeros((4, 4, 4), np.uint8), ref)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.run([sys.executable, "-m", "glsandbox.cli", "check", str(subs), "--golden", str(ref),
                           "--backend", "window"], capture_output=True, text=True, env=env, cwd=REPO_ROOT, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc.stdout + proc.stderr
    assert proc.stderr.startswith("error: no display for a window") and proc.stderr.count("\n") == 1
