"""Lesson 3: the indexed cube, with world, view and projection.

Course section "Küp: vertex + index buffer, 36 indices" and "Vertex/pixel
shader; World, View, Projection". Eight corners go in a vertex buffer once;
the index buffer lists them three per triangle, 36 indices for 12 triangles,
instead of 36 full vertices. The camera is the course's: eye (0, 3, -10) in
DirectX's left-handed coordinates, which is (0, 3, 10) in OpenGL's, looking
at the origin, up (0, 1, 0), 45° field of view, near 0.01, far 100.
``glsandbox.transforms`` documents the one place the conversion happens.

The cube turns about y as the tutorial's ``XMMatrixRotationY(t)`` does. With
``--set flip=front`` the two triangles of the face towards the camera get
their winding swapped: they become back faces, culling drops them, and the
hole shows the background (the inner sides of the other faces are back faces
too).
"""

from __future__ import annotations

import math
import sys

import numpy as np

import glsandbox
from glsandbox import Camera, Lesson, Material, Motion, Node, Param, Scene, geometry, register, transforms


#: Which two of the 12 triangles make each face, in the course's index order.
FACE_TRIANGLES = {"top": (0, 1), "front": (2, 3)}


def cube_with_flipped_face(face: str) -> glsandbox.Mesh:
    """The course cube with one face's two triangles wound the other way."""
    mesh = geometry.cube()
    if face == "none":
        return mesh
    tri = mesh.indices.reshape(-1, 3).copy()
    for k in FACE_TRIANGLES[face]:
        tri[k] = tri[k][[0, 2, 1]]
    return glsandbox.Mesh(f"cube_flip_{face}", mesh.positions, tri.reshape(-1), colors=mesh.colors)


#: The three cubes of ``--set flip=...``: the course's, and one with a face turned away.
CUBES = {face: cube_with_flipped_face(face) for face in ("none", "front", "top")}


#: The course's camera: eye (0, 3, -10) in DirectX, looking at the origin,
#: 45° field of view, near 0.01, far 100.
COURSE_CAMERA = Camera(eye=tuple(transforms.from_directx_point((0.0, 3.0, -10.0))), fov_y=45.0, near=0.01, far=100.0)
#: Tutorial 04's colours: each corner's own, interpolated across the faces.
VERTEX_COLORS = Material(shading="vertex_color")


@register
class IndexedCube(Lesson):
    name = "indexed_cube"
    title = "The indexed cube: 8 vertices, 36 indices"
    course_section = "Küp: vertex + index buffer; World, View, Projection"
    order = 30
    animated = True
    params = (
        Param("speed", 1.0, "turn rate in radians per second (XMMatrixRotationY(t))"),
        Param("flip", "none", "swap the winding of one face's triangles", choices=tuple(CUBES)),
        Param("cull", True, "back-face culling"),
    )

    def cube_model(self) -> np.ndarray:
        """The cube's model at :attr:`time`: DirectX's XMMatrixRotationY(speed*t), converted by the z mirror."""
        angle = float(self.values["speed"]) * self.time
        c, s = math.cos(angle), math.sin(angle)
        dx_rotation = np.array([[c, 0.0, -s, 0.0], [0.0, 1.0, 0.0, 0.0], [s, 0.0, c, 0.0], [0.0, 0.0, 0.0, 1.0]])
        return transforms.from_directx_matrix(dx_rotation)

    def build(self) -> Scene:
        node = Node("cube", CUBES[self.values["flip"]], self.cube_model(), VERTEX_COLORS,
                    cull_back_faces=bool(self.values["cull"]))
        return Scene(self.name, nodes=(node,), camera=COURSE_CAMERA)

    def motion(self) -> Motion:
        """Only the cube turns with time."""
        return Motion(models={"cube": self.cube_model()})

if __name__ == "__main__":
    sys.exit(glsandbox.run(IndexedCube))
