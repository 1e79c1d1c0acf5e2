"""Ray tracing lesson 5: acceleration by backface culling and bounding boxes.

Course section "Hızlandırma: backface culling, AABB". Nine low-poly spheres
(traced as their 224 triangles each, not as exact spheres) on a floor.

- **Backface culling**: a closed mesh's triangles that face away from the ray
  (N·Rd > 0, Möller–Trumbore's det <= 0) can never be the first visible hit;
  skip them after one dot product.
- **AABB**: a box around each node; a ray that misses the box (the slab test)
  skips all of the node's triangles.

The table renders the scene with the numpy engine at a small size under the
four combinations and lists the ray-shape tests each did (the same picture
every time) and, with ``timing=on``, the measured time and speed-up. The
numpy engine computes every lane of a vectorized test anyway, so backface
culling saves it nothing; the GLSL engine returns early per triangle
(``benchmarks/raytrace.py`` measures both).
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
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import RenderStats, render

#: Measured at this size, so the lesson stays quick.
MEASURE_SIZE = (64, 48)
COMBINATIONS = (("none", False, False), ("backface", True, False), ("AABB", False, True), ("both", True, True))


def scene(name: str) -> Scene:
    mesh = replace(geometry.sphere(8, 16), name="sphere_mesh")  # a mesh, not the exact sphere
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
    rows: list[str | list[str]] = [["culling", "ray-shape tests", *(["ms", "speed-up"] if timing else [])]]
    first = None
    for label, cull, aabb in COMBINATIONS:
        stats = RenderStats()
        start = time.perf_counter()
        render(base, MEASURE_SIZE, cull_backfaces=cull, aabb=aabb, stats=stats)
        seconds = time.perf_counter() - start
        first = first or seconds
        cells = [label, f"{stats.tests:,}"]
        if timing:
            cells += [f"{seconds * 1000:.0f}", f"{first / seconds:.1f}x"]
        rows.append(cells)
    return (f"numpy engine, {MEASURE_SIZE[0]}x{MEASURE_SIZE[1]}, shadows on", *rows)  # type: ignore[arg-type]


@register
class RayAcceleration(Lesson):
    name = "ray_acceleration"
    title = "Acceleration: backface culling and AABB, measured"
    course_section = "Hızlandırma: backface culling, AABB"
    order = 150
    defaults = {"renderer": "ray"}
    params = (Param("timing", False, "measure and show times and speed-ups (changes every run)"),)

    def build(self) -> Scene:
        base = scene(self.name)
        panel = text_image(table(self.name, bool(self.values["timing"])))
        return replace(base, overlays=(Overlay("table", panel, None, (4, 4)),))


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayAcceleration))
