"""What a model file looks like beyond its triangles (glsandbox/mesh/looks.py): whether its
triangles close a volume (welded positions, opposite windings), and what the file holds that is
not drawn, one warning line per part. Every model is written by the test (trimesh or by hand)."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import trimesh

import glsandbox
from glsandbox.mesh.looks import is_closed
from glsandbox.mesh.normals import row_ids
from glsandbox.plan import plan
from glsandbox.scene import Scene
from support import two_usemtl_obj


def test_closedness_welds_equal_positions_and_needs_opposite_windings() -> None:
    box = trimesh.creation.box()
    assert is_closed(np.asarray(box.vertices), np.asarray(box.faces))
    # Split into per-face vertices (as uvs or normals split them): still closed.
    corners = np.asarray(box.vertices)[np.asarray(box.faces).reshape(-1)]
    assert is_closed(corners, np.arange(corners.shape[0]).reshape(-1, 3))
    flipped = np.asarray(box.faces).copy()
    flipped[0] = flipped[0][::-1]  # one face wound the other way: not consistently closed
    assert not is_closed(np.asarray(box.vertices), flipped)
    assert not is_closed(np.asarray(box.vertices), np.asarray(box.faces)[:-1])  # a hole
    # The same answers from position ids (the loader's way: positions numbered once, then hashed).
    ids = row_ids(corners, ordered=False)[0]
    assert is_closed(corners, np.arange(corners.shape[0]).reshape(-1, 3), ids)
    assert not is_closed(corners, np.arange(corners.shape[0] - 3).reshape(-1, 3), ids)
    box_ids = row_ids(np.asarray(box.vertices), ordered=False)[0]
    assert not is_closed(np.asarray(box.vertices), flipped, box_ids)


# --- what is not drawn -----------------------------------------------------------


def glb_with(doc_extra: dict, material_extra: dict) -> bytes:
    """A one-triangle GLB written by hand, with extra top-level keys and material keys."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32).tobytes()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
        "materials": [{"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}, **material_extra}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": len(positions)}],
        "buffers": [{"byteLength": len(positions)}], **doc_extra}
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunks = (struct.pack("<I4s", len(text), b"JSON") + text
              + struct.pack("<I4s", len(positions), b"BIN\x00") + positions)
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def test_what_a_gltf_holds_that_is_not_drawn_is_one_warning_per_part(tmp_path: Path) -> None:
    path = tmp_path / "robot.glb"
    path.write_bytes(glb_with({"cameras": [{"type": "perspective", "perspective": {"yfov": 1, "znear": 0.1}}],
                               "animations": [{"channels": [], "samplers": []}] * 2},
                              {"normalTexture": {"index": 0}, "emissiveFactor": [1, 0, 0]}))
    model = glsandbox.load_model(path)
    assert model.warnings == (f"model file {path}: 2 animations, a camera not drawn",
                              f"model file {path}, part 'skin': normal map, emissive colour not drawn")
    scene = Scene("s", nodes=model.nodes("robot"))
    described = plan(scene).describe().splitlines()
    assert [line for line in described if line.startswith("warning:")] == [f"warning: {w}" for w in model.warnings]


def test_a_missing_obj_texture_and_a_normal_map_are_warned_about(tmp_path: Path) -> None:
    path = two_usemtl_obj(tmp_path, extra_mtl="map_Kd nowhere.png\nmap_Bump bumps.png\n")
    model = glsandbox.load_model(path)
    assert model.warnings == (f"model file {path}, part 'blue': its texture nowhere.png (missing or unreadable), "
                              "bump map not drawn",)
