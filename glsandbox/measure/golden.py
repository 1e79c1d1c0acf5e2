"""Golden image comparison and diff artefacts.

The rule the tests use against ``tests/goldens/`` (docs/testing.md):

* Exact match passes.
* Otherwise a pixel is *bad* when its largest channel difference exceeds
  ``threshold`` **and** the 3x3 neighbourhood rule does not excuse it (below).
* The comparison fails when the share of bad pixels exceeds ``max_bad_share``.

Neighbourhood rule, and why it is checked in both directions
------------------------------------------------------------
A pixel that differs by more than ``threshold`` is excused only if

1. the *actual* pixel matches (within ``threshold``) some *expected* pixel in
   the 3x3 neighbourhood around the same position, **and**
2. the *expected* pixel matches some *actual* pixel in its 3x3 neighbourhood.

It is bad if either direction fails. One direction alone is blind to half
of the thin-feature errors: if a 1-pixel line of the golden is missing in the
render, every actual pixel on it is background, and background is found next
to it in the golden, so check 1 passes; only check 2 (the golden's line
colour is nowhere near in the render) catches it. Symmetrically, a spurious
1-pixel line in the render is caught only by check 1. A rasterisation edge
that moved by one pixel passes both checks: each side of the edge finds its
own colour one step away in the other image. The rule is therefore the
symmetric one, which is also what makes ``compare_images(a, b)`` and
``compare_images(b, a)`` count the same bad pixels.

At the image border the neighbourhood is clipped to the image (implemented
with edge padding, which only repeats pixels that are already in the
neighbourhood).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, replace
from pathlib import Path, PurePath

import numpy as np
import numpy.typing as npt

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.measure import metrics

__all__ = [
    "GoldenUpdateRefused",
    "GoldenUpdated",
    "ImageMatch",
    "check_golden",
    "compare_images",
    "write_artifacts",
]

DEFAULT_THRESHOLD = 2
"""Largest channel difference (in levels) that still counts as a match."""

DEFAULT_MAX_BAD_SHARE = 0.0005
"""Largest share of bad pixels that still passes (0.05 %, ~32 pixels of 256x256)."""

UPDATE_HINT = "run pytest --update-goldens"

_AMPLIFY = 10
_MAGENTA = np.array([255, 0, 255], dtype=np.uint8)


class GoldenUpdateRefused(SandboxError):
    """Raised when goldens would be rewritten while the ``CI`` variable is set.

    A :class:`~glsandbox.errors.SandboxError`: it is a user mistake, and it is
    deliberately not an ``AssertionError`` so it cannot pass for a failed check.
    """


class GoldenUpdated(UserWarning):
    """Emitted when :func:`check_golden` writes or rewrites a golden image."""


# --------------------------------------------------------------------------
# comparison
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class ImageMatch:
    """Outcome of comparing an actual image against an expected (golden) one.

    Attributes:
        passed: whether the comparison passes the tolerances.
        identical: every byte of the two images is equal.
        bad_pixels: pixels that fail the threshold and neighbourhood rule.
        total_pixels: pixels compared (of the expected image on a shape mismatch).
        bad_share: ``bad_pixels / total_pixels`` (1.0 on a shape mismatch).
        max_diff: largest channel difference in levels, 0..255 (255 on a
            shape mismatch).
        rmse: root mean square error on the 0..1 scale (NaN on a shape mismatch).
        threshold: the threshold used.
        max_bad_share: the allowed bad share used.
        actual_shape: shape of the actual array.
        expected_shape: shape of the expected array.
        updated: set by :func:`check_golden` when it (re)wrote the golden; the
            other figures then describe the image that was replaced.
        margin_pixels: pixels that differ by more than ``threshold`` where the
            reference's margin allows more (:mod:`glsandbox.measure.margin`).
        with_margin: whether a margin took part.
    """

    passed: bool
    identical: bool
    bad_pixels: int
    total_pixels: int
    bad_share: float
    max_diff: int
    rmse: float
    threshold: int = DEFAULT_THRESHOLD
    max_bad_share: float = DEFAULT_MAX_BAD_SHARE
    actual_shape: tuple[int, ...] = ()
    expected_shape: tuple[int, ...] = ()
    updated: bool = False
    margin_pixels: int = 0
    with_margin: bool = False

    @property
    def shape_mismatch(self) -> bool:
        """Whether the two images had different shapes."""
        return self.actual_shape != self.expected_shape

    @property
    def psnr(self) -> float:
        """PSNR in dB derived from :attr:`rmse` (inf when identical)."""
        if math.isnan(self.rmse):
            return math.nan
        if self.rmse == 0.0:
            return math.inf
        return 20.0 * math.log10(1.0 / self.rmse)

    def summary(self) -> str:
        """One line with the verdict and the figures."""
        verdict = "PASS" if self.passed else "FAIL"
        if self.shape_mismatch:
            return (
                f"{verdict}: shape mismatch: actual {_fmt_shape(self.actual_shape)}"
                f" vs expected {_fmt_shape(self.expected_shape)}"
            )
        if self.identical:
            return f"{verdict}: identical ({self.total_pixels} pixels)"
        inside = f" {self.margin_pixels} differing inside the reference's margin," if self.with_margin else ""
        return (
            f"{verdict}: {self.bad_pixels} bad of {self.total_pixels} pixels"
            f" ({self.bad_share:.4%}, allowed {self.max_bad_share:.4%}),"
            f" max channel diff {self.max_diff} (threshold {self.threshold}),{inside}"
            f" RMSE {self.rmse:.5f}, PSNR {self.psnr:.2f} dB"
        )


def _fmt_shape(shape: tuple[int, ...]) -> str:
    return "x".join(str(n) for n in shape) if shape else "()"


def _check_image(image: npt.ArrayLike, what: str) -> np.ndarray:
    """Return ``image`` as an ndarray after checking it is a uint8 (H, W, C) image."""
    arr = np.asarray(image)
    if arr.dtype != np.uint8:
        raise TypeError(f"{what} image has dtype {arr.dtype}; expected uint8")
    if arr.ndim != 3:
        raise ValueError(f"{what} image has shape {arr.shape}; expected (H, W, C)")
    return arr


def _close(x: np.ndarray, y: np.ndarray, threshold: int | np.ndarray) -> np.ndarray:
    """Whether every channel of ``x`` and ``y`` (uint8, channels last) is within ``threshold``.

    Returns a bool array with the channel axis dropped. ``max - min`` is
    ``|x - y|`` without leaving uint8. For RGBA the four per-channel booleans
    are read as one uint32, equal to 0x01010101 exactly when all are true,
    which is several times faster than a reduction over a length-4 axis.
    ``threshold`` is one number, or one per pixel (uint8, the shape of ``x``
    without its channel axis: a margin, :mod:`glsandbox.measure.margin`).
    """
    d = np.maximum(x, y)
    d -= np.minimum(x, y)
    ok = d <= (min(threshold, 255) if np.isscalar(threshold) else threshold[..., None])
    if ok.shape[-1] == 4:
        return ok.view(np.uint32)[..., 0] == 0x01010101
    return ok.all(axis=-1)


def _bad_mask(
    actual: np.ndarray, expected: np.ndarray, threshold: int, *, dense: bool | None = None,
    margin: np.ndarray | None = None,
) -> np.ndarray:
    """Boolean (H, W) mask of bad pixels for two same-shape uint8 (H, W, C) images.

    Only pixels whose direct difference exceeds the threshold are candidates.
    When they are few (the usual case for a near miss) the 3x3 neighbours of
    just those pixels are gathered; when they are many, whole shifted images
    are compared, which is cheaper per pixel. ``dense`` forces either path
    (for tests); both give the same mask. ``margin`` (uint8 (H, W)): each
    pixel's own threshold where it is larger (a pixel near a decision, in
    both the direct comparison and its neighbourhood's).
    """
    if margin is not None:
        threshold = np.maximum(margin, np.uint8(min(threshold, 255)))
    candidates = ~_close(actual, expected, threshold)
    n = int(np.count_nonzero(candidates))
    if n == 0:
        return candidates  # all False
    if dense is None:
        dense = n * 16 > candidates.size

    h, w = candidates.shape
    pad = ((1, 1), (1, 1), (0, 0))
    a_pad = np.pad(actual, pad, mode="edge")
    e_pad = np.pad(expected, pad, mode="edge")
    offsets = [(dy, dx) for dy in (0, 1, 2) for dx in (0, 1, 2)]  # -1..+1, padded

    if dense:
        a_found = np.zeros((h, w), dtype=bool)  # actual pixel found near in expected
        e_found = np.zeros((h, w), dtype=bool)  # expected pixel found near in actual
        for dy, dx in offsets:
            a_found |= _close(actual, e_pad[dy : dy + h, dx : dx + w], threshold)
            e_found |= _close(expected, a_pad[dy : dy + h, dx : dx + w], threshold)
        return candidates & ~(a_found & e_found)

    ys, xs = np.nonzero(candidates)
    a_px = actual[ys, xs]  # (n, C)
    e_px = expected[ys, xs]
    near = threshold if np.isscalar(threshold) else threshold[ys, xs]
    a_hit = np.zeros(n, dtype=bool)
    e_hit = np.zeros(n, dtype=bool)
    for dy, dx in offsets:
        a_hit |= _close(a_px, e_pad[ys + dy, xs + dx], near)
        e_hit |= _close(e_px, a_pad[ys + dy, xs + dx], near)
    bad = np.zeros_like(candidates)
    bad[ys, xs] = ~(a_hit & e_hit)
    return bad


def compare_images(
    actual: npt.ArrayLike,
    expected: npt.ArrayLike,
    *,
    threshold: int = DEFAULT_THRESHOLD,
    max_bad_share: float = DEFAULT_MAX_BAD_SHARE,
    margin: npt.ArrayLike | None = None,
) -> ImageMatch:
    """Compare two uint8 RGBA images of shape (H, W, 4) with the golden rule.

    Args:
        actual: the freshly rendered image.
        expected: the golden image.
        threshold: largest channel difference, in levels, that still matches.
        max_bad_share: largest share (0..1) of bad pixels that still passes;
            the comparison fails when ``bad_share > max_bad_share``.
        margin: the reference's margin (uint8, (H, W) of ``expected``;
            :mod:`glsandbox.measure.margin`): a pixel's own threshold where
            it is larger than ``threshold``.

    Returns:
        A :class:`ImageMatch`. Different shapes give ``passed=False`` with a
        summary naming both shapes.

    Raises:
        TypeError: an image is not uint8.
        ValueError: an image is not 3-D, or a tolerance is out of range.
    """
    a = _check_image(actual, "actual")
    e = _check_image(expected, "expected")
    if threshold < 0:
        raise ValueError(f"threshold must be >= 0, got {threshold}")
    if not 0.0 <= max_bad_share <= 1.0:
        raise ValueError(f"max_bad_share must be within 0..1, got {max_bad_share}")
    allowance = _check_margin(margin, e.shape)
    common = dict(
        threshold=int(threshold),
        max_bad_share=float(max_bad_share),
        actual_shape=tuple(a.shape),
        expected_shape=tuple(e.shape),
        with_margin=allowance is not None,
    )
    total = int(e.shape[0] * e.shape[1])

    if a.shape != e.shape:
        return ImageMatch(
            passed=False,
            identical=False,
            bad_pixels=total,
            total_pixels=total,
            bad_share=1.0,
            max_diff=255,
            rmse=math.nan,
            **common,
        )
    if np.array_equal(a, e):
        return ImageMatch(
            passed=True,
            identical=True,
            bad_pixels=0,
            total_pixels=total,
            bad_share=0.0,
            max_diff=0,
            rmse=0.0,
            **common,
        )

    bad = int(np.count_nonzero(_bad_mask(a, e, int(threshold), margin=allowance)))
    inside = 0
    if allowance is not None:
        inside = int(np.count_nonzero((allowance > threshold) & ~_close(a, e, int(threshold))))
    share = bad / total if total else 0.0
    return ImageMatch(
        passed=share <= max_bad_share,
        identical=False,
        bad_pixels=bad,
        total_pixels=total,
        bad_share=share,
        max_diff=int(metrics.max_abs_diff(a, e)),
        rmse=metrics.rmse(a, e),
        margin_pixels=inside,
        **common,
    )


def _check_margin(margin: npt.ArrayLike | None, shape: tuple[int, ...]) -> np.ndarray | None:
    """``margin`` as uint8 (H, W) of an image of ``shape``, or None."""
    if margin is None:
        return None
    m = np.asarray(margin)
    if m.dtype != np.uint8 or m.shape != tuple(shape[:2]):
        raise ValueError(f"margin has dtype {m.dtype} and shape {m.shape}; expected uint8 {tuple(shape[:2])}")
    return m


# --------------------------------------------------------------------------
# diff artefacts
# --------------------------------------------------------------------------


def _as_rgba(image: np.ndarray) -> np.ndarray:
    """uint8 (H, W, C) with C in 1, 3, 4 (or (H, W)) as (H, W, 4)."""
    if image.ndim == 2:
        image = image[:, :, None]
    h, w, c = image.shape
    if c == 4:
        return image
    out = np.full((h, w, 4), 255, dtype=np.uint8)
    if c in (1, 3):
        out[:, :, :3] = image  # grey broadcasts to R, G and B
    else:
        raise ValueError(f"cannot show an image with {c} channels")
    return out


def _diff_image(actual: np.ndarray, expected: np.ndarray, threshold: int,
                margin: np.ndarray | None = None) -> np.ndarray:
    """Opaque RGBA picture of where and how much two images differ.

    Background: the expected image as greyscale dimmed to 30 %. Over it, the
    per-channel difference times 10 (clamped; an alpha difference shows as
    grey), and bad pixels in solid magenta. Where the sizes differ, the part
    that only one image covers is magenta too.
    """
    a = _as_rgba(actual)
    e = _as_rgba(expected)
    h, w = max(a.shape[0], e.shape[0]), max(a.shape[1], e.shape[1])
    out = np.zeros((h, w, 4), dtype=np.uint8)
    out[:, :, :3] = _MAGENTA
    out[:, :, 3] = 255

    # overlapping region
    oh, ow = min(a.shape[0], e.shape[0]), min(a.shape[1], e.shape[1])
    a, e = a[:oh, :ow], e[:oh, :ow]
    rgb = e[:, :, :3].astype(np.float32)
    grey = rgb @ np.array([0.299, 0.587, 0.114], dtype=np.float32)  # Rec. 601 luma
    dim = np.rint(grey * 0.3).astype(np.int32)

    diff = np.abs(a.astype(np.int32) - e.astype(np.int32))
    amp = np.minimum(diff * _AMPLIFY, 255)
    amp_rgb = np.maximum(amp[:, :, :3], amp[:, :, 3:4])
    region = np.maximum(amp_rgb, dim[:, :, None]).astype(np.uint8)
    if oh and ow:
        region[_bad_mask(a, e, threshold, margin=margin if a.shape == e.shape else None)] = _MAGENTA
    out[:oh, :ow, :3] = region
    return out


def _check_name(name: str) -> None:
    p = PurePath(name)
    if not name or p.is_absolute() or ".." in p.parts:
        raise ValueError(f"bad artefact name {name!r}: use a relative name without '..'")


def write_artifacts(
    actual: npt.ArrayLike,
    expected: npt.ArrayLike,
    out_dir: str | os.PathLike[str],
    name: str,
    *,
    threshold: int = DEFAULT_THRESHOLD,
    margin: np.ndarray | None = None,
) -> dict[str, Path]:
    """Write ``<name>-actual.png``, ``<name>-expected.png`` and ``<name>-diff.png``.

    ``out_dir`` (and any folder inside ``name``, e.g. ``"lesson1/cube"``) is
    created. The diff image shows the expected image as a dimmed greyscale,
    differences amplified ten times, and bad pixels (same rule and
    ``threshold`` as :func:`compare_images`) in magenta. Images of different
    sizes are drawn over the overlapping area; the rest is magenta. ``margin``:
    the reference's, as :func:`compare_images` takes it.

    Returns:
        ``{"actual": path, "expected": path, "diff": path}``.
    """
    _check_name(name)
    a = _check_image(actual, "actual")
    e = _check_image(expected, "expected")
    base = Path(out_dir)
    paths = {
        "actual": base / f"{name}-actual.png",
        "expected": base / f"{name}-expected.png",
        "diff": base / f"{name}-diff.png",
    }
    files.save_png(a, paths["actual"])
    files.save_png(e, paths["expected"])
    files.save_png(_diff_image(a, e, threshold, _check_margin(margin, e.shape)), paths["diff"])
    return paths


# --------------------------------------------------------------------------
# golden check
# --------------------------------------------------------------------------


def _write_golden(image: np.ndarray, path: Path, why: str) -> None:
    files.save_png(image, path)
    warnings.warn(GoldenUpdated(f"wrote golden {path} ({why})"), stacklevel=3)


def check_golden(
    image: npt.ArrayLike,
    golden_path: str | os.PathLike[str],
    *,
    update: bool,
    results_dir: str | os.PathLike[str],
    threshold: int = DEFAULT_THRESHOLD,
    max_bad_share: float = DEFAULT_MAX_BAD_SHARE,
    name: str | None = None,
    hint: str = UPDATE_HINT,
) -> ImageMatch:
    """Check a rendered RGBA image against the golden PNG at ``golden_path``.

    Behaviour:

    * golden passes: return the comparison; the file is never touched, even
      with ``update=True``.
    * golden missing or unreadable: with ``update`` write it (warning
      :class:`GoldenUpdated`), otherwise raise ``AssertionError`` with
      ``"missing golden <path>; run pytest --update-goldens"``.
    * golden fails: with ``update`` rewrite it (warning :class:`GoldenUpdated`)
      and return the comparison against the old golden with ``updated=True``;
      otherwise write the artefacts into ``results_dir`` and raise
      ``AssertionError`` with the summary figures and the artefact paths.

    Args:
        image: rendered uint8 image of shape (H, W, 4).
        golden_path: the golden PNG.
        update: rewrite missing or failing goldens.
        results_dir: folder for the failure artefacts.
        threshold, max_bad_share: tolerances, see :func:`compare_images`.
        name: artefact file name stem; defaults to the golden's stem.
        hint: how to update, in the messages (the pytest plugin's flag is
            not the project's).

    Raises:
        GoldenUpdateRefused: ``update`` is true while ``CI`` is set (non-empty).
        AssertionError: the golden is missing or fails and ``update`` is false.
    """
    golden = Path(golden_path)
    if name is not None:
        _check_name(name)
    if update and os.environ.get("CI"):
        raise GoldenUpdateRefused(
            f"refusing to update golden {golden}: CI is set, goldens are never rewritten on CI"
        )
    img = _check_image(image, "rendered")
    if img.shape[2] != 4:
        raise ValueError(f"rendered image has shape {img.shape}; goldens are RGBA (H, W, 4)")

    if not golden.exists():
        if update:
            _write_golden(img, golden, "was missing")
            cmp = compare_images(img, img, threshold=threshold, max_bad_share=max_bad_share)
            return replace(cmp, updated=True)
        raise AssertionError(f"missing golden {golden}; {hint}")

    try:
        expected = files.load_png(golden)
    except OSError as exc:  # includes PIL.UnidentifiedImageError
        if update:
            _write_golden(img, golden, f"was unreadable: {exc}")
            cmp = compare_images(img, img, threshold=threshold, max_bad_share=max_bad_share)
            return replace(cmp, updated=True)
        raise AssertionError(f"cannot read golden {golden}: {exc}; {hint}") from exc

    cmp = compare_images(img, expected, threshold=threshold, max_bad_share=max_bad_share)
    if cmp.passed:
        return cmp
    if update:
        _write_golden(img, golden, f"old one failed: {cmp.summary()}")
        return replace(cmp, updated=True)

    paths = write_artifacts(
        img, expected, results_dir, name or golden.stem, threshold=threshold
    )
    lines = [f"golden mismatch for {golden}", f"  {cmp.summary()}"]
    lines += [f"  {kind:8}: {path}" for kind, path in paths.items()]
    note = " and explain it in the issue note" if hint == UPDATE_HINT else ""  # the project's own flow
    lines.append(f"  if the change is intended, {hint}{note}")
    raise AssertionError("\n".join(lines))
