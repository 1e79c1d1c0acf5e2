"""Planar shadows: the shadow's matrix, XMMatrixShadow."""

from __future__ import annotations

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import CUBE_POINTS, camera, cube_segments, edge_probe, row

CONVENTION = ("the course's DirectX row vectors (p' = p·Shadow, then the divide by w); "
              "OpenGL's column form (the transpose) is not accepted")

DOC = """The planar shadow's matrix (gölge matrisi), course section "XMMatrixShadow, shadowOffsetY".

XMMatrixShadow(shadowPlane, light) flattens the model onto the plane
P = (a, b, c, d) along the rays from the light L = (x, y, z, w): w = 1 a point
light at (x, y, z), w = 0 a directional light, (x, y, z) pointing *towards*
the light (the notes pass toMainLight = -lightDir). Normalize the plane
first (divide all four by |(a, b, c)|); the light's direction is already of
length 1 in every case. With dot = P·L over all four components, for row
vectors (p' = p·Shadow):

    Shadow = dot·I - Pᵀ·L        (row i, column j: dot·δij - P_i·L_j)

so p·Shadow = dot·p - (P·p)·L: a point on the line through p and the
light, and P·(p·Shadow) = 0, on the plane. Its w is dot - (P·p)·L.w, which
must stay positive or the GPU clips the vertex.

Worked example: the notes' floor y = -2, P = (0, 1, 0, 2), and their light
direction (0.6, -0.8, 0), so L = toMainLight = (-0.6, 0.8, 0, 0): dot = 0.8;
the origin goes to (1.2, -1.6, 0, 0.8), its shadow is at (1.5, -2, 0).
Passing (0.6, -0.8, 0, 0) itself gives the same points with w = -0.8 < 0.
"""


def reference(plane, light):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.shadow_matrix` (column vectors), transposed."""
    from glsandbox.transforms import shadow_matrix

    return shadow_matrix(plane, light).T


def _shadow(plane, light, *, sign=1.0, whole=1.0, with_w=True):  # noqa: ANN001, ANN202
    p = np.asarray(plane, dtype=np.float64)
    p = p / np.linalg.norm(p[:3])
    l = np.asarray(light, dtype=np.float64)
    dot = float(p @ l) if with_w else float(p[:3] @ l[:3])
    return whole * (dot * np.eye(4) - sign * np.outer(p, l))


def column_vectors(plane, light):  # noqa: ANN001, ANN201
    return row(_shadow(plane, light).T)


def whole_sign(plane, light):  # noqa: ANN001, ANN201
    return row(_shadow(plane, light, whole=-1.0))


def plus_sign(plane, light):  # noqa: ANN001, ANN201
    return row(_shadow(plane, light, sign=-1.0))


def dot_without_w(plane, light):  # noqa: ANN001, ANN201
    return row(_shadow(plane, light, with_w=False))


MISTAKES = (
    Mistake("column_vectors", "that is the column-vector form, the transpose: with p·Shadow row i is "
            "dot·e_i - P_i·L.", column_vectors),
    Mistake("whole_sign", "the matrix's sign matters: P·Lᵀ - dot·I gives the same points with w < 0, and the "
            "GPU clips every one of them (the shadow vanishes); it is dot·I - Pᵀ·L.", whole_sign),
    Mistake("plus_sign", "dot·I - Pᵀ·L, minus: with a plus the points leave the plane instead of landing on it.",
            plus_sign),
    Mistake("dot_without_w", "dot = P·L takes all four components: for a point light (w = 1) it includes the "
            "plane's d.", dot_without_w),
)

FLOOR, TO_LIGHT, LIGHT_DIR = (0.0, 1.0, 0.0, 2.0), (-0.6, 0.8, 0.0, 0.0), (0.6, -0.8, 0.0, 0.0)

VISIBLE = (
    Case("the notes' floor (0, 1, 0, 2), toMainLight = -(0.6, -0.8, 0)", (FLOOR, TO_LIGHT),
         row(reference(FLOOR, TO_LIGHT))),
    Case("the notes' light direction (0.6, -0.8, 0, 0) passed as is (w = -0.8)", (FLOOR, LIGHT_DIR),
         row(reference(FLOOR, LIGHT_DIR))),
    Case("a point light at (2, 6, -1) over the floor", (FLOOR, (2.0, 6.0, -1.0, 1.0)),
         row(reference(FLOOR, (2.0, 6.0, -1.0, 1.0)))),
)


def hidden() -> list[Case]:
    """Unnormalized and oblique planes, point lights, lights grazing the plane, far and tiny scenes."""
    cases = [("the floor written (0, 4, 0, 8)", (0.0, 4.0, 0.0, 8.0), TO_LIGHT, "planes"),
             ("a wall x = 3 under a point light", (-1.0, 0.0, 0.0, 3.0), (-2.0, 1.0, 4.0, 1.0), "planes"),
             ("an oblique plane, an oblique sun", (1.0, 2.0, 2.0, -1.0), (0.0, 0.6, 0.8, 0.0), "planes"),
             ("a low sun, 1e-3 above the horizon", FLOOR, (0.9999995, 1e-3, 0.0, 0.0), "grazing"),
             ("a point light just above the floor", FLOOR, (0.0, -1.999, 0.0, 1.0), "grazing"),
             ("a point light far away (1e5)", FLOOR, (1e5, 1e5, -1e5, 1.0), "scale"),
             ("a tiny scene (1e-4)", (0.0, 1.0, 0.0, 1e-4), (1e-4, 1e-3, 0.0, 1.0), "scale")]
    return [Case(name, (p, l), row(reference(p, l)), rel=1e-9, abs=1e-12, group=group)
            for name, p, l, group in cases]


_PROBE_INPUTS = [(FLOOR, TO_LIGHT), (FLOOR, (2.0, 5.0, -1.0, 1.0)), (FLOOR, (0.0, 0.6, -0.8, 0.0)),
                 ((0.0, 1.0, 0.0, 2.0), (-3.0, 4.0, 2.0, 1.0))]
_CUBE = CUBE_POINTS * np.array([0.7, 0.7, 0.7, 1.0]) + np.array([0.0, 0.5, 0.0, 0.0])
_VIEW = camera((3.0, 8.0, -10.0), (0.0, -1.0, 0.0))


def _segments(shadow: np.ndarray, i: int) -> np.ndarray:
    return np.concatenate([cube_segments(_VIEW, _CUBE), cube_segments(shadow @ _VIEW, _CUBE)])


EXERCISE = Exercise(
    name="shadow_matrix", function="shadow_matrix", params=("plane", "light"),
    section="XMMatrixShadow, shadowOffsetY", term="düzlemsel gölge matrisi (XMMatrixShadow)",
    summary="XMMatrixShadow(plane, light): flatten onto a plane along the light's rays, the course's row form",
    doc=DOC, example="[round(x, 9) for x in shadow_matrix((0, 1, 0, 2), (-0.6, 0.8, 0, 0))[3]] == "
                     "[1.2, -1.6, 0.0, 0.8]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("a cube over the floor y = -2 and its flattened shadow: the notes' sun, point lights at "
                "(2, 5, -1) and (-3, 4, 2), a sun from (0, 0.6, -0.8)", lambda n: list(_PROBE_INPUTS),
                draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=180,
)
