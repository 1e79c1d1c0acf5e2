"""Which pixels a triangle covers: the rasteriser's rule, on the CPU.

A pixel belongs to a triangle when its centre ``(i + ½, j + ½)`` lies inside it: the
three *edge functions* ``E(a, b, p) = (b − a) × (p − a)`` (the z of the 2D cross
product: twice the signed area of ``a, b, p``) all have the triangle's sign. A centre
exactly on an edge (``E = 0``) goes to one triangle only, by the **top-left rule**: it
is inside when that edge is a *top* edge (exactly horizontal, the triangle below it)
or a *left* edge (the triangle to its right). So two triangles sharing an edge never
both draw a pixel, and never both miss one.

"Top" is the first row as the target stores its rows. Direct3D (the course's DX11
half) stores the top row first, so there the rule is top-left as the picture shows it.
GL stores the bottom row first (its window ``y`` runs up), and llvmpipe applies the same
rule to the rows as stored: in the picture as shown, row 0 at the top, the horizontal
edge that counts is the *bottom* one (the X-ray's primitive ids show it, and the tests
pin it). This module works in GL's window coordinates (:func:`window_positions`) and
hands the picture back row 0 at the top, as the X-ray reads it. Vertices are snapped to
the rasteriser's sub-pixel grid (:data:`SUBPIXEL_BITS`: fixed point before the edge
functions), so the edge functions are exact integers.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["SUBPIXEL_BITS", "rasterize_ids", "window_positions"]

#: Sub-pixel precision of the vertices (llvmpipe's, and Direct3D's minimum: 8 bits).
SUBPIXEL_BITS = 8


def window_positions(clip: ArrayLike, size: tuple[int, int]) -> NDArray[np.float64]:
    """Clip-space positions ``(..., 4)`` to GL window pixels ``(..., 2)`` (``y`` up from the bottom
    row): the perspective divide, then the viewport transform of a full-frame viewport."""
    c = np.asarray(clip, dtype=np.float64)
    ndc = c[..., :2] / c[..., 3:4]
    width, height = size
    return np.stack([(ndc[..., 0] + 1.0) * 0.5 * width, (ndc[..., 1] + 1.0) * 0.5 * height], axis=-1)


def rasterize_ids(triangles: ArrayLike, size: tuple[int, int]) -> NDArray[np.int64]:
    """An ``(H, W)`` picture, row 0 at the top, of which triangle covers each pixel centre (its
    index in ``triangles``, ``(T, 3, 2)`` GL window positions, ``y`` up; −1 where none does),
    drawn in order (a later triangle over an earlier one), either winding, by the top-left rule
    on the rows as GL stores them (the bottom row first)."""
    width, height = size
    scale = 1 << SUBPIXEL_BITS
    fixed = np.rint(np.asarray(triangles, dtype=np.float64) * scale).astype(np.int64)  # snapped
    # Pixel centres in the same fixed point: (i + ½)·scale.
    px = (np.arange(width, dtype=np.int64) * scale + scale // 2)[None, :]
    py = (np.arange(height, dtype=np.int64) * scale + scale // 2)[:, None]  # row 0: the bottom one
    out = np.full((height, width), -1, dtype=np.int64)
    for index, (a, b, c) in enumerate(fixed):
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        if area == 0:
            continue  # a degenerate triangle covers nothing
        # area > 0 (clockwise with row 0 first): the interior is where each edge function
        # is positive (E > 0). The other winding: walk the edges the other way.
        corners = (a, b, c) if area > 0 else (a, c, b)
        inside = np.ones((height, width), dtype=bool)
        for p, q in ((corners[0], corners[1]), (corners[1], corners[2]), (corners[2], corners[0])):
            dx, dy = q[0] - p[0], q[1] - p[1]
            e = dx * (py - p[1]) - dy * (px - p[0])
            # Rows counted from the first stored: a top edge runs to +x (dy = 0, dx > 0, the
            # interior on later rows), a left edge runs towards row 0 (dy < 0, the interior to its +x side).
            top_left = (dy == 0 and dx > 0) or dy < 0
            inside &= (e > 0) | ((e == 0) & top_left)
        out[inside] = index
    return out[::-1].copy()  # row 0 at the top
