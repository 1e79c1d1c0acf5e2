"""Lesson: texture mapping, with every sampler filter and wrap mode.

Course section "Texture Mapping (Doku Kaplama)". A cube of 24 vertices
(four per face, since a corner shared by three faces needs three different
uv) carries the course's uv: its front face has (1,0) (1,1) (0,1) (0,0) at
the corners (1,1,-1) (1,-1,-1) (-1,-1,-1) (-1,1,-1) of DirectX, its top face
(0,1) (0,0) (1,0) (1,1) at (-1,1,-1) (-1,1,1) (1,1,1) (1,1,-1): u grows to the
right and v downwards as each face is seen from outside. The default image
labels each quadrant with the uv of its corner, so the mapping can be read
off the picture.

Below it a large checkered ground is seen at a grazing angle: far away many
texels fall into one pixel (minification). Without mipmaps (``nearest``,
``linear``) that shimmers into moiré; ``mip_nearest`` and ``mip_linear``
read pre-shrunk levels (visible bands / smooth blend between levels);
``anisotropic`` takes several samples along the stretched footprint and stays
sharper towards the horizon. The ground's uv runs beyond 0..1 (the tile
0..1 sits under the cube), so ``wrap`` shows repeat, mirrored repeat and
clamp-to-edge. The images are drawn by the project (:mod:`glsandbox.images`);
``--set image=PATH`` puts your own picture on the cube.
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace

import numpy as np

import glsandbox
from glsandbox import (
    TEXTURE_FILTERS,
    TEXTURE_WRAPS,
    Camera,
    Lesson,
    Material,
    Motion,
    Node,
    Param,
    Scene,
    Texture,
    check_texture_source,
    geometry,
    register,
    transforms,
)


GROUND_SIZE = 60.0
GROUND_Y = -1.0
#: The cube's turn at time 0, so three faces show.
START_ANGLE = math.radians(30)


def ground(size: float, tile: float) -> geometry.Mesh:
    """A square ground in the xz plane whose uv repeat every ``tile`` units,
    with the 0..1 tile centred on the origin (so clamp leaves one tile)."""
    mesh = geometry.plane(size)
    uvs = mesh.positions[:, [0, 2]] / tile + 0.5
    return replace(mesh, name=f"ground_{size:g}_{tile:g}", uvs=uvs)


@register
class TextureLesson(Lesson):
    name = "texture"
    title = "Texture mapping: the 24-vertex cube, filters, mipmaps and wrap modes"
    course_section = "Texture Mapping (Doku Kaplama)"
    order = 60
    contrasts = (("the filter grid: minification on the grazing ground",
                  "filter=nearest,linear,mip_nearest,mip_linear,anisotropic"),)
    animated = True
    params = (
        Param("filter", "mip_linear", "sampler filter", choices=TEXTURE_FILTERS),
        Param("wrap", "repeat", "what uv outside 0..1 reads", choices=TEXTURE_WRAPS),
        Param("image", "labels", "the cube's image: labels, checker, mip_levels, or an image file path",
              convert=check_texture_source),
        Param("ground", "checker", "the ground's image (labels shows mirrored and clamped uv best)",
              convert=check_texture_source),
        Param("tile", 3.0, "ground units per texture repeat", minimum=0.01),
        Param("speed", 0.5, "the cube's turn rate in radians per second"),
    )

    def build(self) -> Scene:
        v = self.values
        sampler = {"filter": v["filter"], "wrap": v["wrap"]}
        cube_texture = Texture(str(v["image"]), **sampler)
        ground_texture = Texture(str(v["ground"]), **sampler)
        nodes = (
            Node("ground", ground(GROUND_SIZE, float(v["tile"])), transforms.translate(0.0, GROUND_Y, 0.0),
                 Material(texture=ground_texture)),
            Node("cube", geometry.cube24(), self.cube_turn(), Material(texture=cube_texture)),
        )
        camera = Camera(eye=(0.0, 1.9, 5.5), target=(0.0, -0.3, 0.0), fov_y=45.0, near=0.01, far=100.0)
        return Scene(self.name, nodes=nodes, camera=camera, clear_color=(0.55, 0.7, 0.9, 1.0))

    def cube_turn(self) -> np.ndarray:
        """The cube's model at :attr:`time`: turned about y from :data:`START_ANGLE`."""
        return transforms.rotate_y(START_ANGLE + float(self.values["speed"]) * self.time)

    def motion(self) -> Motion:
        """Only the cube turns with time."""
        return Motion(models={"cube": self.cube_turn()})


def course_uv_table() -> dict[str, list[tuple[tuple[float, float, float], tuple[float, float]]]]:
    """The course's two uv listings, (DirectX position, uv) per corner."""
    return {
        "front": [((1, 1, -1), (1, 0)), ((1, -1, -1), (1, 1)), ((-1, -1, -1), (0, 1)), ((-1, 1, -1), (0, 0))],
        "top": [((-1, 1, -1), (0, 1)), ((-1, 1, 1), (0, 0)), ((1, 1, 1), (1, 0)), ((1, 1, -1), (1, 1))],
    }


if __name__ == "__main__":
    sys.exit(glsandbox.run(TextureLesson))
