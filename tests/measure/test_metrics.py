"""Image error metrics on known values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from glsandbox.measure.metrics import max_abs_diff, mismatch_share, psnr, rmse


def grey(level: int, shape: tuple[int, ...] = (8, 8, 4)) -> np.ndarray:
    return np.full(shape, level, dtype=np.uint8)


def test_identical_images() -> None:
    a = np.arange(8 * 8 * 4, dtype=np.uint8).reshape(8, 8, 4)
    assert max_abs_diff(a, a) == 0
    assert rmse(a, a) == 0.0
    assert psnr(a, a) == math.inf
    assert mismatch_share(a, a) == 0.0


def test_uniform_difference_of_51_levels() -> None:
    a, b = grey(100), grey(151)
    assert max_abs_diff(a, b) == 51
    assert isinstance(max_abs_diff(a, b), int)
    assert rmse(a, b) == pytest.approx(0.2)
    # 20 * log10(1 / 0.2) = 20 * log10(5)
    assert psnr(a, b) == pytest.approx(13.979400, abs=1e-6)
    assert mismatch_share(a, b) == 1.0
    assert mismatch_share(a, b, threshold=51) == 0.0


def test_metrics_are_symmetric_and_uint8_does_not_wrap() -> None:
    a, b = grey(0), grey(255)
    assert max_abs_diff(a, b) == max_abs_diff(b, a) == 255
    assert rmse(a, b) == pytest.approx(1.0)
    assert psnr(a, b) == pytest.approx(0.0)


def test_float_images_use_the_unit_scale() -> None:
    a = np.zeros((4, 4, 3), dtype=np.float32)
    b = np.full((4, 4, 3), 0.1, dtype=np.float32)
    assert rmse(a, b) == pytest.approx(0.1, rel=1e-6)
    assert psnr(a, b) == pytest.approx(20.0, rel=1e-6)
    assert max_abs_diff(a, b) == pytest.approx(0.1, rel=1e-6)
    assert mismatch_share(a, b, threshold=0.05) == 1.0
    assert mismatch_share(a, b, threshold=0.2) == 0.0


def test_uint8_and_its_float_copy_give_the_same_rmse() -> None:
    rng = np.random.default_rng(1)
    a = rng.integers(0, 256, (16, 16, 4), dtype=np.uint8)
    b = rng.integers(0, 256, (16, 16, 4), dtype=np.uint8)
    assert rmse(a, b) == pytest.approx(rmse(a.astype(np.float64) / 255, b))
    assert max_abs_diff(a, b.astype(np.float64) / 255) == pytest.approx(max_abs_diff(a, b) / 255)


def test_rmse_of_a_partial_difference() -> None:
    # One channel of one pixel of 4 off by 255: mean square 1/16 -> RMSE 0.25.
    a = grey(0, (2, 2, 4))
    b = a.copy()
    b[1, 0, 2] = 255
    assert rmse(a, b) == pytest.approx(0.25)
    assert psnr(a, b) == pytest.approx(20 * math.log10(4))


def test_mismatch_share_counts_pixels_not_channels() -> None:
    a = grey(10, (10, 10, 4))
    b = a.copy()
    b[0, 0, :] = 20  # every channel of one pixel
    b[5, 5, 3] = 13  # one channel of another, by 3 levels
    assert mismatch_share(a, b) == pytest.approx(2 / 100)
    assert mismatch_share(a, b, threshold=3) == pytest.approx(1 / 100)
    assert mismatch_share(a, b, threshold=10) == 0.0


def test_two_dimensional_images() -> None:
    a = np.zeros((4, 5), dtype=np.uint8)
    b = a.copy()
    b[0, :] = 255
    assert mismatch_share(a, b) == pytest.approx(5 / 20)
    assert rmse(a, b) == pytest.approx(math.sqrt(5 / 20))


def test_shape_mismatch_is_an_error() -> None:
    with pytest.raises(ValueError, match="shapes differ"):
        rmse(grey(0, (4, 4, 4)), grey(0, (4, 5, 4)))


def test_unsupported_dtype_is_an_error() -> None:
    with pytest.raises(TypeError, match="int32"):
        max_abs_diff(np.zeros((2, 2, 4), np.int32), grey(0, (2, 2, 4)))
