"""World, View, Projection: the View matrix, XMMatrixLookAtLH."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import cube_segments, edge_probe, look_at_lh, perspective_fov_lh, row

CONVENTION = ("the course's DirectX row vectors (p_view = p·View, the translation in the last row), "
              "left-handed (the camera looks down +z); OpenGL's column form (the transpose) is not accepted")

DOC = """The View matrix (bakış matrisi), course section "Vertex/pixel shader; World, View, Projection".

XMMatrixLookAtLH(Eye, At, Up) puts the camera at Eye looking at At. The
camera's axes, left-handed (+z into the screen):

    zaxis = normalize(At - Eye)
    xaxis = normalize(cross(Up, zaxis))
    yaxis = cross(zaxis, xaxis)

and, for row vectors (p_view = p·View), the axes are the columns:

    View = |  xaxis.x       yaxis.x       zaxis.x      0 |
           |  xaxis.y       yaxis.y       zaxis.y      0 |
           |  xaxis.z       yaxis.z       zaxis.z      0 |
           | -xaxis·Eye    -yaxis·Eye    -zaxis·Eye    1 |

Up need not be perpendicular to the view nor of length 1 (the notes' up
experiments: (0.7, 0.7, 0.7) rolls the picture 45°). Up parallel to the view
(the notes' up (0, 0, 1) looking along z) has no answer: no case asks it.

Worked example (the notes' camera): Eye (0, 3, -10), At (0, 0, 1),
Up (0, 1, 0): zaxis = (0, -3, 11)/√130, the last row is
(0, -0.263117, 10.436990, 1).
"""


def reference(eye, at, up):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.look_at` (right-handed, column vectors) of the
    mirrored points, converted to the course's form (:func:`glsandbox.exercises.dxmath.look_at_lh`)."""
    return look_at_lh(eye, at, up)


def _axes(eye, at, up, normalize_x=True):  # noqa: ANN001, ANN202
    e, a, u = (np.asarray(v, dtype=np.float64) for v in (eye, at, up))
    z = (a - e) / np.linalg.norm(a - e)
    x = np.cross(u, z)
    if normalize_x:
        x = x / np.linalg.norm(x)
    return e, x, np.cross(z, x), z


def _matrix(e, x, y, z, translation=None):  # noqa: ANN001, ANN202
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = x, y, z
    m[3, :3] = (-x @ e, -y @ e, -z @ e) if translation is None else translation
    return m


def column_vectors(eye, at, up):  # noqa: ANN001, ANN201
    return row(_matrix(*_axes(eye, at, up)).T)


def right_handed(eye, at, up):  # noqa: ANN001, ANN201
    e, x, y, z = _axes(eye, at, up)
    return row(_matrix(e, -x, y, -z))


def right_axis_not_normalized(eye, at, up):  # noqa: ANN001, ANN201
    return row(_matrix(*_axes(eye, at, up, normalize_x=False)))


def eye_not_rotated(eye, at, up):  # noqa: ANN001, ANN201
    e, x, y, z = _axes(eye, at, up)
    return row(_matrix(e, x, y, z, translation=-e))


MISTAKES = (
    Mistake("column_vectors", "that is the column-vector form, the transpose: with p·View the camera's axes "
            "are the columns and -axis·Eye goes in the last row.", column_vectors),
    Mistake("right_handed", "that is OpenGL's right-handed camera (it looks down -z): LookAtLH keeps "
            "zaxis = At - Eye and xaxis = cross(Up, zaxis).", right_handed),
    Mistake("right_axis_not_normalized", "cross(Up, zaxis) has length |Up|·sin(angle): normalize it, or a "
            "tilted or long Up scales the picture.", right_axis_not_normalized),
    Mistake("eye_not_rotated", "the last row is (-xaxis·Eye, -yaxis·Eye, -zaxis·Eye), the eye in the camera's "
            "axes, not -Eye.", eye_not_rotated),
)

VISIBLE = (
    Case("the notes' camera: Eye (0, 3, -10), At (0, 0, 1), Up (0, 1, 0)",
         ((0.0, 3.0, -10.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
         row(reference((0.0, 3.0, -10.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0))), abs=1e-12),
    Case("the notes' up experiment: Up (0.7, 0.7, 0.7) rolls 45°",
         ((0.0, 0.0, -10.0), (0.0, 0.0, 0.0), (0.7, 0.7, 0.7)),
         row(reference((0.0, 0.0, -10.0), (0.0, 0.0, 0.0), (0.7, 0.7, 0.7))), abs=1e-12),
)


def _case(name, eye, at, up, group, **tolerance):  # noqa: ANN001, ANN202
    return Case(name, (eye, at, up), row(reference(eye, at, up)), group=group, **tolerance)


def hidden() -> list[Case]:
    """Tilted and long up vectors, looking back along -z, sideways, up nearly along the view, far eyes."""
    return [
        _case("looking back along -z", (0.0, 0.0, 5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), "cameras", abs=1e-12),
        _case("looking along +x, Up of length 3", (-4.0, 1.0, 2.0), (6.0, 1.0, 2.0), (0.0, 3.0, 0.0), "cameras",
              abs=1e-12),
        _case("an oblique camera, Up tilted", (3.0, -2.0, 7.0), (-1.0, 4.0, 0.5), (0.2, 1.0, -0.3), "cameras",
              abs=1e-12),
        _case("Up almost along the view (1e-3 off the notes' degenerate (0, 0, 1))", (0.0, 0.0, -10.0),
              (0.0, 0.0, 1.0), (0.0, 1e-3, 1.0), "degenerate", rel=1e-9, abs=1e-10),
        _case("an eye far away (1e5)", (1e5, 2e5, -3e5), (1e5 + 1.0, 2e5, -3e5 + 2.0), (0.0, 1.0, 0.0), "scale",
              rel=1e-9, abs=1e-6),
        _case("a tiny scene (1e-4)", (0.0, 1e-4, -1e-4), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), "scale",
              abs=1e-15),
    ]


_PROBE_INPUTS = [((0.0, 3.0, -10.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
                 ((0.0, 0.0, -8.0), (0.0, 0.0, 0.0), (0.7, 0.7, 0.7)),
                 ((6.0, 4.0, 5.0), (0.0, 0.0, 0.0), (0.0, 2.0, 0.0)),
                 ((-5.0, -3.0, -6.0), (0.5, 0.0, 0.0), (0.3, 1.0, 0.2))]
_PROJECTION = perspective_fov_lh(math.pi / 4.0, 1.0, 0.01, 100.0)


def _segments(view: np.ndarray, i: int) -> np.ndarray:
    return cube_segments(view @ _PROJECTION)


EXERCISE = Exercise(
    name="look_at", function="look_at_lh", params=("eye", "at", "up"),
    section="Vertex/pixel shader; World, View, Projection", term="bakış matrisi (View), XMMatrixLookAtLH",
    summary="XMMatrixLookAtLH(Eye, At, Up), the course's row form",
    doc=DOC, example="[round(x, 6) for x in look_at_lh((0, 3, -10), (0, 0, 1), (0, 1, 0))[3]] == "
                     "[0.0, -0.263117, 10.43699, 1.0]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the course's cube seen through View (the notes' camera, the rolled Up, two others) and a "
                "45° projection", lambda n: list(_PROBE_INPUTS), draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=130,
)
