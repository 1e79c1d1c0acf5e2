"""Vertex normals for triangle meshes that come without them: smooth, flat, or smooth within a crease angle.

A triangle has one normal, ``N = (V1 − V0) × (V2 − V0)`` (counter-clockwise
front, OpenGL's rule and the course's worked example #1). A *vertex* has as
many as the faces around it want, which is why a mesh's vertices are split
where the surface should look sharp:

- ``"flat"``: every corner takes its face's normal (faceted shading);
- ``"smooth"``: every corner takes the average over *all* faces at that
  position (one normal per position: a cube looks like a blob);
- ``"crease"`` (the default of :mod:`glsandbox.mesh.load`): a corner averages
  only the faces around its position whose normals are within
  ``crease_angle`` degrees of its own face's normal: curved surfaces look
  smooth and edges sharper than the angle stay sharp (a cube keeps its
  faces, a sphere its roundness).

The average is weighted by each face's angle at the corner (Thürmer &
Wüthrich 1998): it does not change when a face is cut into more triangles.
Faces meeting at a position are found by the position's exact coordinates,
so vertices split by the file for texture seams still share one normal.

**Linear time.** Testing every pair of corners at a position costs k² for
k corners there: a fan of a million triangles around one point would be a
million million tests. So the crease rule is worked out in three tiers, each
linear in the number of corners:

1. a position whose face normals all lie within *half* the crease angle of
   one direction has every pair within the crease angle (the angle between
   two normals is at most the sum of their angles to that direction): every
   corner there takes the sum over all. The direction tested is that sum's
   own (the angle-weighted sum, one ``bincount`` per component), so a smooth
   position costs one sum and one dot product per corner. Scanned surfaces,
   flat fans and a triangle repeated a million times are all this case;
2. the other positions with at most :data:`PAIR_LIMIT` corners (a cube's
   corner, a crease on a scan) test their pairs exactly as the rule says:
   at most ``PAIR_LIMIT`` tests per corner;
3. a larger position that fails the test of 1 (the apex of a cone of many
   faces) sorts its corners by their angle around the position's mean
   normal, walks that ring and cuts it where two neighbours' normals differ
   by more than the crease angle; each run between cuts is averaged (the
   "smoothing group" rule of modelling tools). It agrees with the pairwise
   rule when the sharp edges are where the normals jump.

The result is a *group* per corner and a unit normal per group
(:func:`normal_groups`); corners in one group share a normal. Afterwards
vertices are made unique again by everything they carry (position, normal,
uv, colour): :func:`split_vertices` numbers (attribute id, normal id) pairs,
integers, so no corner-sized float matrix is ever hashed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # annotations only: numpy.typing is not imported at run time (a cold start)
    from numpy.typing import NDArray

__all__ = ["BLOCK_FACES", "MODES", "PAIR_LIMIT", "corner_normals", "face_geometry", "face_normals", "normal_groups", "row_ids", "split_vertices",
           "unique_vertices"]

#: The ways to make normals.
MODES = ("flat", "smooth", "crease")

#: A position with more corners than this that is not smooth all round is split by
#: walking its ring of corners (tier 3 of the module docstring), not pair by pair.
PAIR_LIMIT = 64

#: Faces worked on at once where a step needs several temporary arrays per face (bounds the
#: memory a big model needs: a few megabytes per array, not one per triangle of the model).
BLOCK_FACES = 1 << 13

#: Pairs tested at once by the pairwise tier (bounds its temporary arrays).
_PAIR_BLOCK = 1 << 21

#: Tier 1 asks for normals within half the crease angle less this much (radians), so
#: rounding in the dot products cannot admit a pair the exact test would refuse.
_HALF_ANGLE_MARGIN = 1e-6


def face_normals(positions: NDArray[np.float64], tris: NDArray[np.intp]) -> NDArray[np.float64]:
    """Unit face normals ``(F, 3)`` of ``N = (V1 − V0) × (V2 − V0)``; zero for a zero-area face."""
    return _unit_rows(face_cross(positions[tris[:, 0]], positions[tris[:, 1]], positions[tris[:, 2]]))[0]


def face_cross(p0: NDArray[np.float64], p1: NDArray[np.float64], p2: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(V1 − V0) × (V2 − V0)`` per face from its corners' positions ``(F, 3)`` each; its length
    is the doubled area."""
    return _cross(p1 - p0, p2 - p0)


def _cross(e1: NDArray[np.float64], e2: NDArray[np.float64]) -> NDArray[np.float64]:
    """``e1 × e2`` row by row, written out per component (``np.cross`` is several times slower)."""
    n = np.empty_like(e1)
    n[:, 0] = e1[:, 1] * e2[:, 2] - e1[:, 2] * e2[:, 1]
    n[:, 1] = e1[:, 2] * e2[:, 0] - e1[:, 0] * e2[:, 2]
    n[:, 2] = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    return n


def _unit_rows(rows: NDArray[np.float64], in_place: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(rows / |row|, |row|)``; a zero row stays zero. ``in_place``: written over ``rows``."""
    size = np.sqrt(np.einsum("ij,ij->i", rows, rows))
    if in_place:
        np.divide(rows, size[:, None], out=rows, where=size[:, None] > 0.0)
        rows[size == 0.0] = 0.0  # (-0.0 too)
        return rows, size
    return np.divide(rows, size[:, None], out=np.zeros_like(rows), where=size[:, None] > 0.0), size


def face_geometry(positions: NDArray[np.float64], tris: NDArray[np.intp], with_angles: bool = True,
                  degenerate_share: float | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                                   NDArray[np.bool_] | None]:
    """What normals need of each face, in one pass over its corners' positions (blocks of
    :data:`BLOCK_FACES` faces): ``(unit normals (F, 3), corner angles (3F,), flat)``.

    The angles are empty unless ``with_angles``. ``flat`` (None unless
    ``degenerate_share`` is given) marks the faces whose doubled area is at most
    ``degenerate_share`` times their longest edge squared (the sine of the
    largest angle is that small): zero area up to rounding.
    """
    f = tris.shape[0]
    faces = np.empty((f, 3))
    angles = np.empty((f, 3) if with_angles else (0, 3))
    flat = None if degenerate_share is None else np.empty(f, dtype=bool)
    for lo in range(0, f, BLOCK_FACES):
        block = tris[lo:lo + BLOCK_FACES]
        p0, p1, p2 = (positions.take(block[:, k], axis=0) for k in range(3))  # take: faster than positions[...]
        e01, e02, e12 = p1 - p0, p2 - p0, p2 - p1
        del p0, p1, p2
        cross = _cross(e01, e02)
        area_sq = np.einsum("ij,ij->i", cross, cross)
        size = np.sqrt(area_sq)
        unit = faces[lo:lo + BLOCK_FACES]
        with np.errstate(invalid="ignore", divide="ignore"):
            np.divide(cross, size[:, None], out=unit)
        unit[size == 0.0] = 0.0  # a zero row stays zero (0/0 above)
        if flat is not None:
            longest = np.einsum("ij,ij->i", e01, e01)
            for e in (e12, e02):
                np.maximum(longest, np.einsum("ij,ij->i", e, e), out=longest)
            # |cross| > share * longest², compared squared (both sides are non-negative).
            flat[lo:lo + BLOCK_FACES] = ~(area_sq > (degenerate_share * longest) ** 2)
        if with_angles:
            # atan2(|e × e'|, e · e') for the two edges leaving each corner; |e × e'| is the doubled
            # area at all three corners. At V1 the edges are -e01 and e12, at V2 -e02 and -e12.
            block_angles = angles[lo:lo + BLOCK_FACES]
            block_angles[:, 0] = np.arctan2(size, np.einsum("ij,ij->i", e01, e02))
            block_angles[:, 1] = np.arctan2(size, -np.einsum("ij,ij->i", e12, e01))
            block_angles[:, 2] = np.arctan2(size, np.einsum("ij,ij->i", e02, e12))
    return faces, angles.reshape(-1), flat


def _by_first_appearance(first: NDArray[np.intp], inverse: NDArray[np.intp]) -> tuple[NDArray[np.intp],
                                                                                      NDArray[np.intp]]:
    """Renumber ``np.unique``'s groups in the order their first member appears."""
    rank = np.empty(first.size, dtype=np.intp)
    by_first = np.argsort(first, kind="stable")
    rank[by_first] = np.arange(first.size)
    return rank[inverse.reshape(-1)], first[by_first]


def row_ids(rows: NDArray[np.float64], ordered: bool = True) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """``(ids, firsts)``: ``ids[i] == ids[j]`` exactly when rows ``i`` and ``j`` are bit-identical
    (``-0.0`` counted as ``0.0``); ``firsts[g]`` is a row of id ``g``. ``ordered``: ids numbered by
    first appearance and ``firsts[g]`` the first row of id ``g`` (a second sort); otherwise in no
    particular order, for ids only compared with each other.

    A 64-bit hash of each row is sorted (much faster than ``np.unique(axis=0)``),
    then every row is compared with its group's representative: on a hash
    collision the exact (slower) row sort answers instead.
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
    if ordered:
        _, first, inverse = np.unique(h, return_index=True, return_inverse=True)
    else:
        _, inverse = np.unique(h, return_inverse=True)
        first = np.empty(int(inverse.max()) + 1, dtype=np.intp)
        first[inverse] = np.arange(n)  # any row of each id: they are all the same, or a collision shows
    inverse = inverse.reshape(-1)
    del h
    # Every row against its id's representative: only the rows that are not their own (a row
    # given once is its own), gathered with take (faster than fancy indexing).
    others = first.take(inverse)
    moved = np.flatnonzero(others != np.arange(n))
    others = others.take(moved)
    if not np.array_equal(bits.take(others, axis=0), bits.take(moved, axis=0)):  # a collision: sort the rows themselves
        _, first, inverse = np.unique(bits, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
    return _by_first_appearance(first, inverse) if ordered else (inverse, first)


def split_vertices(attribute_ids: NDArray[np.intp], normal_ids: NDArray[np.intp],
                   reuse: bool = False) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Vertices from corners: ``(index (C,), a corner of each vertex)``. Two corners share a vertex
    exactly when both their attribute id and their normal id are equal (both ids ``>= 0``).
    ``reuse``: the index is written over ``attribute_ids`` (an ``intp`` array the caller no longer
    needs; one corner-sized array less at the peak).

    Linear, no sort of the corners: each attribute id first takes the normal of
    one of its corners; only corners whose normal differs from that one (a crease,
    a flat face's corner) are numbered by sorting, after them. Vertices are
    numbered in the order of their attribute ids, the extra ones last.
    """
    c = attribute_ids.size
    if c == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    n_attr = int(attribute_ids.max()) + 1
    owner = np.empty(n_attr, dtype=np.intp)
    owner[attribute_ids] = normal_ids  # any one corner's normal per attribute id
    extra = np.flatnonzero(normal_ids != owner.take(attribute_ids))
    del owner
    vertex = attribute_ids if reuse and attribute_ids.dtype == np.intp else attribute_ids.astype(np.intp)
    count = n_attr
    if extra.size:
        span = int(normal_ids.max()) + 1
        _, again = np.unique(attribute_ids[extra].astype(np.int64) * span + normal_ids[extra], return_inverse=True)
        vertex[extra] = n_attr + again.reshape(-1)
        count += int(again.max()) + 1
    # Attribute ids no corner uses (a vertex only a dropped face had) leave no vertex.
    used = np.zeros(count, dtype=bool)
    used[vertex] = True
    renumber = np.cumsum(used, dtype=np.intp) - 1
    # In place (memory): each element reads its own index before it is overwritten; "clip"
    # (no index is out of range) is what lets numpy write into its indices unbuffered.
    np.take(renumber, vertex, out=vertex, mode="clip")
    first = np.empty(int(renumber[-1]) + 1, dtype=np.intp)
    first[vertex] = np.arange(c, dtype=np.intp)  # any corner of each vertex: they carry the same
    return vertex, first


def unique_vertices(corner_attributes: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Vertices from per-corner attribute rows ``(C, k)``: ``(indices (C,), first corner of each vertex)``.

    Corners with bit-identical attributes share a vertex; vertices are
    numbered in the order their first corner appears.
    """
    return row_ids(corner_attributes)


def corner_normals(positions: NDArray[np.float64], tris: NDArray[np.intp], mode: str = "crease",
                   crease_angle: float = 30.0) -> NDArray[np.float64]:
    """A unit normal per face corner, ``(F, 3, 3)``, made the way ``mode`` says (module docstring).

    ``tris`` must hold no zero-area face (drop them first). Where the
    weighted sum cancels to zero (a knife edge), the face's own normal is used.
    """
    group, normals = normal_groups(positions, tris, mode, crease_angle)
    return normals[group].reshape(-1, 3, 3)


def normal_groups(positions: NDArray[np.float64], tris: NDArray[np.intp], mode: str = "crease",
                  crease_angle: float = 30.0, position_ids: NDArray[np.intp] | None = None,
                  geometry: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
                  ) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """``(group (C,), normals (G, 3))``: corner ``c`` (face ``c // 3``, its corner ``c % 3``) has the
    unit normal ``normals[group[c]]``, made the way ``mode`` says (module docstring). Two corners
    at one position (equal ``position_ids``) share a group exactly when their normals are
    bit-identical: with the position, the group tells the vertices apart.

    ``tris`` must hold no zero-area face. Where a weighted sum cancels to zero
    (a knife edge), the corner takes its face's own normal. ``position_ids``:
    :func:`row_ids` of ``positions`` when the caller has it already; ``geometry``: the unit
    face normals and corner angles of :func:`face_geometry`, likewise.
    """
    if mode not in MODES:
        raise ValueError(f"unknown normals mode {mode!r}; use one of {', '.join(MODES)}")
    tris = np.asarray(tris, dtype=np.intp)
    f = tris.shape[0]
    if geometry is None:
        faces, angles, _ = face_geometry(positions, tris, with_angles=mode != "flat")
    else:
        faces, angles = geometry
    if mode == "flat" or f == 0:
        ids, firsts = row_ids(faces, ordered=False)  # coplanar faces' corners at one position: one vertex
        return np.repeat(ids, 3), faces[firsts]
    pid = row_ids(positions, ordered=False)[0] if position_ids is None else position_ids
    corner_pid = pid.take(tris.reshape(-1))  # the welded position of each corner
    del pid
    npos = int(corner_pid.max()) + 1
    if mode == "smooth":
        return _finish(corner_pid, _unit_rows(_sums(corner_pid, faces, angles, npos), in_place=True), faces, npos)
    cos_limit = math.cos(math.radians(crease_angle))
    # Tier 1: positions whose normals all lie within half the crease angle of the direction of their
    # angle-weighted sum (any reference direction serves the triangle inequality; this one is the
    # answer of tier 1 already, so it is summed once).
    unit = _unit_rows(_sums(corner_pid, faces, angles, npos), in_place=True)  # (normals, lengths), written over the sums
    half = max(0.0, math.radians(crease_angle) / 2.0 - _HALF_ANGLE_MARGIN)
    rough_pos = _rough_positions(corner_pid, faces, unit[0], math.cos(half))
    if not rough_pos.any():
        return _finish(corner_pid, unit, faces, npos)
    which = np.flatnonzero(rough_pos[corner_pid])
    del rough_pos
    # Tiers 2 and 3: every rough corner gets a group of its own numbered after the positions;
    # corners of one smoothing group get the same sum, so they merge again by their normal.
    # (Every corner of a rough position is rough: that position's row of ``unit`` is not used.)
    rough_angles = angles[which]
    del angles
    rough_pid = corner_pid[which]
    big = np.bincount(rough_pid, minlength=npos)[rough_pid] > PAIR_LIMIT
    rough_sums = np.zeros((which.size, 3))
    small_corners = which[~big]
    if small_corners.size:
        own = faces[small_corners // 3]
        rough_sums[~big] = _pair_sums(rough_pid[~big], own, own * rough_angles[~big, None], cos_limit)
    big_corners = which[big]
    if big_corners.size:
        big_pid = rough_pid[big]
        own = faces[big_corners // 3]
        # The ring is walked around the position's unweighted mean normal: summed over its corners in order.
        mean = _unit_rows(np.stack([np.bincount(big_pid, own[:, j], minlength=npos) for j in range(3)], axis=1))[0]
        rough_sums[big] = _ring_sums(positions, tris, big_corners, big_pid, own, rough_angles[big], mean[big_pid],
                                     cos_limit)
    group = corner_pid
    group[which] = npos + np.arange(which.size)
    rough_unit = _unit_rows(rough_sums, in_place=True)
    unit = (np.concatenate([unit[0], rough_unit[0]]), np.concatenate([unit[1], rough_unit[1]]))
    return _finish(group, unit, faces, npos, which)


def _rough_positions(corner_pid: NDArray[np.intp], faces: NDArray[np.float64], mean: NDArray[np.float64],
                     cos_half: float) -> NDArray[np.bool_]:
    """Per position: whether a face normal there is further than the half angle from the
    position's ``mean`` (``normal · mean < cos_half``: tier 1 does not apply). Worked out in
    blocks of :data:`BLOCK_FACES` faces, in ``(faces, 3)`` corner layout."""
    rough_pos = np.zeros(mean.shape[0], dtype=bool)
    for lo in range(0, faces.shape[0], BLOCK_FACES):
        block_pid = corner_pid[3 * lo:3 * (lo + BLOCK_FACES)].reshape(-1, 3)
        # Each corner's position's mean, dotted with the corner's face normal.
        spread = np.einsum("fkj,fj->fk", mean.take(block_pid, axis=0), faces[lo:lo + BLOCK_FACES])
        rough_pos[block_pid[spread < cos_half]] = True
    return rough_pos


def _sums(corner_group: NDArray[np.intp], faces: NDArray[np.float64], angles: NDArray[np.float64] | None,
          groups: int) -> NDArray[np.float64]:
    """The angle-weighted sum of face normals over the corners of each group, ``(groups, 3)``
    (every corner given: corner ``c`` is of face ``c // 3``); ``angles`` None: unweighted."""
    sums = np.empty((groups, 3))
    per_face = None if angles is None else angles.reshape(-1, 3)
    weight = np.empty((faces.shape[0], 3))
    for j in range(3):
        if per_face is None:
            weight[:] = faces[:, j, None]
        else:
            np.multiply(per_face, faces[:, j, None], out=weight)  # the face's component, at its three corners
        sums[:, j] = np.bincount(corner_group, weight.reshape(-1), minlength=groups)
    return sums


def _finish(group: NDArray[np.intp], unit_sums: tuple[NDArray[np.float64], NDArray[np.float64]],
            faces: NDArray[np.float64], merge_from: int,
            extra: NDArray[np.intp] | None = None) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Unit normals from the groups' sums, given as ``(sums / |sums|, |sums|)`` (:func:`_unit_rows`);
    a corner whose group's sum cancels (``|sum| <= 1e-300``) takes its face's normal.
    Groups numbered ``merge_from`` and up (the corners ``extra``: a rough corner's, and a cancelled
    corner's) that got bit-identical normals become one; those below are one per position already."""
    unit, size = unit_sums
    ok = size > 1e-300  # (a row that is not ok is used by no corner below)
    extra = np.zeros(0, dtype=np.intp) if extra is None else extra
    if not ok.all():
        cancelled = np.flatnonzero(~ok[group])
        if cancelled.size:  # a knife edge: those corners get groups of their own, with their face's normal
            group[cancelled] = unit.shape[0] + np.arange(cancelled.size)
            unit = np.concatenate([unit, faces[cancelled // 3]])
            extra = np.union1d(extra, cancelled)
    if extra.size:
        ids, firsts = row_ids(unit[merge_from:], ordered=False)
        group[extra] = merge_from + ids[group[extra] - merge_from]
        unit = np.concatenate([unit[:merge_from], unit[merge_from:][firsts]])
    return group, unit


def _pair_sums(corner_pid: NDArray[np.intp], own: NDArray[np.float64], weighted: NDArray[np.float64],
               cos_limit: float) -> NDArray[np.float64]:
    """For every corner given: the sum of ``weighted`` over the given corners at its position whose
    face normal is within the crease angle of its own (``own·other >= cos_limit``).

    Corners are grouped by position; each (corner, corner) pair of a group is
    tested, summed in the group's order for every corner, so corners with the
    same neighbours get bit-identical sums (and share a vertex afterwards).
    Every group here has at most :data:`PAIR_LIMIT` corners.
    """
    c = corner_pid.shape[0]
    order = np.argsort(corner_pid, kind="stable")
    sorted_pid = corner_pid[order]
    starts = np.flatnonzero(np.r_[True, sorted_pid[1:] != sorted_pid[:-1]])
    sizes = np.diff(np.r_[starts, c])
    total = np.zeros((c, 3))
    work = np.cumsum(sizes.astype(np.int64) ** 2)
    cuts = np.searchsorted(work, np.arange(_PAIR_BLOCK, int(work[-1]) + _PAIR_BLOCK, _PAIR_BLOCK), side="right")
    lo = 0
    for hi in np.unique(np.r_[cuts, sizes.size]):
        if hi > lo:
            _pair_block(np.arange(lo, hi), starts, sizes, order, own, weighted, cos_limit, total)
        lo = hi
    return total


def _pair_block(groups: NDArray[np.intp], starts: NDArray[np.intp], sizes: NDArray[np.intp], order: NDArray[np.intp],
                own: NDArray[np.float64], weighted: NDArray[np.float64], cos_limit: float,
                total: NDArray[np.float64]) -> None:
    """:func:`_pair_sums` for a block of groups: all their (target, source) pairs as arrays."""
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


def _ring_sums(positions: NDArray[np.float64], tris: NDArray[np.intp], corners: NDArray[np.intp],
               corner_pid: NDArray[np.intp], own: NDArray[np.float64], angles: NDArray[np.float64],
               mean: NDArray[np.float64], cos_limit: float) -> NDArray[np.float64]:
    """Tier 3 (module docstring): the corners given, sorted by their angle around their position's
    mean normal ``mean``, cut into runs where neighbours' normals differ by more than the crease
    angle (the ring closes: the last run joins the first unless they differ too); each corner
    gets the angle-weighted sum of its run."""
    face, k = corners // 3, corners % 3
    here = positions[tris[face, k]]
    centre = (positions[tris[face, 0]] + positions[tris[face, 1]] + positions[tris[face, 2]]) / 3.0
    toward = centre - here  # where the face lies around the position
    # An axis across the mean normal: the mean with a unit axis it is not close to, crossed.
    axis = np.where(np.abs(mean[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(mean, axis)
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
    v = np.cross(mean, u)
    azimuth = np.arctan2(np.einsum("ij,ij->i", toward, v), np.einsum("ij,ij->i", toward, u))
    order = np.lexsort((azimuth, corner_pid))
    pid, normal = corner_pid[order], own[order]
    n = order.size
    first = np.r_[True, pid[1:] != pid[:-1]]
    starts = np.flatnonzero(first)
    ends = np.r_[starts[1:], n] - 1
    bend = np.einsum("ij,ij->i", normal[1:], normal[:-1]) < cos_limit  # between ring neighbours i-1 and i
    cut = np.r_[False, bend] & ~first
    run = np.cumsum(first | cut) - 1
    # Close each ring: a ring with cuts whose last and first corners agree joins its last run to its first.
    has_cut = np.add.reduceat(cut.astype(np.intp), starts) > 0
    closes = np.einsum("ij,ij->i", normal[ends], normal[starts]) >= cos_limit
    join = has_cut & closes
    remap = np.arange(int(run[-1]) + 1)
    remap[run[ends[join]]] = run[starts[join]]
    run = remap[run]
    weighted = own[order] * angles[order, None]
    sums = np.stack([np.bincount(run, weighted[:, j], minlength=remap.size) for j in range(3)], axis=1)
    total = np.empty((n, 3))
    total[order] = sums[run]
    return total
