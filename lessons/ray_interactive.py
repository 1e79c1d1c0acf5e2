"""Ray tracing lesson 6: the interactive ray tracer with the shared camera.

Course section "W A S D, Z X camera" on the ray tracer. The scene of
``ray_phong`` (spheres, a box, a half-mirror floor, two lights, shadows and
reflections) traced by the GLSL engine every frame. In the window the
camera keys of every lesson work (W/S move, A/D turn 15°, Z/X up and down,
arrows and mouse drag orbit, wheel zooms); while the camera moves the frame
is traced at a quarter of the resolution each way (16 times fewer rays),
and at full resolution as soon as it is still
(:class:`glsandbox.frame.InteractiveResolution`).
``--set renderer=raster`` shows the rasterizer's version of the same scene.
"""

from __future__ import annotations

import sys

import glsandbox
from glsandbox import Lesson, Scene, register
from ._scenes import demo_scene


@register
class RayInteractive(Lesson):
    name = "ray_interactive"
    title = "The interactive ray tracer: WASD camera, coarse while moving"
    course_section = "W A S D, Z X camera (ray tracer)"
    order = 160
    defaults = {"renderer": "ray"}

    def build(self) -> Scene:
        return demo_scene(self.name)


if __name__ == "__main__":
    sys.exit(glsandbox.run(RayInteractive))
