"""Küp: the indexed cube's 36 indices, clockwise front faces."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from glsandbox.exercises.compare import WrongType, normalize
from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import camera

DOC = """The cube's index buffer (küp: vertex + index buffer), course section "Küp: vertex + index buffer, 36 indices".

`vertices` are the eight corners of a box (its faces along the axes), in
any order; return the 36 indices of its index buffer: twelve triangles,
two per face, three indices each into `vertices`. DirectX keeps a triangle
whose corners go round *clockwise* as seen from outside the box (the
course's left-handed coordinates, +z into the screen); the rasterizer
drops the others as back faces. With the usual cross product that is:
(b - a) x (c - a) points *out* of the box.

Any triangulation is right (either diagonal of a face, a triangle's
indices started at any corner, the triangles in any order), as long as
every face is covered exactly once, clockwise.

Worked example: the notes' vertices (Tutorial 04) (-1,1,-1) (1,1,-1)
(1,1,1) (-1,1,1) (-1,-1,-1) (1,-1,-1) (1,-1,1) (-1,-1,1) and their buffer
3,1,0, 2,1,3, 0,5,4, 1,5,0, 3,4,7, 0,4,3, 1,6,5, 2,6,1, 2,7,6, 3,7,2, 6,4,5, 7,4,6.
"""

#: The six faces as (axis, side): -x, +x, -y, +y, -z, +z.
FACES = tuple((axis, side) for axis in range(3) for side in (-1.0, 1.0))


def reference(vertices):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :data:`glsandbox.geometry.COURSE_CUBE_INDICES` (the notes' buffer) with each
    notes' corner mapped to the vertex in that corner of the given box."""
    from glsandbox.geometry import COURSE_CUBE_INDICES, COURSE_CUBE_VERTICES

    v = np.asarray(vertices, dtype=np.float64)
    signs = np.sign(v - v.mean(axis=0))
    where = {tuple(s): i for i, s in enumerate(signs.tolist())}
    corner = [where[tuple(s)] for s in np.sign(COURSE_CUBE_VERTICES).tolist()]
    return [corner[int(k)] for k in COURSE_CUBE_INDICES]


def _face_of(points: np.ndarray, centre: np.ndarray) -> int:
    """The face (index into :data:`FACES`) three corners lie on, or -1."""
    signs = np.sign(points - centre)
    for f, (axis, side) in enumerate(FACES):
        if np.all(signs[:, axis] == side):
            return f
    return -1


def _front(points: np.ndarray, face: int) -> bool:
    axis, side = FACES[face]
    return float(np.cross(points[1] - points[0], points[2] - points[0])[axis] * side) > 0.0


def faces(vertices, indices) -> list[list[tuple[int, bool, frozenset]]] | None:  # noqa: ANN001
    """Each face's triangles as (face, clockwise from outside, its corners); None when an
    index is no vertex or a triangle lies on no face."""
    v = np.asarray(vertices, dtype=np.float64)
    centre = v.mean(axis=0)
    out: list[list] = [[] for _ in FACES]
    for i in range(0, len(indices), 3):
        tri = indices[i:i + 3]
        if any(k >= len(v) for k in tri) or len(set(tri)) < 3:
            return None
        pts = v[list(tri)]
        face = _face_of(pts, centre)
        if face < 0:
            return None
        out[face].append((face, _front(pts, face), frozenset(tri)))
    return out


@dataclass(frozen=True)
class Covers:
    """The expected answer: any buffer covering each face of the box with two clockwise
    triangles that meet along a diagonal."""

    vertices: tuple[tuple[float, float, float], ...]

    def accepts(self, value) -> bool:  # noqa: ANN001
        indices = [k for tri in value for k in tri]
        found = faces(self.vertices, indices)
        if found is None or len(indices) != 36:
            return False
        for triangles in found:
            if len(triangles) != 2 or not all(front for _, front, _ in triangles):
                return False
            a, b = triangles[0][2], triangles[1][2]
            if a == b or len(a | b) != 4 or not self._diagonal(a & b):
                return False
        return True

    def _diagonal(self, pair: frozenset) -> bool:
        """Whether two corners of a face are opposite (differ in both of the face's coordinates):
        two triangles meeting there cover the face once; meeting along an edge, they overlap."""
        p, q = (np.asarray(self.vertices[k]) for k in pair)
        return int(np.sum(p != q)) == 2

    def __repr__(self) -> str:
        return "36 indices, each face twice, clockwise"


def _case(name, vertices, group="visible"):  # noqa: ANN001, ANN202
    vertices = tuple(tuple(float(x) for x in p) for p in vertices)
    return Case(name, (vertices,), Covers(vertices), group=group)


def _box(low, high, order=tuple(range(8))):  # noqa: ANN001, ANN202
    from glsandbox.geometry import COURSE_CUBE_VERTICES

    lo, hi = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
    corners = [tuple(np.where(s > 0, hi, lo).tolist()) for s in COURSE_CUBE_VERTICES]
    return tuple(corners[k] for k in order)


NOTES = _box((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))


def _edit(vertices, change):  # noqa: ANN001, ANN202
    tris = [reference(vertices)[i:i + 3] for i in range(0, 36, 3)]
    return [k for tri in change(tris) for k in tri]


def face_made_back(vertices):  # noqa: ANN001, ANN201
    """The front face's (z = -1) two triangles wound the other way."""
    return _edit(vertices, lambda t: [[a, c, b] if i in (2, 3) else [a, b, c] for i, (a, b, c) in enumerate(t)])


def face_missing(vertices):  # noqa: ANN001, ANN201
    """The +x face's triangles left out: 30 indices."""
    return _edit(vertices, lambda t: [tri for i, tri in enumerate(t) if i not in (6, 7)])


def triangle_twice(vertices):  # noqa: ANN001, ANN201
    """The top face's first triangle written twice, its second missing."""
    return _edit(vertices, lambda t: [t[0] if i == 1 else tri for i, tri in enumerate(t)])


def counter_clockwise(vertices):  # noqa: ANN001, ANN201
    """Every triangle counter-clockwise (OpenGL's front faces)."""
    return _edit(vertices, lambda t: [[a, c, b] for a, b, c in t])


MISTAKES = (
    Mistake("face_made_back", "one face's triangles go round counter-clockwise seen from outside: DirectX "
            "drops them as back faces (swap two indices of each).", face_made_back),
    Mistake("face_missing", "a face has no triangles: 36 indices are six faces of two triangles each.",
            face_missing),
    Mistake("triangle_twice", "a triangle is listed twice and its face's other half is missing: the two "
            "triangles of a face meet along a diagonal.", triangle_twice),
    Mistake("counter_clockwise", "every triangle is counter-clockwise from outside, OpenGL's front faces: "
            "the course's DirectX keeps clockwise ones.", counter_clockwise),
)


def _variant_other_diagonal(vertices):  # noqa: ANN001, ANN202
    """Each face split along its other diagonal, the triangles started at another corner."""
    out = []
    tris = [reference(vertices)[i:i + 3] for i in range(0, 36, 3)]
    for i in range(0, 12, 2):
        first, second = tris[i], tris[i + 1]
        (d,) = set(second) - set(first)
        # the diagonal is the edge x -> y of the first triangle that the second shares; the
        # quad, in the first triangle's turning order, has d between x and y
        for j in range(3):
            x, y = first[j], first[(j + 1) % 3]
            if {x, y} <= set(second):
                ring = [x, d, y, first[(j + 2) % 3]]
        out += [ring[1], ring[2], ring[3], ring[3], ring[0], ring[1]]
    return out


VISIBLE = (_case("the notes' eight vertices (Tutorial 04)", NOTES),)


def hidden() -> list[Case]:
    """The corners in other orders, boxes of other sizes, far away and tiny."""
    return [
        _case("the notes' corners listed backwards", _box((-1, -1, -1), (1, 1, 1), tuple(range(7, -1, -1))),
              "orders"),
        _case("the corners in another order", _box((-1, -1, -1), (1, 1, 1), (5, 2, 7, 0, 3, 6, 1, 4)), "orders"),
        _case("a flat box (4 x 0.5 x 2) off the origin", _box((1, 2, 3), (5, 2.5, 5), (1, 0, 3, 2, 5, 4, 7, 6)),
              "boxes"),
        _case("a box far away (1e5)", _box((1e5, 1e5, -1e5), (1e5 + 1, 1e5 + 2, -1e5 + 1), (6, 7, 4, 5, 2, 3, 0, 1)),
              "boxes"),
        _case("a tiny box (1e-4)", _box((0, 0, 0), (1e-4, 1e-4, 1e-4), (3, 1, 0, 2, 7, 5, 4, 6)), "boxes"),
    ]


_PROBE_INPUTS = [(NOTES,), (_box((-1, -1, -1), (1, 1, 1), (5, 2, 7, 0, 3, 6, 1, 4)),), (NOTES,), (NOTES,)]
_EYES = [(-3.0, 4.0, -6.0), (4.0, -3.5, 5.0), (5.0, 3.0, 4.0), (-4.0, -3.0, -5.0)]


def _raster(vertices, indices, view: np.ndarray, size: int) -> np.ndarray:  # noqa: ANN001
    """Each pixel's nearest triangle as 1 + 2·face + clockwise on screen (0: nothing, 13: a
    triangle on no face), DirectX's rule: clockwise on screen is a front face."""
    v = np.asarray(vertices, dtype=np.float64)
    clip = np.hstack([v, np.ones((len(v), 1))]) @ view
    ndc = clip[:, :3] / clip[:, 3:4]
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    px, py = np.meshgrid(centres, -centres)
    depth = np.full((size, size), np.inf)
    out = np.zeros((size, size), dtype=np.int64)
    found = faces(vertices, indices)
    for i in range(0, len(indices), 3):
        a, b, c = (ndc[k] for k in indices[i:i + 3])
        def edge(u, v):  # noqa: ANN001, ANN202 - twice the signed area of (u, v, pixel)
            return (v[0] - u[0]) * (py - u[1]) - (v[1] - u[1]) * (px - u[0])

        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        if abs(area) < 1e-12:
            continue
        wa, wb, wc = edge(b, c) / area, edge(c, a) / area, edge(a, b) / area
        inside = (wa >= 0) & (wb >= 0) & (wc >= 0)
        z = wa * a[2] + wb * b[2] + wc * c[2]
        nearer = inside & (z < depth)
        face = 12 if found is None else _face_of(np.asarray(vertices, dtype=np.float64)[list(indices[i:i + 3])],
                                                   np.asarray(vertices, dtype=np.float64).mean(axis=0))
        code = 13 if face < 0 else 1 + 2 * face + int(area < 0)
        depth[nearer], out[nearer] = z[nearer], code
    return out


def _draw(reference, student, errors, n):  # noqa: ANN001, ANN202
    """Four views of the box, each pixel the nearest triangle's face and facing: grey where the
    student's and the reference's are the same, amber where they differ (a face seen from
    behind, another face), red/blue where only one has a triangle."""
    k, size = 2, n // 2
    classes, shade = np.zeros((n, n), dtype=np.uint8), np.zeros((n, n))
    own = np.full(len(reference), 5, dtype=np.uint8)
    for i, (r, s) in enumerate(zip(reference, student, strict=True)):
        y0, x0 = (i // k) * size, (i % k) * size
        tile, level = classes[y0:y0 + size, x0:x0 + size], shade[y0:y0 + size, x0:x0 + size]
        vertices = _PROBE_INPUTS[i][0]
        try:
            got = [x for tri in normalize(s, "indices") for x in tri]
        except WrongType:
            got = None
        if i in errors or got is None or any(x >= 8 for x in got):
            tile[:] = 5
            continue
        own[i] = 1 if Covers(vertices).accepts(normalize(s, "indices")) else 4
        view = camera(_EYES[i])
        a, b = _raster(vertices, r, view, size), _raster(vertices, got, view, size)
        tile[(a > 0) & (a == b)] = 1
        tile[(a > 0) & (b > 0) & (a != b)] = 4
        tile[(a == 0) & (b > 0)] = 2
        tile[(a > 0) & (b == 0)] = 3
        level[:] = np.where(tile == 1, a, b) / 14.0
    return classes, shade, own


EXERCISE = Exercise(
    name="cube_indices", function="cube_indices", params=("vertices",),
    section="Küp: vertex + index buffer, 36 indices", term="küp indeks tamponu (index buffer)",
    summary="the 36 indices of a box's twelve triangles, clockwise from outside",
    doc=DOC, example="len(cube_indices(((-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1), (-1, -1, -1), "
                     "(1, -1, -1), (1, -1, 1), (-1, -1, 1)))) == 36",
    returns="indices", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the notes' cube (and its corners in another order) from four sides, each pixel its nearest "
                "triangle's face and winding", lambda n: list(_PROBE_INPUTS), draw=_draw),
    mistakes=MISTAKES, order=115, extra={"variants": {"the other diagonal": _variant_other_diagonal}},
)
