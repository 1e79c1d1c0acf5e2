"""The ray_triangle lesson (course "Işın-Üçgen kesim testi"): its figures and its golden."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden


def test_triangle_figures():
    from glsandbox.lessons.ray_triangle import panels

    triangle = "\n".join(panels(False)[1])
    assert "D = 72; ray (0,0,1): t = 90, triangle: miss" in triangle
    assert "all six agree on 4800 rays: yes" in triangle


def test_golden(gl, golden):
    image = check_lesson_golden(gl, golden, "ray_triangle")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear


def test_the_lessons_vectorised_row_ranks_the_tests_as_the_tradeoffs_report_does():
    """``timing=on``'s vectorised costs and the report's ``triangle_test`` times, taken in turn in
    one run (the load hits both alike): Möller–Trumbore over watertight is the same ratio in
    both within their noise, since both time the same scans on the same rays. A ratio, no
    wall-clock limit."""
    import statistics

    from glsandbox.lessons import ray_triangle
    from glsandbox.measure.knobs import triangle_test
    from glsandbox.measure.tradeoffs import time_pass

    class Context:  # what a knob's render reads of the report's render context
        size = ray_triangle.TIMING_SIZE

    settings = {s.label: s for s in (*triangle_test.KNOB.settings, triangle_test.KNOB.reference)}
    mt, wt = settings["Möller–Trumbore float64, at 0"], settings["watertight float64, at 0"]
    renders = [lambda: mt.render(Context()), lambda: wt.render(Context())]
    lesson, report = [], []
    for _ in range(3):  # in turn, three times: the medians of each side's ratios are compared
        times = time_pass(renders, rounds=5)
        report.append(statistics.median(times[0]) / statistics.median(times[1]))
        costs, rays, triangles = ray_triangle.vectorised_costs(rounds=5)
        lesson.append(costs["moller_trumbore"] / costs["watertight"])
    assert (rays, triangles) == (64 * 48, 80)
    ratio_lesson, ratio_report = statistics.median(lesson), statistics.median(report)
    assert 1 / 1.6 < ratio_lesson / ratio_report < 1.6, (lesson, report)
    rows = ray_triangle.panels(True)[1]
    assert any(row.startswith("ns per vectorised test (3072 rays x 80 triangles, as tradeoffs)") for row in rows)
