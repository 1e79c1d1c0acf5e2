"""The ray_camera lesson (course "Bakış noktası, görüntü düzlemi GD(x,y)": a primary ray per pixel): its golden."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden


def test_golden(gl, golden):
    image = check_lesson_golden(gl, golden, "ray_camera")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
