"""Screen overlays: labels and figures drawn on top of a frame. No GL here.

An :class:`Overlay` is an RGBA image placed at a pixel position in a viewport
(or the whole frame). The raster executor draws it 1:1, texel for pixel, after
the 3D passes, so text stays sharp and renders are repeatable; the plan has
an ``overlay`` pass only when a scene has overlays. :func:`text_image` draws
text with Pillow's built-in font, so no font file is needed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

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

    def __post_init__(self) -> None:
        image = np.asarray(self.image)
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 4 or 0 in image.shape:
            raise SandboxError(f"overlay {self.name!r}: expected a non-empty (H, W, 4) uint8 image, "
                               f"got {image.dtype} {image.shape}")
        # The overlay keeps the image read-only: the GL side may then skip
        # re-hashing the same array object from one frame to the next.
        image.setflags(write=False)
        object.__setattr__(self, "image", image)

    def placement(self, region: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
        """Where the image lands, as a GL rectangle (x, y from the bottom left, w, h) in pixels."""
        rx, ry, rw, rh = region
        h, w = self.image.shape[:2]
        px, py = self.position
        left = px if px >= 0 else rw + px - w + 1
        top = py if py >= 0 else rh + py - h + 1
        return rx + left, ry + rh - top - h, w, h


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
