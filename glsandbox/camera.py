"""The interactive camera, shared by every lesson (and later the ray tracer).

Course section "W A S D, Z X camera; rotateLeft/Right 15° about the camera".
In the notes the keys move the *room* around a fixed camera: W and S push
every point along the view normal by 10 units, A and D call ``rotateLeft`` and
``rotateRight``, which turn every point 15° about the camera (``P - camera``,
rotate in the xz plane, ``+ camera``). Turning the room by -15° about the
camera is the same picture as turning the camera by +15°, so here the camera
moves and the scene stays put.

Exact turns
-----------
The notes multiply the points by a rotation built from the constants 0.9666
and 0.259 on every key press. Those are not cos 15° = 0.965926 and
sin 15° = 0.258819: ``0.9666² + 0.259² = 1.0014``, so each press scales the
room by ``sqrt(1.0014) = 1.0007`` (see :func:`course_drift`), and the notes'
``rotateRight`` has determinant ``-(0.9666² + 0.259²) = -1.0014``: a mirror,
not the inverse turn (:func:`course_right_determinant`).

:class:`FlyCamera` never multiplies a matrix into itself. It *keeps the
angle*: the yaw is a whole number of 15° key turns (kept modulo 24) plus the
yaw set by orbiting, and the view matrix is rebuilt from the angles every
frame. So 24 turns give back exactly the same camera, left then right is the
identity, and a million turns leave every distance unchanged to the last bit
of the cosine.

Orientation (OpenGL, right-handed, y up): yaw 0 and pitch 0 look down -z;
a positive yaw turns left (a right-handed rotation about +y takes -z towards
-x); a positive pitch looks up. ``forward = R_y(yaw) R_x(pitch) (0, 0, -1)``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from glsandbox.errors import SandboxError, plain
from glsandbox.scene import Camera, Motion, Scene, moved_scene

#: One A/D press: the course's 15° turn.
TURN_DEGREES = 15.0
#: Key turns in a full circle; the turn counter is kept modulo this.
TURNS_PER_CIRCLE = 24
#: The notes' cosine and sine of 15° (rotateLeft/rotateRight).
COURSE_COS = 0.9666
COURSE_SIN = 0.259
#: Pitch is kept short of straight up/down, where the up vector (0, 1, 0)
#: would be parallel to the view and look_at would have no answer.
MAX_PITCH = 89.0


# --- the notes' constants, for the lesson and the tests ---------------------


def course_rotate_left(p: Sequence[float], camera: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The notes' ``rotateLeft``: turn point ``p`` about ``camera`` in the xz plane.

    ``P.X = x*0.9666 - z*0.259; P.Z = x*0.259 + z*0.9666`` (float64 here).
    """
    q = np.asarray(p, dtype=np.float64) - np.asarray(camera, dtype=np.float64)
    x, z = q[0], q[2]
    q[0] = x * COURSE_COS - z * COURSE_SIN
    q[2] = x * COURSE_SIN + z * COURSE_COS
    return q + np.asarray(camera, dtype=np.float64)


def course_rotate_right(p: Sequence[float], camera: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The notes' ``rotateRight`` as written: ``P.X = x*0.9666 + z*0.259;
    P.Z = x*0.259 - z*0.9666``. Its matrix ``[[c, s], [s, -c]]`` is a mirror."""
    q = np.asarray(p, dtype=np.float64) - np.asarray(camera, dtype=np.float64)
    x, z = q[0], q[2]
    q[0] = x * COURSE_COS + z * COURSE_SIN
    q[2] = x * COURSE_SIN - z * COURSE_COS
    return q + np.asarray(camera, dtype=np.float64)


@functools.cache  # a pure function of two numbers, shown on every frame of some lessons
def course_drift(turns: int, radius: float = 10.0) -> float:
    """Distance from the camera of a point ``radius`` away after ``turns``
    presses of the notes' rotateLeft, applied one after another as the notes do.

    Each press multiplies the distance by ``sqrt(0.9666² + 0.259²)``:
    10 becomes 10.17 after a full turn (24 presses) and 20.09 after 1000.
    """
    if turns < 0:
        raise SandboxError(f"turns must be 0 or more, got {turns}")
    p = np.array([0.0, 0.0, float(radius)])
    for _ in range(int(turns)):
        p = course_rotate_left(p)
    return float(np.linalg.norm(p))


def course_right_determinant() -> float:
    """Determinant of the notes' rotateRight in the xz plane: ``-c² - s²``, about -1.0014.

    A rotation has determinant +1; -1 means it mirrors the room left to right.
    """
    return float(np.linalg.det(np.array([[COURSE_COS, COURSE_SIN], [COURSE_SIN, -COURSE_COS]])))


def course_figures() -> str:
    """One line of the notes' drift figures, for overlays and printing."""
    return (f"notes' 0.9666/0.259: r=10 -> {course_drift(24):.2f} after 24 turns, "
            f"{course_drift(1000):.2f} after 1000; rotateRight det {course_right_determinant():.4f}")


# --- the camera -------------------------------------------------------------


def _forward(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """``R_y(yaw) R_x(pitch) (0, 0, -1)``: the unit view direction."""
    yaw, pitch = math.radians(yaw_deg), math.radians(pitch_deg)
    return np.array([-math.sin(yaw) * math.cos(pitch), math.sin(pitch), -math.cos(yaw) * math.cos(pitch)])


@dataclass
class FlyCamera:
    """A camera at ``eye`` looking along (yaw, pitch), with a focus distance.

    The focus point ``eye + focus * forward`` is what the arrow keys and the
    mouse orbit about and what scrolling zooms towards. Yaw is
    ``yaw_base + 15° * turns``: key turns only change the integer ``turns``.
    """

    eye: np.ndarray
    yaw_base: float = 0.0
    turns: int = 0
    pitch: float = 0.0
    focus: float = 10.0
    fov_y: float = 45.0
    near: float = 0.01
    far: float = 100.0
    #: W/S/Z/X step in world units (the notes move 10 per press in a 100-unit room).
    step: float = 0.5
    #: Degrees per arrow-key press when orbiting.
    orbit_step: float = 5.0

    def __post_init__(self) -> None:
        self.eye = np.asarray(self.eye, dtype=np.float64).reshape(3).copy()
        if not np.all(np.isfinite(self.eye)):
            raise SandboxError(f"camera eye must be finite, got {plain(self.eye)}")
        self.pitch = max(-MAX_PITCH, min(MAX_PITCH, float(self.pitch)))

    @classmethod
    def from_camera(cls, camera: Camera) -> FlyCamera:
        """Start from a scene camera: same eye, view direction, lens; focus at its target."""
        eye = np.asarray(camera.eye, dtype=np.float64)
        offset = np.asarray(camera.target, dtype=np.float64) - eye
        distance = float(np.linalg.norm(offset))
        if distance == 0.0:
            raise SandboxError(f"camera eye and target are the same point {plain(eye)}")
        f = offset / distance
        pitch = math.degrees(math.asin(max(-1.0, min(1.0, f[1]))))
        # forward = (-sin yaw cos pitch, ., -cos yaw cos pitch)
        yaw = math.degrees(math.atan2(-f[0], -f[2])) if abs(f[1]) < 1.0 else 0.0
        return cls(eye=eye, yaw_base=yaw, pitch=pitch, focus=distance, fov_y=camera.fov_y,
                   near=camera.near, far=camera.far)

    # --- derived quantities -------------------------------------------------

    @property
    def yaw(self) -> float:
        """The heading in degrees: orbit yaw plus whole 15° key turns."""
        return self.yaw_base + TURN_DEGREES * self.turns

    @property
    def forward(self) -> np.ndarray:
        return _forward(self.yaw, self.pitch)

    @property
    def target(self) -> np.ndarray:
        return self.eye + self.focus * self.forward

    def camera(self) -> Camera:
        """The :class:`~glsandbox.scene.Camera` the renderers use, rebuilt from the angles."""
        return Camera(eye=tuple(float(v) for v in self.eye), target=tuple(float(v) for v in self.target),
                      up=(0.0, 1.0, 0.0), fov_y=self.fov_y, near=self.near, far=self.far)

    def view(self) -> np.ndarray:
        """The view matrix (world -> camera), rebuilt from eye and angles."""
        return self.camera().view()

    # --- moves (the course's keys) -----------------------------------------

    def move(self, distance: float) -> None:
        """W (+) / S (-): along the view direction, as the notes move along the view normal."""
        self.eye = self.eye + distance * self.forward

    def lift(self, distance: float) -> None:
        """Z (+) / X (-): straight up or down."""
        self.eye = self.eye + np.array([0.0, distance, 0.0])

    def turn(self, steps: int) -> None:
        """A (+1) / D (-1): turn ``steps`` × 15° about the camera's own position.

        Only the integer turn count changes (modulo 24), so a full circle or a
        left-right pair gives back exactly the same camera.
        """
        self.turns = (self.turns + int(steps)) % TURNS_PER_CIRCLE

    def orbit(self, d_yaw: float, d_pitch: float) -> None:
        """Arrows / mouse drag: move the eye around the focus point by degrees."""
        pivot = self.target
        self.yaw_base = (self.yaw_base + float(d_yaw)) % 360.0
        self.pitch = max(-MAX_PITCH, min(MAX_PITCH, self.pitch + float(d_pitch)))
        self.eye = pivot - self.focus * self.forward

    def zoom(self, clicks: float) -> None:
        """Scroll: each click moves 10% of the way towards (+) or away from (-) the focus point."""
        pivot = self.target
        self.focus = max(0.1, min(self.far, self.focus * 0.9 ** float(clicks)))
        self.eye = pivot - self.focus * self.forward

    def key(self, name: str) -> bool:
        """Apply a window key by name (``"w"``, ``"left"``...); True when it is a camera key."""
        actions = {
            "w": lambda: self.move(self.step), "s": lambda: self.move(-self.step),
            "a": lambda: self.turn(1), "d": lambda: self.turn(-1),
            "z": lambda: self.lift(self.step), "x": lambda: self.lift(-self.step),
            "left": lambda: self.orbit(-self.orbit_step, 0.0), "right": lambda: self.orbit(self.orbit_step, 0.0),
            "up": lambda: self.orbit(0.0, -self.orbit_step), "down": lambda: self.orbit(0.0, self.orbit_step),
        }
        action = actions.get(name.lower())
        if action is None:
            return False
        action()
        return True


#: The key names :meth:`FlyCamera.key` understands.
CAMERA_KEYS = ("w", "a", "s", "d", "z", "x", "left", "right", "up", "down")


class CameraInput:
    """The window's camera: idle until the user moves it, then it overrides the scene's.

    Kept free of glfw so it can be tested; :func:`glsandbox.app.window.run_window`
    feeds it key names, drags (pixels) and scroll clicks.
    """

    #: Degrees of orbit per pixel of mouse drag.
    DRAG_DEGREES = 0.3

    def __init__(self) -> None:
        self.camera: FlyCamera | None = None

    def _ensure(self, scene: Scene) -> FlyCamera:
        if self.camera is None:
            self.camera = FlyCamera.from_camera(scene.camera)
        return self.camera

    def key(self, name: str, scene: Scene) -> bool:
        if name.lower() not in CAMERA_KEYS:
            return False
        return self._ensure(scene).key(name)

    def drag(self, dx: float, dy: float, scene: Scene) -> None:
        # Dragging right swings the eye to the left round the focus, so the scene turns with the hand.
        self._ensure(scene).orbit(-dx * self.DRAG_DEGREES, dy * self.DRAG_DEGREES)

    def scroll(self, clicks: float, scene: Scene) -> None:
        self._ensure(scene).zoom(clicks)

    def reset(self) -> None:
        self.camera = None

    def apply(self, scene: Scene) -> Scene:
        """The scene seen through the interactive camera, or unchanged if never moved."""
        if self.camera is None:
            return scene
        # Moved, not replaced: the renderers keep the plan while only the camera changes.
        return moved_scene(scene, Motion(camera=self.camera.camera()))
