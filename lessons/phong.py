"""Lesson: two orbiting lights and the course's Phong, with a correct normal matrix.

Course sections "Phong boyama modeli" and "Lighting". Two point lights orbit
in opposite directions, white (1, 1, 1) and yellow (1, 1, 0), each drawn as
a small unlit cube with the plain solid program (the course's
``g_pPixelShaderSolid``); the lit objects use the course's pixel-shader
Phong (``g_pPixelShaderPhong``), per light::

    min(0.1*mesh + 0.4*diffuse + 0.3*specular, 1),   exponent 32, summed over the lights

The ellipsoid is a unit sphere scaled non-uniformly (1.8, 0.7, 0.9). Its
normals go through the normal matrix, the inverse transpose of the model
matrix's 3x3: under a scale (a, b, c) a normal must shrink by (1/a, 1/b,
1/c) to stay perpendicular to the stretched surface. ``--set normals=naive``
uses the course's ``mul(Input.Norm, world)`` instead; the normals then lean
towards the long axis and the shading slides across the surface (the
notes' own vertex shader has this mistake; the lesson shows why it is one).

Parameters switch the variants: ``shading`` per-pixel Phong, per-vertex
Gouraud, Blinn-Phong; ``ambient``, ``diffuse``, ``specular`` switch a term
off by zeroing its coefficient, the course's experiments. In the window the
keys 1, 2, 3 toggle the three terms, 4 cycles the shading, 5 the normals.
"""

from __future__ import annotations

import math
import sys

import numpy as np

import glsandbox
from glsandbox import (
    LIT_SHADINGS,
    NORMAL_MODES,
    Camera,
    Lesson,
    Light,
    Material,
    Motion,
    Node,
    Param,
    Scene,
    geometry,
    register,
    transforms,
)


#: The course's light colours: vLightColor[2] = {(1,1,1,1), (1,1,0,1)}.
LIGHT_COLORS = ((1.0, 1.0, 1.0), (1.0, 1.0, 0.0))
#: The course's coefficients and exponent.
AMBIENT, DIFFUSE, SPECULAR, SHININESS = 0.1, 0.4, 0.3, 32.0
ORBIT_RADIUS = 3.0
ORBIT_HEIGHT = 1.5
#: The white light starts at 60° (front right), the yellow one mirrored (front left).
START_ANGLE = math.pi / 3
#: The light cubes' size: the course cube (half-size 1) scaled by this.
LIGHT_CUBE_SCALE = 0.15
#: The non-uniform scale that shows why normals need the normal matrix.
ELLIPSOID_SCALE = (1.8, 0.7, 0.9)


def light_positions(time: float, speed: float, count: int = 2) -> list[tuple[float, float, float]]:
    """Where the lights are at ``time``: on a circle, turning in opposite directions.

    Light 0 is at angle ``START_ANGLE + speed*t``; light 1 at
    ``pi - START_ANGLE - speed*t``, its mirror image in the yz plane.
    """
    angles = (START_ANGLE + speed * time, math.pi - START_ANGLE - speed * time)
    return [(ORBIT_RADIUS * math.cos(a), ORBIT_HEIGHT, ORBIT_RADIUS * math.sin(a)) for a in angles[:count]]


def light_cube(index: int, light: Light) -> Node:
    """A light drawn as a small cube in its own colour, unlit (solid program)."""
    return Node(f"light{index}", geometry.cube(), light_cube_model(light.position),
                Material(color=(*light.color, 1.0), shading="solid"))


def light_cube_model(position: tuple[float, float, float]) -> np.ndarray:
    """A light's cube: the course cube scaled by :data:`LIGHT_CUBE_SCALE`, at the light."""
    return transforms.translate(*position) @ transforms.scale(*(LIGHT_CUBE_SCALE,) * 3)


@register
class PhongLesson(Lesson):
    name = "phong"
    title = "Two orbiting lights: Phong, Gouraud, Blinn-Phong, and the normal matrix"
    course_section = "Phong boyama modeli; Lighting"
    order = 50
    contrasts = (("per-pixel Phong, per-vertex Gouraud, Blinn-Phong", "shading=phong,gouraud,blinn_phong"),
                 ("the normal matrix against the course's mul(Norm, world)", "normals=correct,naive"))
    animated = True
    params = (
        Param("shading", "phong", "per-pixel Phong, per-vertex Gouraud, or Blinn-Phong", choices=LIT_SHADINGS),
        Param("normals", "correct", "normal matrix (inverse transpose) or the course's mul(Norm, world)",
              choices=NORMAL_MODES),
        Param("ambient", True, "the ambient term 0.1*mesh (key 1)"),
        Param("diffuse", True, "the diffuse term 0.4*max(N.L,0)*mesh (key 2)"),
        Param("specular", True, "the specular term 0.3*max(R.E,0)^32 (key 3)"),
        Param("lights", 2, "how many lights (the shader's loop is sized to them)", minimum=0, maximum=2),
        Param("speed", 0.8, "orbit speed of the lights in radians per second"),
    )

    def material(self, color: tuple[float, float, float, float]) -> Material:
        """A lit material with the course's coefficients, switched terms zeroed."""
        v = self.values
        return Material(color=color, shading=v["shading"], normals=v["normals"],
                        ambient=AMBIENT if v["ambient"] else 0.0,
                        diffuse=DIFFUSE if v["diffuse"] else 0.0,
                        specular=SPECULAR if v["specular"] else 0.0,
                        shininess=SHININESS)

    def build(self) -> Scene:
        count = int(self.values["lights"])
        positions = light_positions(self.time, float(self.values["speed"]), count)
        lights = tuple(Light(p, c) for p, c in zip(positions, LIGHT_COLORS))
        ellipsoid = transforms.rotate_y(math.radians(30)) @ transforms.scale(*ELLIPSOID_SCALE)
        nodes = [
            Node("ground", geometry.plane(12.0), transforms.translate(0.0, -1.2, 0.0),
                 self.material((0.6, 0.6, 0.6, 1.0))),
            Node("ellipsoid", geometry.sphere(), ellipsoid, self.material((1.0, 0.25, 0.2, 1.0))),
            *(light_cube(i, light) for i, light in enumerate(lights)),
        ]
        camera = Camera(eye=(0.0, 2.5, 8.0), target=(0.0, 0.0, 0.0), fov_y=45.0, near=0.01, far=100.0)
        return Scene(self.name, nodes=tuple(nodes), camera=camera, lights=lights)

    def motion(self) -> Motion:
        """The lights orbit with time, and their cubes with them."""
        count = int(self.values["lights"])
        positions = light_positions(self.time, float(self.values["speed"]), count)
        return Motion(models={f"light{i}": light_cube_model(p) for i, p in enumerate(positions)},
                      lights=dict(enumerate(positions)))

    def on_key(self, key: str) -> bool:
        """1, 2, 3: toggle ambient, diffuse, specular; 4: next shading; 5: normals."""
        toggles = {"1": "ambient", "2": "diffuse", "3": "specular"}
        if key in toggles:
            self.values[toggles[key]] = not self.values[toggles[key]]
        elif key == "4":
            shadings = list(LIT_SHADINGS)
            self.values["shading"] = shadings[(shadings.index(self.values["shading"]) + 1) % len(shadings)]
        elif key == "5":
            self.values["normals"] = "naive" if self.values["normals"] == "correct" else "correct"
        else:
            return False
        return True


if __name__ == "__main__":
    sys.exit(glsandbox.run(PhongLesson))
