"""The headless backends (glsandbox.gl.context): EGL and OSMesa give the same pixels for every
lesson, and a lesson's default picture is the same in every run.

One ``glsandbox tour`` per backend, each in its own process (OSMesa and EGL must not share
one), compared file by file with the same lesson rendered in this process: a picture that
depends on the run (a measured time drawn into a panel) differs between two processes even
on one backend.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from support import glsandbox

from glsandbox.files import load_png
from glsandbox.lesson import all_lessons, find_lesson

pytestmark = pytest.mark.slow  # every lesson on each backend, in subprocesses

LESSONS = [cls.name for cls in all_lessons()]
SIZE = (256, 256)  # large enough for every panel (ray_acceleration's rock line ends near row 210)


@pytest.fixture(scope="module")
def tour(backend: str, tmp_path_factory) -> dict[str, np.ndarray]:
    """Every lesson's picture from one ``glsandbox tour --backend BACKEND``, by lesson name."""
    out = tmp_path_factory.mktemp(f"tour_{backend}")
    proc = glsandbox("tour", "--backend", backend, "--size", f"{SIZE[0]}x{SIZE[1]}", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    entries = json.loads((out / "tour.json").read_text())["lessons"]
    return {entry["lesson"]: load_png(out / entry["image"]) for entry in entries}


def test_the_tour_has_every_lesson(tour) -> None:
    assert sorted(tour) == sorted(LESSONS)


@pytest.mark.parametrize("lesson", LESSONS)
def test_each_backend_in_another_run_gives_the_same_pixels(gl, tour, backend: str, lesson: str) -> None:
    here = gl.render(find_lesson(lesson)(), SIZE).image  # the tour renders each lesson's defaults
    np.testing.assert_array_equal(
        tour[lesson], here,
        err_msg=f"{lesson}: `tour --backend {backend}` against this process ({gl.host.backend})")
