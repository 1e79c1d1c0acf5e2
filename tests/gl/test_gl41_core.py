"""Everything stays within what macOS gives: Mesa forced to a 4.1 core profile runs the tour and the goldens.

macOS's OpenGL stops at 4.1 core (no compute shaders, no GL_ARB_clip_control
in core, no debug output). Mesa can pretend to be it: with these two
variables its EGL and OSMesa contexts report 4.1 and GLSL 4.10, and refuse
what 4.1 does not have.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT as REPO

MACOS_GL = {"MESA_GL_VERSION_OVERRIDE": "4.1", "MESA_GLSL_VERSION_OVERRIDE": "410"}

#: Run pytest on exactly the tests that compare with a golden image (wherever they live).
GOLDENS_ONLY = """
import sys, pytest
from pathlib import Path

class GoldensOnly:
    def pytest_collection_modifyitems(self, config, items):
        kept = [item for item in items if "golden" in getattr(item, "fixturenames", ())]
        config.hook.pytest_deselected(items=[item for item in items if item not in kept])
        items[:] = kept
        print(f"golden tests: {len(kept)}", flush=True)

# Only the files that name the fixture are collected (collecting all of them took longer than
# running their goldens). -n 0: in this process, where the plugin is (pyproject's -n auto would
# start workers without it, each running the whole suite, this test again included).
files = sorted(str(p) for p in Path("tests").rglob("test_*.py") if "golden" in p.read_text(encoding="utf-8"))
sys.exit(pytest.main([*files, "-n", "0", "-q", "-p", "no:cacheprovider", "-x"], plugins=[GoldensOnly()]))
"""


def run(*args: str, timeout: int) -> subprocess.CompletedProcess:
    env = {**os.environ, **MACOS_GL}
    env.pop("GLSANDBOX_BACKEND", None)
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=timeout, env=env,
                          cwd=REPO)


@pytest.mark.slow
def test_mesa_gives_a_41_core_context(gl) -> None:
    code = ("from glsandbox.gl.context import open_context; h = open_context(); "
            "print(h.ctx.version_code, h.ctx.info['GL_VERSION'])")
    proc = run("-c", code, timeout=120)
    assert proc.returncode == 0, proc.stderr
    version, rest = proc.stdout.strip().split(" ", 1)
    assert version == "410" and rest.startswith("4.1 (Core Profile)")


@pytest.mark.slow
def test_the_tour_runs_on_41_core(gl, tmp_path) -> None:
    proc = run("-m", "glsandbox", "tour", "--out", str(tmp_path), "--size", "96x64", timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "FAILED" not in proc.stderr
    assert len(list(tmp_path.glob("*.png"))) >= 14


@pytest.mark.slow
def test_the_goldens_pass_on_41_core(gl) -> None:
    proc = run("-c", GOLDENS_ONLY, timeout=900)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    count = int(proc.stdout.split("golden tests: ", 1)[1].split()[0])
    assert count >= 30  # every golden test ran (38 call sites when this was written)
    assert " passed" in proc.stdout and " failed" not in proc.stdout
