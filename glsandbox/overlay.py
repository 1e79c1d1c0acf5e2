"""Screen overlays: labels and figures drawn on top of a frame. No GL here.

An :class:`Overlay` is an RGBA image placed at a pixel position in a viewport
(or the whole frame). The raster executor draws it 1:1, texel for pixel, after
the 3D passes, so text stays sharp and renders are repeatable; the plan has
an ``overlay`` pass only when a scene has overlays. :func:`text_image` draws
text with Pillow's built-in font, so no font file is needed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
from PIL import Image

from glsandbox.errors import SandboxError

RGBA = tuple[int, int, int, int]

#: Overlay colours: white text on a translucent black panel.
TEXT_COLOR: RGBA = (255, 255, 255, 255)
PANEL_COLOR: RGBA = (0, 0, 0, 150)


@dataclass(frozen=True, eq=False)
class Overlay:
    """An RGBA image (``(H, W, 4)`` uint8, top row first, straight alpha) on the frame.

    ``viewport`` is the region it belongs to and is clipped to (a viewport
    index, or None for the whole frame). ``position`` is the image's top-left
    corner in pixels from the region's top-left; a negative coordinate counts
    from the right or bottom edge instead (``(4, -4)``: bottom-left, 4 pixels in).
    """

    name: str
    image: np.ndarray
    viewport: int | None = None
    position: tuple[int, int] = (4, 4)
    #: Text and figures scale with the region (:func:`overlay_scale`); a picture that
    #: must land texel for pixel (a traced image, the panel's screen) sets this False.
    scalable: bool = True

    def __post_init__(self) -> None:
        image = np.asarray(self.image)
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 4 or 0 in image.shape:
            raise SandboxError(f"overlay {self.name!r}: expected a non-empty (H, W, 4) uint8 image, "
                               f"got {image.dtype} {image.shape}")
        # The overlay keeps the image read-only: the GL side may then skip
        # re-hashing the same array object from one frame to the next.
        image.setflags(write=False)
        object.__setattr__(self, "image", image)

    def scale(self, region: tuple[int, int, int, int]) -> float:
        """How much the image grows or shrinks in ``region`` (see :func:`overlay_scale`)."""
        if not self.scalable:
            return 1.0
        h, w = self.image.shape[:2]
        return overlay_scale(region[2], region[3], w, h)

    def drawn_image(self, region: tuple[int, int, int, int]) -> np.ndarray:
        """The image as drawn in ``region``: scaled by :meth:`scale` (the same array at 1)."""
        return scaled_image(self.image, self.scale(region))

    def seen_by(self, camera: Any, region: tuple[int, int, int, int]) -> Overlay:
        """The overlay as drawn through ``camera`` in ``region``: itself (a :class:`WorldLines`
        projects its lines there)."""
        return self

    def placement(self, region: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
        """Where the image lands, as a GL rectangle (x, y from the bottom left, w, h) in pixels:
        the scaled image (:meth:`drawn_image`), its offset from the corner scaled alike."""
        rx, ry, rw, rh = region
        factor = self.scale(region)
        h, w = self.drawn_image(region).shape[:2]
        px, py = (round(c * factor) if c >= 0 else -round(-c * factor) for c in self.position)
        left = px if px >= 0 else rw + px - w + 1
        top = py if py >= 0 else rh + py - h + 1
        return rx + left, ry + rh - top - h, w, h


#: The frame size (its shorter side, pixels) overlays are drawn for 1:1; a larger frame
#: grows them by whole texels (sharp text), a smaller one shrinks them.
REFERENCE_SIZE = 256
#: The most of its region an overlay may cover, as a share of the region's area, and of
#: its width and height: past these it is shrunk, so the scene stays visible at any size.
MAX_AREA_SHARE = 0.16
MAX_WIDTH_SHARE = 0.6
MAX_HEIGHT_SHARE = 0.45


def overlay_scale(region_w: int, region_h: int, image_w: int, image_h: int) -> float:
    """The factor an ``image_w`` x ``image_h`` overlay is drawn at in a region of that size.

    It follows the region's shorter side (1 up to :data:`REFERENCE_SIZE`, whole numbers
    above, so a text's texels stay square), and is capped so the image covers at most
    :data:`MAX_AREA_SHARE` of the region and :data:`MAX_WIDTH_SHARE` /
    :data:`MAX_HEIGHT_SHARE` of its sides.
    """
    # Below the reference size only the caps shrink it: a short label stays readable.
    factor = max(1.0, float(np.floor(min(region_w, region_h) / REFERENCE_SIZE)))
    cap = min(float(np.sqrt(MAX_AREA_SHARE * region_w * region_h / (image_w * image_h))),
              MAX_WIDTH_SHARE * region_w / image_w, MAX_HEIGHT_SHARE * region_h / image_h)
    return max(min(factor, cap), 1.0 / max(image_w, image_h))


#: Scaled images kept, by (id of the image, size): (the image, kept alive so its id is not reused; the result).
_SCALED: dict[tuple[int, tuple[int, int]], tuple[np.ndarray, np.ndarray]] = {}
_SCALED_KEPT = 256


def _scaled(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``image`` resized to ``size`` (w, h): whole-number growth by repeating texels, any
    other factor by Pillow's box filter on premultiplied colour (no dark fringes)."""
    h, w = image.shape[:2]
    if size[0] % w == 0 and size[1] % h == 0 and size[0] // w == size[1] // h:
        k = size[0] // w
        out = np.repeat(np.repeat(image, k, axis=0), k, axis=1)
    else:
        pre = image.astype(np.float32)
        pre[..., :3] *= pre[..., 3:4] / 255.0
        channels = [np.asarray(Image.fromarray(np.ascontiguousarray(pre[..., c])).resize(size, Image.Resampling.BOX))
                    for c in range(4)]
        stack = np.dstack(channels)
        alpha = stack[..., 3:4]
        stack[..., :3] = np.where(alpha > 0, stack[..., :3] * 255.0 / np.maximum(alpha, 1e-6), 0.0)
        out = np.clip(np.rint(stack), 0, 255).astype(np.uint8)
    out.setflags(write=False)
    return out


def scaled_image(image: np.ndarray, factor: float) -> np.ndarray:
    """``image`` drawn ``factor`` times its size (at least 1x1); the same array at 1."""
    h, w = image.shape[:2]
    size = (max(1, round(w * factor)), max(1, round(h * factor)))
    if size == (w, h):
        return image
    key = (id(image), size)
    entry = _SCALED.get(key)
    if entry is None or entry[0] is not image:
        if len(_SCALED) >= _SCALED_KEPT:
            del _SCALED[next(iter(_SCALED))]
        entry = (image, _scaled(image, size))
        _SCALED[key] = entry
    return entry[1]


@lru_cache(maxsize=1)
def _font() -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    from PIL import ImageFont  # imported when text is drawn: a cold start without an overlay skips it

    return ImageFont.load_default()


def text_image(rows: Sequence[str | Sequence[str]], *, color: RGBA = TEXT_COLOR, panel: RGBA = PANEL_COLOR,
               padding: int = 3, line_gap: int = 2, column_gap: int = 8) -> np.ndarray:
    """Rows of text on a panel, as a read-only RGBA array for an :class:`Overlay`.

    A row is a string, or a sequence of cells: cells of all such rows are
    right-aligned in shared columns (used for matrices, whose numbers would
    not line up in a proportional font). The same rows give back the same
    array (recently drawn panels are kept), so a lesson may rebuild its
    overlays every frame and pay for the text once.
    """
    key = tuple(row if isinstance(row, str) else tuple(row) for row in rows)
    return _text_image(key, color, panel, padding, line_gap, column_gap)


@lru_cache(maxsize=1024)
def _text_width(text: str) -> int:
    """A string's width in pixels in the panel font: the numbers of a matrix panel
    recur from frame to frame, so each is measured once."""
    from PIL import ImageDraw

    return int(np.ceil(ImageDraw.Draw(Image.new("RGBA", (1, 1))).textlength(text, font=_font())))


@lru_cache(maxsize=128)
def _text_image(rows: tuple[str | tuple[str, ...], ...], color: RGBA, panel: RGBA,
                padding: int, line_gap: int, column_gap: int) -> np.ndarray:
    from PIL import ImageDraw

    font = _font()
    width = _text_width
    ascent, descent = font.getmetrics() if hasattr(font, "getmetrics") else (10, 2)
    line_h = ascent + descent
    cells = [r for r in rows if not isinstance(r, str)]
    n_cols = max((len(r) for r in cells), default=0)
    col_w = [max((width(r[c]) for r in cells if c < len(r)), default=0) for c in range(n_cols)]
    table_w = sum(col_w) + column_gap * max(n_cols - 1, 0)
    text_w = max([width(r) for r in rows if isinstance(r, str)] + [table_w, 1])
    w = text_w + 2 * padding
    h = len(rows) * line_h + max(len(rows) - 1, 0) * line_gap + 2 * padding
    image = Image.new("RGBA", (w, h), panel)
    draw = ImageDraw.Draw(image)
    y = padding
    for row in rows:
        if isinstance(row, str):
            draw.text((padding, y), row, font=font, fill=color)
        else:
            x = padding
            for c, cell in enumerate(row):
                draw.text((x + col_w[c] - width(cell), y), cell, font=font, fill=color)
                x += col_w[c] + column_gap
        y += line_h + line_gap
    pixels = np.asarray(image, dtype=np.uint8).copy()
    pixels.setflags(write=False)
    return pixels


# --- lines in the world, drawn over the frame -------------------------------------------

Point = tuple[float, float, float]


@dataclass(frozen=True)
class WorldLine:
    """A segment from ``start`` to ``end`` (world coordinates) drawn over the frame in ``color``;
    ``dashed`` for a part the question rules out (a shadow ray past its blocker)."""

    start: Point
    end: Point
    color: RGBA
    dashed: bool = False

    def __post_init__(self) -> None:
        _set_points(self, "start", "end")


@dataclass(frozen=True)
class WorldMark:
    """A dot at ``point`` (world coordinates) with ``text`` beside it (to its right, or its
    left with ``left``: away from a line that passes on that side)."""

    point: Point
    text: str
    color: RGBA
    left: bool = False

    def __post_init__(self) -> None:
        _set_points(self, "point")


def _set_points(item: object, *names: str) -> None:
    """A line's or mark's points as three finite floats each, its colour as four bytes
    (plain tuples: a figure's image is kept by its lines and marks)."""
    for name in names:
        point = tuple(float(v) for v in np.asarray(getattr(item, name), dtype=np.float64).ravel())
        if len(point) != 3 or not all(np.isfinite(point)):
            raise SandboxError(f"{type(item).__name__} {name}: expected three finite numbers, got {getattr(item, name)!r}")
        object.__setattr__(item, name, point)
    color = tuple(int(c) for c in getattr(item, "color"))
    if len(color) != 4 or not all(0 <= c <= 255 for c in color):
        raise SandboxError(f"{type(item).__name__} color: expected four numbers 0-255 (RGBA), got {color!r}")
    object.__setattr__(item, "color", color)


#: A transparent texel: what a :class:`WorldLines` holds until a camera projects it.
_NOTHING = np.zeros((1, 1, 4), dtype=np.uint8)


@dataclass(frozen=True, eq=False)
class WorldLines(Overlay):
    """Segments and marked points in the world, drawn over the frame where the camera sees them.

    A figure of the question over the picture: rays, the points they hit, the light. It is
    projected through the frame's camera when drawn (:meth:`seen_by`), so it stays on its
    points as the camera moves, and it lies over the picture whoever drew that (the
    rasterizer or a ray tracer: their traced image is an overlay underneath). Drawn over
    everything, never hidden by the scene: a ray inside a sphere still shows.
    """

    image: np.ndarray = field(default_factory=lambda: _NOTHING)
    position: tuple[int, int] = (0, 0)
    scalable: bool = False
    lines: tuple[WorldLine, ...] = ()
    marks: tuple[WorldMark, ...] = ()

    def seen_by(self, camera: Any, region: tuple[int, int, int, int]) -> Overlay:
        """The figure as ``camera`` (a :class:`~glsandbox.scene.Camera`) sees it in ``region``:
        an image the region's size, placed over it."""
        w, h = region[2], region[3]
        clip = camera.projection(w / max(h, 1)) @ camera.view()
        image = _figure(self.lines, self.marks, tuple(map(float, clip.ravel())), (w, h))
        return Overlay(self.name, image, self.viewport, (0, 0), scalable=False)


def project_segment(clip: np.ndarray, start: Sequence[float], end: Sequence[float],
                    size: tuple[int, int]) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The part of the segment the camera sees, as two pixel positions (x right, y down from the
    top left), or None when none of it is in view.

    ``clip`` is projection x view (the course's View and Projection). Clipped in clip space,
    before the divide by w, as the rasterizer clips a triangle: on the segment
    ``p(s) = a + s(b - a)``, 0 <= s <= 1, each inequality ``-w <= x <= w``, ``-w <= y <= w`` and
    ``w > 0`` is linear in s, so each cuts the range of s at one point (Liang-Barsky); a point
    behind the eye never reaches the divide.
    """
    a = clip @ np.array([*start, 1.0])
    b = clip @ np.array([*end, 1.0])
    low, high = 0.0, 1.0
    tiny = 1e-9 * max(abs(a[3]), abs(b[3]), 1.0)
    for fa, fb in ((a[3] + a[0], b[3] + b[0]), (a[3] - a[0], b[3] - b[0]), (a[3] + a[1], b[3] + b[1]),
                   (a[3] - a[1], b[3] - b[1]), (a[3] - tiny, b[3] - tiny)):
        if fa < 0.0 and fb < 0.0:
            return None
        if fa < 0.0:
            low = max(low, fa / (fa - fb))
        elif fb < 0.0:
            high = min(high, fa / (fa - fb))
    if low > high:
        return None
    w, h = size

    def pixel(q: np.ndarray) -> tuple[float, float]:
        x, y = q[0] / q[3], q[1] / q[3]  # normalised device coordinates, -1..1
        return (x + 1.0) * 0.5 * w, (1.0 - y) * 0.5 * h

    return pixel(a + low * (b - a)), pixel(a + high * (b - a))


#: Dark edge drawn under every line and dot, so a figure reads on a bright surface too.
EDGE_COLOR: RGBA = (0, 0, 0, 200)


#: Below this frame size (its shorter side, pixels) a figure shows its lines and dots only:
#: the labels would cover them (the lesson's text panel says the numbers).
MIN_LABELLED_SIZE = 200


def line_width(size: tuple[int, int]) -> int:
    """A figure's line width in pixels: 2 up to a 320-pixel frame, then growing with it."""
    return max(2, round(min(size) / 160))


@lru_cache(maxsize=16)
def _figure(lines: tuple[WorldLine, ...], marks: tuple[WorldMark, ...], clip: tuple[float, ...],
            size: tuple[int, int]) -> np.ndarray:
    """The figure's image for one camera and region size (read-only; an unchanged camera
    gets the same array, so the overlay's texture is not uploaded again)."""
    from PIL import ImageDraw

    matrix = np.array(clip).reshape(4, 4)
    width = line_width(size)
    canvas = Image.new("RGBA", size, (0, 0, 0, 0))
    draw = ImageDraw.Draw(canvas)
    for edge in (True, False):
        for line in lines:
            ends = project_segment(matrix, line.start, line.end, size)
            if ends is None:
                continue
            color, thick = (EDGE_COLOR, width + 2) if edge else (line.color, width)
            for a, b in _dashes(*ends, 4 * width, 3 * width) if line.dashed else [ends]:
                draw.line([a, b], fill=color, width=thick)
    radius = 2 * width
    seen = [(mark, ends[0]) for mark in marks if (ends := project_segment(matrix, mark.point, mark.point, size))]
    for mark, (x, y) in seen:
        draw.ellipse([x - radius - 1, y - radius - 1, x + radius + 1, y + radius + 1], fill=EDGE_COLOR)
        draw.ellipse([x - radius, y - radius, x + radius, y + radius], fill=mark.color)
    if min(size) < MIN_LABELLED_SIZE:
        return _frozen(canvas)
    factor = max(1, int(min(size) // REFERENCE_SIZE))  # as text panels grow: by whole texels
    for mark, (x, y) in seen:  # the labels over every line and dot
        if mark.text:
            label = Image.fromarray(scaled_image(text_image([mark.text], color=mark.color), factor))
            lx = x - radius - 2 - label.width if mark.left else x + radius + 2
            lx = int(min(max(lx, 0), max(size[0] - label.width, 0)))
            ly = int(min(max(y - label.height - radius, 0), max(size[1] - label.height, 0)))
            canvas.alpha_composite(label, (lx, ly))
    return _frozen(canvas)


def _frozen(canvas: Image.Image) -> np.ndarray:
    """A canvas as a read-only RGBA array."""
    pixels = np.asarray(canvas, dtype=np.uint8).copy()
    pixels.setflags(write=False)
    return pixels


def _dashes(a: tuple[float, float], b: tuple[float, float], dash: float, gap: float) -> list:
    """The pieces of a dashed line from pixel ``a`` to pixel ``b``."""
    length = float(np.hypot(b[0] - a[0], b[1] - a[1]))
    pieces, s = [], 0.0
    while s < length:
        e = min(s + dash, length)
        pieces.append(((a[0] + (b[0] - a[0]) * s / length, a[1] + (b[1] - a[1]) * s / length),
                       (a[0] + (b[0] - a[0]) * e / length, a[1] + (b[1] - a[1]) * e / length)))
        s = e + gap
    return pieces
