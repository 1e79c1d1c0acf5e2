"""The pure foundation: the DirectX conversion, geometry, plans. No GL."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.plan import plan


def outward(triangles: np.ndarray) -> np.ndarray:
    """Per triangle: does the counter-clockwise normal point away from the origin?"""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    normal = np.cross(b - a, c - a)
    return np.einsum("ij,ij->i", normal, (a + b + c) / 3) > 0


def test_course_cube_has_8_vertices_and_36_indices() -> None:
    cube = geometry.cube()
    assert cube.positions.shape == (8, 3)
    assert cube.indices.shape == (36,)
    assert sorted(set(cube.indices.tolist())) == list(range(8))


def test_course_cube_is_clockwise_in_directx_and_counter_clockwise_after_conversion() -> None:
    # In the course's left-handed frame every triangle's algebraic normal
    # (b-a)x(c-a) points outward, which a left-handed viewer sees clockwise.
    course = geometry.COURSE_CUBE_VERTICES[geometry.COURSE_CUBE_INDICES.reshape(-1, 3)]
    assert outward(course).all()
    # After the one conversion (mirror z, swap two indices) they are
    # counter-clockwise as seen from outside in OpenGL: all front faces.
    assert outward(geometry.cube().triangles()).all()


def test_mirror_alone_would_make_every_face_a_back_face() -> None:
    mirrored = geometry.COURSE_CUBE_VERTICES * np.array([1, 1, -1])
    tri = mirrored[geometry.COURSE_CUBE_INDICES.reshape(-1, 3)]
    assert not outward(tri).any()


def test_directx_matrix_conversion_flips_rotation_sense_about_y() -> None:
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    # XMMatrixRotationY (row-vector form, left-handed).
    dx = np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(transforms.from_directx_matrix(dx), transforms.rotate_y(-angle), atol=1e-15)
    # A DirectX point transformed then converted equals converted then transformed.
    p = np.array([1.0, 2.0, 3.0])
    via_dx = (np.append(p, 1.0) @ dx)[:3]
    via_gl = transforms.transform_points(transforms.from_directx_matrix(dx), transforms.from_directx_point(p)[None])[0]
    np.testing.assert_allclose(transforms.from_directx_point(via_dx), via_gl, atol=1e-12)


def test_compose_applies_the_order_string_left_to_right() -> None:
    S, T, R = transforms.scale(0.3, 1, 0.3), transforms.translate(4, 0, 0), transforms.rotate_y(np.pi / 2)
    np.testing.assert_array_equal(transforms.compose("STR", S=S, T=T, R=R), R @ T @ S)
    # Translate then scale: the distance 4 shrinks to 4 * 0.3 = 1.2 (course).
    m = transforms.compose("TSR", S=S, T=T, R=np.eye(4))
    assert transforms.transform_points(m, np.zeros((1, 3)))[0, 0] == pytest.approx(1.2)
    with pytest.raises(SandboxError, match="valid orders: STR, SRT"):
        transforms.parse_order("SST")


def test_perspective_matches_the_textbook_formula() -> None:
    m = transforms.perspective(45.0, 16 / 9, 0.01, 100.0)
    f = 1 / np.tan(np.radians(22.5))
    assert m[0, 0] == pytest.approx(f * 9 / 16)
    assert m[1, 1] == pytest.approx(f)
    assert m[3, 2] == -1.0
    # The near plane maps to depth -1 and the far plane to +1.
    for z, ndc in ((-0.01, -1.0), (-100.0, 1.0)):
        clip = m @ np.array([0, 0, z, 1.0])
        assert clip[2] / clip[3] == pytest.approx(ndc)


def test_look_at_puts_the_target_straight_ahead() -> None:
    view = transforms.look_at((0, 3, 10), (0, 0, 0), (0, 1, 0))
    eye_space = view @ np.array([0, 0, 0, 1.0])
    np.testing.assert_allclose(eye_space[:2], 0, atol=1e-12)
    assert eye_space[2] == pytest.approx(-np.sqrt(109))  # in front: negative z
    with pytest.raises(SandboxError, match="parallel to the view direction"):
        transforms.look_at((0, 0, 0), (0, 0, 5), (0, 0, 1))


def test_strip_and_list_quads_cover_the_same_triangles_with_the_same_winding() -> None:
    def canonical(tris: np.ndarray) -> list:
        out = []
        for t in tris:  # rotate each triangle so its smallest vertex is first: keeps winding
            k = min(range(3), key=lambda i: tuple(t[i]))
            out.append(tuple(map(tuple, np.roll(t, -k, axis=0))))
        return sorted(out)

    strip, quad_list = geometry.quad_strip(), geometry.quad_list()
    assert strip.vertex_count == 4 and quad_list.vertex_count == 6
    assert canonical(strip.triangles()) == canonical(quad_list.triangles())
    swapped = geometry.quad_list_swapped().triangles()
    normals_z = np.cross(swapped[:, 1] - swapped[:, 0], swapped[:, 2] - swapped[:, 0])[:, 2]
    assert normals_z[0] > 0 > normals_z[1]


# --- plans: one pinned per lesson -------------------------------------------

PINNED_PLANS = {
    "clear_and_swap": """plan for clear_and_swap
buffers: colour RGBA8, no MSAA
programs:
  (none)
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1)
  2. clear viewport 1: colour (0.6, 0.125, 0, 1)""",
    "triangle": """plan for triangle
buffers: colour RGBA8, no MSAA
programs:
  basic[SOLID_COLOR]
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1)
  2. draw viewport 0 (no depth test): strip with basic[SOLID_COLOR]
  3. clear viewport 1: colour (0, 0.125, 0.6, 1)
  4. draw viewport 1 (no depth test): list with basic[SOLID_COLOR]""",
    "indexed_cube": """plan for indexed_cube
buffers: colour RGBA8, depth 24, no MSAA
programs:
  basic[VERTEX_COLOR]
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1) + depth
  2. draw viewport 0 (depth test): cube with basic[VERTEX_COLOR]""",
}


@pytest.mark.parametrize("name", sorted(PINNED_PLANS))
def test_lesson_plan_is_pinned(name: str) -> None:
    assert plan(find_lesson(name)().scene()).describe() == PINNED_PLANS[name]


def test_every_lesson_has_a_course_section_and_builds_a_scene_at_any_time() -> None:
    for cls in all_lessons():
        assert cls.course_section and cls.title
        for t in (0.0, 1.25):
            scene = cls(time=t).scene()
            assert scene.viewports


def test_single_viewport_split_off_plans_one_clear() -> None:
    scene = find_lesson("clear_and_swap").from_settings(["split=off"]).scene()
    assert [p.kind for p in plan(scene).passes] == ["clear"]


def test_unknown_lesson_suggests_the_closest_name() -> None:
    with pytest.raises(SandboxError, match="did you mean 'indexed_cube'"):
        find_lesson("indexed_cub")
