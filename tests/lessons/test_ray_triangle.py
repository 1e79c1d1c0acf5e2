"""The ray_triangle lesson (course "Işın-Üçgen kesim testi"): its figures and its golden."""

from __future__ import annotations

import pytest

import numpy as np
from support import check_lesson_golden


def test_triangle_figures():
    from lessons.ray_triangle import panels

    triangle = "\n".join(panels(False)[1])
    assert "D = 72; ray (0,0,1): t = 90, triangle: miss" in triangle
    assert "all six agree on 4800 rays: yes" in triangle


def test_golden(gl, golden):
    image = check_lesson_golden(gl, golden, "ray_triangle")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear


@pytest.mark.slow
def test_the_lessons_timing_rows_agree_with_the_tradeoffs_report_on_mt_against_watertight() -> None:
    """``ray_triangle --set timing=on`` and ``glsandbox tradeoffs`` tell the same story: the
    ratio Möller–Trumbore / watertight from the lesson's vectorised row and from the report's
    own frames (its ``triangle_test`` knob), measured in one run, interleaved, best of 3."""
    import time

    from glsandbox.measure.knobs.triangle_test import frame
    from lessons.ray_triangle import TIMING_SIZE, vectorised_costs

    lesson, report = [], []
    for _ in range(3):
        costs, _, _ = vectorised_costs(rounds=1)
        lesson.append(costs["moller_trumbore"] / costs["watertight"])
        seconds = {}
        for test in ("mt64", "watertight"):
            start = time.perf_counter()
            frame(test, 0.0, TIMING_SIZE)
            seconds[test] = time.perf_counter() - start
        report.append(seconds["mt64"] / seconds["watertight"])
    a, b = sorted(lesson)[1], sorted(report)[1]  # the medians
    assert 1 / 1.6 < a / b < 1.6, (lesson, report)
