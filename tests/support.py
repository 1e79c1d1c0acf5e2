"""Helpers shared by test modules (no tests here).

Model files with materials, written on the spot (no downloads): each is small,
lies in the box -1..1 (so ``fit`` leaves it as it is, up to a shift in z), and
has its parts at known places so a test can read each part's colour from a
rendered frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh
from trimesh.visual import TextureVisuals
from trimesh.visual.material import PBRMaterial

# --- model files with materials ---------------------------------------------------

QUAD_FACES = np.array([[0, 1, 2], [0, 2, 3]])


def quad(x0: float, x1: float, z: float = 0.0, facing: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A square from x0 to x1, y -1..1 at depth z; facing +z (counter-clockwise seen from +z) or -z."""
    vertices = np.array([[x0, -1, z], [x1, -1, z], [x1, 1, z], [x0, 1, z]], dtype=np.float64)
    return vertices, QUAD_FACES if facing > 0 else QUAD_FACES[:, ::-1]


def gltf_part(vertices: np.ndarray, faces: np.ndarray, **material: object) -> trimesh.Trimesh:
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.visual = TextureVisuals(material=PBRMaterial(**material))
    return mesh


def two_material_glb(path: Path) -> Path:
    """An opaque red square on the left and a half-transparent blue one in front, on the right."""
    red = gltf_part(*quad(-1.0, 0.2), name="paint", baseColorFactor=[255, 0, 0, 255])
    glass = gltf_part(*quad(-0.2, 1.0, z=0.4), name="glass", baseColorFactor=[0, 0, 255, 128], alphaMode="BLEND")
    trimesh.Scene([red, glass]).export(path)
    return path


def two_usemtl_obj(folder: Path, extra_mtl: str = "") -> Path:
    """Two squares side by side, one usemtl group each: red on the left, blue on the right (Kd)."""
    (folder / "two.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n" + extra_mtl)
    (folder / "two.obj").write_text(
        "mtllib two.mtl\n"
        "v -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\n"
        "v 0.05 -1 0\nv 1 -1 0\nv 1 1 0\nv 0.05 1 0\n"
        "usemtl red\nf 1 2 3\nf 1 3 4\n"
        "usemtl blue\nf 5 6 7\nf 5 7 8\n")
    return folder / "two.obj"


def coloured_ply(path: Path) -> Path:
    """Two squares with vertex colours, red on the left and blue on the right (ASCII PLY)."""
    rows = [(-1, -1, 255, 0, 0), (0, -1, 255, 0, 0), (0, 1, 255, 0, 0), (-1, 1, 255, 0, 0),
            (0.05, -1, 0, 0, 255), (1, -1, 0, 0, 255), (1, 1, 0, 0, 255), (0.05, 1, 0, 0, 255)]
    header = ("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 4\n"
              "property list uchar int vertex_indices\nend_header\n")
    body = "".join(f"{x} {y} 0 {r} {g} {b}\n" for x, y, r, g, b in rows)
    path.write_text(header + body + "3 0 1 2\n3 0 2 3\n3 4 5 6\n3 4 6 7\n")
    return path


def reversed_obj(folder: Path) -> Path:
    """An open square wound clockwise as seen from +z (its front faces -z: a scan the wrong way
    round), green."""
    (folder / "back.mtl").write_text("newmtl green\nKd 0 1 0\n")
    (folder / "back.obj").write_text("mtllib back.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                     "usemtl green\nf 1 3 2\nf 1 4 3\n")
    return folder / "back.obj"


CUBE_OBJ = ("v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
            "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\n"
            "f 2 3 7\nf 2 7 6\n")


def double_sided_glb(path: Path, double_sided: bool = True) -> Path:
    """A green square whose front faces away from +z (where the model lesson's camera is):
    seen only from behind, so drawn only when the material is double-sided."""
    plane = gltf_part(*quad(-1, 1, facing=-1), name="leaf", baseColorFactor=[0, 255, 0, 255],
                      doubleSided=double_sided)
    trimesh.Scene([plane]).export(path)
    return path


def masked_glb(path: Path) -> Path:
    """A red square behind a white one cut out by a texture's alpha (glTF MASK): the white
    square's left half (alpha 0) is cut away, its right half (alpha 255) is drawn."""
    from PIL import Image

    red = gltf_part(*quad(-1, 1, z=-0.2), name="wall", baseColorFactor=[255, 0, 0, 255])
    vertices, faces = quad(-1, 1, z=0.2)
    pixels = np.full((1, 4, 4), 255, dtype=np.uint8)
    pixels[0, :2, 3] = 0  # the left half transparent
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    stencil = trimesh.Trimesh(vertices, faces, process=False)
    stencil.visual = TextureVisuals(uv=uv, material=PBRMaterial(name="stencil", baseColorTexture=Image.fromarray(
        pixels[0:1].repeat(4, axis=0), "RGBA"), alphaMode="MASK", alphaCutoff=0.5))
    trimesh.Scene([red, stencil]).export(path)
    return path
