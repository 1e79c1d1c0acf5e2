"""The ray_interactive lesson (the ray tracer at interactive resolution): its golden."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden


def test_golden(gl, golden):
    image = check_lesson_golden(gl, golden, "ray_interactive")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
