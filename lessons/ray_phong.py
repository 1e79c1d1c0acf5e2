"""Ray tracing lesson 4: Phong with shadow rays and reflections; the two exam scenes.

Course sections "Phong boyama modeli" (ka + kd + ks = 1), "Yansıma vektörü"
(R = Rd - 2(Rd·N)N, followed to depth 2) and "Gölge testi" (a point is in
shadow iff something lies at 0 < t < distance to the light). ``--set
scene=...``:

- ``demo``: spheres and a box on a half-mirror floor, two lights;
- ``exam2013``: worked examples #8 and #9. The ray from the origin along
  (0.96, 0.28, 0) hits the red sphere (C = (80,15,0), r = 10) at t = 75, the
  point (72,21,0) with normal (-0.8,0.6,0); the reflected ray (0,1,0) hits
  the blue sphere (C = (72,121,0), r = 35) at t = 65. Towards the light
  L = (100,117,0) (distance 100, direction (0.28,0.96,0)) the blue sphere is
  crossed at t = 75 < 100: the point is in shadow. The red sphere is a
  mirror here so the reflection shows; the notes' typo of #9 (subtracting
  the blue centre) is corrected;
- ``far_eye``: shadow acne from a far eye. Rays from an eye 1e7 away hit a
  unit sphere at the origin on 400 points that face the light: none can be in
  shadow (the sphere alone is convex). The simple relative offset
  (``epsilon=SHADOW_EPSILON``, 2⁻³²·max(1, |P|)) is 2e-10 there, smaller than
  the hit point's own rounding error (about 1e-9: ``P = R0 + t·Rd`` with
  ``|t·Rd|`` = 1e7), and about a fifth of the points shadow themselves;
  the offset from the hit's error bound (:attr:`Hit.error`, the default)
  shadows none;
- ``exam2012``: worked example #10. From P = (0,-8,-5) towards L = (0,10,-29)
  (distance 30, direction (0,0.6,-0.8)) the plane N = (0,-0.6,0.8), D = 39.2
  is crossed at t = 40, *beyond* the light: P is lit. The notes conclude
  "in shadow"; that is the erratum, and the picture shows the light
  reaching the floor under the tilted plane.

Course coordinates are DirectX's; they are mirrored to OpenGL's (z -> -z).
"""

from __future__ import annotations

import math
import sys

import glsandbox
from glsandbox import (
    Camera,
    Lesson,
    Light,
    Node,
    Overlay,
    Param,
    Scene,
    WorldLine,
    WorldLines,
    WorldMark,
    geometry,
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import SHADOW_EPSILON, Plane, Ray, Sphere, first_hit, in_shadow, reflect, shadow_ray
from ._scenes import KA, KD, KS, demo_scene, dx, lamp, material, sphere

SCENES = ("demo", "exam2013", "exam2012", "far_eye")


def fmt(v) -> str:
    """A vector as the course writes it: (0, 0.6, -0.8)."""
    return "(" + ", ".join(f"{round(float(x), 9) + 0.0:.6g}" for x in v) + ")"


#: The figure's colours (RGBA), each far from the scene's own: the eye's ray, the reflected
#: ray, the shadow ray up to what it meets, the hit points, the light.
RAY_COLOR = (255, 225, 0, 255)
REFLECTED_COLOR = (0, 230, 255, 255)
SHADOW_RAY_COLOR = (255, 120, 0, 255)
LIT_COLOR = (90, 255, 90, 255)
BLOCKED_COLOR = (255, 60, 200, 255)
POINT_COLOR = (255, 255, 255, 255)
LIGHT_COLOR = (255, 255, 150, 255)


def along(ray: Ray, t: float) -> tuple[float, float, float]:
    """The point at ``t`` on ``ray`` (its direction is a unit vector: t is a distance)."""
    return tuple(float(o + t * d) for o, d in zip(ray.origin, ray.direction))  # type: ignore[return-value]


def exam2013(name: str) -> tuple[Scene, list[str], WorldLines]:
    red, blue, light = Sphere(dx((80, 15, 0)), 10.0), Sphere(dx((72, 121, 0)), 35.0), dx((100, 117, 0))
    ray = Ray((0.0, 0.0, 0.0), dx((0.96, 0.28, 0.0)))
    hit = first_hit(ray, [red, blue])
    assert hit is not None
    bounce = Ray(hit.point, reflect(ray.direction, hit.normal))
    t_blue = blue.intersect(bounce)
    to_light, distance = shadow_ray(hit.point, light, hit.normal)
    t_block = blue.intersect(to_light)
    rows = ["2013 exam (#8, #9)",
            f"red hit t = {hit.t:.6g} at {fmt(hit.point)}, N = {fmt(hit.normal)}",
            f"reflected {fmt(bounce.direction)} hits blue at t = {t_blue:.6g}",
            f"to light: distance {distance:.6g}, blue at t = {t_block:.6g} < {distance:.6g}: "
            + ("in shadow" if in_shadow(hit, light, [red, blue]) else "lit")]
    nodes = (sphere("red", tuple(red.center), 10.0, material((0.9, 0.1, 0.1), reflectivity=0.5)),
             sphere("blue", tuple(blue.center), 35.0, material((0.15, 0.25, 0.9))),
             lamp(0, light, 2.0))
    camera = Camera(eye=(70.0, 30.0, 170.0), target=(76.0, 55.0, 0.0), fov_y=55.0, far=1000.0)
    # The question drawn over the picture: the ray to the red hit, the reflection to the blue
    # one, and the shadow ray towards the light (inside the blue sphere), solid up to the
    # blue sphere that blocks it and dashed beyond, where the light is not reached.
    point, blocked = tuple(map(float, hit.point)), along(to_light, t_block)
    verdict = "IN SHADOW" if in_shadow(hit, light, [red, blue]) else "lit"
    figure = WorldLines("exam rays", lines=(
        WorldLine(ray.origin, point, RAY_COLOR),
        WorldLine(point, along(bounce, t_blue), REFLECTED_COLOR),
        WorldLine(point, blocked, SHADOW_RAY_COLOR),
        WorldLine(blocked, light, BLOCKED_COLOR, dashed=True),
    ), marks=(
        WorldMark(ray.origin, "eye ray", RAY_COLOR, left=True),
        WorldMark(point, f"hit t={hit.t:.4g}", POINT_COLOR),
        WorldMark(along(bounce, t_blue), f"reflected: blue t={t_blue:.4g}", REFLECTED_COLOR, left=True),
        WorldMark(blocked, f"blocked t={t_block:.4g} < {distance:.4g}: {verdict}", BLOCKED_COLOR),
        WorldMark(light, "light", LIGHT_COLOR),
    ))
    scene = Scene(name, nodes=nodes, camera=camera, lights=(Light(light),), clear_color=(0.08, 0.08, 0.12, 1.0))
    return scene, rows, figure


def exam2012(name: str) -> tuple[Scene, list[str], WorldLines]:
    light, point = dx((0, 10, -29)), dx((0, -8, -5))
    normal = dx((0.0, -0.6, 0.8))
    plane = Plane.through(normal, dx((0, 20, -34)))
    to_light, distance = shadow_ray(point, light, (0.0, 1.0, 0.0))
    t_plane = plane.intersect(Ray(point, to_light.direction))
    rows = ["2012 exam (#10)",
            f"P = (0,-8,-5) -> L = (0,10,-29): distance {distance:.6g}",
            f"plane N = (0,-0.6,0.8), D = {-plane.d if plane.d < 0 else plane.d:.6g}: hit at t = {t_plane:.6g}",
            f"t = {t_plane:.6g} > {distance:.6g}: beyond the light, P is LIT",
            "(the notes' 'in shadow' is the erratum: rule is 0 < t < distance)"]
    angle = math.atan2(normal[2], normal[1])  # R_x(angle) turns the plane's +y normal onto N
    tilted = Node("tilted", geometry.plane(60.0),
                  transforms.translate(*dx((0, 20, -34))) @ transforms.rotate_x(angle),
                  material((0.7, 0.7, 0.75)), cull_back_faces=False)
    floor = Node("floor", geometry.plane(80.0), transforms.translate(0.0, -8.0, 0.0), material((0.6, 0.55, 0.45)))
    marker = sphere("P", point, 0.6, material((0.9, 0.2, 0.2)))
    camera = Camera(eye=(30.0, 8.0, -20.0), target=(0.0, 3.0, 17.0), fov_y=60.0, far=500.0)
    nodes = (floor, tilted, marker, lamp(0, light, 0.6))
    # The question drawn over the picture: the shadow ray reaches the light (solid) before the
    # plane, which it meets only beyond it (dashed): nothing blocks it, P is lit.
    crossing = along(Ray(point, to_light.direction), t_plane)
    figure = WorldLines("exam rays", lines=(
        WorldLine(point, light, LIT_COLOR),
        WorldLine(light, crossing, BLOCKED_COLOR, dashed=True),
    ), marks=(
        WorldMark(point, "P", POINT_COLOR),
        WorldMark(light, f"light at {distance:.4g}: LIT", LIGHT_COLOR),
        WorldMark(crossing, f"plane t={t_plane:.4g}", BLOCKED_COLOR, left=True),
    ))
    scene = Scene(name, nodes=nodes, camera=camera, lights=(Light(light),), clear_color=(0.08, 0.08, 0.12, 1.0))
    return scene, rows, figure


def self_shadowed(eye_distance: float, epsilon: float | None, count: int = 400) -> int:
    """How many of ``count`` lit points of a unit sphere at the origin, seen from
    ``eye_distance`` away, :func:`in_shadow` wrongly calls shadowed (the sphere is the
    only shape): with ``epsilon`` the teaching variant's offset, else the error bound."""
    import numpy as np

    rng = np.random.default_rng(1)
    ball, light = Sphere((0.0, 0.0, 0.0), 1.0), np.array([5.0, 5.0, 5.0])
    eye = -eye_distance * np.array([1.0, 0.3, 0.1])
    wrong = found = 0
    while found < count:
        q = rng.standard_normal(3)
        q /= np.linalg.norm(q)
        if q @ eye <= 0.0 or q @ light <= 0.0:
            continue  # a point the eye cannot see, or one facing away from the light
        hit = first_hit(Ray(tuple(eye), tuple(q - eye)), [ball])
        if hit is None or float(np.dot(hit.normal, light - hit.point)) <= 0.0:
            continue
        found += 1
        # The Hit carries its error bound; a bare point and epsilon: the teaching variant.
        wrong += in_shadow(hit, light, [ball]) if epsilon is None else \
            in_shadow(hit.point, light, [ball], hit.normal, epsilon=epsilon)
    return wrong


def far_eye(name: str) -> tuple[Scene, list[str]]:
    rows = ["Shadow acne from a far eye: a unit sphere, the eye 1e7 away",
            f"simple offset 2^-32*max(1,|P|): {self_shadowed(1e7, SHADOW_EPSILON)} of 400 lit points self-shadowed",
            f"offset from the hit's error bound: {self_shadowed(1e7, None)} of 400",
            "(P = R0 + t*Rd is off by ~1e-16*(|R0| + |t*Rd|) = 1e-9; the simple offset is 2e-10)"]
    light = (5.0, 5.0, 5.0)
    nodes = (sphere("ball", (0.0, 0.0, 0.0), 1.0, material((0.9, 0.5, 0.2))), lamp(0, light, 0.3))
    camera = Camera(eye=(-3.0, 1.0, 3.5), target=(0.0, 0.0, 0.0), fov_y=45.0)
    return Scene(name, nodes=nodes, camera=camera, lights=(Light(light),), clear_color=(0.08, 0.08, 0.12, 1.0)), rows


@register
class RayPhong(Lesson):
    name = "ray_phong"
    title = "Phong, shadow rays and reflections; the 2013 and 2012 exam scenes"
    course_section = "Phong boyama modeli; Yansıma vektörü; Gölge testi"
    order = 140
    contrasts = (("raster against ray: the same Scene rasterized and ray traced", "renderer=raster,ray"),)
    defaults = {"renderer": "ray"}
    params = (Param("scene", "demo", "which scene", choices=SCENES),
              Param("exam_rays", True, "the exam scenes: draw the question's rays, hits and light over the picture"))

    def build(self) -> Scene:
        which = self.values["scene"]
        figures: tuple[WorldLines, ...] = ()
        if which == "demo":
            scene = demo_scene(self.name)
            rows = [f"Phong ka={KA} kd={KD} ks={KS} (sum 1), shadows, reflections to depth 2"]
        elif which == "far_eye":
            scene, rows = far_eye(self.name)
        else:
            scene, rows, figure = {"exam2013": exam2013, "exam2012": exam2012}[which](self.name)
            figures = (figure,) if self.values["exam_rays"] else ()
        from dataclasses import replace

        return replace(scene, overlays=(*figures, Overlay("figures", text_image(rows), None, (4, 4))))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayPhong))
