"""The shared camera (course section "W A S D, Z X; rotateLeft/rotateRight 15°")."""

from __future__ import annotations

import math

import numpy as np
import pytest

from glsandbox import camera as cam
from glsandbox.errors import SandboxError
from glsandbox.scene import Camera, Scene


def course_camera() -> cam.FlyCamera:
    # The course's eye (0,3,-10) in DirectX is (0,3,10) in OpenGL, looking at the origin.
    return cam.FlyCamera.from_camera(Camera())


def distance_in_view(fly: cam.FlyCamera, point) -> float:
    """A world point's distance from the camera, measured in camera space."""
    p = fly.view() @ np.array([*point, 1.0])
    return float(np.linalg.norm(p[:3]))


# --- the notes' constants ------------------------------------------------------


def test_notes_constants_drift_as_the_course_md_says() -> None:
    assert round(cam.course_drift(24), 2) == 10.17
    assert round(cam.course_drift(1000), 2) == 20.09
    # Closed form: every press multiplies the distance by sqrt(c² + s²).
    growth = math.sqrt(cam.COURSE_COS ** 2 + cam.COURSE_SIN ** 2)
    assert cam.course_drift(24) == pytest.approx(10 * growth ** 24, rel=1e-12)
    assert round(cam.COURSE_COS ** 2 + cam.COURSE_SIN ** 2, 4) == 1.0014


def test_notes_rotate_right_is_a_mirror_and_does_not_undo_left() -> None:
    det = cam.course_right_determinant()
    assert det < 0 and round(det, 4) == -1.0014
    p = np.array([3.0, 1.0, 7.0])
    back = cam.course_rotate_right(cam.course_rotate_left(p))
    assert not np.allclose(back, p, atol=1e-3)
    assert "10.17" in cam.course_figures() and "20.09" in cam.course_figures()


# --- exact turns ------------------------------------------------------------------


def test_a_full_turn_and_left_then_right_are_exact() -> None:
    fly = course_camera()
    start = fly.view()
    for _ in range(cam.TURNS_PER_CIRCLE):
        fly.turn(1)
    assert np.array_equal(fly.view(), start)
    fly.turn(1)
    fly.turn(-1)
    assert np.array_equal(fly.view(), start)
    fly.key("a")
    fly.key("d")
    assert np.array_equal(fly.view(), start)


def test_a_million_turns_keep_the_radius_to_1e_9() -> None:
    fly = course_camera()
    point = (0.0, 3.0, 0.0)  # the eye's height, 10 units in front: radius 10 about the camera
    radius = distance_in_view(fly, point)
    for _ in range(1_000_000):
        fly.turn(1)
    assert abs(distance_in_view(fly, point) - radius) < 1e-9
    for _ in range(7):
        fly.turn(1)
    assert abs(distance_in_view(fly, point) - radius) < 1e-9
    assert abs(radius - 10.0) < 1e-9


def test_a_turns_left_by_15_degrees_about_the_camera() -> None:
    fly = cam.FlyCamera(eye=np.array([1.0, 2.0, 3.0]))
    assert np.allclose(fly.forward, (0, 0, -1))
    fly.key("a")
    assert np.allclose(fly.forward, (-math.sin(math.radians(15)), 0, -math.cos(math.radians(15))))
    assert np.array_equal(fly.eye, (1.0, 2.0, 3.0))  # turning about the camera does not move it


# --- the other keys ---------------------------------------------------------------


def test_w_s_move_along_the_view_and_z_x_move_up_and_down() -> None:
    fly = course_camera()
    eye, forward = fly.eye.copy(), fly.forward.copy()
    fly.key("w")
    assert np.allclose(fly.eye, eye + fly.step * forward)
    fly.key("s")
    assert np.allclose(fly.eye, eye)
    fly.key("z")
    assert np.allclose(fly.eye, eye + (0, fly.step, 0))
    fly.key("x")
    assert np.allclose(fly.eye, eye)
    assert not fly.key("q")


def test_orbit_keeps_the_focus_point_and_distance_and_zoom_approaches_it() -> None:
    fly = course_camera()
    pivot = fly.target.copy()
    for key in ("left", "left", "up", "right", "down", "down"):
        fly.key(key)
        assert np.allclose(fly.target, pivot, atol=1e-12)
        assert np.linalg.norm(fly.eye - pivot) == pytest.approx(fly.focus)
    before = fly.focus
    fly.zoom(1)
    assert fly.focus == pytest.approx(before * 0.9)
    assert np.allclose(fly.target, pivot, atol=1e-12)


def test_pitch_is_kept_short_of_the_pole() -> None:
    fly = course_camera()
    for _ in range(100):
        fly.orbit(0, 5)
    assert fly.pitch == cam.MAX_PITCH
    fly.view()  # up (0,1,0) is never parallel to the view


def test_from_camera_reproduces_the_scene_camera() -> None:
    scene_cam = Camera()
    fly = cam.FlyCamera.from_camera(scene_cam)
    assert np.allclose(fly.camera().view(), scene_cam.view(), atol=1e-12)
    with pytest.raises(SandboxError, match="same point"):
        cam.FlyCamera.from_camera(Camera(eye=(0, 0, 0), target=(0, 0, 0)))


def test_camera_input_overrides_the_scene_camera_only_once_moved() -> None:
    scene = Scene("s")
    window_camera = cam.CameraInput()
    assert window_camera.apply(scene) is scene
    assert not window_camera.key("1", scene)  # number keys stay with the lesson
    assert window_camera.key("w", scene)
    moved = window_camera.apply(scene)
    assert moved.camera != scene.camera
    assert np.allclose(moved.camera.eye, np.array(scene.camera.eye) + 0.5 * window_camera.camera.forward)
    window_camera.drag(10, 0, scene)
    window_camera.scroll(1, scene)
    window_camera.reset()
    assert window_camera.apply(scene) is scene
