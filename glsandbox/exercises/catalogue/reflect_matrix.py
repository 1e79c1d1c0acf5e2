"""The stencil test: the mirror's matrix, XMMatrixReflect."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import CUBE_POINTS, camera, cube_segments, edge_probe, row

CONVENTION = ("the course's DirectX row vectors (p' = p·Reflect, the translation in the last row); "
              "OpenGL's column form (the transpose) is not accepted")

DOC = """The mirror matrix (yansıma matrisi), course section "Stencil: MarkMirrorDSS, DrawReflectionDSS, XMMatrixReflect, CullClockwise".

The stencil mirror draws the room a second time through
XMMatrixReflect(mirrorPlane). The plane (a, b, c, d) is the points with
a·x + b·y + c·z + d = 0. Normalize it first (XMPlaneNormalize: divide all
four by |(a, b, c)|); then a point p at signed distance s = n·p + d goes to
p - 2·s·n. For row vectors (p' = p·Reflect):

    Reflect = | 1-2aa   -2ba   -2ca   0 |
              | -2ab   1-2bb   -2cb   0 |
              | -2ac   -2bc   1-2cc   0 |
              | -2ad   -2bd   -2cd    1 |

(det = -1: the mirror turns clockwise triangles counter-clockwise, which is
why the reflected pass sets CullClockwise.)

Worked example: the notes' mirror plane (0, 0, 1, -6), z = 6: z goes to
12 - z, the last row is (0, 0, 12, 1).
"""


def reference(plane):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.reflection_matrix` (column vectors), transposed."""
    from glsandbox.transforms import reflection_matrix

    return reflection_matrix(plane).T


def _reflect(plane, *, normalize=True, factor=2.0, sign=1.0):  # noqa: ANN001, ANN202
    p = np.asarray(plane, dtype=np.float64)
    if normalize:
        p = p / np.linalg.norm(p[:3])
    n, d = p[:3], p[3]
    m = np.eye(4)
    m[:3, :3] -= factor * np.outer(n, n)
    m[3, :3] = -factor * sign * d * n
    return m


def column_vectors(plane):  # noqa: ANN001, ANN201
    return row(_reflect(plane).T)


def plane_not_normalized(plane):  # noqa: ANN001, ANN201
    return row(_reflect(plane, normalize=False))


def distance_sign(plane):  # noqa: ANN001, ANN201
    return row(_reflect(plane, sign=-1.0))


def projected_not_mirrored(plane):  # noqa: ANN001, ANN201
    return row(_reflect(plane, factor=1.0))


MISTAKES = (
    Mistake("column_vectors", "that is the column-vector form, the transpose: with p·Reflect the -2d·n "
            "goes in the last row.", column_vectors),
    Mistake("plane_not_normalized", "normalize the plane first (divide a, b, c, d by |(a, b, c)|): "
            "(0, 0, 2, -12) is the same mirror as (0, 0, 1, -6).", plane_not_normalized),
    Mistake("distance_sign", "the point moves by -2·s·n with s = n·p + d: the last row is -2d·n, so z = 6 "
            "sends the origin to z = 12, not -12.", distance_sign),
    Mistake("projected_not_mirrored", "p - s·n lands on the mirror (a projection); the image is twice as "
            "far, p - 2·s·n.", projected_not_mirrored),
)

VISIBLE = (
    Case("the notes' mirror plane (0, 0, 1, -6): z = 6", ((0.0, 0.0, 1.0, -6.0),),
         row(reference((0.0, 0.0, 1.0, -6.0)))),
)


def hidden() -> list[Case]:
    """Unnormalized planes, planes through the origin, oblique planes, far and tiny mirrors."""
    s = 1.0 / math.sqrt(2.0)
    planes = [("the mirror plane scaled: (0, 0, 2, -12)", (0.0, 0.0, 2.0, -12.0), "planes"),
              ("the floor y = -2 written (0, 3, 0, 6)", (0.0, 3.0, 0.0, 6.0), "planes"),
              ("through the origin, x = y", (s, -s, 0.0, 0.0), "planes"),
              ("an oblique plane (1, 2, -2, 3)", (1.0, 2.0, -2.0, 3.0), "planes"),
              ("a mirror far away (z = 1e5)", (0.0, 0.0, 1.0, -1e5), "scale"),
              ("a tiny room (x = 1e-4)", (-1.0, 0.0, 0.0, 1e-4), "scale")]
    return [Case(name, (p,), row(reference(p)), rel=1e-9, abs=1e-12, group=group) for name, p, group in planes]


_PROBE_INPUTS = [((0.0, 0.0, 1.0, -6.0),), ((0.0, 2.0, 0.0, 2.0),), ((1.0, 0.0, 1.0, -5.0),),
                 ((1.0, -1.0, 0.0, 1.0),)]
_CUBE = CUBE_POINTS * np.array([0.8, 0.8, 0.8, 1.0]) + np.array([1.0, 1.0, 3.0, 0.0])
_VIEW = camera((11.0, 7.0, -6.0), (0.0, 0.0, 5.0))


def _segments(reflect: np.ndarray, i: int) -> np.ndarray:
    return np.concatenate([cube_segments(_VIEW, _CUBE), cube_segments(reflect @ _VIEW, _CUBE)])


EXERCISE = Exercise(
    name="reflect_matrix", function="reflect_matrix", params=("plane",),
    section="Stencil: MarkMirrorDSS, DrawReflectionDSS, XMMatrixReflect, CullClockwise",
    term="yansıma matrisi (XMMatrixReflect), ayna",
    summary="XMMatrixReflect(plane): the mirror image through a plane, the course's row form",
    doc=DOC, example="list(reflect_matrix((0, 0, 1, -6))[3]) == [0.0, 0.0, 12.0, 1.0]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("a cube near (1, 1, 3) and its mirror image through z = 6, y = -1, x + z = 5 and x = y - 1",
                lambda n: list(_PROBE_INPUTS), draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=170,
)
