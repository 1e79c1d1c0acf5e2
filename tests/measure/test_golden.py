"""Golden image comparison, artefacts and update rules, on synthetic images."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from glsandbox.files import load_png, save_png
from glsandbox.measure.golden import (
    GoldenUpdated,
    GoldenUpdateRefused,
    ImageMatch,
    check_golden,
    compare_images,
    write_artifacts,
)

SIZE = 256
BACKGROUND = (20, 30, 40, 255)
OBJECT = (230, 200, 60, 255)


def scene(x0: int = 100, y0: int = 80, w: int = 50, h: int = 70) -> np.ndarray:
    """A 256x256 RGBA image: a flat rectangle on a flat background."""
    img = np.empty((SIZE, SIZE, 4), dtype=np.uint8)
    img[:] = BACKGROUND
    img[y0 : y0 + h, x0 : x0 + w] = OBJECT
    return img


def brighter(img: np.ndarray, levels: int) -> np.ndarray:
    """``img`` with every colour channel raised by ``levels`` (alpha kept)."""
    out = img.copy()
    out[..., :3] += np.uint8(levels)
    return out


@pytest.fixture(autouse=True)
def _no_ci(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run every test as off CI; tests that need CI set it themselves."""
    monkeypatch.delenv("CI", raising=False)


# --- compare_images ---------------------------------------------------------


def test_identical_passes() -> None:
    img = scene()
    cmp = compare_images(img, img.copy())
    assert cmp.passed and cmp.identical
    assert (cmp.bad_pixels, cmp.total_pixels, cmp.max_diff, cmp.rmse) == (0, SIZE * SIZE, 0, 0.0)
    assert cmp.summary().startswith("PASS: identical")


def test_one_level_change_passes() -> None:
    expected = scene()
    actual = brighter(expected, 1)
    cmp = compare_images(actual, expected)
    assert cmp.passed and not cmp.identical
    assert cmp.bad_pixels == 0
    assert cmp.max_diff == 1
    assert cmp.rmse == pytest.approx((3 / 4) ** 0.5 / 255)  # 3 of 4 channels off by 1


def test_change_beyond_threshold_everywhere_fails() -> None:
    expected = scene()
    actual = brighter(expected, 3)
    cmp = compare_images(actual, expected)
    assert not cmp.passed
    assert cmp.bad_pixels == SIZE * SIZE
    assert compare_images(actual, expected, threshold=3).passed


@pytest.mark.parametrize("dx, dy", [(1, 0), (0, 1), (-1, 0), (1, 1), (-1, 1)])
def test_edge_moved_by_one_pixel_passes(dx: int, dy: int) -> None:
    expected = scene()
    actual = scene(100 + dx, 80 + dy)
    assert compare_images(actual, expected, threshold=2).max_diff > 2
    cmp = compare_images(actual, expected, max_bad_share=0.0)
    assert cmp.passed, cmp.summary()
    assert cmp.bad_pixels == 0


def test_object_moved_further_fails() -> None:
    expected = scene()
    actual = scene(110, 80)  # 10 px to the right: two 10x70 bands differ
    cmp = compare_images(actual, expected)
    assert not cmp.passed
    # Every pixel of both bands is bad (each band edge fails one of the two
    # directions) except the 4 band corners that touch the object's other edge.
    assert cmp.bad_pixels == 2 * 10 * 70 - 4
    assert cmp.bad_share == pytest.approx(1396 / SIZE**2)
    assert cmp.summary().startswith("FAIL: 1396 bad of 65536 pixels")


def test_edge_moved_by_two_pixels_has_bad_pixels() -> None:
    cmp = compare_images(scene(102, 80), scene(), max_bad_share=0.0)
    assert not cmp.passed
    assert cmp.bad_pixels == 2 * 2 * 70 - 4  # both 2-px bands, less 4 corners


def test_missing_thin_line_is_caught_in_both_directions() -> None:
    """Only the expected->actual check sees a line that vanished (and vice versa)."""
    plain = scene()
    lined = plain.copy()
    lined[200, 10:110] = (255, 255, 255, 255)  # a 1-px line of 100 pixels
    missing = compare_images(plain, lined, max_bad_share=0.0)  # render lost the line
    extra = compare_images(lined, plain, max_bad_share=0.0)  # render grew a line
    assert missing.bad_pixels == extra.bad_pixels == 100
    assert not missing.passed and not extra.passed


def test_isolated_bad_pixel_is_within_default_share() -> None:
    expected = scene()
    actual = expected.copy()
    actual[10, 10] = (255, 0, 0, 255)
    cmp = compare_images(actual, expected)
    assert cmp.passed
    assert cmp.bad_pixels == 1
    assert cmp.bad_share == pytest.approx(1 / SIZE**2)
    strict = compare_images(actual, expected, max_bad_share=0.0)
    assert not strict.passed
    assert strict.bad_pixels == 1


def test_bad_pixels_on_the_border_are_counted() -> None:
    expected = scene()
    actual = expected.copy()
    for y, x in [(0, 0), (0, SIZE - 1), (SIZE - 1, 0), (SIZE - 1, SIZE - 1), (0, 128)]:
        actual[y, x] = (0, 255, 0, 255)
    assert compare_images(actual, expected).bad_pixels == 5


def test_share_limit_is_inclusive() -> None:
    expected = np.zeros((10, 10, 4), dtype=np.uint8)
    actual = expected.copy()
    actual[2, 2] = 200
    actual[7, 7] = 200
    assert compare_images(actual, expected, max_bad_share=0.02).passed
    assert not compare_images(actual, expected, max_bad_share=0.019).passed


def test_alpha_differences_count() -> None:
    expected = scene()
    actual = expected.copy()
    actual[100:140, 20:60, 3] = 0
    assert not compare_images(actual, expected).passed


def test_shape_mismatch_fails_with_a_clear_summary() -> None:
    cmp = compare_images(scene(), np.zeros((128, 256, 4), np.uint8))
    assert not cmp.passed and not cmp.identical and cmp.shape_mismatch
    assert cmp.summary() == "FAIL: shape mismatch: actual 256x256x4 vs expected 128x256x4"
    channels = compare_images(scene()[:, :, :3], scene())
    assert not channels.passed
    assert "256x256x3" in channels.summary()


def test_wrong_dtype_is_rejected() -> None:
    with pytest.raises(TypeError, match="uint8"):
        compare_images(scene().astype(np.float32), scene())


def test_comparison_is_frozen() -> None:
    cmp = compare_images(scene(), scene())
    with pytest.raises(AttributeError):
        cmp.passed = False  # type: ignore[misc]


@pytest.mark.parametrize("channels", [4, 3])
@pytest.mark.parametrize("threshold", [0, 2, 40])
def test_sparse_and_dense_neighbourhood_searches_agree(channels: int, threshold: int) -> None:
    from glsandbox.measure.golden import _bad_mask

    rng = np.random.default_rng(threshold + channels)
    expected = rng.integers(0, 4, (64, 48, channels), dtype=np.uint8) * np.uint8(60)
    actual = expected.copy()
    actual[rng.random((64, 48)) < 0.2] += np.uint8(30)  # scattered changes
    shifted = rng.random((64, 47)) < 0.1  # and some pixels copied from their left neighbour
    actual[:, 1:][shifted] = expected[:, :-1][shifted]
    sparse = _bad_mask(actual, expected, threshold, dense=False)
    dense = _bad_mask(actual, expected, threshold, dense=True)
    np.testing.assert_array_equal(sparse, dense)
    assert 0 < sparse.sum() < sparse.size


def test_full_size_random_images_compare() -> None:
    """A worst case (every pixel a candidate) at 1024x1024 works vectorised."""
    rng = np.random.default_rng(0)
    a = rng.integers(0, 256, (1024, 1024, 4), dtype=np.uint8)
    b = rng.integers(0, 256, (1024, 1024, 4), dtype=np.uint8)
    cmp = compare_images(a, b)
    assert not cmp.passed
    assert cmp.bad_share > 0.99


# --- PNG input / output ------------------------------------------------------


def test_save_and_load_round_trip_leaves_no_temp_files(tmp_path: Path) -> None:
    img = scene()
    img[..., 3] = np.arange(SIZE, dtype=np.uint8)[None, :]  # varied alpha survives
    path = tmp_path / "sub" / "img.png"
    assert save_png(img, path) == path
    save_png(img, path)  # overwrite
    assert os.listdir(path.parent) == ["img.png"]
    np.testing.assert_array_equal(load_png(path), img)


def test_load_png_returns_rgba(tmp_path: Path) -> None:
    rgb = scene()[:, :, :3]
    save_png(rgb, tmp_path / "rgb.png")
    loaded = load_png(tmp_path / "rgb.png")
    assert loaded.shape == (SIZE, SIZE, 4) and loaded.dtype == np.uint8
    assert (loaded[..., 3] == 255).all()


def test_greyscale_saves_and_loads_as_opaque_rgba(tmp_path: Path) -> None:
    grey = np.arange(64, dtype=np.uint8).reshape(8, 8)
    save_png(grey[:, :, None], tmp_path / "g.png")
    loaded = load_png(tmp_path / "g.png")
    for c in range(3):
        np.testing.assert_array_equal(loaded[..., c], grey)
    assert (loaded[..., 3] == 255).all()


def test_failed_save_keeps_the_old_file_and_no_temp(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "img.png"
    save_png(scene(), path)
    before = path.read_bytes()

    def broken_replace(src: str, dst: str) -> None:
        raise OSError("disk gone")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk gone"):
        save_png(scene(0, 0), path)
    assert os.listdir(tmp_path) == ["img.png"]
    assert path.read_bytes() == before


# --- artefacts ---------------------------------------------------------------


def test_artifacts_are_valid_pngs_of_the_right_size(tmp_path: Path) -> None:
    expected = scene()
    actual = scene(110, 80)
    actual[5, 5] = (255, 255, 255, 255)
    out = tmp_path / "results"
    paths = write_artifacts(actual, expected, out, "lesson/cube")
    assert set(paths) == {"actual", "expected", "diff"}
    assert paths["diff"] == out / "lesson" / "cube-diff.png"
    for path in paths.values():
        with Image.open(path) as im:
            im.verify()
        with Image.open(path) as im:
            assert im.format == "PNG"
            assert im.size == (SIZE, SIZE)
    np.testing.assert_array_equal(load_png(paths["actual"]), actual)
    np.testing.assert_array_equal(load_png(paths["expected"]), expected)

    diff = load_png(paths["diff"])
    assert tuple(diff[5, 5]) == (255, 0, 255, 255)  # bad pixel: magenta
    assert tuple(diff[100, 105]) == (255, 0, 255, 255)  # moved band: magenta
    assert diff[0, 0, 0] == diff[0, 0, 1] == diff[0, 0, 2] < 40  # dim grey elsewhere


def test_diff_amplifies_small_differences(tmp_path: Path) -> None:
    expected = np.zeros((4, 4, 4), dtype=np.uint8)
    expected[..., 3] = 255
    actual = expected.copy()
    actual[..., 1] = 2  # within threshold, not bad, but visible
    diff = load_png(write_artifacts(actual, expected, tmp_path, "amp")["diff"])
    assert tuple(diff[0, 0]) == (0, 20, 0, 255)


def test_artifacts_for_different_sizes(tmp_path: Path) -> None:
    paths = write_artifacts(scene(), scene()[:200, :100], tmp_path, "sizes")
    with Image.open(paths["diff"]) as im:
        assert im.size == (SIZE, SIZE)
    with Image.open(paths["expected"]) as im:
        assert im.size == (100, 200)


def test_artifact_name_cannot_escape(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="artefact name"):
        write_artifacts(scene(), scene(), tmp_path, "../evil")


# --- check_golden --------------------------------------------------------------


def test_missing_golden_without_update_fails_with_hint(tmp_path: Path) -> None:
    golden = tmp_path / "goldens" / "cube.png"
    with pytest.raises(AssertionError, match=r"missing golden .*cube\.png; run pytest --update-goldens"):
        check_golden(scene(), golden, update=False, results_dir=tmp_path / "results")
    assert not golden.exists()


def test_missing_golden_with_update_is_written(tmp_path: Path) -> None:
    golden = tmp_path / "goldens" / "cube.png"
    with pytest.warns(GoldenUpdated, match="was missing"):
        cmp = check_golden(scene(), golden, update=True, results_dir=tmp_path / "results")
    assert cmp.updated and cmp.passed
    np.testing.assert_array_equal(load_png(golden), scene())


def test_passing_golden(tmp_path: Path) -> None:
    golden = tmp_path / "cube.png"
    save_png(scene(), golden)
    cmp = check_golden(scene(101, 80), golden, update=False, results_dir=tmp_path / "results")
    assert isinstance(cmp, ImageMatch)
    assert cmp.passed and not cmp.updated
    assert not (tmp_path / "results").exists()


def test_failing_golden_writes_artifacts_and_reports(tmp_path: Path) -> None:
    golden = tmp_path / "cube.png"
    save_png(scene(), golden)
    results = tmp_path / "results"
    with pytest.raises(AssertionError) as info:
        check_golden(scene(140, 80), golden, update=False, results_dir=results)
    message = str(info.value)
    assert "FAIL:" in message and "bad of 65536 pixels" in message and "max channel diff" in message
    for kind in ("actual", "expected", "diff"):
        path = results / f"cube-{kind}.png"
        assert path.is_file()
        assert str(path) in message
    np.testing.assert_array_equal(load_png(golden), scene())  # golden untouched


def test_tolerances_are_passed_through(tmp_path: Path) -> None:
    golden = tmp_path / "cube.png"
    save_png(scene(), golden)
    actual = brighter(scene(), 4)
    with pytest.raises(AssertionError):
        check_golden(actual, golden, update=False, results_dir=tmp_path / "r")
    cmp = check_golden(actual, golden, update=False, results_dir=tmp_path / "r", threshold=4)
    assert cmp.passed


def test_update_rewrites_only_failing_goldens(tmp_path: Path) -> None:
    goldens = tmp_path / "goldens"
    passing, near, failing = goldens / "pass.png", goldens / "near.png", goldens / "fail.png"
    for path in (passing, near, failing):
        save_png(scene(), path)
        os.utime(path, ns=(1_000_000_000, 1_000_000_000))  # an old, recognisable mtime
    before = {p: p.read_bytes() for p in (passing, near, failing)}
    results = tmp_path / "results"

    assert check_golden(scene(), passing, update=True, results_dir=results).passed
    within = brighter(scene(), 1)  # passes within tolerance: must not be rewritten
    assert not check_golden(within, near, update=True, results_dir=results).updated
    for path in (passing, near):
        assert path.read_bytes() == before[path]
        assert path.stat().st_mtime_ns == 1_000_000_000

    new = scene(30, 30)
    with pytest.warns(GoldenUpdated, match="old one failed: FAIL"):
        cmp = check_golden(new, failing, update=True, results_dir=results)
    assert cmp.updated and not cmp.passed  # figures describe the replaced golden
    assert failing.read_bytes() != before[failing]
    np.testing.assert_array_equal(load_png(failing), new)
    assert not results.exists()  # no artefacts in update mode
    assert sorted(os.listdir(goldens)) == ["fail.png", "near.png", "pass.png"]


def test_update_rewrites_an_unreadable_golden(tmp_path: Path) -> None:
    golden = tmp_path / "cube.png"
    golden.write_text("version https://git-lfs.github.com/spec/v1\n")
    with pytest.raises(AssertionError, match="cannot read golden"):
        check_golden(scene(), golden, update=False, results_dir=tmp_path / "r")
    with pytest.warns(GoldenUpdated, match="unreadable"):
        check_golden(scene(), golden, update=True, results_dir=tmp_path / "r")
    np.testing.assert_array_equal(load_png(golden), scene())


def test_update_is_refused_on_ci(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CI", "true")
    golden = tmp_path / "cube.png"
    with pytest.raises(GoldenUpdateRefused, match="CI is set"):
        check_golden(scene(), golden, update=True, results_dir=tmp_path / "r")
    assert not golden.exists()
    # Without update a missing golden simply fails on CI.
    with pytest.raises(AssertionError, match="missing golden"):
        check_golden(scene(), golden, update=False, results_dir=tmp_path / "r")


def test_empty_ci_variable_does_not_count(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CI", "")
    golden = tmp_path / "cube.png"
    with pytest.warns(GoldenUpdated):
        check_golden(scene(), golden, update=True, results_dir=tmp_path / "r")
    assert golden.exists()


def test_rendered_image_must_be_rgba(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="RGBA"):
        check_golden(scene()[:, :, :3], tmp_path / "x.png", update=True, results_dir=tmp_path)


# --- the pytest plumbing (tests/conftest.py) -------------------------------------


def test_golden_fixture_uses_the_goldens_folder(
    golden, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Point the fixture's module-level folders at tmp_path, whatever the import mode.
    monkeypatch.setitem(golden.__globals__, "GOLDENS_DIR", tmp_path / "goldens")
    monkeypatch.setitem(golden.__globals__, "RESULTS_DIR", tmp_path / "results")
    with pytest.raises(AssertionError, match="run pytest --update-goldens"):
        golden(scene(), "lesson/cube")
    save_png(scene(), tmp_path / "goldens" / "lesson" / "cube.png")
    assert golden(scene(), "lesson/cube").passed
    with pytest.raises(AssertionError, match=r"results.lesson.cube-diff\.png"):
        golden(scene(0, 0), "lesson/cube", max_bad_share=0.01)


def test_update_goldens_option_is_a_usage_error_on_ci() -> None:
    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "CI": "1"}
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "--update-goldens", "--collect-only", "-q", "-n", "0",
         "-p", "no:cacheprovider", "tests/measure/test_metrics.py"],
        cwd=root, env=env, capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == pytest.ExitCode.USAGE_ERROR, proc.stdout + proc.stderr
    assert "--update-goldens is refused while CI is set" in proc.stderr
