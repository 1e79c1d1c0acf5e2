"""The transform-order lesson (course section "Rotation, two cubes, transform order")
and the conventions it rests on: order strings, pyrr's operator order, the DirectX
conversion and look_at's up vector."""

from __future__ import annotations

import math

import numpy as np
import pyrr
import pytest

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.plan import plan
from glsandbox.lessons.transform_order import TransformOrder, order_classes, second_cube_model

SIZE = (256, 256)
#: The classes the course claims: at time 0 only the order of S and T matters;
#: later S and R commute (the scale is 0.3 along both x and z) but nothing else does.
CLASSES_AT_0 = {frozenset({"STR", "SRT", "RST"}), frozenset({"TSR", "TRS", "RTS"})}
CLASSES_LATER = {frozenset({"STR"}), frozenset({"SRT", "RST"}), frozenset({"RTS"}), frozenset({"TSR", "TRS"})}


def as_sets(groups) -> set[frozenset[str]]:
    return {frozenset(g) for g in groups}


# --- order strings, from matrices -----------------------------------------------


def test_order_string_is_the_order_applied_to_a_vertex() -> None:
    S, T, R = transforms.scale(0.3, 1, 0.3), transforms.translate(4, 0, 0), transforms.rotate_y(0.7)
    assert np.array_equal(transforms.compose("STR", S=S, T=T, R=R), R @ T @ S)
    assert np.array_equal(transforms.compose("RTS", S=S, T=T, R=R), S @ T @ R)
    with pytest.raises(SandboxError, match="valid orders: STR, SRT, TSR, TRS, RST, RTS"):
        transforms.parse_order("SST")


def test_six_orders_fall_into_two_classes_at_time_0_and_four_later() -> None:
    assert as_sets(order_classes(0.0)) == CLASSES_AT_0
    assert as_sets(order_classes(1.0)) == CLASSES_LATER


def test_translate_then_rotate_orbits_and_rotate_then_translate_spins_in_place() -> None:
    def centre(order: str, angle: float) -> np.ndarray:
        return transforms.transform_points(second_cube_model(order, angle), np.zeros((1, 3)))[0]

    for angle in (0.3, 1.0, 2.5):
        assert np.linalg.norm(centre("STR", angle)) == pytest.approx(4.0)  # T then R: orbit, radius 4
        assert np.allclose(centre("SRT", angle), (4, 0, 0))  # R then T: in place
        # T then S: the scale shrinks the distance too, 4 × 0.3 = 1.2.
        assert np.linalg.norm(centre("TSR", angle)) == pytest.approx(1.2)
        assert np.allclose(centre("RTS", angle), (1.2, 0, 0))
    assert not np.allclose(centre("STR", 0.3), centre("STR", 1.0))


def test_pyrr_multiplication_applies_the_right_operand_first() -> None:
    # A known trap: pyrr matrices are row-vector form, and a * b
    # means "apply b, then a" (it computes b @ a in row-vector terms).
    t = pyrr.Matrix44.from_translation([4.0, 0.0, 0.0])
    s = pyrr.Matrix44.from_scale([0.3, 1.0, 0.3])
    point = pyrr.Vector4([0.0, 0.0, 0.0, 1.0])
    scaled_last = np.asarray(point) @ np.asarray(s * t)  # row vector: v @ (s*t) applies t, then s
    assert np.allclose(scaled_last[:3], (1.2, 0, 0))
    assert np.allclose(np.asarray(s * t), np.asarray(t) @ np.asarray(s))
    # glsandbox's column-vector form of the same thing is S @ T.
    ours = transforms.scale(0.3, 1, 0.3) @ transforms.translate(4, 0, 0)
    assert np.allclose(ours, np.asarray(s * t).T)


def test_directx_product_converts_to_the_gl_order() -> None:
    # The course's mScale * mTranslate * mRotate (row vectors, left-handed) is
    # R @ T @ S in OpenGL once converted by the z mirror.
    a = 0.8
    c, s = math.cos(a), math.sin(a)
    dx_s = np.diag([0.3, 1, 0.3, 1])
    dx_t = np.eye(4)
    dx_t[3, :3] = (4, 0, 0)
    dx_r = np.array([[c, 0, -s, 0], [0, 1, 0, 0], [s, 0, c, 0], [0, 0, 0, 1]])  # XMMatrixRotationY(a)
    converted = transforms.from_directx_matrix(dx_s @ dx_t @ dx_r)
    assert np.allclose(converted, second_cube_model("STR", a), atol=1e-12)
    # The same vertex lands on the same (mirrored) place either way.
    v_dx = np.array([1.0, 1.0, 1.0, 1.0]) @ dx_s @ dx_t @ dx_r
    v_gl = second_cube_model("STR", a) @ np.array([1.0, 1.0, -1.0, 1.0])
    assert np.allclose(v_gl[:3], transforms.from_directx_point(v_dx[:3]))


def test_look_at_up_along_the_view_is_a_clear_error() -> None:
    eye = transforms.from_directx_point((0, 0, -10))
    up = transforms.from_directx_point((0, 0, 1))  # the course's up (0,0,1) while looking along z
    with pytest.raises(SandboxError, match="parallel to the view direction"):
        transforms.look_at(eye, (0, 0, 0), up)


def test_look_at_up_0_7_0_7_0_7_rolls_the_view_45_degrees() -> None:
    eye = transforms.from_directx_point((0, 0, -10))
    view = transforms.look_at(eye, (0, 0, 0), transforms.from_directx_point((0.7, 0.7, 0.7)))
    assert np.all(np.isfinite(view))
    x, y = (view @ np.array([0.0, 1.0, 0.0, 0.0]))[:2]  # world up, on the screen
    assert math.degrees(math.atan2(abs(x), y)) == pytest.approx(45.0, abs=1e-9)


# --- the lesson -------------------------------------------------------------------


def test_bad_order_is_refused_naming_the_value_and_listing_valid_ones() -> None:
    with pytest.raises(SandboxError, match=r"--set order=SXR: .*valid orders: STR, SRT"):
        TransformOrder.from_settings(["order=SXR"])
    assert TransformOrder.from_settings(["order=trs"]).values["order"] == "TRS"


def test_keys_pick_orders_and_tab_splits() -> None:
    lesson = TransformOrder()
    assert lesson.on_key("4") and lesson.values["order"] == transforms.ORDERS[3]
    assert lesson.on_key("tab") and lesson.values["view"] == "split"
    assert len(lesson.scene().viewports) == 6
    assert lesson.on_key("1") and lesson.values["view"] == "single" and lesson.values["order"] == "STR"
    assert not lesson.on_key("q")


def test_plan_has_an_overlay_pass_only_with_the_overlay() -> None:
    on = plan(TransformOrder.from_settings(["time=1"]).scene())
    off = plan(TransformOrder.from_settings(["time=1", "overlay=off"]).scene())
    assert [p.kind for p in on.passes] == ["clear", "draw", "overlay"]
    assert "overlay" in [v.key for v in on.programs]
    assert [p.kind for p in off.passes] == ["clear", "draw"]
    assert "overlay" not in [v.key for v in off.programs]
    assert "trail" not in off.describe() and "trail" in on.describe()


def render(gl, order: str, time: float, *extra: str) -> np.ndarray:
    lesson = TransformOrder.from_settings([f"order={order}", f"time={time}", *extra])
    return gl.render(lesson, SIZE).image.copy()


def image_classes(images: dict[str, np.ndarray]) -> set[frozenset[str]]:
    groups: list[list[str]] = []
    for order, image in images.items():
        for g in groups:
            if np.array_equal(images[g[0]], image):
                g.append(order)
                break
        else:
            groups.append([order])
    return as_sets(groups)


def test_rendered_orders_fall_into_two_classes_at_time_0_and_four_later(gl) -> None:
    at_0 = {o: render(gl, o, 0.0, "overlay=off") for o in transforms.ORDERS}
    later = {o: render(gl, o, 1.0, "overlay=off") for o in transforms.ORDERS}
    assert image_classes(at_0) == CLASSES_AT_0
    assert image_classes(later) == CLASSES_LATER


def test_overlay_off_hides_label_matrix_and_trail(gl) -> None:
    with_overlay = render(gl, "STR", 1.0)
    without = render(gl, "STR", 1.0, "overlay=off")
    assert not np.array_equal(with_overlay, without)
    # Top-left corner: the label panel darkens the course-blue background.
    assert tuple(without[6, 6, :3]) == (0, 32, 153)
    assert tuple(with_overlay[6, 6, :3]) != (0, 32, 153)


@pytest.mark.parametrize("order", transforms.ORDERS)
def test_golden_orders(gl, golden, order: str) -> None:
    golden(render(gl, order, 1.0), f"transform_order/{order}")


def test_golden_split_view(gl, golden) -> None:
    lesson = TransformOrder.from_settings(["view=split", "time=1"])
    golden(gl.render(lesson, SIZE).image, "transform_order/split")


def test_the_trail_is_the_top_corner_under_each_recent_model() -> None:
    from glsandbox.lessons.transform_order import TRAIL_POINT, trail_mesh

    for order in transforms.ORDERS:
        trail = trail_mesh(order, 1.3, 2.0).positions
        assert trail.shape == (64, 3)
        for k in (0, 21, 63):  # sample k sits at angle 1.3 - 2 + 2k/63
            model = second_cube_model(order, 1.3 - 2.0 + 2.0 * k / 63)
            np.testing.assert_allclose(trail[k], (model @ np.append(TRAIL_POINT, 1.0))[:3], atol=1e-12)


def test_a_new_trail_every_frame_does_not_pile_up_on_the_gpu(gl, monkeypatch) -> None:
    # Each frame's trail is a new mesh; past MESH_LIMIT the least recently drawn are released.
    monkeypatch.setattr(gl.executor, "MESH_LIMIT", 6)
    lesson = TransformOrder(overlay=True)
    first = gl.render(lesson.at(0.0), (96, 72)).image.copy()
    for k in range(1, 20):
        gl.render(lesson.at(0.1 * k), (96, 72))
        assert gl.executor.mesh_count <= 6
    # The released meshes come back when drawn again: the first frame is unchanged.
    np.testing.assert_array_equal(gl.render(lesson.at(0.0), (96, 72)).image, first)
