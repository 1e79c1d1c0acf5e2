"""Ray tracing lesson 3: the ray-sphere test and the nearest hit.

Course sections "Işın-Küre kesim testi" and the nearest hit (``tDistances``,
``min_indis``). Worked example #4 is the scene: the eye at the origin, a
sphere C = (0, 0, 100), r = 75, and the ray along (0, 0.6, 0.8): l = C - R0,
s = l·Rd = 80, m² = l·l - s² = 3600, q = sqrt(r² - m²) = 45, and from
outside t = s - q = 35, the point (0, 21, 28). Two smaller spheres overlap
it: every pixel keeps the *nearest* positive t over all shapes, which is
what hides the parts behind. The overlay prints the figures computed by the
library (geometric and stable forms agree) and the nearest-hit table of the
centre pixel's ray. Course coordinates (DirectX, +z ahead) are mirrored to
OpenGL's -z.
"""

from __future__ import annotations

import sys

import numpy as np

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
from glsandbox.raytrace import Ray, Sphere, nearest_hit

#: (name, centre in course coordinates, radius, colour)
SPHERES = (
    ("big", (0.0, 0.0, 100.0), 75.0, (0.85, 0.3, 0.25)),
    ("left", (-45.0, 10.0, 40.0), 18.0, (0.25, 0.7, 0.35)),
    ("right", (50.0, -20.0, 30.0), 14.0, (0.3, 0.45, 0.9)),
)


def figures() -> list[str]:
    """Worked example #4 through the public API, and the centre ray's nearest hit."""
    big = Sphere(SPHERES[0][1], SPHERES[0][2])
    ray = Ray((0.0, 0.0, 0.0), (0.0, 0.6, 0.8))
    l = big.center - ray.origin  # noqa: E741 (the course's l)
    s = float(l @ ray.direction)
    m2 = float(l @ l) - s * s
    q = float(np.sqrt(big.radius**2 - m2))
    t = big.intersect(ray, method="geometric")
    stable = big.intersect(ray)
    shapes = [Sphere(c, r) for _, c, r, _ in SPHERES]
    centre = Ray((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    ts = [shape.intersect(centre) for shape in shapes]
    t_min, index = nearest_hit(centre, shapes)
    return [
        "#4: C=(0,0,100) r=75, Rd=(0,0.6,0.8)",
        f"s = {s:g}, m^2 = {m2:g}, q = {q:g}",
        f"t = s - q = {t:g} (stable: {stable:g}), P = (" + ", ".join(f"{float(v):.6g}" for v in ray.at(t)) + ")",
        "centre ray tDistances: " + ", ".join("miss" if v is None else f"{v:g}" for v in ts),
        f"nearest: t = {t_min:g}, min_indis = {index} ({SPHERES[index][0]})",
    ]


@register
class RaySpheres(Lesson):
    name = "ray_spheres"
    title = "Ray-sphere test (worked example #4) and the nearest hit"
    course_section = "Işın-Küre kesim testi; nearest hit"
    order = 130
    defaults = {"renderer": "ray"}

    def build(self) -> Scene:
        nodes = tuple(
            Node(name, geometry.sphere(),
                 transforms.translate(*transforms.from_directx_point(c)) @ transforms.scale(r, r, r),
                 Material(color=(*col, 1.0), shading="phong", ambient=0.2, diffuse=0.6, specular=0.2))
            for name, c, r, col in SPHERES
        )
        # Back from the course's eye (the origin), so all three spheres show.
        camera = Camera(eye=tuple(transforms.from_directx_point((0.0, 40.0, -140.0))),
                        target=tuple(transforms.from_directx_point((0.0, 0.0, 60.0))), fov_y=60.0, far=500.0)
        light = Light(tuple(transforms.from_directx_point((-100.0, 150.0, -50.0))))
        return Scene(self.name, nodes=nodes, camera=camera, lights=(light,), clear_color=(0.05, 0.05, 0.1, 1.0),
                     overlays=(Overlay("figures", text_image(figures()), None, (4, 4)),))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RaySpheres))
