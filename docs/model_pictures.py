"""Makes the README's two model pictures (docs/model_materials.png, docs/model_bunny.png).

Both models are written here, nothing is downloaded:

- a glTF with four materials: a red box (opaque), a half-transparent blue
  sphere (``alphaMode`` BLEND), a green leaf seen from behind (``doubleSided``)
  and a textured sign whose texture's alpha cuts out a window (MASK);
- the Stanford bunny from pymeshlab's wheel (the bench group: ``uv sync
  --group bench``) written as a PLY with vertex colours (red at the feet to
  yellow at the ears) and turned to Z-up, so ``--set up=z`` stands it upright.

Run: ``uv run --group bench python docs/model_pictures.py`` (from the repository
root), or give the bunny's path: ``uv run python docs/model_pictures.py bunny.obj``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image
from trimesh.visual import TextureVisuals
from trimesh.visual.material import PBRMaterial

DOCS = Path(__file__).resolve().parent


def part(mesh: trimesh.Trimesh, **material: object) -> trimesh.Trimesh:
    mesh.visual = TextureVisuals(uv=material.pop("uv", None), material=PBRMaterial(**material))
    return mesh


def materials_glb(path: Path) -> None:
    box = part(trimesh.creation.box((0.8, 0.8, 0.8)), name="paint", baseColorFactor=[220, 40, 30, 255])
    box.apply_translation([-0.9, -0.3, 0.0])
    glass = part(trimesh.creation.icosphere(3, 0.55), name="glass", baseColorFactor=[60, 110, 255, 110],
                 alphaMode="BLEND")
    glass.apply_translation([0.0, -0.15, 0.5])
    leaf = trimesh.Trimesh([[0, 0, 0], [0.7, 0, -0.1], [0.7, 0.9, 0], [0, 0.9, 0.1]], [[0, 2, 1], [0, 3, 2]],
                           process=False)  # wound clockwise from the front: seen from behind
    leaf = part(leaf, name="leaf", baseColorFactor=[60, 200, 70, 255], doubleSided=True)
    leaf.apply_translation([0.6, -0.7, -0.4])
    pixels = np.zeros((64, 64, 4), dtype=np.uint8)
    pixels[..., :3] = (250, 220, 120)
    pixels[..., 3] = 255
    pixels[16:48, 16:48, 3] = 0  # a square window cut out of the sign
    sign = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    sign = part(sign, name="sign", baseColorTexture=Image.fromarray(pixels, "RGBA"), alphaMode="MASK",
                uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64))
    sign.apply_translation([-0.4, 0.15, -0.9])
    trimesh.Scene([box, glass, leaf, sign]).export(path)


def bunny_obj() -> Path:
    """pymeshlab's bunny, or the file named on the command line."""
    if len(sys.argv) > 1:
        return Path(sys.argv[1])
    import pymeshlab

    return Path(pymeshlab.__file__).parent / "tests" / "sample_meshes" / "bunny.obj"


def bunny_ply(path: Path) -> None:
    source = bunny_obj()
    bunny = trimesh.load(source, process=False, force="mesh")
    height = np.asarray(bunny.vertices)[:, 1]
    share = (height - height.min()) / np.ptp(height)
    colours = np.stack([np.full_like(share, 230), 60 + 170 * share, 40 + 20 * share, np.full_like(share, 255)], 1)
    bunny.visual = trimesh.visual.ColorVisuals(bunny, vertex_colors=colours.astype(np.uint8))
    bunny.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))  # y up -> z up
    bunny.export(path)


def render(model: Path, out: Path, *settings: str) -> None:
    from glsandbox.cli import main

    status = main(["render", "model", "--set", f"mesh={model}", *settings, "--size", "800x360", "--out", str(out)])
    if status:
        sys.exit(status)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as folder:
        materials_glb(Path(folder) / "materials.glb")
        render(Path(folder) / "materials.glb", DOCS / "model_materials.png", "--set", "time=1.5")
        bunny_ply(Path(folder) / "bunny.ply")
        render(Path(folder) / "bunny.ply", DOCS / "model_bunny.png", "--set", "up=z")
