"""Ray tracing lesson 2: ray-plane, then ray-triangle with all six inside tests.

Course section "Işın-Üçgen kesim testi". First the plane of the triangle
(N = (V1-V0)×(V2-V0) normalised, D = -N·V0, t = -(N·R0 + D)/(N·Rd); worked
example #2: N = (0, 0.6, -0.8), D = 72, t = 90), then "is the point inside?"
by the course's four tests (I area sums, II edge distances, III dot-product
barycentrics, IV area ratios), and the two one-step tests Möller-Trumbore and
the watertight test (Woop, Benthin, Wald 2013). Each panel shows one test on
the triangle of worked example #3 (V0 = (30,-40,60), V1 = (60,-120,0),
V2 = (0,-120,0)), rays from the origin through a grid: white = triangle,
grey = its plane only, dark = nothing. The footer says whether all six agree
on every ray and, with ``timing=on``, the cost of one test: in microseconds
for the scalar tests (Python, one ray at a time), and in nanoseconds for the
two the engines run vectorised, Möller-Trumbore and watertight, timed as
``glsandbox tradeoffs`` times them (its ``triangle_test`` rays and scans), so
the lesson and the report rank them alike.
"""

from __future__ import annotations

import functools
import statistics
import sys
import time

import numpy as np

import glsandbox
from glsandbox import (
    Camera,
    Lesson,
    Material,
    Mesh,
    Node,
    Overlay,
    Param,
    Scene,
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import INSIDE_TESTS, Plane, Ray, Triangle, aimed_rays, nearest_by

V0, V1, V2 = (30.0, -40.0, 60.0), (60.0, -120.0, 0.0), (0.0, -120.0, 0.0)
GRID = (80, 60)
PANEL_SCALE = 1


#: The frame size whose rays :func:`vectorised_costs` times (``glsandbox tradeoffs --quick``'s).
TIMING_SIZE = (64, 48)


def vectorised_costs(rounds: int = 5) -> tuple[dict[str, float], int, int]:
    """Nanoseconds per ray-triangle pair of Möller–Trumbore (float64) and the watertight test,
    measured as ``glsandbox tradeoffs`` measures them (its ``triangle_test`` row): the vectorised
    scans over every triangle of its closed icosphere, on its rays (aimed at the vertices and
    edges, :func:`~glsandbox.raytrace.aimed_rays`), the two timed in turn for ``rounds`` rounds
    (the order swapped every other round, so a load that comes and goes hits both alike), the
    median of each. Returns the costs, the rays and the triangles."""
    tris, origins, directions = aimed_rays(TIMING_SIZE)
    pairs = directions.shape[0] * tris[0].shape[0]
    tests = (("mt64", "moller_trumbore"), ("watertight", "watertight"))
    times: dict[str, list[float]] = {name: [] for _, name in tests}
    for number in range(rounds):
        for test, name in tests if number % 2 == 0 else tests[::-1]:
            start = time.perf_counter()
            nearest_by(test, tris, origins, directions)
            times[name].append(time.perf_counter() - start)
    costs = {name: statistics.median(taken) / pairs * 1e9 for name, taken in times.items()}
    return costs, directions.shape[0], tris[0].shape[0]


@functools.lru_cache(maxsize=2)
def panels(timing: bool) -> tuple[np.ndarray, list[str]]:
    """The six panels side by side (3 x 2) and the footer rows."""
    tri = Triangle(V0, V1, V2)
    plane = Plane.through(tri.normal, V0)
    w, h = GRID
    xs = np.linspace(-150.0, 150.0, w)
    ys = np.linspace(40.0, -260.0, h)
    rays = [Ray((0.0, 0.0, 0.0), (x, y, 60.0)) for y in ys for x in xs]
    on_plane = np.array([plane.intersect(r) is not None for r in rays]).reshape(h, w)
    results, costs = {}, {}
    for name in INSIDE_TESTS:
        start = time.perf_counter()
        hits = [tri.intersect(r, method=name, cull_backfaces=False) for r in rays]
        costs[name] = (time.perf_counter() - start) / len(rays) * 1e6
        results[name] = np.array([t is not None for t in hits]).reshape(h, w)
    images = []
    for name, hit in results.items():
        rgb = np.where(hit[..., None], 235, np.where(on_plane[..., None], 90, 25)).astype(np.uint8)
        rgba = np.concatenate([np.repeat(rgb, 3, axis=2), np.full((h, w, 1), 255, np.uint8)], axis=2)
        rgba = np.repeat(np.repeat(rgba, PANEL_SCALE, axis=0), PANEL_SCALE, axis=1)
        label = text_image([name])[:, : rgba.shape[1] - 2]
        rgba[: label.shape[0], : label.shape[1]] = label
        rgba[:, -2:] = (0, 0, 0, 255)  # a dark gap between panels
        images.append(rgba)
    top = np.concatenate(images[:3], axis=1)
    bottom = np.concatenate(images[3:], axis=1)
    reference = results["moller_trumbore"]
    agree = all(np.array_equal(v, reference) for v in results.values())
    rows = [f"#2: plane N = ({', '.join(f'{v:.6g}' for v in tri.normal)}), D = {plane.d:.6g}; "
            f"ray (0,0,1): t = {plane.intersect(Ray((0, 0, 0), (0, 0, 1))):.6g}, triangle: "
            f"{'hit' if tri.intersect(Ray((0, 0, 0), (0, 0, 1))) else 'miss'}",
            f"all six agree on {w * h} rays: {'yes' if agree else 'NO'}; {int(reference.sum())} hit the triangle"]
    if timing:
        # The scalar tests, one Python call per ray (the six side by side, the course's code), and
        # the two the engines use, vectorised as the tradeoffs report times them: the numbers
        # to compare tests by (a Python call costs far more than the test inside it).
        rows.append("us per scalar test (a Python call a ray): "
                    + ", ".join(f"{k} {v:.1f}" for k, v in costs.items()))
        fast, n_rays, n_tris = vectorised_costs()
        rows.append(f"ns per vectorised test ({n_rays} rays x {n_tris} triangles, as tradeoffs): "
                    + ", ".join(f"{k} {v:.1f}" for k, v in fast.items()))
    return np.concatenate([top, bottom], axis=0), rows


@register
class RayTriangle(Lesson):
    name = "ray_triangle"
    title = "Ray-plane and ray-triangle: six inside tests side by side"
    course_section = "Işın-Üçgen kesim testi"
    order = 120
    defaults = {"renderer": "ray"}
    params = (Param("timing", False, "measure and show each test's cost (changes every run)"),)

    def build(self) -> Scene:
        image, rows = panels(bool(self.values["timing"]))
        # The triangle itself, in 3D, from the course's eye (DirectX +z is OpenGL -z).
        positions = np.array([transforms.from_directx_point(v) for v in (V0, V1, V2)])
        mesh = Mesh("exam_triangle", positions)
        node = Node("triangle", mesh, transforms.identity(), Material(color=(0.9, 0.6, 0.2, 1.0)),
                    cull_back_faces=False)
        camera = Camera(eye=(30.0, -60.0, 150.0), target=(30.0, -80.0, -30.0), fov_y=60.0, far=500.0)
        return Scene(self.name, nodes=(node,), camera=camera, clear_color=(0.05, 0.05, 0.1, 1.0),
                     overlays=(Overlay("panels", image, None, (4, 4)),
                               Overlay("footer", text_image(rows), None, (4, -4))))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayTriangle))
