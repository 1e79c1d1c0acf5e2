"""Ray tracing lesson 5: acceleration by backface culling, bounding boxes and a BVH.

Course section "Hızlandırma: backface culling, AABB". Nine low-poly spheres
(traced as their 224 triangles each, not as exact spheres) on a floor.

- **Backface culling**: a closed mesh's triangles that face away from the ray
  (N·Rd > 0, Möller–Trumbore's det <= 0) can never be the first visible hit;
  skip them after one dot product.
- **AABB**: a box around each node; a ray that misses the box (the slab test)
  skips all of the node's triangles.
- **BVH** (bounding volume hierarchy): the box test asked again inside the
  box, for two smaller boxes, and so on down to leaves of a few triangles
  (``glsandbox.raytrace.bvh``); a ray tests a few dozen boxes and triangles
  instead of all of a node's triangles. Shadow rays stop at their first hit.

The table renders the scene with the numpy engine at a small size under six
combinations and lists the ray-shape and ray-box tests each did (the same
picture every time) and, with ``timing=on``, the measured time and speed-up.
Backface culling skips tests in the numpy engine too: rays that share an
origin (the primary rays) drop each triangle that faces away from it before
any test (for a hit ``d·N`` has the sign of ``(V0 − O)·N``), other rays drop
the pairs with ``d·N > 0`` after that dot product; the count shows the tests
left and the time falls with it. The GLSL engine returns early per triangle
(``benchmarks/raytrace.py`` measures both). Below it, with ``rock=on`` (the
default), the BVH and the AABB alone trace a generated rock of 5,120
triangles (:data:`ROCK_SIZE`): the shape tests each does and, with
``timing=on``, the speed-up a real model sees. The default picture holds only
counts, so it is the same in every run and on every backend; measured times
change every run and are shown only when asked for. On the nine small spheres the BVH does twenty times fewer
shape tests than the AABB but is no faster in numpy: with 224 triangles a
node, the per-level bookkeeping of the packet traversal (and the first
render's BVH builds) costs what the tests save; on the rock it wins by an
order of magnitude.
"""

from __future__ import annotations

import functools
import sys
import time
from dataclasses import replace

import glsandbox
from glsandbox import (
    Camera,
    Lesson,
    Light,
    Material,
    Node,
    Overlay,
    Param,
    Scene,
    geometry,
    meshgen,
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import RenderStats, render

#: Measured at this size, so the lesson stays quick.
MEASURE_SIZE = (64, 48)
#: (label, cull_backfaces, aabb, bvh)
COMBINATIONS = (("none", False, False, False), ("backface", True, False, False), ("AABB", False, True, False),
                ("both", True, True, False), ("BVH", False, True, True), ("BVH+backface", True, True, True))
#: The rock is timed at this size (the AABB alone tests every ray against its 5,120 triangles).
ROCK_SIZE = (48, 36)


def scene(name: str) -> Scene:
    mesh = replace(geometry.sphere(8, 16), name="sphere_mesh", analytic=None)  # a mesh, not the exact sphere
    material = Material(color=(0.8, 0.5, 0.3, 1.0), shading="phong", ambient=0.2, diffuse=0.6, specular=0.2)
    nodes = [Node("floor", geometry.plane(20.0), transforms.translate(0.0, -1.0, 0.0),
                  Material(color=(0.5, 0.5, 0.55, 1.0), shading="phong", ambient=0.2, diffuse=0.6, specular=0.2))]
    for i in range(3):
        for j in range(3):
            model = transforms.translate(2.5 * (i - 1), -0.3, 2.5 * (j - 1)) @ transforms.scale(0.7, 0.7, 0.7)
            nodes.append(Node(f"ball{i}{j}", mesh, model, material))
    return Scene(name, nodes=tuple(nodes), camera=Camera(eye=(0.0, 4.0, 8.0), target=(0.0, -0.5, 0.0)),
                 lights=(Light((3.0, 6.0, 4.0)),), clear_color=(0.1, 0.12, 0.2, 1.0))


@functools.lru_cache(maxsize=2)
def table(base_name: str, timing: bool) -> tuple[str, ...]:
    """The table's rows (computed once per process: the window rebuilds the scene every frame)."""
    base = scene(base_name)
    rows: list[str | list[str]] = [["culling", "ray-shape tests", "box tests",
                                    *(["ms", "speed-up"] if timing else [])]]
    first = None
    for label, cull, aabb, bvh in COMBINATIONS:
        stats = RenderStats()
        start = time.perf_counter()
        render(base, MEASURE_SIZE, cull_backfaces=cull, aabb=aabb, bvh=bvh, stats=stats)
        seconds = time.perf_counter() - start
        first = first or seconds
        cells = [label, f"{stats.tests:,}", f"{stats.box_tests:,}"]
        if timing:
            cells += [f"{seconds * 1000:.0f}", f"{first / seconds:.1f}x"]
        rows.append(cells)
    return (f"numpy engine, {MEASURE_SIZE[0]}x{MEASURE_SIZE[1]}, shadows on", *rows)  # type: ignore[arg-type]


def rock_scene() -> Scene:
    """A generated rock of 5,120 triangles on the floor: a real model for the BVH."""
    rock = glsandbox.fit_mesh(meshgen.rock(4, seed=4, roughness=0.3))
    base = scene("rock")
    material = base.nodes[1].material
    return replace(base, nodes=(base.nodes[0], Node("rock", rock, transforms.translate(0.0, 0.0, 0.0), material)),
                   camera=Camera(eye=(0.0, 1.6, 4.0), target=(0.0, -0.1, 0.0)))


@functools.lru_cache(maxsize=2)
def rock_rows(timing: bool) -> tuple[str, ...]:
    """The rock's line: the AABB alone against the BVH, shape tests counted and, with
    ``timing``, timed (computed once per process)."""
    rock = rock_scene()
    cells = {}
    for label, bvh in (("AABB", False), ("BVH", True)):
        stats = RenderStats()
        start = time.perf_counter()
        render(rock, ROCK_SIZE, bvh=bvh, stats=stats)
        cells[label] = (time.perf_counter() - start, stats.tests)
    (aabb_s, aabb_tests), (bvh_s, bvh_tests) = cells["AABB"], cells["BVH"]
    triangles = int(rock.nodes[1].mesh.triangle_indices().shape[0])
    if not timing:
        return (f"rock, {triangles:,} triangles, {ROCK_SIZE[0]}x{ROCK_SIZE[1]}:",
                f"AABB: {aabb_tests:,} shape tests",
                f"BVH: {bvh_tests:,} shape tests, {aabb_tests / bvh_tests:.0f}x fewer")
    return (f"rock, {triangles:,} triangles, {ROCK_SIZE[0]}x{ROCK_SIZE[1]} (times change every run):",
            f"AABB {aabb_s * 1000:.0f} ms, {aabb_tests:,} shape tests",
            f"BVH {bvh_s * 1000:.0f} ms, {bvh_tests:,} shape tests: {aabb_s / bvh_s:.0f}x faster")


@register
class RayAcceleration(Lesson):
    name = "ray_acceleration"
    title = "Acceleration: backface culling, AABB and BVH, measured"
    course_section = "Hızlandırma: backface culling, AABB"
    order = 150
    defaults = {"renderer": "ray"}
    params = (Param("timing", False, "measure and show times and speed-ups (changes every run)"),
              Param("rock", True, "the BVH against the AABB on a 5,120-triangle rock: shape tests (and, with "
                                  "timing=on, times)"))

    def build(self) -> Scene:
        base = scene(self.name)
        timing = bool(self.values["timing"])
        rows = table(self.name, timing)
        if self.values["rock"]:
            rows = (*rows, "", *rock_rows(timing))
        panel = text_image(rows)
        return replace(base, overlays=(Overlay("table", panel, None, (4, 4)),))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayAcceleration))
