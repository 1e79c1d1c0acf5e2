"""The built wheel carries the shaders and lessons: install it elsewhere and render."""

from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from support import REPO_ROOT as REPO
from support import STUDENT_LESSONS_CHECK, need, student_lessons_folder

from glsandbox.files import load_png

pytestmark = pytest.mark.slow  # builds a wheel and installs it in a fresh venv


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "GLSANDBOX_SHADER_DIR")}
    proc = subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, f"{' '.join(args)}\n{proc.stdout}\n{proc.stderr}"
    return proc


def venv_site(venv: Path) -> Path:
    """The site-packages folder of a fresh venv."""
    return next(venv.glob("lib/python3.*/site-packages")).resolve()


def test_wheel_installs_in_a_fresh_venv_and_renders_outside_the_repository(tmp_path: Path, gl) -> None:
    uv = shutil.which("uv")
    if uv is None:
        need("uv", "not on PATH")
    dist = tmp_path / "dist"
    run(uv, "build", "--wheel", "--out-dir", str(dist), str(REPO), cwd=tmp_path)
    wheel = next(dist.glob("glsandbox-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    assert "glsandbox/shaders/basic.glsl" in names and "glsandbox/shaders/common/transform.glsl" in names
    assert "glsandbox/lessons/indexed_cube.py" in names and not any(n.startswith("lessons/") for n in names)
    assert "glsandbox/templates/lesson.py.tmpl" in names and "glsandbox/templates/scene.toml.tmpl" in names
    entry_points = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith("entry_points.txt"))).decode()
    assert "[pytest11]" in entry_points and "glsandbox = glsandbox.pytest_plugin" in entry_points

    venv = tmp_path / "venv"
    run(uv, "venv", "--quiet", str(venv), cwd=tmp_path)
    python = venv / "bin" / "python"
    run(uv, "pip", "install", "--quiet", "--python", str(python), str(wheel), cwd=tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run(str(venv / "bin" / "glsandbox"), "render", "indexed_cube", "--size", "64x48", "--out", "cube.png",
        cwd=elsewhere)
    run(str(python), "-m", "glsandbox.lessons.triangle", "--headless", "--out", "tri.png", "--size", "64x48", cwd=elsewhere)
    assert load_png(elsewhere / "cube.png").shape == (48, 64, 4)
    # glsandbox new reads its templates from the installed package, and what it writes renders
    run(str(venv / "bin" / "glsandbox"), "new", "starter", cwd=elsewhere)
    run(str(venv / "bin" / "glsandbox"), "render", "starter.py", "--size", "64x48", "--out", "starter.png",
        cwd=elsewhere)
    assert load_png(elsewhere / "starter.png").shape == (48, 64, 4)
    assert load_png(elsewhere / "tri.png").shape == (48, 64, 4)
    # A user's own lessons/ package in the working directory and the installed course's lessons.
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    student_lessons_folder(theirs)
    run(str(venv / "bin" / "glsandbox"), "render", "indexed_cube", "--size", "64x48", "--out", "cube.png", cwd=theirs)
    for order in ("theirs first", "course first"):
        mine, course, module = run(str(python), "-c", STUDENT_LESSONS_CHECK, order, cwd=theirs).stdout.split()
        assert Path(mine) == theirs / "lessons" / "__init__.py"
        assert Path(course).parent == venv_site(venv) / "glsandbox" / "lessons" and module == "glsandbox.lessons.indexed_cube"
    # The installed copy found its own shaders, not the repository's.
    located = run(str(python), "-c", "from glsandbox.gl.shaders import shader_root; print(shader_root())",
                  cwd=elsewhere).stdout.strip()
    assert located.startswith(str(venv))
