"""Texture images: the ones the project draws itself, and user image files.

No GL here: every function returns RGBA ``uint8`` arrays of shape (H, W, 4)
with row 0 at the *top* of the picture, as image files store them. Course
section "Texture Mapping": uv (0, 0) is the image's top-left corner and v
grows downwards (DirectX's convention, which the course's cube uses); the
texture upload in :mod:`glsandbox.gl.textures` keeps rows in this order, so
the course's uv values need no flip.

A texture is a list of mip levels: one image (the others are built by the
GPU), or, for ``mip_levels``, every level drawn by hand in its own colour so
a test can read back which level was sampled.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from glsandbox.errors import SandboxError
from glsandbox.files import open_user_file
from glsandbox.scene import BUILTIN_TEXTURES, Texture

#: The colours of the four quadrants of the ``labels`` image, by the uv
#: corner they hold: (0,0) top-left red, (1,0) top-right green, (0,1)
#: bottom-left blue, (1,1) bottom-right yellow.
QUADRANT_COLORS: dict[tuple[int, int], tuple[int, int, int]] = {
    (0, 0): (220, 40, 40),
    (1, 0): (40, 170, 60),
    (0, 1): (40, 80, 220),
    (1, 1): (230, 200, 40),
}

#: The two colours of the ``checker`` image.
CHECKER_COLORS = ((240, 240, 240), (30, 60, 150))

#: One colour per mip level of the ``mip_levels`` image (level 0 first).
MIP_COLORS: tuple[tuple[int, int, int], ...] = (
    (255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 0), (255, 0, 255),
    (0, 255, 255), (255, 255, 255), (128, 128, 128), (0, 0, 0),
)


def _rgba(rgb: np.ndarray) -> np.ndarray:
    alpha = np.full(rgb.shape[:2] + (1,), 255, dtype=np.uint8)
    return np.ascontiguousarray(np.concatenate([rgb.astype(np.uint8), alpha], axis=2))


def checker(size: int = 256, squares: int = 8) -> np.ndarray:
    """A ``squares`` x ``squares`` checkerboard, ``size`` pixels square.

    High contrast and sharp edges: the picture where filters differ most
    (magnified, nearest shows blocks and linear blends; minified at a grazing
    angle, no mipmaps shimmer into moiré).
    """
    cell = np.arange(size) * squares // size
    odd = (cell[:, None] + cell[None, :]) % 2 == 1
    rgb = np.where(odd[..., None], np.array(CHECKER_COLORS[1]), np.array(CHECKER_COLORS[0]))
    return _rgba(rgb)


def labels(size: int = 256) -> np.ndarray:
    """Four coloured quadrants, each labelled with the uv of its corner.

    On the course's cube every face maps uv 0..1, so each face shows this
    picture once; the labels tell which corner of the face got which uv, and
    the colours let tests check the mapping without reading text.
    """
    from PIL import ImageDraw, ImageFont  # drawing and fonts: only the labels texture needs them

    image = Image.new("RGB", (size, size))
    draw = ImageDraw.Draw(image)
    half = size // 2
    font = ImageFont.load_default(size=max(8, size // 7))
    for (u, v), color in QUADRANT_COLORS.items():
        x0, y0 = u * half, v * half
        draw.rectangle((x0, y0, x0 + half - 1, y0 + half - 1), fill=color)
        draw.text((x0 + half / 2, y0 + half / 2), f"{u},{v}", fill=(255, 255, 255), font=font, anchor="mm")
    border = max(1, size // 64)
    draw.rectangle((0, 0, size - 1, size - 1), outline=(255, 255, 255), width=border)
    return _rgba(np.asarray(image))


def mip_levels(size: int = 256) -> list[np.ndarray]:
    """A full mip chain whose level k is one flat colour, ``MIP_COLORS[k]``.

    Level k of a ``size`` texture is ``size >> k`` pixels square; the chain
    ends at 1x1. Sampling returns the colour of the level the GPU chose.
    """
    levels = []
    for k in range(size.bit_length()):
        side = max(1, size >> k)
        color = np.array(MIP_COLORS[k % len(MIP_COLORS)], dtype=np.uint8)
        levels.append(_rgba(np.broadcast_to(color, (side, side, 3))))
    return levels


def builtin_levels(name: str) -> list[np.ndarray]:
    """The mip levels of a built-in image (one level: the GPU builds the rest)."""
    if name == "checker":
        return [checker()]
    if name == "labels":
        return [labels()]
    if name == "mip_levels":
        return mip_levels()
    raise SandboxError(f"unknown built-in texture {name!r}; use one of {', '.join(BUILTIN_TEXTURES)} "
                       "or an image file path")


def texture_levels(texture: Texture, max_size: int | None = None) -> list[np.ndarray]:
    """The mip levels of a texture, whatever its source: the image it carries
    in memory, a built-in image, or an image file (read with :func:`load_image`;
    ``max_size`` as there). Both renderers read textures through this."""
    if texture.image is not None:
        return [texture.image]
    if not texture.is_file:
        return builtin_levels(texture.source)
    return [load_image(texture.source, max_size)]


def check_texture_source(text: str) -> str:
    """A lesson parameter's texture (``Param(..., convert=check_texture_source)``): a built-in
    image's name, or an image file that loads, else the :class:`SandboxError` naming it.
    Checked when the value is given (``--set``, the window's panel, where a refused value
    shows in red and the frame keeps the last one), not when a frame draws."""
    if text not in BUILTIN_TEXTURES:
        load_image(text)
    return text


def load_image(path: str | Path, max_size: int | None = None) -> np.ndarray:
    """Read an image file as RGBA ``uint8`` (row 0 at the top).

    Every failure is a one-line :class:`SandboxError` naming the file: not
    found, a folder, a named pipe or device (refused before anything is read:
    a pipe would block forever), unreadable, not an image or corrupt, larger
    than ``max_size`` on a side (checked from the header, before decoding), or
    more pixels than Pillow decodes safely (its decompression-bomb limit,
    :data:`PIL.Image.MAX_IMAGE_PIXELS`: refused, not warned about). 16-bit
    greyscale images are scaled to 8 bits (see :func:`to_rgba8`).
    """
    p = Path(path)
    handle = open_user_file(p, "texture file", "an image file")
    try:
        with handle, warnings.catch_warnings():
            # Pillow warns (on stderr) above MAX_IMAGE_PIXELS and refuses above twice that: refuse both.
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(handle) as image:
                width, height = image.size
                if max_size is not None and max(width, height) > max_size:
                    raise SandboxError(f"texture file {p} is {width}x{height}, larger than this context "
                                       f"allows ({max_size}x{max_size})")
                rgba = to_rgba8(image)
    except SandboxError:
        raise
    except UnidentifiedImageError:
        raise SandboxError(f"texture file {p} is not an image Pillow can read") from None
    except PermissionError:
        raise SandboxError(f"texture file {p} is not readable (permission denied)") from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as exc:
        raise SandboxError(f"texture file {p} is too large to decode safely ({' '.join(str(exc).split())})") from None
    except (OSError, SyntaxError, ValueError) as exc:  # truncated or corrupt data
        raise SandboxError(f"texture file {p} is corrupt or unreadable ({' '.join(str(exc).split())})") from None
    if rgba.ndim != 3 or rgba.shape[0] == 0 or rgba.shape[1] == 0:
        raise SandboxError(f"texture file {p} has no pixels")
    return np.ascontiguousarray(rgba)


#: Pillow's modes of 16-bit greyscale samples (a 16-bit greyscale PNG opens as
#: ``I;16``) and of 32-bit integer ones (``I``), which PNG and TIFF readers
#: also use for 16-bit greyscale.
_WIDE_GREY = ("I;16", "I;16L", "I;16B", "I;16N", "I")


def to_rgba8(image: Image.Image) -> np.ndarray:
    """An open image as RGBA ``uint8``.

    Pillow's own ``convert("RGBA")`` clips 16-bit greyscale to 0..255 (a
    full-range ramp comes out 99.6% white); here its samples are scaled,
    ``round(v * 255 / 65535)``, so 0 stays black and 65535 becomes 255 (``I``
    samples are taken as 16-bit, clipped to 0..65535). Pillow already reduces
    16-bit RGB, RGBA and greyscale-with-alpha to 8 bits itself.
    """
    if image.mode in _WIDE_GREY:
        wide = np.clip(np.asarray(image, dtype=np.int64), 0, 65535)
        grey = ((wide * 255 + 32767) // 65535).astype(np.uint8)
        return np.ascontiguousarray(np.stack([grey, grey, grey, np.full_like(grey, 255)], axis=-1))
    return np.asarray(image.convert("RGBA"), dtype=np.uint8)
