"""Lesson: shadow maps beside the course's planar shadow, checked by the ray tracer.

After "The stencil Test" (``XMMatrixShadow``: a planar shadow falls on one
plane only). A shadow map renders the scene's depth from the light into a
texture first (a pass of its own, listed by ``glsandbox plan shadow_map``);
then each lit pixel projects its world point with the light's matrix and
compares its depth with the stored one: farther means something stands
between it and the light. Any shape casts, any surface receives, the cube
shadows itself and the sphere drops its shadow on the cube.

Side by side (``show=all``): the planar shadow (only on the floor; the
sphere's shadow misses the cube), the shadow map, and the ray tracer's
exact shadow rays on the same scene. ``show=map`` draws the shadow map
alone, so ``glsandbox compare shadow_map --set show=map --vary
renderer=raster,ray`` gives the difference against the exact answer.

The knobs: ``size`` (texels per side: small maps give blocky edges),
``bias`` and ``slope_bias`` (how far the receiver moves towards the light
before comparing, in texels of the map where it is, so the same values work
for a scene of any size: at 0 the floor shadows itself in stripes, acne,
because a texel's one depth cannot match every point it covers; too much
and the shadow comes loose from the cube's foot, peter-panning: try
``bias=50``), ``pcf`` (the width of the percentage-closer filter: 1 is
one comparison per pixel, hard stairs; 3, 5, 7 average a grid).
"""

from __future__ import annotations

import sys

import numpy as np

import glsandbox
from glsandbox import Camera, Lesson, Light, Material, Motion, Node, Param, PlanarShadow, Scene, ShadowMap, Viewport
from glsandbox import geometry, register, transforms

#: The floor y = 0, normal up.
FLOOR_PLANE = (0.0, 1.0, 0.0, 0.0)
LIGHT = (-1.5, 4.0, 1.0)
CUBE_HALF = 0.5
CUBE_AT = (0.3, CUBE_HALF, -0.2)
FLOOR_SIZE = 8.0
#: Between the light and the cube's top: its shadow falls on the cube, which a planar shadow cannot show.
SPHERE = ((-0.45, 2.2, 0.3), 0.3)
#: A thin panel standing on the floor (centre, half extents): its shadow starts at
#: its foot, so a bias larger than its thickness opens a gap there (peter-panning).
PANEL = ((1.4, 0.4, 1.3), (0.04, 0.4, 0.6))
SHADOW_COLOR = (0.0, 0.0, 0.0, 0.5)
COLORS = {"floor": (0.75, 0.72, 0.65), "cube": (0.35, 0.55, 0.9), "sphere": (0.95, 0.45, 0.2),
          "panel": (0.5, 0.8, 0.45)}
#: The camera of one technique alone (eye, target); side by side it stands farther back.
SINGLE_VIEW = ((2.6, 3.6, 5.4), (0.0, 0.7, 0.0))
TILES_VIEW = ((3.6, 6.5, 9.5), (0.5, 0.6, 0.4))
FOV, NEAR, FAR = 40.0, 0.1, 50.0
CLEAR = (0.08, 0.08, 0.12, 1.0)
#: The shadow map's frustum (degrees): wide enough for the floor around the objects.
MAP_FOV = 80.0
#: The tiles of show=all, left to right.
TECHNIQUES = ("planar", "map", "ray")


def _lit(rgb: tuple[float, float, float]) -> Material:
    return Material(color=(*rgb, 1.0), shading="phong")


@register
class ShadowMapLesson(Lesson):
    name = "shadow_map"
    title = "Shadow maps beside the planar shadow, against the ray tracer"
    course_section = "after The stencil Test: shadow maps (depth from the light, compared per pixel)"
    order = 75
    animated = True
    contrasts = (("each technique alone: planar (floor only), shadow map, ray-traced", "show=planar,map,ray"),
                 ("acne, a sound bias, peter-panning", "bias=0,2.5,50"),
                 ("map size: blocky edges at 256, fine at 2048", "size=256,2048"))
    params = (
        Param("show", "all", "planar shadow, shadow map and ray-traced side by side, or one technique alone",
              choices=("all", *TECHNIQUES)),
        Param("size", "1024", "shadow map size in texels per side", choices=("256", "512", "1024", "2048")),
        Param("bias", 2.5, "constant depth bias, texels of the map towards the light (0: acne, 50: peter-panning)",
              minimum=0.0, maximum=200.0),
        Param("slope_bias", 2.5, "bias in texels per unit of tan(angle between normal and light)", minimum=0.0,
              maximum=200.0),
        Param("pcf", "3", "percentage-closer filter width in texels (1: one comparison)",
              choices=("1", "3", "5", "7")),
        Param("speed", 0.5, "the cube's turn rate, radians per second"),
    )

    def shadow_map(self) -> ShadowMap:
        v = self.values
        return ShadowMap(size=int(v["size"]), bias=float(v["bias"]), slope_bias=float(v["slope_bias"]),
                         pcf=int(v["pcf"]), fov=MAP_FOV)

    def objects(self, technique: str, viewport: int | None) -> list[Node]:
        """The floor, the turning cube and the sphere, as ``technique`` draws them in ``viewport``."""
        views = None if viewport is None else (viewport,)
        # Only the map's own tile casts and receives it (a lone ray tile too: --set renderer=ray on show=map).
        mapped = technique == "map" or viewport is None and technique == "ray"
        models = {
            "floor": transforms.scale(FLOOR_SIZE, 1.0, FLOOR_SIZE),
            "cube": self.cube_model(),
            "sphere": transforms.translate(*SPHERE[0]) @ transforms.scale(*(SPHERE[1],) * 3),
            "panel": transforms.translate(*PANEL[0]) @ transforms.scale(*PANEL[1]),
        }
        meshes = {"floor": geometry.plane(1.0), "cube": geometry.cube24(), "sphere": geometry.sphere(),
                  "panel": geometry.cube24()}
        prefix = "" if viewport is None else f"{technique}_"
        return [Node(prefix + name, meshes[name], models[name], _lit(COLORS[name]), viewports=views,
                     casts_shadow=mapped, receives_shadow=mapped) for name in models]

    def cube_model(self) -> np.ndarray:
        """The cube's model at :attr:`time`: turning about y on the floor."""
        turn = transforms.rotate_y(0.4 + float(self.values["speed"]) * self.time)
        return transforms.translate(*CUBE_AT) @ turn @ transforms.scale(*(CUBE_HALF,) * 3)

    def techniques(self) -> tuple[str, ...]:
        show = self.values["show"]
        return TECHNIQUES if show == "all" else (show,)

    def motion(self) -> Motion:
        """Only the cube turns with time, in every tile."""
        techniques = self.techniques()
        prefixes = [f"{t}_" for t in techniques] if len(techniques) > 1 else [""]
        model = self.cube_model()
        return Motion(models={f"{prefix}cube": model for prefix in prefixes})

    def build(self) -> Scene:
        techniques = self.techniques()
        several = len(techniques) > 1
        width = 1.0 / len(techniques)
        viewports, nodes = [], []
        for index, technique in enumerate(techniques):
            viewports.append(Viewport(rect=(index * width, 0.0, width, 1.0), label=technique,
                                      renderer="ray" if technique == "ray" else "raster"))
            nodes += self.objects(technique, index if several else None)
        planar = None
        if "planar" in techniques:
            prefix = "planar_" if several else ""
            planar = PlanarShadow(f"{prefix}floor", FLOOR_PLANE, (*LIGHT, 1.0), (f"{prefix}cube", f"{prefix}sphere", f"{prefix}panel"),
                                  color=SHADOW_COLOR)
        light = Light(LIGHT, shadow=self.shadow_map() if "map" in techniques else None)
        # Tall narrow tiles side by side: from farther, at the middle of the objects.
        eye, target = TILES_VIEW if several else SINGLE_VIEW
        camera = Camera(eye=eye, target=target, fov_y=FOV, near=NEAR, far=FAR)
        return Scene(self.name, nodes=tuple(nodes), camera=camera, lights=(light,),
                     clear_color=CLEAR, viewports=tuple(viewports), planar_shadow=planar)


if __name__ == "__main__":
    sys.exit(glsandbox.run(ShadowMapLesson))
