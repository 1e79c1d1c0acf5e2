"""Lesson: a room with a stencil mirror and a planar shadow, and depth precision.

Course section "The stencil Test" (MarkMirrorDSS, DrawReflectionDSS,
XMMatrixReflect, CullClockwise, XMMatrixShadow, shadowOffsetY); Frank Luna's
Direct3D 11 mirror demo is the same scene. A floor, a left wall, a back wall
with a hole in which the mirror's glass sits, a turning cube in front of it,
and one light.

Mirror (``--set mirror=stencil``): the frame is the normal scene without the
glass; then the glass is drawn into the stencil buffer only (always pass,
replace: its visible pixels get bit 1; colour and depth writes off); then
the floor, the left wall, the cube and the light are drawn again through the
reflection matrix R of the glass's plane, only where the stencil bit is set
(equal, keep). R has determinant -1: it turns counter-clockwise triangles
clockwise, so the front-face rule flips for that pass (CullClockwise), and
the light is reflected too. Last the glass is blended on top. The back wall
has a hole behind the glass so the reflection (which lies behind the plane)
is not hidden by the wall's depth. ``mirror=no_stencil`` skips the marking:
the reflection leaks outside the glass (over the wall top and beside it).

Shadow (``--set shadow=on``): the cube flattened onto the floor by the
shadow matrix ``S = (P·L) I - L Pᵀ`` (P the floor plane, L the light: a
point with w = 1 or a direction with w = 0), lifted by ``lift`` along the
normal (the course's shadowOffsetY, 0.005), drawn black at alpha 0.5 with
the depth test on and depth writes off. The flattened cube covers each
shadow pixel twice (its faces towards and away from the light), so the
stencil lets a pixel darken once only; ``shadow=double_blend`` shows the
dark overlap without it.

Depth precision: ``near``, ``far``, ``lift``, ``offset`` (polygon offset on
the shadow), ``depth`` (``standard``: 24-bit integer depth, -1..1 clip depth;
``reverse_z``: float depth, ``glClipControl`` 0..1, near at 1, far at 0) and
``distance`` (how far the camera stands back). With near 0.01, far 100, a
24-bit buffer and only the 0.005 lift, the shadow z-fights with the floor
beyond a distance of about 29: depth ``d = A + B/z`` has slope ``near/z²``,
and 0.01·0.005/z² falls below one step 2^-24 when z > 29. The default,
reverse-Z plus polygon offset, holds at every distance the room is seen from.
"""

from __future__ import annotations

import math
import sys

import numpy as np

import glsandbox
from glsandbox import (
    DEPTH_MODES,
    Camera,
    Lesson,
    Light,
    Material,
    Mirror,
    Motion,
    Node,
    Param,
    PlanarShadow,
    SandboxError,
    Scene,
    geometry,
    register,
    transforms,
)


#: The room (OpenGL coordinates, y up): floor y = 0, back wall z = BACK, left wall x = -HALF_WIDTH.
HALF_WIDTH = 5.0
BACK = -4.0
FRONT = 5.0
WALL_HEIGHT = 3.0
#: The glass: x in -GLASS_HALF..GLASS_HALF, y in GLASS_BOTTOM..GLASS_TOP, in the back wall.
GLASS_HALF, GLASS_BOTTOM, GLASS_TOP = 1.6, 0.4, 2.4
#: The mirror plane z = BACK as (a, b, c, d): 0·x + 0·y + 1·z + 4 = 0, normal towards the room.
MIRROR_PLANE = (0.0, 0.0, 1.0, -BACK)
#: The floor plane y = 0, normal up (the course's shadowPlane (0, 1, 0, 2) is the floor at y = -2).
FLOOR_PLANE = (0.0, 1.0, 0.0, 0.0)
#: The glass's tint; its alpha is how much of the glass covers the reflection.
GLASS_COLOR = (0.55, 0.7, 0.9, 0.25)
SHADOW_COLOR = (0.0, 0.0, 0.0, 0.5)
CUBE_CENTRE = (0.5, 0.6, -1.5)
CUBE_HALF = 0.6
#: Where the camera looks; ``distance`` moves the eye along EYE_DIRECTION from here.
TARGET = (-0.5, 0.8, -1.5)
EYE_DIRECTION = (0.5, 0.45, 0.8)
LIGHT_CUBE_SCALE = 0.12
#: A directional light is shaded as a point this far away along its direction.
FAR_LIGHT = 1.0e4


def quad(width: float, height: float, centre: tuple[float, float, float], facing: str) -> np.ndarray:
    """The model matrix of a ``width`` x ``height`` rectangle made from the unit
    plane (xz, facing +y): turned to face +z (a back-wall piece) or +x (the left wall)."""
    if facing == "+z":  # rotate_x(90°) takes +y to +z and the plane's z extent to y
        turn = transforms.rotate_x(math.radians(90.0))
    elif facing == "+x":  # rotate_z(-90°) takes +y to +x and the plane's x extent to y
        turn = transforms.rotate_z(math.radians(-90.0))
        width, height = height, width
    else:
        raise ValueError(facing)
    return transforms.translate(*centre) @ turn @ transforms.scale(width, 1.0, height)


def back_wall_pieces() -> list[tuple[str, np.ndarray]]:
    """The back wall as four rectangles around the glass's hole."""
    side = HALF_WIDTH - GLASS_HALF
    return [
        ("wall_back_left", quad(side, WALL_HEIGHT, (-(GLASS_HALF + side / 2), WALL_HEIGHT / 2, BACK), "+z")),
        ("wall_back_right", quad(side, WALL_HEIGHT, (GLASS_HALF + side / 2, WALL_HEIGHT / 2, BACK), "+z")),
        ("wall_back_low", quad(2 * GLASS_HALF, GLASS_BOTTOM, (0.0, GLASS_BOTTOM / 2, BACK), "+z")),
        ("wall_back_high", quad(2 * GLASS_HALF, WALL_HEIGHT - GLASS_TOP,
                                (0.0, (GLASS_TOP + WALL_HEIGHT) / 2, BACK), "+z")),
    ]


def _lit(rgb: tuple[float, float, float]) -> Material:
    return Material(color=(*rgb, 1.0), shading="phong")


def room_nodes() -> tuple[Node, ...]:
    """The floor, the left wall, the back wall around the glass's hole, and the glass."""
    depth_z = FRONT - BACK
    nodes = (
        Node("floor", geometry.plane(1.0),
             transforms.translate(0.0, 0.0, (FRONT + BACK) / 2) @ transforms.scale(2 * HALF_WIDTH, 1.0, depth_z),
             _lit((0.75, 0.72, 0.65))),
        Node("wall_left", geometry.plane(1.0), quad(depth_z, WALL_HEIGHT, (-HALF_WIDTH, WALL_HEIGHT / 2,
                                                                        (FRONT + BACK) / 2), "+x"),
             _lit((0.45, 0.6, 0.5))),
        *(Node(name, geometry.plane(1.0), model, _lit((0.6, 0.55, 0.7))) for name, model in back_wall_pieces()),
        Node("glass", geometry.plane(1.0),
             quad(2 * GLASS_HALF, GLASS_TOP - GLASS_BOTTOM, (0.0, (GLASS_BOTTOM + GLASS_TOP) / 2, BACK), "+z"),
             Material(color=GLASS_COLOR, shading="solid")),
    )
    return nodes


#: The room does not move: built once.
ROOM = room_nodes()


def glass_mirror(reflected: tuple[str, ...], stencil: bool) -> Mirror:
    """The mirror in the back wall's hole, reflecting ``reflected``."""
    return Mirror("glass", MIRROR_PLANE, reflected, stencil=stencil)


@register
class MirrorLesson(Lesson):
    name = "mirror"
    title = "A stencil mirror, a planar shadow, and depth precision"
    course_section = "The stencil Test: MarkMirrorDSS, DrawReflectionDSS, XMMatrixReflect, XMMatrixShadow"
    order = 70
    contrasts = (("stencil against leak: the reflection through the stencil, and without it",
                  "mirror=stencil,no_stencil"),)
    animated = True
    params = (
        Param("mirror", "stencil", "the mirror: through the stencil, without it (leaks), or none",
              choices=("stencil", "no_stencil", "off")),
        Param("shadow", "on", "the cube's planar shadow: stencil-guarded, blended twice, or none",
              choices=("on", "double_blend", "off")),
        Param("light", "point", "point light at (lx, ly, lz), or directional from direction (lx, ly, lz)",
              choices=("point", "directional")),
        Param("lx", -2.0, "light x (position, or direction towards the light)"),
        Param("ly", 4.5, "light y"),
        Param("lz", 1.0, "light z"),
        Param("depth", "reverse_z", "standard (24-bit, -1..1) or reverse_z (float, glClipControl 0..1)",
              choices=DEPTH_MODES),
        Param("near", 0.01, "near plane distance", minimum=1e-6),
        Param("far", 100.0, "far plane distance", minimum=1e-6),
        Param("lift", 0.005, "the shadow's offset along the floor normal (the course's shadowOffsetY)", minimum=0.0),
        Param("offset", True, "polygon offset on the shadow (pulls it towards the camera in the depth test)"),
        Param("distance", 10.5, "the camera's distance from the room's centre", minimum=0.5),
        Param("fov", 45.0, "vertical field of view in degrees (narrow it to see the room from far away)",
              minimum=1.0, maximum=170.0),
        Param("speed", 0.4, "the cube's turn rate, radians per second"),
    )

    def light_vector(self) -> tuple[float, float, float, float]:
        """The light for the shadow matrix: (x, y, z, 1) a point, (x, y, z, 0) a direction."""
        v = self.values
        return (float(v["lx"]), float(v["ly"]), float(v["lz"]), 1.0 if v["light"] == "point" else 0.0)

    def build(self) -> Scene:
        v = self.values
        if not float(v["near"]) < float(v["far"]):
            raise SandboxError(f"--set near={v['near']}: must be less than far={v['far']}")
        light = transforms.light_vector(self.light_vector())
        if light[3] == 1.0:
            shading_light = Light(tuple(float(c) for c in light[:3]))
        else:  # a directional light: a point so far away that its rays are parallel in the room
            shading_light = Light(tuple(float(c) for c in FAR_LIGHT * light[:3]))
        nodes = [
            *ROOM,
            Node("cube", geometry.cube24(), self.cube_model(), _lit((1.0, 0.5, 0.15))),
        ]
        reflected = ["floor", "wall_left", "cube"]
        if light[3] == 1.0:
            nodes.append(Node("light", geometry.cube(),
                              transforms.translate(*light[:3]) @ transforms.scale(*(LIGHT_CUBE_SCALE,) * 3),
                              Material(color=(1.0, 1.0, 0.85, 1.0), shading="solid")))
            reflected.append("light")
        mirror = None
        if v["mirror"] != "off":
            mirror = glass_mirror(tuple(reflected), v["mirror"] == "stencil")
        shadow = None
        if v["shadow"] != "off":
            shadow = PlanarShadow("floor", FLOOR_PLANE, self.light_vector(), ("cube",), lift=float(v["lift"]),
                                  polygon_offset=bool(v["offset"]), stencil=v["shadow"] == "on",
                                  color=SHADOW_COLOR)
        direction = np.asarray(EYE_DIRECTION) / np.linalg.norm(EYE_DIRECTION)
        eye = np.asarray(TARGET) + float(v["distance"]) * direction
        camera = Camera(eye=tuple(float(c) for c in eye), target=TARGET, fov_y=float(v["fov"]),
                        near=float(v["near"]), far=float(v["far"]))
        return Scene(self.name, nodes=tuple(nodes), camera=camera, lights=(shading_light,),
                     clear_color=(0.08, 0.08, 0.12, 1.0), mirror=mirror, planar_shadow=shadow, depth_mode=v["depth"])

    def cube_model(self) -> np.ndarray:
        """The cube's model at :attr:`time`: turning about y at its place."""
        turn = transforms.rotate_y(0.5 + float(self.values["speed"]) * self.time)
        return transforms.translate(*CUBE_CENTRE) @ turn @ transforms.scale(CUBE_HALF, CUBE_HALF, CUBE_HALF)

    def motion(self) -> Motion:
        """Only the cube turns with time (its reflection and shadow follow it in the passes)."""
        return Motion(models={"cube": self.cube_model()})

    def on_key(self, key: str) -> bool:
        """1: cycle the mirror mode; 2: the shadow mode; 3: the depth mode; 4: the light type."""
        cycles = {"1": "mirror", "2": "shadow", "3": "depth", "4": "light"}
        if key not in cycles:
            return False
        param = next(p for p in self.params if p.name == cycles[key])
        choices = list(param.choices or ())
        self.values[param.name] = choices[(choices.index(self.values[param.name]) + 1) % len(choices)]
        return True


if __name__ == "__main__":
    sys.exit(glsandbox.run(MirrorLesson))
