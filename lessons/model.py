"""Lesson: a real model, rasterized and ray traced side by side.

A model of a few thousand triangles, lit by the course's two lights (white
and yellow, as in ``phong``), drawn by the rasterizer on the left and traced
by the GLSL ray tracer on the right: the same Scene, the same per-light Phong,
with the shadows only the ray tracer has. The overlay gives the triangle
count, and the ray side the BVH's figures once the ray tracer builds one
(:func:`bvh_figures`).

``--set mesh=PATH`` loads any OBJ, PLY, STL, OFF, glTF or GLB file
(``glsandbox.load_model``: normals from the file or made with a 30° crease
angle), one node per material of the file with its colour, texture, alpha
mode and sidedness, vertex colours tinting the lit colour; the default is a
generated rock (``glsandbox.meshgen``: no file, no download, the same every
run). ``--set fit=off`` keeps the file's own size and place; ``on`` (the
default) centres it and scales it into the box -1..1. ``--set up=z`` stands a
Z-up file (a scan, CAD) upright; glTF is +Y up, as OpenGL, and stands as
written. In the window the ray-traced side is traced coarse while the model
turns or the camera moves (:class:`glsandbox.frame.InteractiveResolution`),
so a big model keeps the window answering.

Both ray engines trace a mesh through its BVH (the GLSL engine for a mesh
node of more than 64 triangles, where the BVH measured faster than testing
every triangle), so their time grows slowly with the triangle count: on
llvmpipe (two shared cores) the 800x600 GLSL frame of a 1,000-triangle
terrain and of a 1,000,000-triangle one differ by well under 2x
(``glsandbox bench``, "ray tracer on models"). ``--set view=raster`` shows
the rasterizer alone.
"""

from __future__ import annotations

import functools
import math
import sys
from pathlib import Path

import numpy as np

import glsandbox
from glsandbox import (
    Camera,
    Lesson,
    Light,
    Material,
    Mesh,
    Motion,
    Node,
    Overlay,
    Param,
    Scene,
    Viewport,
    geometry,
    meshgen,
    register,
    text_image,
    transforms,
)
from glsandbox.raytrace import bvh_for_mesh

#: Models made on the spot (``--set mesh=NAME``); anything else is a file path.
GENERATED = {
    "rock": lambda: meshgen.rock(2, seed=4, roughness=0.3),  # 320 triangles, crease-angle normals
    "rock_fine": lambda: meshgen.rock(3, seed=4, roughness=0.3),  # the same stone, 1,280 triangles
    "terrain": lambda: meshgen.terrain(16, seed=1),  # 512 triangles, facing +y
}
#: Models that ship with glsandbox (``glsandbox/models``, CC0: see LICENSE.md there), by name.
SHIPPED = {"boulder": Path(glsandbox.__file__).resolve().parent / "models" / "boulder.obj"}
#: The course's light colours, ``vLightColor[2] = {(1,1,1,1), (1,1,0,1)}``, placed as the
#: ``phong`` lesson places them at time 0: radius 3, height 1.5, at 60° and 120°.
LIGHTS = tuple(Light((3.0 * math.cos(a), 1.5, 3.0 * math.sin(a)), color)
               for a, color in ((math.pi / 3, (1.0, 1.0, 1.0)), (2 * math.pi / 3, (1.0, 1.0, 0.0))))
#: The course's coefficients and exponent (section "Lighting").
MATERIAL = dict(shading="phong", ambient=0.1, diffuse=0.4, specular=0.3, shininess=32.0)
MODEL_COLOR = (0.75, 0.7, 0.65, 1.0)
FLOOR_COLOR = (0.55, 0.55, 0.6, 1.0)
VIEWS = ("split", "raster", "ray")
#: A file's up axis: y (glTF's +Y up, OpenGL's) or z (many scans and CAD files).
UP_AXES = ("y", "z")
#: What each renderer is called in the overlay.
RENDERER_TITLES = {"raster": "rasterizer", "ray": "ray tracer (GLSL)", "ray_numpy": "ray tracer (numpy, float64)"}


@functools.cache
def generated(name: str) -> Mesh:
    """A generated model, made once (a changed value builds the scene again: the same Mesh
    object keeps its GPU buffers)."""
    return GENERATED[name]()


@functools.cache
def fitted(name: str) -> Mesh:
    """A generated model fitted into -1..1, made once (:meth:`ModelLesson.motion` asks every frame)."""
    return glsandbox.fit_mesh(generated(name))


def check_mesh(text: str) -> str:
    """``--set mesh=...``: a generated or shipped model's name, or a model file that loads (the error names it)."""
    if text not in GENERATED and text not in SHIPPED:
        glsandbox.load_model(text)
    return text


def bvh_figures(mesh: Mesh) -> str:
    """The overlay's BVH line for ``mesh``: its node and leaf counts (no build time: a
    picture shows only what the same settings always give).

    The BVH over the mesh's own triangles (``glsandbox.raytrace.bvh_for_mesh``,
    binned SAH, cached by content: built once per process
    ). The numpy engine (``--set renderer=ray_numpy``) traces
    through such a BVH; the GLSL engine does not use one yet.
    """
    bvh = bvh_for_mesh(mesh)
    return f"BVH: {bvh.node_total:,} nodes, {bvh.leaf_count:,} leaves"


def triangle_count(mesh: Mesh) -> int:
    return int(mesh.triangle_indices().shape[0])


@register
class ModelLesson(Lesson):
    name = "model"
    title = "A real model: rasterized and ray traced side by side"
    course_section = "Meshes from files; Phong boyama modeli; Işın-Üçgen kesim testi"
    order = 170
    animated = True
    params = (
        Param("mesh", "boulder", "a model file (OBJ, PLY, STL, OFF, glTF, GLB), the shipped model "
              + ", ".join(SHIPPED) + ", or a generated model: " + ", ".join(GENERATED), convert=check_mesh),
        Param("fit", True, "centre the model and scale it into the box -1..1"),
        Param("up", "y", "the file's up axis: y (glTF, most OBJ) or z (scans, CAD: stood upright)",
              choices=UP_AXES),
        Param("view", "split", "rasterizer left and ray tracer right, or one of them alone", choices=VIEWS),
        Param("speed", 0.3, "the model's turn about y, radians per second"),
    )

    def model(self) -> tuple[str, tuple[tuple[str, Mesh, Material], ...]]:
        """The model's label and its parts: one ``(name, mesh, material)`` per material of
        the file (colour, texture, alpha, sidedness and vertex colours as the file gives them)."""
        source = self.values["mesh"]
        fit = bool(self.values["fit"])
        if source in GENERATED:
            shown = fitted(source) if fit else generated(source)
            return source, (("model", shown, Material(color=MODEL_COLOR, **MATERIAL)),)
        source = str(SHIPPED.get(source, source))
        loaded = glsandbox.load_model(source, fit=fit)
        parts = []
        for part in loaded.parts:
            # A part the file gives no colour or texture: the lesson's stone colour.
            plain = part.color is None and part.texture is None
            material = part.material(**MATERIAL, **({"color": MODEL_COLOR} if plain else {}))
            name = "model" if len(loaded.parts) == 1 else f"model/{part.name}"
            parts.append((name, part.mesh, material))
        return Path(source).name, tuple(parts)

    def placement(self, parts: tuple[tuple[str, Mesh, Material], ...]) -> tuple[np.ndarray, np.ndarray]:
        """The model's matrix at this time (its turn about y) and the floor's, just under the
        turned model's lowest point."""
        # --set up=z: a Z-up file (a scan, CAD) stood upright: z becomes y (a -90° turn about x).
        upright = transforms.rotate_x(-math.pi / 2) if self.values["up"] == "z" else np.eye(4)
        turn = transforms.rotate_y(float(self.values["speed"]) * self.time) @ upright
        low = min((float(transforms.transform_points(turn, mesh.positions)[:, 1].min())
                   for _, mesh, _ in parts if mesh.vertex_count), default=-1.0)
        return turn, transforms.translate(0.0, min(low, -1.0) - 0.01, 0.0)

    def motion(self) -> Motion:
        """Time turns the model and moves the floor under it; the rest is built once."""
        _, parts = self.model()
        turn, floor = self.placement(parts)
        return Motion(models={"floor": floor, **{name: turn for name, _, _ in parts}})

    def build(self) -> Scene:
        label, parts = self.model()
        turn, floor = self.placement(parts)
        nodes = [
            Node("floor", geometry.plane(12.0), floor, Material(color=FLOOR_COLOR, **MATERIAL)),
            *(Node(name, mesh, turn, material) for name, mesh, material in parts),
        ]
        view = self.values["view"]
        sides = ["raster", "ray"] if view == "split" else [view]
        # --set renderer=ray (or ray_numpy) traces every viewport (Lesson.scene): say so in the labels.
        everywhere = self.values["renderer"]
        width = 1.0 / len(sides)
        viewports = tuple(Viewport(rect=(i * width, 0.0, width, 1.0), renderer=renderer,
                                   label=RENDERER_TITLES[renderer if everywhere == "raster" else everywhere])
                          for i, renderer in enumerate(sides))
        count = f"{label}: {sum(triangle_count(mesh) for _, mesh, _ in parts):,} triangles" + (
            f", {len(parts)} materials" if len(parts) > 1 else "")
        biggest = max((mesh for _, mesh, _ in parts), key=triangle_count)
        overlays = tuple(
            Overlay(f"label{i}", text_image([vp.label, count] + ([bvh_figures(biggest)] if "ray " in vp.label else [])),
                    viewport=i, position=(4, 4))
            for i, vp in enumerate(viewports))
        camera = Camera(eye=(0.0, 1.6, 5.2), target=(0.0, -0.1, 0.0), fov_y=45.0)
        return Scene(self.name, nodes=tuple(nodes), camera=camera, lights=LIGHTS, viewports=viewports,
                     overlays=overlays, clear_color=(0.12, 0.14, 0.2, 1.0))


if __name__ == "__main__":
    sys.exit(glsandbox.run(ModelLesson))
