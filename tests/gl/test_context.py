"""EGL and OSMesa give the same pixels for every lesson."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import backend_available, need

from glsandbox.files import load_png
from glsandbox.lesson import all_lessons

pytestmark = pytest.mark.slow  # every lesson on both backends, in subprocesses

LESSONS = [cls.name for cls in all_lessons()]


@pytest.fixture(scope="module")
def headless_backends() -> None:
    for name in ("egl", "osmesa"):
        reason = backend_available(name)
        if reason:
            need(f"the {name} backend", reason)


def render_with(backend: str, lesson: str, out: Path) -> np.ndarray:
    proc = subprocess.run(
        [sys.executable, "-m", "glsandbox.cli", "render", lesson, "--backend", backend, "--size", "160x120",
         "--set", "time=0.7", "--out", str(out)],
        capture_output=True, text=True, timeout=180, env=os.environ.copy())
    assert proc.returncode == 0, proc.stderr
    return load_png(out)


@pytest.mark.parametrize("lesson", LESSONS)
def test_egl_and_osmesa_agree(headless_backends, tmp_path: Path, lesson: str) -> None:
    egl = render_with("egl", lesson, tmp_path / "egl.png")
    osmesa = render_with("osmesa", lesson, tmp_path / "osmesa.png")
    np.testing.assert_array_equal(egl, osmesa)
