"""Verdicts that hold on any machine: a reference's margin, written by ``check --update``, lets the
pixels near a decision differ, and the right answer passes on every llvmpipe set-up while every
wrong one still fails."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from support import REPO_ROOT, glsandbox

pytestmark = pytest.mark.slow

SIZE = "160x120"
MODEL = REPO_ROOT / "lessons" / "phong.py"
#: Wrong answers, each one edit of the model answer, some of them subtle (a few levels, a degree).
WRONG = {
    "w_color": ("(1.0, 0.25, 0.2, 1.0)", "(1.0, 0.25, 0.23, 1.0)"),
    "w_diffuse": ("0.1, 0.4, 0.3, 32.0", "0.1, 0.42, 0.3, 32.0"),
    "w_shininess": ("0.1, 0.4, 0.3, 32.0", "0.1, 0.4, 0.3, 28.0"),
    "w_scale": ("ELLIPSOID_SCALE = (1.8, 0.7, 0.9)", "ELLIPSOID_SCALE = (1.8, 0.72, 0.9)"),
    "w_turn": ("math.radians(30)", "math.radians(31)"),
}
#: The same llvmpipe set up as other machines have it: each variable read when a context opens.
VARIANTS = {
    "egl": {"GLSANDBOX_BACKEND": "egl"},
    "osmesa": {"GLSANDBOX_BACKEND": "osmesa"},
    "threads_0": {"LP_NUM_THREADS": "0"},
    "threads_2": {"LP_NUM_THREADS": "2"},
    "vector_128": {"LP_NATIVE_VECTOR_WIDTH": "128"},  # llvmpipe as on a CPU without AVX
    "core_4_1": {"MESA_GL_VERSION_OVERRIDE": "4.1", "MESA_GLSL_VERSION_OVERRIDE": "410"},  # macOS's profile
}

#: Renders each submission in a plain process (no warm template, whose context has no threads),
#: judges it with the reference's margin, and says what the context was.
JUDGE = r"""
import json, os, sys
from pathlib import Path
from glsandbox.files import load_png
from glsandbox.frame import HeadlessRenderer
from glsandbox.lesson import submission_lesson
from glsandbox.measure.golden import compare_images
from glsandbox.measure.margin import read_margin
ref = Path(sys.argv[1]); expected = load_png(ref); margin = read_margin(ref, expected.shape)
out = {}
with HeadlessRenderer() as r:
    for path in sys.argv[2:]:
        image = r.render(submission_lesson(Path(path))(), (expected.shape[1], expected.shape[0])).image
        out[Path(path).stem] = compare_images(image, expected, margin=margin).passed
    threads = [open(f"/proc/self/task/{t}/comm").read().strip() for t in os.listdir("/proc/self/task")]
    out["context"] = {"version": r.host.ctx.info["GL_VERSION"], "renderer": r.host.ctx.info["GL_RENDERER"],
                      "backend": r.host.backend, "rasterizer_threads": sum(t.startswith("llvmpipe") for t in threads)}
print(json.dumps(out))
"""


def outcomes(stdout: str) -> dict[str, str]:
    return dict((m.group(2), m.group(1)) for m in re.finditer(r"\[\d+/\d+\] (PASS|FAIL|BROKEN) +(.*?): ", stdout))


@pytest.fixture(scope="module")
def graded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A class folder (the model answer as ``a_good`` and :data:`WRONG`), and the reference
    written from the model answer by ``check --update`` at the default set-up."""
    pytest.importorskip("moderngl")
    folder = tmp_path_factory.mktemp("margins")
    subs = folder / "subs"
    subs.mkdir()
    source = MODEL.read_text()
    (subs / "a_good.py").write_text(source)
    for name, (old, new) in WRONG.items():
        assert source.count(old) == 1, name
        (subs / f"{name}.py").write_text(source.replace(old, new))
    ref = folder / "ref.png"
    proc = glsandbox("check", str(subs / "a_good.py"), "--golden", str(ref), "--update", "--size", SIZE)
    if proc.returncode != 0 and "no OpenGL" in proc.stderr:
        from support import need

        need("headless OpenGL", proc.stderr.strip())
    assert proc.returncode == 0, proc.stderr
    assert f"wrote margin {folder / 'ref.margin.png'} (" in proc.stdout
    return subs, ref


def test_update_writes_the_margin_beside_the_reference(graded: tuple[Path, Path]) -> None:
    subs, ref = graded
    margin_file = ref.with_name("ref.margin.png")
    with Image.open(margin_file) as image:
        assert image.mode == "L" and image.size == (160, 120)
        margin = np.asarray(image)
    share = np.count_nonzero(margin) / margin.size
    assert 0.005 < share < 0.05, share  # the silhouettes, the horizon, the highlights: a thin share
    assert f"({share:.2%} of its pixels near a decision may differ)" in glsandbox(
        "check", str(subs / "a_good.py"), "--golden", str(ref), "--update").stdout
    # a passing reference is kept byte for byte, and its margin comes out the same again
    assert np.array_equal(np.asarray(Image.open(margin_file)), margin)


def test_the_grader_passes_the_right_answer_and_fails_every_wrong_one(graded: tuple[Path, Path], backend: str) -> None:
    subs, ref = graded
    proc = glsandbox("check", str(subs), "--golden", str(ref), "--backend", backend)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert outcomes(proc.stdout) == {"a_good": "PASS", **{name: "FAIL" for name in WRONG}}, proc.stdout
    assert "differing inside the reference's margin" in proc.stdout  # the margin took part


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_verdicts_hold_under_each_llvmpipe_set_up(graded: tuple[Path, Path], variant: str) -> None:
    subs, ref = graded
    env = VARIANTS[variant]
    if env.get("GLSANDBOX_BACKEND") == "osmesa":
        from support import backend_available, need

        reason = backend_available("osmesa")
        if reason:
            need("the osmesa backend", reason)
    files = [str(subs / "a_good.py"), *(str(subs / f"{name}.py") for name in WRONG)]
    proc = subprocess.run([sys.executable, "-c", JUDGE, str(ref), *files], capture_output=True, text=True,
                          env={**__import__("os").environ, **env}, timeout=300, cwd=REPO_ROOT)
    assert proc.returncode == 0, proc.stderr
    verdicts = json.loads(proc.stdout.strip().splitlines()[-1])
    context = verdicts.pop("context")
    assert verdicts == {"a_good": True, **{name: False for name in WRONG}}, (variant, context)
    # the set-up asked for is the one that drew
    checks = {"egl": context["backend"] == "egl", "osmesa": context["backend"] == "osmesa",
              "threads_0": context["rasterizer_threads"] == 0, "threads_2": context["rasterizer_threads"] == 2,
              "vector_128": "128 bits" in context["renderer"], "core_4_1": context["version"].startswith("4.1 (Core")}
    assert checks[variant], context
