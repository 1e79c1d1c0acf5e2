"""Image error metrics.

All functions take two images of the same shape, ``(H, W, C)`` or ``(H, W)``,
either ``uint8`` (levels 0..255) or floating point (0..1).

Scales:

* :func:`rmse` and :func:`psnr` always work on the 0..1 scale: ``uint8`` inputs
  are divided by 255 first, so a ``uint8`` image and its float copy give the
  same figures.
* :func:`max_abs_diff` and :func:`mismatch_share` work in the images' own unit
  when both are ``uint8`` (whole levels, exact integer arithmetic); as soon as
  one of them is floating point both are compared on the 0..1 scale.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["max_abs_diff", "mismatch_share", "psnr", "rmse"]

ImageArray = npt.NDArray[np.generic]


def _check_pair(a: ImageArray, b: ImageArray) -> tuple[np.ndarray, np.ndarray]:
    """Validate dtypes and shapes; return the two arrays as ndarrays."""
    a = np.asarray(a)
    b = np.asarray(b)
    for name, img in (("a", a), ("b", b)):
        if not (img.dtype == np.uint8 or np.issubdtype(img.dtype, np.floating)):
            raise TypeError(
                f"image {name} has dtype {img.dtype}; expected uint8 or floating point"
            )
        if img.ndim not in (2, 3):
            raise ValueError(f"image {name} has shape {img.shape}; expected (H, W) or (H, W, C)")
    if a.shape != b.shape:
        raise ValueError(f"image shapes differ: {a.shape} vs {b.shape}")
    return a, b


def _unit(img: np.ndarray) -> np.ndarray:
    """The image as float64 on the 0..1 scale."""
    if img.dtype == np.uint8:
        return img.astype(np.float64) / 255.0
    return img.astype(np.float64)


def _abs_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per-element absolute difference in the pair's common unit (see module doc)."""
    if a.dtype == np.uint8 and b.dtype == np.uint8:
        return np.abs(a.astype(np.int16) - b.astype(np.int16))
    return np.abs(_unit(a) - _unit(b))


def max_abs_diff(a: ImageArray, b: ImageArray) -> int | float:
    """Largest absolute difference of any channel of any pixel.

    Returns an ``int`` in levels (0..255) when both images are ``uint8``,
    otherwise a ``float`` on the 0..1 scale. Empty images give 0.
    """
    a, b = _check_pair(a, b)
    diff = _abs_diff(a, b)
    if diff.size == 0:
        return 0 if diff.dtype.kind == "i" else 0.0
    peak = diff.max()
    return int(peak) if diff.dtype.kind == "i" else float(peak)


def rmse(a: ImageArray, b: ImageArray) -> float:
    """Root mean square error over all channels, on the 0..1 scale.

    A uniform difference of 51 levels in ``uint8`` images gives ``51/255 = 0.2``.
    Empty images give 0.0.
    """
    a, b = _check_pair(a, b)
    if a.size == 0:
        return 0.0
    d = _unit(a) - _unit(b)
    return float(np.sqrt(np.mean(d * d)))


def psnr(a: ImageArray, b: ImageArray) -> float:
    """Peak signal-to-noise ratio in dB with peak 1.0 (255 levels for ``uint8``).

    ``PSNR = 20 * log10(1 / RMSE)``; identical images give ``math.inf``.
    An RMSE of 0.1 is 20 dB, 0.01 is 40 dB.
    """
    err = rmse(a, b)
    if err == 0.0:
        return math.inf
    return 20.0 * math.log10(1.0 / err)


def mismatch_share(a: ImageArray, b: ImageArray, threshold: float = 0) -> float:
    """Share (0..1) of pixels whose largest channel difference exceeds ``threshold``.

    ``threshold`` is in levels for two ``uint8`` images, otherwise on the
    0..1 scale. A pixel is a mismatch when ``max_c |a - b| > threshold``, so
    the default 0 counts every pixel that differs at all. For 2-D images each
    element is a pixel. Empty images give 0.0.
    """
    a, b = _check_pair(a, b)
    diff = _abs_diff(a, b)
    per_pixel = diff.max(axis=-1) if diff.ndim == 3 and diff.shape[-1] > 0 else diff
    if per_pixel.size == 0:
        return 0.0
    return float(np.count_nonzero(per_pixel > threshold)) / per_pixel.size
