"""The README's code runs as written."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from glsandbox.files import load_png

ROOT = Path(__file__).resolve().parents[1]


def test_the_readme_lesson_of_your_own_renders(tmp_path: Path, gl) -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
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
