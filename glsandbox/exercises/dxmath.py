"""The course's DirectXMath matrices (row vectors, ``v·M``, left-handed) made from the engine's.

The engine keeps OpenGL's form (column vectors ``M @ v``, right-handed; see
:mod:`glsandbox.transforms`); the raster exercises ask for the course's. A
matrix with no handedness in it (a scale, a rotation about an axis, a
mirror, a planar shadow) is the engine's one transposed: ``(M v)ᵀ = vᵀ Mᵀ``.
The camera and the projection also change handedness, through the engine's
one conversion :func:`glsandbox.transforms.from_directx_matrix` (its own
inverse) and, for the projection, the depth range: DirectX keeps
``0 <= z <= w`` where OpenGL keeps ``-w <= z <= w``.

Also here: the unit cube's image under a matrix, drawn as the probe picture
of every matrix exercise (:func:`edge_probe`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from glsandbox.exercises.compare import WrongType, matches, normalize

__all__ = ["look_at_lh", "perspective_fov_lh", "row", "CUBE_POINTS", "CUBE_EDGES", "camera", "edge_probe",
           "cube_segments"]

#: OpenGL's clip depth (-w .. w) mapped to DirectX's (0 .. w): z' = (z + w) / 2.
_DEPTH_0_1 = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.5, 0.5], [0.0, 0.0, 0.0, 1.0]])


def row(m: np.ndarray) -> list[list[float]]:
    """A matrix as four rows of four Python floats (how the exercises' answers are written)."""
    return [[float(x) for x in r] for r in np.asarray(m, dtype=np.float64).tolist()]


def look_at_lh(eye: Sequence[float], at: Sequence[float], up: Sequence[float]) -> np.ndarray:
    """``XMMatrixLookAtLH`` in the course's row form: the engine's right-handed
    :func:`~glsandbox.transforms.look_at` of the z-mirrored points, converted back."""
    from glsandbox.transforms import from_directx_matrix, from_directx_point, look_at

    gl = look_at(from_directx_point(eye), from_directx_point(at), from_directx_point(up))
    return from_directx_matrix(gl)


def perspective_fov_lh(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    """``XMMatrixPerspectiveFovLH`` in the course's row form: the engine's OpenGL
    :func:`~glsandbox.transforms.perspective` (degrees) acting on mirrored view space, its
    depth range moved from -w..w to 0..w, transposed for row vectors."""
    from glsandbox.transforms import MIRROR_Z, perspective

    gl = perspective(math.degrees(fov_y), aspect, near, far)
    return (_DEPTH_0_1 @ gl @ MIRROR_Z).T


# --- the probe: the unit cube's image under a matrix ------------------------------------------

#: The course's cube (Tutorial 04's eight vertices) as row vectors with w = 1.
CUBE_POINTS = np.array([[-1, 1, -1, 1], [1, 1, -1, 1], [1, 1, 1, 1], [-1, 1, 1, 1],
                        [-1, -1, -1, 1], [1, -1, -1, 1], [1, -1, 1, 1], [-1, -1, 1, 1]], dtype=np.float64)
#: Its twelve edges: the pairs of corners that differ in one coordinate.
CUBE_EDGES = [(a, b) for a in range(8) for b in range(a + 1, 8)
              if int(np.sum(CUBE_POINTS[a, :3] != CUBE_POINTS[b, :3])) == 1]


def camera(eye: Sequence[float] = (0.0, 4.0, -9.0), at: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """A fixed View·Projection (row form, 45°, square) that the probes look through."""
    return look_at_lh(eye, at, (0.0, 1.0, 0.0)) @ perspective_fov_lh(math.pi / 4.0, 1.0, 0.01, 100.0)


def cube_segments(to_clip: np.ndarray, points: np.ndarray = CUBE_POINTS) -> np.ndarray:
    """``(12, 2, 4)`` clip-space ends of the cube's edges for row vectors ``p·to_clip``."""
    clip = points @ to_clip
    return np.array([(clip[a], clip[b]) for a, b in CUBE_EDGES])


def as_matrix(value: Any) -> np.ndarray | None:
    """A student's answer as a 4x4 array, or None when it is not one."""
    try:
        return np.array(normalize(value, "matrix4"), dtype=np.float64)
    except WrongType:
        return None


def _mask(segments: np.ndarray, size: int) -> np.ndarray:
    """The pixels a set of clip-space segments covers in a ``size²`` tile, clipped as DirectX
    clips (w > 0, -w <= x, y <= w, 0 <= z <= w), two pixels wide."""
    mask = np.zeros((size, size), dtype=bool)
    if segments.size == 0 or not np.all(np.isfinite(segments)):
        return mask
    t = np.linspace(0.0, 1.0, 3 * size)[None, :, None]
    p = segments[:, 0:1, :] + t * (segments[:, 1:2, :] - segments[:, 0:1, :])
    p = p.reshape(-1, 4)
    x, y, z, w = p.T
    keep = (w > 1e-12) & (np.abs(x) <= w) & (np.abs(y) <= w) & (z >= 0.0) & (z <= w)
    px = np.clip(((x[keep] / w[keep] + 1.0) * 0.5 * size).astype(int), 0, size - 1)
    py = np.clip(((1.0 - y[keep] / w[keep]) * 0.5 * size).astype(int), 0, size - 1)
    mask[py, px] = True
    mask[:, 1:] |= mask[:, :-1].copy()
    mask[1:, :] |= mask[:-1, :].copy()
    return mask


def edge_probe(segments: Callable[[np.ndarray, int], np.ndarray]) -> Callable[..., tuple[np.ndarray, np.ndarray]]:
    """A ``Probe.draw`` for a matrix exercise: the probe's inputs in tiles (2x2 for four), each
    tile the clip-space segments ``segments(matrix, i)`` of the reference's matrix and of the
    student's: an edge of both is grey, the student's only red, the reference's only blue; a
    tile whose answer is no 4x4 matrix (or raised) is magenta."""

    from glsandbox.exercises.probe import PROBE_ABS, PROBE_REL

    def draw(reference: list[Any], student: list[Any], errors: dict[int, str], n: int):  # noqa: ANN202
        k = max(1, math.ceil(math.sqrt(len(reference))))
        size = n // k
        classes = np.zeros((n, n), dtype=np.uint8)
        own = np.full(len(reference), 5, dtype=np.uint8)
        for i, (r, s) in enumerate(zip(reference, student, strict=True)):
            y0, x0 = (i // k) * size, (i % k) * size
            tile = classes[y0:y0 + size, x0:x0 + size]
            ref, got = as_matrix(r), as_matrix(s)
            if i in errors or got is None or ref is None:
                tile[:] = 5
                continue
            own[i] = 1 if matches(tuple(map(tuple, got)), tuple(map(tuple, ref)), PROBE_REL, PROBE_ABS) else 4
            a = _mask(segments(ref, i), size)
            with np.errstate(all="ignore"):
                b = _mask(segments(got, i), size)
            tile[a & b] = 1
            tile[b & ~a] = 2
            tile[a & ~b] = 3
        return classes, np.full((n, n), 0.8), own

    return draw
