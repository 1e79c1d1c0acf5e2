"""A reference's margin: how near a decision each of its pixels is, so a verdict holds on any machine.

A picture is the sum of many discrete decisions (COURSE.md, the rasteriser
and the ray tracer): an edge function's sign at the pixel centre (is the
pixel inside the triangle?), a depth test (which of two surfaces is nearer?),
the nearest ``t`` among a ray's hits, a shadow-map comparison, the texel a
lookup lands in. Where a decision is close, the last bits of rounding decide
it, and those differ between machines running the same driver (llvmpipe
with or without AVX, threads, FMA) and between drivers. A pixel far from
every decision has the same colour everywhere, up to a level or two of
rounding in the shading, which the golden rule's ``threshold`` covers.

The margin is a second image beside the reference, ``NAME.margin.png``
(8-bit grey, one value per pixel): 0 where the pixel must match within the
check's ``threshold``; otherwise the number of levels by which that pixel may
differ. :func:`glsandbox.measure.golden.compare_images` takes it as a
per-pixel threshold (the larger of the two), and the rest of the rule (3x3
neighbourhood in both directions, the allowed bad share) is unchanged.

How it is computed: by perturbation, not analytically
-----------------------------------------------------
The reference is rendered again, by the same renderer, with the camera
nudged by less than a pixel (:data:`NUDGES`: an eighth of a pixel left,
right, up and down, the view turned about the eye by that much at the
image centre) and with the near plane moved by 0.1 % (every depth value
shifts, so depth tests near equality flip, as z-fighting does). A pixel's
margin is the largest channel difference between the reference and any
nudged picture, kept only where it exceeds the threshold (smooth shading
moves by a level or so under a nudge; that is noise, not a decision).

An analytic margin (an edge function, a ``t`` gap, an ``N·L`` per pixel,
from a primitive-id and depth pass) would need each renderer, the course's
own shaders and every student lesson's hand-written shader to report its
decisions; a perturbation needs nothing from them and sees every decision
that a camera or depth change reaches: coverage at triangle edges, depth
ties, ray hit or miss at a silhouette, the nearest of two hits, shadow and
texel boundaries (the surface point each pixel sees moves). What it does
not nudge: the lights (an ``N·L`` near 0 is clamped continuously, a level of
rounding at most, which the threshold already covers) and overlays (text
and figures are placed in whole pixels and must match exactly).

Why it stays honest: the margin is the reference's own: a pixel gets one
only where a move of an eighth of a pixel changes the model answer itself,
and only by as much as that move changes it. A wrong submission (a wrong
colour, light, transform or shader) differs inside its surfaces, where the
margin is 0, and fails as before; only the pixels on a decision boundary
may differ, by at most the amount the nudge showed. That is about 1 % of
a lesson's pixels or less (``benchmarks/_margin_share.py`` prints the share
per lesson), except where a picture is near a decision almost everywhere:
the texture lesson's minified checkerboard floor, a third of its pixels, by
a median of 13 levels (its wrong filters, wraps and tilings still fail).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
from PIL import Image

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.lesson import Lesson
from glsandbox.scene import Camera, Scene, moved_scene

__all__ = ["NUDGES", "margin_path", "nudged_camera", "nudged_scene", "nudged_image", "margin_from", "inside_share",
           "save_margin", "read_margin", "lesson_margin", "share_rows"]

#: How far a nudge moves the camera, in pixels at the image centre.
STEP = 0.125
#: The perturbations a margin is made of: (dx pixels, dy pixels, near-plane factor).
NUDGES: tuple[tuple[float, float, float], ...] = (
    (STEP, 0.0, 1.0), (-STEP, 0.0, 1.0), (0.0, STEP, 1.0), (0.0, -STEP, 1.0), (0.0, 0.0, 1.001))
#: What a margin file's name adds to its reference's stem.
SUFFIX = ".margin.png"


def margin_path(reference: str | os.PathLike[str]) -> Path:
    """``NAME.margin.png`` beside the reference ``NAME.png``."""
    path = Path(reference)
    return path.with_name(path.stem + SUFFIX)


def nudged_camera(camera: Camera, dx: float, dy: float, near: float, height: int) -> Camera:
    """``camera`` turned about its eye so the image centre moves by (``dx``, ``dy``) pixels of a
    picture ``height`` pixels high, its near plane times ``near``.

    One pixel at the centre of the image plane at distance 1 is ``2·tan(fov/2)/height`` wide
    (the perspective projection, COURSE.md's camera section), so the target moves by that much
    per pixel along the camera's right and up axes, scaled by its distance from the eye.
    """
    eye = np.asarray(camera.eye, dtype=np.float64)
    ahead = np.asarray(camera.target, dtype=np.float64) - eye
    distance = float(np.linalg.norm(ahead))
    forward = ahead / distance
    right = np.cross(forward, np.asarray(camera.up, dtype=np.float64))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    pitch = 2.0 * math.tan(math.radians(camera.fov_y) / 2.0) / max(height, 1)
    target = eye + distance * (forward + pitch * (dx * right + dy * up))
    near_plane = min(camera.near * near, (camera.near + camera.far) / 2.0)
    return replace(camera, target=tuple(float(v) for v in target), near=near_plane)


def nudged_scene(scene: Scene, nudge: Sequence[float], size: tuple[int, int]) -> Scene:
    """``scene`` with its camera and each viewport's own camera nudged (:func:`nudged_camera`)."""
    dx, dy, near = nudge
    viewports = tuple(
        vp if vp.camera is None else replace(vp, camera=nudged_camera(vp.camera, dx, dy, near,
                                                                      vp.pixels(*size)[3]))
        for vp in scene.viewports)
    return replace(scene, camera=nudged_camera(scene.camera, dx, dy, near, size[1]), viewports=viewports)


def nudged_image(renderer, lesson: Lesson, size: tuple[int, int], samples: int,
                 nudge: Sequence[float]) -> np.ndarray:
    """``lesson``'s picture with the camera nudged, drawn by ``renderer`` (a
    :class:`~glsandbox.frame.HeadlessRenderer`): the scene it draws, as
    :meth:`~glsandbox.frame.HeadlessRenderer.render` makes it, then nudged."""
    from glsandbox.frame import with_samples

    parts = lesson.moving() if type(lesson).scene is Lesson.scene else None
    scene = moved_scene(*parts) if parts is not None else lesson.scene()
    scene = with_samples(nudged_scene(scene, nudge, size), samples)
    return renderer.render_scene(scene, size).image


def margin_from(reference: np.ndarray, nudged: Sequence[np.ndarray], threshold: int) -> np.ndarray:
    """The margin (uint8, H x W) of ``reference`` from its ``nudged`` pictures: the largest channel
    difference to any of them, where it exceeds ``threshold``; 0 elsewhere."""
    ref = reference.astype(np.int16)
    largest = np.zeros(reference.shape[:2], dtype=np.int16)
    for image in nudged:
        if image.shape != reference.shape:
            raise SandboxError(f"a nudged picture of shape {image.shape} for a reference of {reference.shape}")
        np.maximum(largest, np.abs(image.astype(np.int16) - ref).max(axis=-1), out=largest)
    largest[largest <= threshold] = 0
    return largest.astype(np.uint8)


def inside_share(margin: np.ndarray) -> float:
    """The share of pixels inside the margin (allowed more than the threshold)."""
    return float(np.count_nonzero(margin)) / margin.size if margin.size else 0.0


def save_margin(margin: np.ndarray, path: Path) -> None:
    """Write the margin as an 8-bit grey PNG (one line naming it when it cannot be written)."""
    try:
        files.save_png(margin, path)
    except OSError as exc:
        raise SandboxError(f"margin {path}: cannot write ({exc.strerror or exc})") from None


def read_margin(reference: Path, shape: tuple[int, ...]) -> np.ndarray | None:
    """The margin beside ``reference`` (its pixels, H x W), None when there is none; one line
    naming it when it is not an 8-bit grey PNG of the reference's size."""
    path = margin_path(reference)
    if not path.exists() and not path.is_symlink():
        return None
    data = files.read_user_file(path, "margin", "a .png file")
    try:
        with Image.open(io.BytesIO(data), formats=["PNG"]) as image:
            if image.mode != "L":
                raise SandboxError(f"margin {path}: a {image.mode} image; a margin is 8-bit grey (L)")
            if image.size != (shape[1], shape[0]):
                raise SandboxError(f"margin {path}: {image.size[0]}x{image.size[1]}, its reference "
                                   f"{reference.name} is {shape[1]}x{shape[0]}; write both with --update")
            return np.asarray(image, dtype=np.uint8).copy()
    except SandboxError:
        raise
    except (OSError, ValueError, SyntaxError):
        raise SandboxError(f"margin {path}: not a PNG image ({len(data)} bytes that PNG cannot read)") from None


def lesson_margin(renderer, lesson: Lesson, size: tuple[int, int], samples: int = 0,
                  threshold: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """``lesson``'s picture and its margin, drawn in this process by ``renderer`` (what
    ``check --update`` writes, without the isolation a student's code needs)."""
    reference = renderer.render(lesson, size, samples).image
    nudged = [nudged_image(renderer, lesson, size, samples, nudge) for nudge in NUDGES]
    return reference, margin_from(reference, nudged, threshold)


def share_rows(renderer, lessons: Sequence[type[Lesson]], size: tuple[int, int]) -> list[tuple[str, float, int, int]]:
    """For each lesson at its defaults: (name, share of pixels inside the margin, the median and
    the largest allowance among them, in levels)."""
    rows = []
    for cls in lessons:
        _, margin = lesson_margin(renderer, cls(), size)
        inside = margin[margin > 0]
        rows.append((cls.name, inside_share(margin), int(np.median(inside)) if inside.size else 0,
                     int(inside.max()) if inside.size else 0))
    return rows
