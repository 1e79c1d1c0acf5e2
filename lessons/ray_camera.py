"""Ray tracing lesson 1: the eye, the image plane and one ray per pixel.

Course section "Bakış noktası, görüntü düzlemi GD(x,y)". The notes put the
eye at the origin looking along +z (DirectX) and an image plane 16 by 9
units at z = 10; pixel (x, y) of an 800x450 image lands on

    GD(x, y) = (16x/799 - 8, 4.5 - 9y/449, 10)

and the primary ray is R0 = (0,0,0), Rd = GD(x, y) - R0. The overlay shows
GD at the corners and the centre. The first and last pixel sit *on* the
plane's edges; the rasterizer (and so the engines, to draw the same picture)
sample pixel *centres*, half a pixel in: ``x_ndc = 2(x + 1/2)/W - 1``. The
scene: three spheres on the course's axis, seen through that camera
(OpenGL mirrors z, so the course's +z is -z here).
"""

from __future__ import annotations

import sys

import glsandbox
from glsandbox import (
    Camera,
    Lesson,
    Light,
    Material,
    Node,
    Overlay,
    Scene,
    geometry,
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import course_image_plane

#: The course's image plane: 16 x 9 units at distance 10, so the vertical field of view is 2·atan(4.5/10).
FOV_Y = 48.46554491945989


def ball(name: str, center_dx: tuple[float, float, float], radius: float, color: tuple[float, float, float]) -> Node:
    """A sphere placed in the course's (DirectX) coordinates."""
    c = transforms.from_directx_point(center_dx)
    return Node(name, geometry.sphere(), transforms.translate(*c) @ transforms.scale(radius, radius, radius),
                Material(color=(*color, 1.0), shading="phong", ambient=0.2, diffuse=0.6, specular=0.2))


def gd_panel() -> list[str]:
    rows = ["GD(x,y) = (16x/799 - 8, 4.5 - 9y/449, 10)  [800x450]"]
    for x, y in ((0, 0), (799, 0), (400, 225), (799, 449)):
        p = course_image_plane(x, y)
        rows.append(f"GD({x},{y}) = ({p[0]:.4f}, {p[1]:.4f}, {p[2]:g})")
    rows.append("engines: pixel centres, x_ndc = 2(x+0.5)/W - 1")
    return rows


@register
class RayCamera(Lesson):
    name = "ray_camera"
    title = "The eye, the image plane GD(x,y) and a primary ray per pixel"
    course_section = "Bakış noktası, görüntü düzlemi GD(x,y)"
    order = 110
    defaults = {"renderer": "ray"}

    def build(self) -> Scene:
        nodes = (
            ball("near", (-3.0, -1.0, 20.0), 1.5, (0.9, 0.2, 0.2)),
            ball("middle", (0.0, 0.0, 30.0), 3.0, (0.2, 0.8, 0.3)),
            ball("far", (6.0, 2.0, 45.0), 5.0, (0.2, 0.4, 0.9)),
        )
        # The course's eye at the origin looking along +z: -z in OpenGL.
        camera = Camera(eye=(0.0, 0.0, 0.0), target=(0.0, 0.0, -1.0), fov_y=FOV_Y, near=0.01, far=200.0)
        light = Light(tuple(transforms.from_directx_point((-10.0, 20.0, 0.0))))
        return Scene(self.name, nodes=nodes, camera=camera, lights=(light,), clear_color=(0.05, 0.05, 0.1, 1.0),
                     overlays=(Overlay("gd", text_image(gd_panel()), None, (4, 4)),))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayCamera))
