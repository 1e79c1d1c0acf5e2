"""The ray_spheres lesson (course "Işın-Küre kesim testi"): its figures and its golden."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden


def test_sphere_figures():
    from glsandbox.lessons.ray_spheres import figures

    spheres = "\n".join(figures())
    assert "s = 80, m^2 = 3600, q = 45" in spheres and "t = s - q = 35 (stable: 35), P = (0, 21, 28)" in spheres


def test_golden(gl, golden):
    image = check_lesson_golden(gl, golden, "ray_spheres")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
