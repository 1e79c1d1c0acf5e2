"""Generated "real" models: many triangles, no download, the same every run.

No model file ships with the project's dependencies (trimesh's wheel has
none), and nothing is ever downloaded at run time, so lessons and tests that
need a model of thousands to millions of triangles make one:

- :func:`icosphere`: the unit sphere as a subdivided icosahedron,
  ``20·4^s`` nearly equal triangles, closed (every edge shared by two);
- :func:`rock`: the icosphere pushed in and out along its radius by a sum
  of fixed random waves, a closed lumpy stone with smooth normals (what a
  scanned model looks like to a ray tracer: many small triangles of every
  orientation);
- :func:`terrain`: a height field over a square grid, ``2·cells²``
  triangles, facing ``+y``, with uv; any triangle count, so the benchmark's
  1k, 10k, 100k and 1M come out exactly.

Everything is deterministic: the waves come from ``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from glsandbox.geometry import Mesh
from glsandbox.mesh.normals import corner_normals, unique_vertices

__all__ = ["icosphere", "rock", "terrain", "terrain_cells_for"]


def _icosahedron() -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """The 12 vertices (on the unit sphere) and 20 counter-clockwise faces of an icosahedron."""
    g = (1.0 + 5.0**0.5) / 2.0  # the golden ratio: the corners are (0, ±1, ±g) and its cyclic shifts
    v = np.array([(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g),
                  (0, -1, -g), (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)], dtype=np.float64)
    f = np.array([(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
                  (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
                  (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)], dtype=np.intp)
    return v / np.linalg.norm(v, axis=1, keepdims=True), f


@functools.cache
def _sphere_arrays(subdivisions: int) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Positions and faces of the icosphere: each step cuts every triangle into four
    at its edge midpoints, pushed out onto the sphere (one numpy pass per step)."""
    v, f = _icosahedron()
    for _ in range(subdivisions):
        edges = np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], axis=1).reshape(-1, 2)
        lo, hi = edges.min(axis=1), edges.max(axis=1)
        key = lo * v.shape[0] + hi  # an edge, whichever way round a face walks it
        unique, inverse = np.unique(key, return_inverse=True)
        mid = v[unique // v.shape[0]] + v[unique % v.shape[0]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = (v.shape[0] + inverse).reshape(-1, 3)  # midpoints of edges 01, 12, 20 of each face
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        m01, m12, m20 = m[:, 0], m[:, 1], m[:, 2]
        f = np.concatenate([np.stack(t, axis=1) for t in ((a, m01, m20), (b, m12, m01), (c, m20, m12),
                                                          (m01, m12, m20))])
        v = np.concatenate([v, mid])
    return v, f


def _check_subdivisions(subdivisions: int) -> None:
    if int(subdivisions) != subdivisions or not 0 <= subdivisions <= 9:
        raise ValueError(f"subdivisions must be an integer in 0..9, got {subdivisions!r}")


def icosphere(subdivisions: int = 3) -> Mesh:
    """The unit sphere as an icosahedron subdivided ``subdivisions`` times: ``20·4^s`` triangles,
    counter-clockwise seen from outside, normals equal to the positions."""
    _check_subdivisions(subdivisions)
    v, f = _sphere_arrays(int(subdivisions))
    return Mesh(f"icosphere{subdivisions}", v.copy(), f.reshape(-1).astype(np.uint32), v.copy())


def _waves(points: NDArray[np.float64], seed: int, count: int = 24) -> NDArray[np.float64]:
    """A sum of ``count`` plane waves ``a·sin(f·(p·u) + φ)`` with random unit directions ``u``,
    frequencies ``f`` from 1 to 12 and amplitudes falling as ``1/f``: smooth lumps of every size.
    Scaled to lie in about ``[-1, 1]``."""
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(count, points.shape[1]))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    freq = np.exp(rng.uniform(0.0, np.log(12.0), count))
    phase = rng.uniform(0.0, 2.0 * np.pi, count)
    amp = 1.0 / freq
    total = np.zeros(points.shape[0])
    for k in range(count):  # one pass per wave, not per point
        # p·u as plain products and sums, not a matrix product: BLAS's kernel for this CPU may
        # fuse them (FMA) or not, and the same seed would give other last bits on other machines
        along = points[:, 0] * u[k, 0]
        for axis in range(1, points.shape[1]):
            along = along + points[:, axis] * u[k, axis]
        total += amp[k] * np.sin(freq[k] * along + phase[k])
    return total / amp.sum() * 2.5


def rock(subdivisions: int = 5, *, seed: int = 0, roughness: float = 0.2) -> Mesh:
    """A closed lumpy stone: the icosphere with radius ``1 + roughness·waves(p)``
    (``20·4^s`` triangles: 5 gives 20,480, 8 gives 1,310,720), crease-angle normals."""
    _check_subdivisions(subdivisions)
    v, f = _sphere_arrays(int(subdivisions))
    radius = 1.0 + roughness * np.clip(_waves(v, seed), -1.0, 1.0)
    positions = v * radius[:, None]
    return _with_normals(f"rock{subdivisions}", positions, f)


def _with_normals(name: str, positions: NDArray[np.float64], faces: NDArray[np.intp],
                  uvs: NDArray[np.float64] | None = None) -> Mesh:
    """A mesh with crease-angle normals (:mod:`glsandbox.mesh.normals`), vertices split where they differ."""
    normals = corner_normals(positions, faces).reshape(-1, 3)
    corner_vertex = faces.reshape(-1)
    rows = [positions[corner_vertex], normals]
    if uvs is not None:
        rows.append(uvs[corner_vertex])
    index, first = unique_vertices(np.concatenate(rows, axis=1))
    return Mesh(name, positions[corner_vertex[first]], index.astype(np.uint32), normals[first],
                None if uvs is None else uvs[corner_vertex[first]])


def terrain_cells_for(triangles: int) -> int:
    """The grid size whose terrain has about ``triangles`` triangles (``2·cells²``)."""
    return max(1, round((triangles / 2.0) ** 0.5))


def terrain(cells: int = 64, *, seed: int = 0, size: float = 2.0, height: float = 0.25) -> Mesh:
    """A height field over the square ``size`` wide in the xz plane, centred at the origin:
    ``cells x cells`` quads, ``2·cells²`` triangles facing ``+y``, uv 0..1 across it
    (v down the image from ``−z``), heights within about ``±height``."""
    if int(cells) != cells or not 1 <= cells <= 4096:
        raise ValueError(f"cells must be an integer in 1..4096, got {cells!r}")
    n = int(cells) + 1
    s = np.linspace(-size / 2.0, size / 2.0, n)
    x, z = np.meshgrid(s, s)  # row i: z = s[i]
    xz = np.stack([x.reshape(-1), z.reshape(-1)], axis=1)
    y = height * _waves(xz * (3.0 / size), seed)
    positions = np.stack([xz[:, 0], y, xz[:, 1]], axis=1)
    u, v = np.meshgrid(np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n))
    uvs = np.stack([u.reshape(-1), v.reshape(-1)], axis=1)
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    a = (i * n + j).reshape(-1)  # corner (i, j); b one step +x, c one step +z
    b, c, d = a + 1, a + n, a + n + 1
    # Counter-clockwise seen from above (+y): a, c, b and b, c, d.
    faces = np.concatenate([np.stack([a, c, b], axis=1), np.stack([b, c, d], axis=1)])
    order = np.argsort(np.concatenate([np.arange(a.size) * 2, np.arange(a.size) * 2 + 1]), kind="stable")
    return _with_normals(f"terrain{cells}", positions, faces[order], uvs)
