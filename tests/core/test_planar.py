"""The planar effects as scene data (glsandbox/planar.py): a mirror's plane normalized, and which
casters a planar shadow keeps: none above a point light, the caster's bounding box deciding as its
vertices would (course section "The stencil Test", ``XMMatrixShadow``)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.lessons.mirror import MirrorLesson
from glsandbox.plan import plan
from glsandbox.planar import Mirror, PlanarShadow, shadow_casters

RNG = np.random.default_rng(5)


def test_a_mirrors_plane_is_normalized_and_it_cannot_reflect_itself() -> None:
    assert Mirror("glass", (0, 0, 2, 8), ("cube",)).plane == (0.0, 0.0, 1.0, 4.0)
    with pytest.raises(SandboxError, match="cannot reflect itself"):
        Mirror("glass", (0, 0, 1, 4), ("glass",))


def test_caster_above_a_point_light_is_culled():
    # The cube's top is at 0.6 + 0.6 = 1.2; a light at 1.0 has vertices above it.
    step = [p for p in plan(MirrorLesson(ly=1.0).scene()).passes if p.kind == "planar_shadow"][0]
    assert step.draws == () and "cube culled" in step.describe()
    shadow = PlanarShadow("floor", (0, 1, 0, 0), (0, 2, 0, 1), ("box",))
    box = (np.eye(4), np.array([[0, 1.9, 0], [0, 2.0, 0], [1, 0.5, 0]]))
    assert shadow_casters(shadow, {"box": box}).culled[0][0] == "box"
    assert shadow_casters(shadow, {"box": (transforms.translate(0, -0.2, 0), box[1])}).kept == ("box",)


def test_the_casters_box_decides_as_their_vertices_do():
    # A read-only mesh array is checked from its bounding box first (planar._below_by_box, once per
    # frame for a moving caster); a writable copy goes by its vertices alone. Moved and turned so
    # that the top vertex lands at, just under and just over the light's height: the same decisions
    # and reasons, and the box alone keeps the casters clearly below.
    from glsandbox.planar import _below_by_box

    light_y = 2.0
    shadow = PlanarShadow("floor", (0, 1, 0, 0), (0.3, light_y, -0.2, 1), ("part",))
    # A box's corners and points inside it: the box is the points' own, so its bound is their top.
    half = RNG.uniform(0.2, 0.6, 3)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    points = np.vstack([corners, RNG.uniform(-half, half, (32, 3))]) + RNG.uniform(-1, 1, 3)
    frozen = points.copy()
    frozen.setflags(write=False)
    kept_by_box = 0
    for _ in range(300):
        turn = transforms.rotate_y(RNG.uniform(0, 6.3)) @ transforms.rotate_x(RNG.uniform(0, 6.3))
        model = turn @ transforms.scale(*RNG.uniform(0.2, 2.0, 3))
        top = float(np.max(transforms.transform_points(model, points)[:, 1]))
        model = transforms.translate(0.0, light_y - top + RNG.choice([-0.3, -1e-6, -1e-10, 0.0, 1e-10, 0.2]), 0.0) @ model
        exact = shadow_casters(shadow, {"part": (model, points)})
        assert shadow_casters(shadow, {"part": (model, frozen)}) == exact
        if _below_by_box(shadow.plane, shadow.height, model, frozen):
            assert exact.kept == ("part",)
            kept_by_box += 1
    assert kept_by_box > 0
    lesson = MirrorLesson().scene()
    cube = next(node for node in lesson.nodes if node.name == "cube")
    assert _below_by_box(lesson.planar_shadow.plane, lesson.planar_shadow.height, cube.model, cube.mesh.positions)
    # What the box cannot tell, the vertices decide: a writable array, a projective model.
    projective = np.eye(4)
    projective[3] = (0.0, 0.1, 0.0, 1.0)
    assert not _below_by_box(shadow.plane, shadow.height, np.eye(4), points)
    assert not _below_by_box(shadow.plane, shadow.height, projective, frozen)
