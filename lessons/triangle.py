"""Lesson 2: a quad as a triangle strip and as a triangle list; winding.

Course section "Triangle; vertex buffer; TRIANGLESTRIP vs TRIANGLELIST".
A quad is two triangles. As a *list* it needs six vertices (two corners are
sent twice); as a *strip* four, because each new vertex makes a triangle with
the two before it. Both give the same pixels. The order of a triangle's
corners (its winding) decides which side is the front: OpenGL keeps
counter-clockwise triangles and, with back-face culling on, drops clockwise
ones, so swapping two corners of one triangle makes half the quad vanish.
"""

from __future__ import annotations

import sys

import glsandbox
from glsandbox import Camera, Lesson, Material, Motion, Node, Param, Scene, Viewport, geometry, register


ORANGE = (1.0, 0.55, 0.1, 1.0)
#: Looking straight at the quad from +z, so it fills the middle of the view.
CAMERA = Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))


@register
class Triangle(Lesson):
    name = "triangle"
    title = "Quad as strip and as list; winding and culling"
    course_section = "Triangle; vertex buffer; TRIANGLESTRIP vs TRIANGLELIST"
    order = 20
    contrasts = (("strip against list", "topology=strip,list"),)
    params = (
        Param("topology", "both", "draw the quad as a strip, a list, or both side by side",
              choices=("both", "strip", "list")),
        Param("winding", "ccw", "ccw: both triangles front-facing; swapped: the list's second "
              "triangle is clockwise, a back face that culling removes", choices=("ccw", "swapped")),
        Param("cull", True, "back-face culling (off: both windings are drawn)"),
    )

    def build(self) -> Scene:
        strip = geometry.quad_strip()
        quad_list = geometry.quad_list_swapped() if self.values["winding"] == "swapped" else geometry.quad_list()
        cull = bool(self.values["cull"])
        topology = self.values["topology"]
        if topology == "both":
            viewports = (Viewport(rect=(0.0, 0.0, 0.5, 1.0), label="strip: 4 vertices"),
                         Viewport(rect=(0.5, 0.0, 0.5, 1.0), label="list: 6 vertices"))
            nodes = (Node("strip", strip, material=Material(ORANGE), cull_back_faces=cull, viewports=(0,)),
                     Node("list", quad_list, material=Material(ORANGE), cull_back_faces=cull, viewports=(1,)))
        else:
            mesh = strip if topology == "strip" else quad_list
            viewports = (Viewport(label=topology),)
            nodes = (Node(topology, mesh, material=Material(ORANGE), cull_back_faces=cull),)
        return Scene(self.name, nodes=nodes, camera=CAMERA, viewports=viewports)

    def motion(self) -> Motion:
        """Nothing moves: the scene is built once per set of values."""
        return Motion()


if __name__ == "__main__":
    sys.exit(glsandbox.run(Triangle))
