"""What the package says about itself: metadata, extras, version, entry points, and where lessons come from."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from email.parser import Parser
from pathlib import Path

import pytest
from support import REPO_ROOT as REPO
from support import STUDENT_LESSONS_CHECK, student_lessons_folder

import glsandbox
from glsandbox import cli



@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> zipfile.ZipFile:
    uv = shutil.which("uv")
    if uv is None:
        pytest.fail("uv is not on PATH (the README's set-up installs it)")
    dist = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([uv, "build", "--wheel", "--out-dir", str(dist), str(REPO)], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return zipfile.ZipFile(next(dist.glob("glsandbox-*.whl")))


def metadata(wheel: zipfile.ZipFile):
    name = next(n for n in wheel.namelist() if n.endswith(".dist-info/METADATA"))
    return Parser().parsestr(wheel.read(name).decode())


def ci_pythons() -> list[str]:
    """The Python versions .ci/run tests (its PYTHONS line)."""
    match = re.search(r'^PYTHONS="([^"]+)"', (REPO / ".ci" / "run").read_text(), re.MULTILINE)
    assert match, ".ci/run has no PYTHONS line"
    return match.group(1).split()


@pytest.mark.slow
def test_the_wheel_carries_license_types_and_honest_metadata(wheel) -> None:
    names = wheel.namelist()
    assert "glsandbox/py.typed" in names  # mypy reads glsandbox's hints in a student's lesson
    assert any(n.endswith(".dist-info/licenses/LICENSE") or n.endswith(".dist-info/LICENSE") for n in names)
    meta = metadata(wheel)
    assert meta["Version"] == glsandbox.__version__
    requires = meta.get_all("Requires-Dist")
    imgui = [r for r in requires if r.startswith("imgui-bundle")]
    assert imgui and all(re.search(r"extra == ['\"]panel['\"]", r) for r in imgui)  # never required
    assert "panel" in meta.get_all("Provides-Extra")
    classifiers = meta.get_all("Classifier")
    claimed = sorted(c.rsplit(" :: ", 1)[1] for c in classifiers
                     if re.fullmatch(r"Programming Language :: Python :: 3\.\d+", c))
    assert claimed == sorted(ci_pythons())  # the classifiers claim what CI tests
    for system in ("POSIX :: Linux", "Microsoft :: Windows", "MacOS"):
        assert f"Operating System :: {system}" in classifiers
    assert "License :: OSI Approved :: MIT License" in classifiers
    assert any(c.startswith("Topic :: Multimedia :: Graphics") for c in classifiers)


def test_the_license_is_mit_and_the_changelog_names_this_version() -> None:
    assert (REPO / "LICENSE").read_text().startswith("MIT License")
    assert (REPO / "glsandbox" / "py.typed").is_file()
    changelog = (REPO / "CHANGELOG.md").read_text()
    assert "## Unreleased" in changelog or f"## {glsandbox.__version__}" in changelog
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert "version" in project["dynamic"]  # one place: glsandbox.__version__


def test_version_prints_and_exits_0(capsys) -> None:
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out == f"glsandbox {glsandbox.__version__}\n"


def test_python_dash_m_glsandbox_is_the_command(tmp_path) -> None:
    proc = subprocess.run([sys.executable, "-m", "glsandbox", "--version"], capture_output=True, text=True,
                          cwd=tmp_path, timeout=60)
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, f"glsandbox {glsandbox.__version__}\n", "")


def test_a_users_lessons_folder_and_the_courses_lessons_neither_hide_the_other(tmp_path) -> None:
    folder = student_lessons_folder(tmp_path)
    # python -m puts the working directory first on sys.path, as Jupyter does.
    listed = subprocess.run([sys.executable, "-m", "glsandbox", "list"], capture_output=True, text=True,
                            cwd=folder, timeout=120)
    assert listed.returncode == 0, listed.stderr
    assert listed.stdout.split("\n")[2].startswith("indexed_cube")
    for order in ("theirs first", "course first"):
        proc = subprocess.run([sys.executable, "-c", STUDENT_LESSONS_CHECK, order], capture_output=True, text=True,
                              cwd=folder, timeout=120)
        assert proc.returncode == 0, proc.stderr
        theirs, course, module = proc.stdout.split()
        assert Path(theirs) == folder / "lessons" / "__init__.py", order  # the user's own package
        assert Path(course).parent == REPO / "lessons" and module == "glsandbox.lessons.indexed_cube", order


def test_the_lessons_still_run_as_modules_of_the_repository() -> None:
    proc = subprocess.run([sys.executable, "-m", "glsandbox.lessons.triangle", "--help"], capture_output=True, text=True,
                          cwd=REPO, timeout=60)
    assert proc.returncode == 0 and "--headless" in proc.stdout


def test_pyrrs_escape_sequence_warning_never_reaches_the_student(tmp_path) -> None:
    # A fresh bytecode cache: pyrr is compiled from source, as on the first import after install.
    strict = [sys.executable, "-X", f"pycache_prefix={tmp_path}", "-W", "error::SyntaxWarning",
              "-W", "error::DeprecationWarning", "-c"]
    plain_pyrr = subprocess.run([*strict, "import pyrr"], capture_output=True, text=True, timeout=120)
    assert plain_pyrr.returncode != 0 and "invalid escape sequence" in plain_pyrr.stderr  # the warning is real
    shutil.rmtree(tmp_path)
    ours = subprocess.run([*strict, "import glsandbox.transforms"], capture_output=True, text=True, timeout=120)
    assert (ours.returncode, ours.stderr) == (0, "")
