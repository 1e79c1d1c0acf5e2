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
