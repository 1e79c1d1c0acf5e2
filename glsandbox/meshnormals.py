"""Vertex normals for triangle meshes that come without them: smooth, flat, or smooth within a crease angle.

A triangle has one normal, ``N = (V1 − V0) × (V2 − V0)`` (counter-clockwise
front, OpenGL's rule and the course's worked example #1). A *vertex* has as
many as the faces around it want, which is why a mesh's vertices are split
where the surface should look sharp:

- ``"flat"``: every corner takes its face's normal (faceted shading);
- ``"smooth"``: every corner takes the average over *all* faces at that
  position (one normal per position: a cube looks like a blob);
- ``"crease"`` (the default of :mod:`glsandbox.meshfile`): a corner averages
  only the faces around its position whose normals are within
  ``crease_angle`` degrees of its own face's normal: curved surfaces look
  smooth and edges sharper than the angle stay sharp (a cube keeps its
  faces, a sphere its roundness).

The average is weighted by each face's angle at the corner (Thürmer &
Wüthrich 1998): it does not change when a face is cut into more triangles.
Faces meeting at a position are found by the position's exact coordinates,
so vertices split by the file for texture seams still share one normal.

Afterwards vertices are made unique again by everything they carry
(position, normal, uv, colour): corners that ended up with bit-identical
attributes share one vertex (:func:`unique_vertices`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["MODES", "corner_normals", "face_normals", "row_ids", "unique_vertices"]

#: The ways to make normals.
MODES = ("flat", "smooth", "crease")

#: A position shared by more corners than this gets its crease test done as a
#: matrix product in blocks instead of one (corner, corner) pair per entry.
_PAIR_GROUP_LIMIT = 64


def face_normals(positions: NDArray[np.float64], tris: NDArray[np.intp]) -> NDArray[np.float64]:
    """Unit face normals ``(F, 3)`` of ``N = (V1 − V0) × (V2 − V0)``; zero for a zero-area face."""
    a, b, c = positions[tris[:, 0]], positions[tris[:, 1]], positions[tris[:, 2]]
    n = np.cross(b - a, c - a)
    size = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, size, out=np.zeros_like(n), where=size > 0.0)


def _corner_angles(positions: NDArray[np.float64], tris: NDArray[np.intp]) -> NDArray[np.float64]:
    """The angle ``(F, 3)`` of each face at each of its corners."""
    p = positions[tris]  # (F, 3, 3)
    to_next = np.roll(p, -1, axis=1) - p
    to_prev = np.roll(p, 1, axis=1) - p
    sin = np.linalg.norm(np.cross(to_next, to_prev), axis=2)
    cos = np.einsum("fkj,fkj->fk", to_next, to_prev)
    return np.arctan2(sin, cos)


def row_ids(rows: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """``(ids, firsts)``: ``ids[i] == ids[j]`` exactly when rows ``i`` and ``j`` are bit-identical
    (``-0.0`` counted as ``0.0``), numbered by first appearance; ``firsts[g]`` is the first row of id ``g``.

    A 64-bit hash of each row is sorted (much faster than ``np.unique(axis=0)``),
    then every row is compared with its group's first row: on a hash collision
    the exact (slower) row sort answers instead.
    """
    rows = np.ascontiguousarray(rows + 0.0)  # -0.0 + 0.0 == +0.0: one bit pattern for zero
    n = rows.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    bits = rows.view(np.uint64).reshape(n, -1)
    h = np.full(n, np.uint64(0xCBF29CE484222325))
    with np.errstate(over="ignore"):
        for col in range(bits.shape[1]):
            h ^= bits[:, col]
            h *= np.uint64(0x100000001B3)
            h ^= h >> np.uint64(29)
    _, first, inverse = np.unique(h, return_index=True, return_inverse=True)
    if not np.array_equal(bits[first[inverse]], bits):  # a collision: sort the rows themselves
        _, first, inverse = np.unique(bits, axis=0, return_index=True, return_inverse=True)
    # Number the groups by first appearance, so the output keeps the input's order.
    rank = np.empty(first.size, dtype=np.intp)
    by_first = np.argsort(first, kind="stable")
    rank[by_first] = np.arange(first.size)
    return rank[inverse.reshape(-1)], first[by_first]


def corner_normals(positions: NDArray[np.float64], tris: NDArray[np.intp], mode: str = "crease",
                   crease_angle: float = 30.0) -> NDArray[np.float64]:
    """A unit normal per face corner, ``(F, 3, 3)``, made the way ``mode`` says (module docstring).

    ``tris`` must hold no zero-area face (drop them first). Where the
    weighted sum cancels to zero (a knife edge), the face's own normal is used.
    """
    if mode not in MODES:
        raise ValueError(f"unknown normals mode {mode!r}; use one of {', '.join(MODES)}")
    faces = face_normals(positions, tris)
    f = tris.shape[0]
    if mode == "flat" or f == 0:
        return np.repeat(faces[:, None, :], 3, axis=1)
    weighted = faces[:, None, :] * _corner_angles(positions, tris)[:, :, None]  # (F, 3, 3)
    pid, _ = row_ids(positions)
    corner_pid = pid[tris].reshape(-1)  # the welded position of each corner
    w = weighted.reshape(-1, 3)
    total: NDArray[np.float64]
    if mode == "smooth":
        sums = np.stack([np.bincount(corner_pid, w[:, j], minlength=int(pid.max()) + 1) for j in range(3)], axis=1)
        total = np.asarray(sums[corner_pid], dtype=np.float64)
    else:
        total = _crease_sums(corner_pid, np.repeat(faces, 3, axis=0), w, float(np.cos(np.radians(crease_angle))))
    size = np.linalg.norm(total, axis=1, keepdims=True)
    own = np.repeat(faces, 3, axis=0)
    unit = np.where(size > 1e-300, total / np.where(size > 1e-300, size, 1.0), own)
    return unit.reshape(f, 3, 3)


def _crease_sums(corner_pid: NDArray[np.intp], own: NDArray[np.float64], weighted: NDArray[np.float64],
                 cos_limit: float) -> NDArray[np.float64]:
    """For every corner: the sum of ``weighted`` over the corners at its position whose
    face normal is within the crease angle of its own (``own·other >= cos_limit``).

    Corners are grouped by position; each (corner, corner) pair of a group is
    tested, summed in the group's order for every corner, so corners with the
    same neighbours get bit-identical sums (and share a vertex afterwards).
    """
    c = corner_pid.shape[0]
    order = np.argsort(corner_pid, kind="stable")
    sorted_pid = corner_pid[order]
    starts = np.flatnonzero(np.r_[True, sorted_pid[1:] != sorted_pid[:-1]])
    sizes = np.diff(np.r_[starts, c])
    total = np.zeros((c, 3))
    small = sizes <= _PAIR_GROUP_LIMIT
    # Small groups: every pair at once, in blocks of about 4M pairs.
    group_ids = np.flatnonzero(small)
    work = np.cumsum(sizes[group_ids].astype(np.int64) ** 2)
    cuts: NDArray[np.intp] = np.zeros(0, dtype=np.intp)
    if work.size:
        cuts = np.searchsorted(work, np.arange(1 << 22, int(work[-1]) + (1 << 22), 1 << 22), side="right")
    lo = 0
    for hi in np.unique(np.r_[cuts, group_ids.size]):
        if hi > lo:
            _pair_block(group_ids[lo:hi], starts, sizes, order, own, weighted, cos_limit, total)
        lo = hi
    # Large groups (a fan of many faces at one point): a thresholded matrix product.
    for g in np.flatnonzero(~small):
        members = order[starts[g]:starts[g] + sizes[g]]
        n_own, w_own = own[members], weighted[members]
        for lo in range(0, members.size, 1024):
            rows = members[lo:lo + 1024]
            mask = (own[rows] @ n_own.T) >= cos_limit
            total[rows] = mask.astype(np.float64) @ w_own
    return total


def _pair_block(groups: NDArray[np.intp], starts: NDArray[np.intp], sizes: NDArray[np.intp], order: NDArray[np.intp],
                own: NDArray[np.float64], weighted: NDArray[np.float64], cos_limit: float,
                total: NDArray[np.float64]) -> None:
    """:func:`_crease_sums` for a block of small groups: all their (target, source) pairs as arrays."""
    size = sizes[groups]
    start = starts[groups]
    # Targets: each member of each group, repeated once per member of its group.
    member_group = np.repeat(np.arange(groups.size), size)
    member_pos = np.repeat(start, size) + (np.arange(size.sum()) - np.repeat(np.cumsum(size) - size, size))
    reps = size[member_group]
    target = np.repeat(order[member_pos], reps)
    # Sources: for each target, every member of its group, in the group's order.
    pair_group = np.repeat(member_group, reps)
    first_pair = np.cumsum(reps) - reps
    within = np.arange(reps.sum()) - np.repeat(first_pair, reps)
    source = order[start[pair_group] + within]
    keep = np.einsum("ij,ij->i", own[target], own[source]) >= cos_limit
    target, source = target[keep], source[keep]
    for j in range(3):
        total[:, j] += np.bincount(target, weighted[source, j], minlength=total.shape[0])


def unique_vertices(corner_attributes: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Vertices from per-corner attribute rows ``(C, k)``: ``(indices (C,), first corner of each vertex)``.

    Corners with bit-identical attributes share a vertex; vertices are
    numbered in the order their first corner appears.
    """
    return row_ids(corner_attributes)
