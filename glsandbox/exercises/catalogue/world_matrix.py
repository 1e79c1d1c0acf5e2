"""Rotation, two cubes, transform order: the World matrix for an order string such as "STR"."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import camera, cube_segments, edge_probe, row

CONVENTION = ("the course's DirectX row vectors: a point is a row, p' = p·World, and the product "
              "mScale·mTranslate·mRotate applies S first; OpenGL's column form (its transpose) is not accepted")

DOC = """The World matrix (dünya matrisi), course section "Rotation, two cubes, transform order".

The second cube of the notes is scaled, moved and turned with
S = XMMatrixScaling(0.3, 1, 0.3), T = XMMatrixTranslation(4, 0, 0) and
R = XMMatrixRotationY(angle) (angle in radians). `order` lists them in the
order they act on a vertex: "STR" is the course's

    World = mScale * mTranslate * mRotate

Convention: DirectX row vectors, p' = p·World, so the matrix written first
acts first and the translation sits in the last row. In that form

    XMMatrixRotationY(a) = | cos a  0  -sin a  0 |
                           |   0    1    0     0 |
                           | sin a  0   cos a  0 |
                           |   0    0    0     1 |

Return World as four rows of four numbers.

Worked example: translate, then scale ("TSR", angle 0): the scale shrinks
the distance too, the last row is (4 × 0.3, 0, 0, 1) = (1.2, 0, 0, 1).
"""


def reference(order, angle):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.compose` of its scale, translate and rotate_y
    (column vectors), transposed into the course's row form."""
    from glsandbox.transforms import compose, rotate_y, scale, translate

    m = compose(order, S=scale(0.3, 1.0, 0.3), T=translate(4.0, 0.0, 0.0), R=rotate_y(float(angle)))
    return m.T


def _parts(angle: float) -> dict[str, np.ndarray]:
    c, s = math.cos(angle), math.sin(angle)
    return {"S": np.diag([0.3, 1.0, 0.3, 1.0]),
            "T": np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [4, 0, 0, 1]], dtype=np.float64),
            "R": np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1]], dtype=np.float64)}


def _product(order: str, angle: float) -> np.ndarray:
    parts, m = _parts(angle), np.eye(4)
    for letter in order.upper():
        m = m @ parts[letter]
    return m


def order_reversed(order, angle):  # noqa: ANN001, ANN201
    return row(_product(order[::-1], angle))


def column_vectors(order, angle):  # noqa: ANN001, ANN201
    return row(_product(order, angle).T)


def angle_in_degrees(order, angle):  # noqa: ANN001, ANN201
    return row(_product(order, math.radians(angle)))


def rotation_right_handed(order, angle):  # noqa: ANN001, ANN201
    return row(_product(order, -angle))


MISTAKES = (
    Mistake("order_reversed", "with row vectors the matrix written first acts first: \"STR\" is "
            "mScale*mTranslate*mRotate, not mRotate*mTranslate*mScale.", order_reversed),
    Mistake("column_vectors", "that is OpenGL's column-vector form, the transpose: the course multiplies "
            "p·World, so the translation goes in the last row, not the last column.", column_vectors),
    Mistake("angle_in_degrees", "the angle is in radians already: math.cos(angle), not "
            "math.cos(math.radians(angle)).", angle_in_degrees),
    Mistake("rotation_right_handed", "XMMatrixRotationY turns x towards -z in row form: row 0 is "
            "(cos a, 0, -sin a, 0), row 2 is (sin a, 0, cos a, 0).", rotation_right_handed),
)

VISIBLE = (
    Case("\"STR\", angle 0: scaled, then moved to (4, 0, 0)", ("STR", 0.0), row(reference("STR", 0.0))),
    Case("\"TSR\", angle 0: moved, then scaled: 4 × 0.3 = 1.2", ("TSR", 0.0), row(reference("TSR", 0.0))),
    Case("\"STR\", a quarter turn: the cube orbits to (0, 0, -4)", ("STR", math.pi / 2),
         row(reference("STR", math.pi / 2)), abs=1e-12),
)


def hidden() -> list[Case]:
    """Every order at turns that tell the signs and the order apart; a negative angle; many turns."""
    cases = [Case(f"\"{o}\" at {a:g} rad", (o, a), row(reference(o, a)), abs=1e-12, group="orders")
             for o in ("STR", "SRT", "TSR", "TRS", "RST", "RTS") for a in (0.3, 2.0)]
    cases += [Case("\"RTS\" at -1.1 rad", ("RTS", -1.1), row(reference("RTS", -1.1)), abs=1e-12, group="angles"),
              Case("\"STR\" after 100 turns and a bit", ("STR", 200 * math.pi + 0.5),
                   row(reference("STR", 200 * math.pi + 0.5)), rel=1e-9, abs=1e-11, group="angles")]
    return cases


_PROBE_INPUTS = [("STR", 0.7), ("TSR", 2.3), ("RTS", 0.7), ("TRS", -1.0)]
_VIEW = camera((0.0, 9.0, -10.0))


def _segments(world: np.ndarray, i: int) -> np.ndarray:
    return cube_segments(world @ _VIEW)


EXERCISE = Exercise(
    name="world_matrix", function="world_matrix", params=("order", "angle"),
    section="Rotation, two cubes, transform order", term="dünya matrisi (World), dönüşüm sırası",
    summary="the World matrix of S = scale(0.3, 1, 0.3), T = translate(4, 0, 0), R = rotate_y(angle) in order",
    doc=DOC, example="[round(x, 9) for x in world_matrix('TSR', 0.0)[3]] == [1.2, 0.0, 0.0, 1.0]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the course's cube under World for \"STR\" 0.7, \"TSR\" 2.3, \"RTS\" 0.7, \"TRS\" -1.0, "
                "seen from above", lambda n: list(_PROBE_INPUTS), draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=120,
)
