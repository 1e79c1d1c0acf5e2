"""The manual's tutorial code runs as written (docs/your-own.md, docs/how-it-works.md)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT as ROOT

from glsandbox.files import load_png


def test_the_readme_lesson_of_your_own_renders(tmp_path: Path, gl) -> None:
    text = (ROOT / "docs" / "how-it-works.md").read_text(encoding="utf-8")
    code = re.search(r"A lesson of your own is a Lesson subclass:\n\n```python\n(.*?)```", text, re.S).group(1)
    script = tmp_path / "spin.py"
    script.write_text(code, encoding="utf-8")
    out = tmp_path / "spin.png"
    proc = subprocess.run([sys.executable, str(script), "--headless", "--out", str(out), "--size", "64x48",
                           "--set", "time=0.5"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    image = load_png(out)
    assert image.shape == (48, 64, 4)
    assert (image[24, 32, :3] > 200).all()  # the white cube in the middle of the course's blue


def tutorial_section() -> str:
    text = (ROOT / "docs" / "your-own.md").read_text(encoding="utf-8")
    return re.search(r"## Your own lesson, step by step\n(.*?)\n## ", text, re.S).group(1)


@pytest.mark.slow
def test_the_readme_tutorial_works_step_by_step(tmp_path: Path, gl) -> None:
    """Every command of "Your own lesson, step by step", as written, in a fresh folder
    (``uv run glsandbox`` / ``uv run pytest`` become this interpreter's ``-m glsandbox.cli`` /
    ``-m pytest``; ``glsandbox run`` opens a window and is only looked up, not run)."""
    import shlex

    section = tutorial_section()
    commands = [line.split(" #")[0].strip() for block in re.findall(r"```sh\n(.*?)```", section, re.S)
                for line in block.splitlines() if line.strip()]
    (test_code,) = re.findall(r"```python\n(.*?)```", section, re.S)
    assert "test_my_lesson.py" in section
    cwd = tmp_path
    ran = []
    for command in commands:
        for part in command.split(" && "):
            words = shlex.split(part)
            if words[:2] == ["mkdir", "-p"]:
                (cwd / words[2]).mkdir(parents=True, exist_ok=True)
                continue
            if words[0] == "cd":
                cwd = cwd / words[1]
                continue
            assert words[:2] == ["uv", "run"], part
            if words[2:4] == ["glsandbox", "run"]:  # a window
                assert (cwd / words[4]).is_file()
                continue
            if words[2] == "glsandbox":
                args = [sys.executable, "-m", "glsandbox.cli", *words[3:]]
            else:
                assert words[2] == "pytest", part
                (cwd / "test_my_lesson.py").write_text(test_code, encoding="utf-8")
                args = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *words[3:]]
            proc = subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=300)
            assert proc.returncode == 0, f"{part}\n{proc.stdout}\n{proc.stderr}"
            ran.append(words[2:4])
    assert ["glsandbox", "new"] in ran and ["glsandbox", "check"] in ran and ["pytest", "test_my_lesson.py"] in ran
    mine = tmp_path / "mine"
    for picture in ("my_lesson.png", "my_scene.png", "compare_my_lesson_py.png", "goldens/my_lesson.png"):
        image = load_png(mine / picture)
        assert len({tuple(px) for px in image.reshape(-1, 4)[::7]}) > 20, picture  # a picture, not a clear colour
    assert "1 passed" in proc.stdout  # the fixture checked goldens/my_lesson.png


def test_the_readme_model_commands_run_as_written_from_the_repository(tmp_path: Path, gl) -> None:
    """Every ``glsandbox render model`` line of the README and docs/models.md, run from
    the repository's root (a fresh clone) with only ``--out`` moved and a small size:
    the model they name ships with the package."""
    import shlex

    from support import run_cli

    texts = (ROOT / "README.md").read_text(encoding="utf-8") + (ROOT / "docs" / "models.md").read_text(encoding="utf-8")
    commands = [line.split("#")[0].split() for line in texts.splitlines()
                if line.startswith("uv run glsandbox render model")]
    assert len(commands) >= 4
    for i, words in enumerate(commands):
        args = words[3:]
        if any("/path/to/" in a for a in args):
            continue
        out = args.index("--out")
        args[out + 1] = str(tmp_path / f"{i}.png")
        proc = run_cli(*args, "--size", "64x48", cwd=ROOT)
        assert proc.returncode == 0, (shlex.join(words), proc.stderr)
        assert load_png(tmp_path / f"{i}.png").shape == (48, 64, 4)
    assert any("mesh=glsandbox/models/boulder.obj" in " ".join(w) for w in commands)
