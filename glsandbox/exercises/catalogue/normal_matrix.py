"""Lighting: the matrix that carries normals, the inverse transpose of World."""

from __future__ import annotations

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import CUBE_POINTS, camera, cube_segments, edge_probe, row

CONVENTION = ("the course's DirectX row vectors (n' = n·NormalMatrix, as the shader's mul(Input.Norm, M)); "
              "OpenGL's column form (the transpose) is not accepted")

DOC = """The normal matrix (normal matrisi), course section "Lighting: two lights, Phong in the pixel shader".

The Lighting tutorial turns the normals with the World matrix itself,
Output.Norm = mul(Input.Norm, World). That is right for rotations only:
under a non-uniform scale a surface's tangent t goes to t·A (A the
upper-left 3x3 of World) and the normal must stay perpendicular to it, so
normals go through

    N = (A⁻¹)ᵀ        (the inverse transpose), n' = n·N

(for a rotation A⁻¹ = Aᵀ, so N = A; under a uniform scale s, N = A / s²).
`world` is the course's World (row vectors, four rows of four). Return the
4x4 with N in its upper-left 3x3 and (0, 0, 0, 1) as its last row and
column; the whole 4x4 inverse transpose of World is accepted too (its last
column only reaches w, which a normal (x, y, z, 0) leaves alone).

Worked example: World = XMMatrixScaling(2, 2, 2) (a uniform scale):
N = diag(0.5, 0.5, 0.5), where World's own 3x3 would give diag(2, 2, 2).
"""


def _embed(n3: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = n3
    return m


def reference(world):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.normal_matrix` of the column form (World
    transposed), transposed back, in a 4x4."""
    from glsandbox.transforms import normal_matrix

    return _embed(normal_matrix(np.asarray(world, dtype=np.float64).T).T)


def _block(world):  # noqa: ANN001, ANN202
    return np.asarray(world, dtype=np.float64)[:3, :3]


def naive_world(world):  # noqa: ANN001, ANN201
    return row(_embed(_block(world)))


def inverse_only(world):  # noqa: ANN001, ANN201
    return row(_embed(np.linalg.inv(_block(world))))


def transpose_only(world):  # noqa: ANN001, ANN201
    return row(_embed(_block(world).T))


MISTAKES = (
    Mistake("naive_world", "mul(Input.Norm, World) is right for rotations only: under a scale the normals "
            "lean off the surface; use the inverse transpose of World's 3x3.", naive_world),
    Mistake("inverse_only", "the inverse without the transpose (which is also the inverse transpose in "
            "column-vector form): for n·N the matrix is (A⁻¹)ᵀ.", inverse_only),
    Mistake("transpose_only", "the transpose without the inverse: a scale of 2 must shrink normals by 1/2, "
            "so N = (A⁻¹)ᵀ.", transpose_only),
)


def _world(scale=(1.0, 1.0, 1.0), angle=0.0, move=(0.0, 0.0, 0.0), shear=0.0):  # noqa: ANN001, ANN202
    """A row-form World: scale, shear x by y, rotate about y, move (row vectors: in that order)."""
    from glsandbox.transforms import rotate_y
    from glsandbox.transforms import scale as scaling
    from glsandbox.transforms import translate

    shearing = np.eye(4)
    shearing[0, 1] = shear
    return row((translate(*move) @ rotate_y(angle) @ shearing @ scaling(*scale)).T)


def _case(name, world, group, **tolerance):  # noqa: ANN001, ANN202
    full = np.linalg.inv(np.asarray(world, dtype=np.float64)).T
    return Case(name, (world,), row(reference(world)), also=(row(full),), group=group,
                margin="the whole 4x4 inverse transpose draws the same normals", **tolerance)


VISIBLE = (
    _case("the Lighting tutorial's turn: rotate 0.5 about y, move to (0, 0, 5)",
          _world(angle=0.5, move=(0.0, 0.0, 5.0)), "visible", abs=1e-12),
    _case("a uniform scale 2", _world(scale=(2.0, 2.0, 2.0)), "visible"),
)


def hidden() -> list[Case]:
    """Non-uniform scales (the second cube's), scale then turn, a shear, far and tiny worlds."""
    return [
        _case("the second cube's scale (0.3, 1, 0.3)", _world(scale=(0.3, 1.0, 0.3)), "non-uniform", abs=1e-12),
        _case("scale (3, 1, 0.5), turn 1.1, move", _world((3.0, 1.0, 0.5), 1.1, (1.0, 2.0, 3.0)), "non-uniform",
              abs=1e-12),
        _case("a shear (x += 0.8 y), turned", _world(angle=-0.4, shear=0.8), "non-uniform", abs=1e-12),
        _case("moved far away (1e5)", _world((2.0, 1.0, 1.0), 0.3, (1e5, -1e5, 1e5)), "scale", abs=1e-12),
        _case("a tiny model (scale 1e-4)", _world((1e-4, 2e-4, 1e-4), 0.7), "scale", rel=1e-9, abs=1e-6),
    ]


_PROBE_INPUTS = [(_world((2.0, 0.5, 1.0), 0.6),), (_world((0.3, 1.0, 0.3), -0.5),),
                 (_world(angle=0.3, shear=0.9),), (_world((1.5, 1.5, 1.5), 2.0),)]
_VIEW = camera((4.0, 5.0, -8.0))
#: The centres of the cube's six faces and their outward normals (row vectors).
_FACES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64)


def _segments(normals: np.ndarray, i: int) -> np.ndarray:
    world = np.asarray(_PROBE_INPUTS[i][0], dtype=np.float64)
    start = np.hstack([_FACES, np.ones((6, 1))]) @ world
    end = start + np.hstack([1.2 * _FACES @ normals[:3, :3], np.zeros((6, 1))])
    tips = np.stack([start @ _VIEW, end @ _VIEW], axis=1)
    return np.concatenate([cube_segments(world @ _VIEW, CUBE_POINTS), tips])


EXERCISE = Exercise(
    name="normal_matrix", function="normal_matrix", params=("world",),
    section="Lighting: two lights, Phong in the pixel shader", term="normal matrisi (ters devrik, inverse transpose)",
    summary="the matrix that carries normals: the inverse transpose of World's 3x3, the course's row form",
    doc=DOC, example="[round(normal_matrix([[2, 0, 0, 0], [0, 2, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]])[i][i], 9) "
                     "for i in range(4)] == [0.5, 0.5, 0.5, 1.0]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("four scaled, sheared and turned cubes (grey when both agree) with the six face normals "
                "n·N drawn from the faces' centres", lambda n: list(_PROBE_INPUTS), draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=150,
)
