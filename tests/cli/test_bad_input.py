"""Hostile input at the command line: one ``error:`` line and exit 2, or a clean stop; never a
traceback, never a half-written file or an empty folder left behind.

Runs are in this process (``support.run_cli``) but where the process is the point: a closed
pipe, a lesson module's own entry point, the OSMesa library path, no display."""

from __future__ import annotations

import ctypes.util
import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest

from glsandbox import cli
from support import REPO_ROOT as REPO
from support import assert_user_error, glsandbox, run_cli


@pytest.mark.parametrize("args, fragment", [
    (["render", "indexed_cube", "--samples", "3"], "--samples 3"),
    (["render", "indexed_cube", "--samples", "-1"], "--samples -1"),
    (["render", "indexed_cube", "--set", "time=1e308", "--set", "speed=10"], "time=1e308"),
    (["render", "mirror", "--set", "far=1e308"], "far=1e308"),
    (["render", "mirror", "--set", "distance=1e300"], "distance=1e300"),
    (["render", "mirror", "--set", "lx=1e308", "--set", "light=directional"], "lx=1e308"),
    (["compare", "phong", "--vary", "speed=1e308,1", "--set", "time=2"], "speed=1e308"),
])
def test_out_of_range_numbers_are_refused_where_they_enter(tmp_path: Path, args: list[str], fragment: str) -> None:
    out = tmp_path / "x.png"
    assert_user_error(run_cli(*args, "--out", str(out), unchanged=tmp_path), fragment)
    assert not out.exists()


def test_a_bad_sample_count_stops_a_tour_before_it_starts(tmp_path: Path) -> None:
    out = tmp_path / "tour"
    assert_user_error(run_cli("tour", "--samples", "3", "--out", str(out)), "--samples 3")
    assert not out.exists()


def test_argparse_mistakes_are_one_line() -> None:
    for args in (["render"], ["render", "indexed_cube"], ["nosuchcommand"], ["render", "x", "--samples", "many"]):
        assert_user_error(run_cli(*args), "see glsandbox")


def test_a_lesson_module_reports_argparse_mistakes_in_one_line() -> None:
    proc = subprocess.run([sys.executable, "-m", "glsandbox.lessons.indexed_cube", "--no-such-flag"], capture_output=True,
                          text=True, cwd=REPO, timeout=60)
    assert_user_error(proc, "--no-such-flag")


def test_tour_with_set_leaves_no_empty_folder(tmp_path: Path) -> None:
    out = tmp_path / "tour"
    assert_user_error(run_cli("tour", "--set", "x=1", "--out", str(out)), "--set")
    assert not out.exists()


def test_tour_into_a_read_only_folder_is_refused_up_front(tmp_path: Path, monkeypatch, capsys) -> None:
    # Root (as in CI) may write anywhere, so the folder is made unwritable as
    # the access check sees it.
    out = tmp_path / "locked"
    out.mkdir()
    real_access = os.access
    monkeypatch.setattr(cli.os, "access", lambda p, mode: False if Path(p) == out else real_access(p, mode))
    assert cli.main(["tour", "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip() == f"error: --out {out}: folder is not writable"
    assert list(out.iterdir()) == []


def test_a_full_disk_is_one_error_line_and_no_partial_file(tmp_path: Path, monkeypatch, capsys, gl) -> None:
    def full(image, path):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(cli, "save_png", full)
    out = tmp_path / "cube.png"
    assert cli.main(["render", "indexed_cube", "--size", "32x32", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: --out {out}: cannot write (No space left on device)"]
    assert list(tmp_path.iterdir()) == []


def test_a_reader_that_stops_early_ends_the_command_quietly() -> None:
    # `true` reads nothing and exits at once: every write of the command meets a closed pipe.
    command = f"{sys.executable} -m glsandbox.cli plan mirror | true"
    proc = subprocess.run(["bash", "-c", command], capture_output=True, text=True, cwd=REPO, timeout=60)
    assert proc.stderr == "", proc.stderr


def test_tradeoffs_into_an_unwritable_folder_or_a_full_disk_is_one_line(tmp_path: Path, monkeypatch,
                                                                        capsys, gl) -> None:
    from glsandbox.measure import tradeoffs

    out = tmp_path / "locked"
    out.mkdir()
    real_access = os.access
    monkeypatch.setattr(tradeoffs.os, "access", lambda p, mode: False if Path(p) == out else real_access(p, mode))
    assert cli.main(["tradeoffs", "--quick", "--knob", "depth", "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == f"error: --out {out}: folder is not writable"
    monkeypatch.undo()

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(tradeoffs, "save_png", full)
    full_out = tmp_path / "full"
    assert cli.main(["tradeoffs", "--quick", "--knob", "depth", "--out", str(full_out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == f"error: --out {full_out}: cannot write (No space left on device)"
    assert not [line for line in err if line.startswith("Traceback")]


@pytest.mark.parametrize("renderer", ["raster", "ray", "ray_numpy"])
def test_successful_renders_of_every_lesson_print_no_warning(tmp_path: Path, capsys, gl, renderer: str) -> None:
    # RuntimeWarnings (numpy's overflow, invalid value, division by zero), Pillow's and glfw's
    # warnings reach stderr beside the output: a successful run prints only its "wrote" line,
    # and the one warning each for what the chosen renderer ignores of the lesson's scene
    # (plan.ignored_settings_notes: a texture filter, a planar mirror under renderer=ray),
    # nothing else. Raster renders ignore nothing: they print nothing.
    import warnings

    from glsandbox.lesson import all_lessons
    from glsandbox.plan import ignored_settings_notes

    out = tmp_path / "x.png"
    for cls in all_lessons():
        for time in ("0", "1.7"):
            settings = [f"renderer={renderer}", f"time={time}"]
            expected = "".join(f"warning: {note}\n"
                               for note in ignored_settings_notes(cls.from_settings(settings).scene()))
            assert renderer != "raster" or expected == "", cls.name
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                status = cli.main(["render", cls.name, "--size", "32x24", "--set", f"renderer={renderer}",
                                   "--set", f"time={time}", "--out", str(out)])
            captured = capsys.readouterr()
            assert status == 0 and captured.err == expected, (cls.name, captured.err)
            assert [str(w.message) for w in caught] == [], cls.name


def test_control_characters_in_a_value_keep_the_message_on_one_line() -> None:
    # "\x1e" (and "\r", "\u2028", ...) end a line for str.splitlines: the value is shown escaped.
    proc = run_cli("render", "indexed_cube", "--set", "time=0\x1e0", "--out", "x.png")
    assert_user_error(proc, "--set time=0\\x1e0: expected a number")
    assert_user_error(run_cli("render", "cube\u2028x", "--out", "x.png"), "unknown lesson 'cube\\u2028x'")


@pytest.mark.slow  # several subprocesses: the process is the point
def test_an_osmesa_that_is_not_osmesa_is_one_line_naming_it(tmp_path: Path) -> None:
    libc = ctypes.util.find_library("c")
    text_file = tmp_path / "libOSMesa.so"
    text_file.write_text("not a library\n")
    out = tmp_path / "x.png"
    cases = [(str(text_file), f"cannot load GLSANDBOX_OSMESA={text_file}")]
    if libc:
        cases.append((libc, f"GLSANDBOX_OSMESA={libc} is not an OSMesa library (it has no OSMesaCreateContextAttribs)"))
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.so")  # the dynamic loader would block reading it
        cases.append((str(tmp_path / "pipe.so"), "is not a regular file"))
    for value, fragment in cases:
        proc = glsandbox("render", "triangle", "--backend", "osmesa", "--out", str(out),
                         env={"GLSANDBOX_OSMESA": value})
        assert_user_error(proc, "OSMesa backend unavailable", fragment)
    assert not out.exists()


def _display_without_a_server() -> str:
    """A display number no X server listens on here (a fixed one may be another program's Xvfb)."""
    return next(f":{n}" for n in range(77, 200) if not Path(f"/tmp/.X11-unix/X{n}").exists()
                and not Path(f"/tmp/.X{n}-lock").exists())


def test_a_display_with_no_server_is_exactly_one_line() -> None:
    # pyGLFW printed a GLFWError warning (two lines) before the error.
    display = _display_without_a_server()
    proc = glsandbox("run", "indexed_cube", env={"DISPLAY": display, "WAYLAND_DISPLAY": ""})
    assert_user_error(proc, f"'{display}'")
    assert "GLFWError" not in proc.stderr and "warn" not in proc.stderr


@pytest.mark.slow  # several subprocesses: the process is the point
def test_no_display_errors_offer_what_the_command_can_do() -> None:
    env = {"DISPLAY": "", "WAYLAND_DISPLAY": ""}
    # render is headless already: it suggests a headless backend, not --headless.
    proc = glsandbox("render", "indexed_cube", "--backend", "window", "--out", "x.png", env=env)
    assert_user_error(proc, "no display", "--backend egl")
    assert "--headless" not in proc.stderr
    # run has no --headless either: it suggests glsandbox render.
    proc = glsandbox("run", "indexed_cube", "--backend", "egl", env=env)
    assert_user_error(proc, "glsandbox render indexed_cube --out FILE.png")
    assert "--headless" not in proc.stderr
    # A lesson module has --headless.
    proc = subprocess.run([sys.executable, "-m", "glsandbox.lessons.triangle"], capture_output=True, text=True, cwd=REPO,
                          env={**os.environ, **env}, timeout=60)
    assert_user_error(proc, "python -m glsandbox.lessons.triangle --headless --out FILE.png")
