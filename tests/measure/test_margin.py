"""A reference's margin: nudged cameras, the margin image, and the golden rule that reads it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.files import save_png
from glsandbox.lesson import find_lesson
from glsandbox.measure import golden
from glsandbox.measure.golden import compare_images, write_artifacts
from glsandbox.measure.margin import (NUDGES, inside_share, lesson_margin, margin_from, margin_path, nudged_camera,
                                      nudged_image, read_margin, save_margin, share_rows)
from glsandbox.scene import Camera


def pixel_of(camera: Camera, point, size: tuple[int, int]) -> np.ndarray:
    """Where ``point`` lands, in pixels (x right, y up) of a ``size`` picture seen by ``camera``."""
    w, h = size
    clip = camera.projection(w / h) @ camera.view() @ np.array([*point, 1.0])
    ndc = clip[:2] / clip[3]
    return (ndc + 1.0) / 2.0 * np.array([w, h])


def test_a_nudge_moves_the_image_centre_by_the_pixels_asked_and_the_near_plane_by_its_factor() -> None:
    camera = Camera(eye=(1.0, 2.0, 6.0), target=(0.5, 0.0, 0.0), fov_y=40.0)
    size = (200, 150)
    before = pixel_of(camera, camera.target, size)
    for dx, dy in ((0.125, 0.0), (0.0, -0.125), (0.5, 0.25)):
        moved = nudged_camera(camera, dx, dy, 1.0, size[1])
        # the old target, seen by the turned camera, moved the other way by (dx, dy)
        np.testing.assert_allclose(before - pixel_of(moved, camera.target, size), (dx, dy), atol=1e-3)  # a turn, not a shift: exact at the centre
        assert moved.eye == camera.eye and moved.near == camera.near
    assert nudged_camera(camera, 0.0, 0.0, 1.001, size[1]).near == pytest.approx(camera.near * 1.001)
    assert np.allclose(nudged_camera(camera, 0, 0, 1.0, size[1]).view(), camera.view())
    assert {n[:2] for n in NUDGES} >= {(0.125, 0.0), (-0.125, 0.0), (0.0, 0.125), (0.0, -0.125)}


def test_margin_from_keeps_the_largest_difference_above_the_threshold() -> None:
    ref = np.zeros((2, 3, 4), dtype=np.uint8)
    a, b = ref.copy(), ref.copy()
    a[0, 0, 1] = 2  # rounding: within the threshold, no margin
    a[0, 1, 0] = 40
    b[0, 1, 2] = 90  # the largest of the nudges wins
    b[1, 2, 3] = 3
    margin = margin_from(ref, [a, b], threshold=2)
    assert margin.dtype == np.uint8 and margin.tolist() == [[0, 90, 0], [0, 0, 3]]
    assert inside_share(margin) == pytest.approx(2 / 6)
    with pytest.raises(SandboxError, match="nudged picture of shape"):
        margin_from(ref, [np.zeros((3, 3, 4), np.uint8)], 2)


def test_the_golden_rule_with_a_margin_allows_each_pixel_its_own_difference_and_no_more() -> None:
    rng = np.random.default_rng(3)
    expected = rng.integers(0, 256, (40, 50, 4), dtype=np.uint8)
    actual = expected.copy()
    margin = np.zeros((40, 50), dtype=np.uint8)
    actual[10, 10] = expected[10, 10] // 2 + 10  # noise: no neighbour matches it
    margin[10, 10] = 140  # ... but the margin allows up to 140 levels there
    plain = compare_images(actual, expected, max_bad_share=0.0)
    assert not plain.passed and plain.bad_pixels == 1
    within = compare_images(actual, expected, max_bad_share=0.0, margin=margin)
    assert within.passed and within.bad_pixels == 0 and within.margin_pixels == 1
    assert "(threshold 2), 1 differing inside the reference's margin, RMSE" in within.summary()

    margin[10, 10] = 5  # a margin smaller than the difference does not excuse it
    assert compare_images(actual, expected, max_bad_share=0.0, margin=margin).bad_pixels == 1
    margin[:] = 0
    margin[20, 20] = 255  # a margin elsewhere excuses nothing here
    assert compare_images(actual, expected, max_bad_share=0.0, margin=margin).bad_pixels == 1
    # the dense and sparse paths agree with a margin
    actual[:20] = 255 - expected[:20]
    margin[:10] = 255
    m = golden._bad_mask(actual, expected, 2, margin=margin, dense=True)
    assert np.array_equal(m, golden._bad_mask(actual, expected, 2, margin=margin, dense=False))
    assert not m[:10].any() and m[10:20].all()
    with pytest.raises(ValueError, match="margin has dtype"):
        compare_images(actual, expected, margin=margin[:5])
    with pytest.raises(ValueError, match="margin has dtype"):
        compare_images(actual, expected, margin=margin.astype(np.int32))


def test_the_diff_picture_marks_only_what_the_margin_does_not_excuse(tmp_path: Path) -> None:
    expected = np.zeros((8, 8, 4), dtype=np.uint8)
    expected[..., 3] = 255
    actual = expected.copy()
    actual[2, 2, :3] = 200
    actual[5, 5, :3] = 200
    margin = np.zeros((8, 8), dtype=np.uint8)
    margin[2, 2] = 255
    from glsandbox.files import load_png

    diff = load_png(write_artifacts(actual, expected, tmp_path, "x", margin=margin)["diff"])
    assert diff[5, 5, :3].tolist() == [255, 0, 255] and diff[2, 2, :3].tolist() != [255, 0, 255]


def test_a_margin_file_beside_its_reference_reads_back_or_is_one_line(tmp_path: Path) -> None:
    ref = tmp_path / "ref.png"
    assert margin_path(ref) == tmp_path / "ref.margin.png"
    assert read_margin(ref, (4, 6, 4)) is None  # none written: the plain rule
    margin = np.arange(24, dtype=np.uint8).reshape(4, 6)
    save_margin(margin, margin_path(ref))
    assert np.array_equal(read_margin(ref, (4, 6, 4)), margin)
    with pytest.raises(SandboxError, match=r"6x4, its reference ref.png is 5x4; write both with --update"):
        read_margin(ref, (4, 5, 4))
    save_png(np.zeros((4, 6, 3), np.uint8), margin_path(ref))
    with pytest.raises(SandboxError, match="a RGB image; a margin is 8-bit grey"):
        read_margin(ref, (4, 6, 4))
    margin_path(ref).write_bytes(b"not a png")
    with pytest.raises(SandboxError, match="not a PNG image"):
        read_margin(ref, (4, 6, 4))
    (tmp_path / "file").write_text("")
    with pytest.raises(SandboxError, match="cannot write"):
        save_margin(margin, tmp_path / "file" / "x.margin.png")


def test_the_nudged_pictures_of_a_lesson_mark_its_edges_not_its_surfaces(gl) -> None:
    lesson = find_lesson("phong")
    size = (160, 120)
    base = gl.render(lesson(), size).image
    nudged = [nudged_image(gl, lesson(), size, 0, nudge) for nudge in NUDGES]
    assert np.array_equal(nudged_image(gl, lesson(), size, 0, (0.0, 0.0, 1.0)), base)  # no nudge: the picture
    assert all(not np.array_equal(image, base) for image in nudged[:4])  # each camera nudge reaches edges
    margin = margin_from(base, nudged, 2)
    share = inside_share(margin)
    assert 0.002 < share < 0.06, share  # a thin share: the silhouettes and the horizon
    # the sky above the lights and the ground in front are far from every decision
    assert not margin[:25].any() and not margin[100:].any()


def test_a_lesson_near_decisions_everywhere_still_fails_every_wrong_setting(gl) -> None:
    """The texture lesson's far checkerboard is near a texel decision in a third of its pixels;
    a wrong filter, wrap or tiling still fails by far more than the allowed share."""
    lesson = find_lesson("texture")
    size = (160, 120)
    reference, margin = lesson_margin(gl, lesson(), size)
    assert 0.1 < inside_share(margin) < 0.5
    assert compare_images(gl.render(lesson(), size).image, reference, margin=margin).identical
    for wrong in ("filter=mip_nearest", "wrap=clamp", "tile=3.1", "image=checker"):
        image = gl.render(lesson.from_settings([wrong]), size).image
        match = compare_images(image, reference, margin=margin)
        assert not match.passed and match.bad_share > 0.02, (wrong, match.summary())


def test_the_share_rows_name_each_lesson_with_its_share_and_allowances(gl) -> None:
    rows = share_rows(gl, [find_lesson("clear_and_swap"), find_lesson("phong")], (80, 60))
    assert [r[0] for r in rows] == ["clear_and_swap", "phong"]
    assert rows[0][1:] == (0.0, 0, 0)  # a cleared screen decides nothing
    name, share, median, largest = rows[1]
    assert 0.0 < share < 0.1 and 2 < median <= largest <= 255
