"""A model file's materials as loaded (glsandbox.mesh.load): one part per material with its
colour, texture, alpha mode and sidedness; a warning printed once; and the plan, which shows blending and two-sided lighting only
for a part that asks. Every model is written by the test (trimesh or by hand)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

import glsandbox
from support import (CUBE_OBJ, coloured_ply, gltf_part, masked_glb, quad, reversed_obj, two_material_glb,
                     two_usemtl_obj)
from glsandbox.plan import plan
from glsandbox.scene import Material, Node, Scene
from glsandbox.scene_file import load_scene

# --- parts and their materials -------------------------------------------------------


def test_a_gltf_with_two_materials_is_two_parts_each_with_its_colour_and_alpha_mode(tmp_path: Path) -> None:
    model = glsandbox.load_model(two_material_glb(tmp_path / "two.glb"))
    parts = {part.name: part for part in model.parts}
    assert sorted(parts) == ["glass", "paint"] and model.triangles == 4
    assert parts["paint"].color == (1.0, 0.0, 0.0, 1.0) and parts["paint"].alpha_mode == "opaque"
    glass = parts["glass"]
    assert glass.color is not None and glass.color[:3] == (0.0, 0.0, 1.0) and glass.color[3] == pytest.approx(128 / 255)
    assert glass.alpha_mode == "blend" and not glass.double_sided
    material = glass.material(shading="phong")
    assert (material.alpha_mode, material.color, material.shading) == ("blend", glass.color, "phong")
    # Node names: the part's name after the model's; the whole model as one mesh still exists.
    assert sorted(node.name for node in model.nodes("duck")) == ["duck/glass", "duck/paint"]
    assert model.mesh.vertex_count == sum(part.mesh.vertex_count for part in model.parts)


def test_gltf_double_sided_and_mask_cutoff_are_read(tmp_path: Path) -> None:
    plane = gltf_part(*quad(-1, 1, facing=-1), name="leaf", baseColorFactor=[0, 255, 0, 255], doubleSided=True,
                      alphaMode="MASK", alphaCutoff=0.25)
    path = tmp_path / "leaf.glb"
    trimesh.Scene([plane]).export(path)
    (part,) = glsandbox.load_model(path).parts
    assert (part.double_sided, part.alpha_mode, part.alpha_cutoff) == (True, "mask", 0.25)
    node = Node("leaf", part.mesh, material=part.material(shading="phong"))
    assert node.cull_back_faces is False  # a double-sided material turns culling off


def test_an_obj_with_two_usemtl_groups_is_two_parts_with_their_kd(tmp_path: Path) -> None:
    model = glsandbox.load_model(two_usemtl_obj(tmp_path))
    colours = {part.name: part.color for part in model.parts}
    assert colours == {"red": (1.0, 0.0, 0.0, 1.0), "blue": (0.0, 0.0, 1.0, 1.0)}
    assert not model.closed and all(part.double_sided for part in model.parts)  # open: seen from both sides
    assert model.warnings == ()


def test_an_obj_material_with_dissolve_below_one_is_blended(tmp_path: Path) -> None:
    path = two_usemtl_obj(tmp_path, extra_mtl="d 0.25\n")  # on the blue material
    parts = {part.name: part for part in glsandbox.load_model(path).parts}
    assert (parts["blue"].alpha_mode, parts["blue"].color) == ("blend", (0.0, 0.0, 1.0, 0.25))
    assert (parts["red"].alpha_mode, parts["red"].color) == ("opaque", (1.0, 0.0, 0.0, 1.0))


def test_a_ply_with_vertex_colours_tints_a_lit_material(tmp_path: Path) -> None:
    (part,) = glsandbox.load_model(coloured_ply(tmp_path / "c.ply")).parts
    assert part.mesh.colors is not None and part.color is None
    assert part.material(shading="phong").vertex_colors
    assert not part.material(shading="vertex_color").vertex_colors  # unlit vertex colours: as before


def test_sidedness_of_formats_without_materials_follows_closedness(tmp_path: Path) -> None:
    (tmp_path / "cube.obj").write_text(CUBE_OBJ)
    cube = glsandbox.load_model(tmp_path / "cube.obj")
    assert cube.closed and not cube.parts[0].double_sided  # a closed cube: back faces culled
    scan = glsandbox.load_model(reversed_obj(tmp_path))
    assert not scan.closed and scan.parts[0].double_sided


def test_render_prints_each_warning_once(tmp_path: Path, gl, capsys) -> None:
    path = two_usemtl_obj(tmp_path, extra_mtl="map_Kd nowhere.png\n")
    from glsandbox.lessons.model import ModelLesson

    gl.render(ModelLesson(mesh=str(path), view="raster"), (32, 24))
    gl.render(ModelLesson(mesh=str(path), view="raster"), (32, 24))
    err = capsys.readouterr().err
    assert err.count(f"warning: model file {path}, part 'blue': its texture nowhere.png") == 1


# --- the plan --------------------------------------------------------------------


def test_blending_and_two_sided_lighting_appear_in_the_plan_only_when_a_part_needs_them(tmp_path: Path) -> None:
    from glsandbox.lessons.model import ModelLesson

    rock = plan(ModelLesson(view="raster", mesh="rock").scene()).describe()
    assert not any(word in rock for word in ("no depth writes", "TWO_SIDED", "ALPHA_MASK", "VERTEX_COLOR"))
    two = plan(ModelLesson(view="raster", mesh=str(two_material_glb(tmp_path / "two.glb"))).scene())
    (draw_pass,) = [p for p in two.passes if p.kind == "draw"]
    assert [d.node for d in draw_pass.draws] == ["floor", "model/paint", "model/glass"]  # blended last
    assert [d.blend for d in draw_pass.draws] == [False, False, True]
    assert "model/glass with phong[NUM_LIGHTS=2] (blended, no depth writes)" in two.describe()
    scan = plan(ModelLesson(view="raster", mesh=str(reversed_obj(tmp_path))).scene()).describe()
    assert "model with phong[NUM_LIGHTS=2,TWO_SIDED] (no culling)" in scan
    ply = plan(ModelLesson(view="raster", mesh=str(coloured_ply(tmp_path / "c.ply"))).scene()).describe()
    assert "phong[NUM_LIGHTS=2,VERTEX_COLOR,TWO_SIDED]" in ply


def test_blended_nodes_are_drawn_farthest_first() -> None:
    square = glsandbox.geometry.quad_list()
    glass = Material(color=(0, 0, 1, 0.5), alpha_mode="blend")
    near = Node("near", square, glsandbox.transforms.translate(0, 0, 2), glass)
    far = Node("far", square, glsandbox.transforms.translate(0, 0, -2), glass)
    solid = Node("solid", square, np.eye(4), Material())
    (draw_pass,) = [p for p in plan(Scene("s", nodes=(near, solid, far))).passes if p.kind == "draw"]
    assert [d.node for d in draw_pass.draws] == ["solid", "far", "near"]


def test_material_refuses_an_unknown_alpha_mode_or_cutoff() -> None:
    with pytest.raises(glsandbox.SandboxError, match="unknown alpha mode 'glass'"):
        Material(alpha_mode="glass")
    with pytest.raises(glsandbox.SandboxError, match="alpha cutoff must lie in 0..1"):
        Material(alpha_cutoff=2.0)


# --- scene files -------------------------------------------------------------------


def test_a_scene_file_node_becomes_one_node_per_material_and_up_z_stands_it_upright(tmp_path: Path) -> None:
    two_usemtl_obj(tmp_path)
    scene_path = tmp_path / "scene.toml"
    scene_path.write_text('[[lights]]\nposition = [0, 2, 3]\n\n[[nodes]]\nname = "sign"\nmesh = "two.obj"\n'
                          'shading = "phong"\nup = "z"\n')
    nodes = load_scene(scene_path).nodes
    assert sorted((n.name, n.material.color) for n in nodes) == [("sign/blue", (0.0, 0.0, 1.0, 1.0)),
                                                                 ("sign/red", (1.0, 0.0, 0.0, 1.0))]
    # up = "z": the file's +z turns to +y (and its +y to -z).
    assert np.allclose(nodes[0].model[:3, :3] @ [0, 0, 1], [0, 1, 0])
    assert np.allclose(nodes[0].model[:3, :3] @ [0, 1, 0], [0, 0, -1])
    scene_path.write_text('[[nodes]]\nmesh = "two.obj"\nup = "x"\n')
    with pytest.raises(glsandbox.SandboxError, match=r"scene.toml:3: nodes\[0\].up: unknown up axis 'x'"):
        load_scene(scene_path)


def test_a_gltf_whose_texture_image_is_missing_or_garbage_loads_and_says_so(tmp_path: Path) -> None:
    from PIL import Image

    square = trimesh.Trimesh(*quad(-1, 1), process=False)
    square.visual = trimesh.visual.TextureVisuals(
        uv=[[0, 0], [1, 0], [1, 1], [0, 1]],
        material=trimesh.visual.material.PBRMaterial(name="skin", baseColorTexture=Image.new("RGB", (4, 4))))
    for case, content in (("missing", None), ("garbage", b"not a png")):
        folder = tmp_path / case  # a folder each: loads are cached by the model file
        folder.mkdir()
        for name, data in trimesh.Scene([square]).export(file_type="gltf").items():
            (folder / name).write_bytes(data)
        doc = json.loads((folder / "model.gltf").read_text())
        doc["images"] = [{"uri": "skin.png"}]  # an image file next to it, instead of the embedded one
        (folder / "model.gltf").write_text(json.dumps(doc))
        if content is not None:
            (folder / "skin.png").write_bytes(content)
        model = glsandbox.load_model(folder / "model.gltf")
        assert model.parts[0].texture is None
        assert model.warnings == (f"model file {folder / 'model.gltf'}, part 'skin': its base colour texture "
                                  "skin.png (missing or unreadable) not drawn",)


def test_a_scene_file_node_with_its_own_colour_stays_one_node_with_every_part(tmp_path: Path) -> None:
    two_usemtl_obj(tmp_path)
    scene_path = tmp_path / "scene.toml"
    scene_path.write_text('[[nodes]]\nname = "sign"\nmesh = "two.obj"\ncolor = [1, 1, 0]\n')
    (node,) = load_scene(scene_path).nodes
    assert node.name == "sign" and node.material.color == (1.0, 1.0, 0.0, 1.0)
    assert node.mesh.triangle_indices().shape[0] == 4  # both parts' squares



def test_scene_file_material_keys_for_alpha_and_sides(tmp_path: Path) -> None:
    scene_path = tmp_path / "scene.toml"
    scene_path.write_text('[[nodes]]\nmesh = "cube24"\ncolor = [0, 0, 1, 0.5]\nalpha_mode = "blend"\n'
                          'double_sided = true\n\n[[nodes]]\nmesh = "quad_list"\nalpha_mode = "mask"\n'
                          'alpha_cutoff = 0.3\n')
    glass, leaf = load_scene(scene_path).nodes
    assert (glass.material.alpha_mode, glass.material.double_sided, glass.cull_back_faces) == ("blend", True, False)
    assert (leaf.material.alpha_mode, leaf.material.alpha_cutoff) == ("mask", 0.3)
    for text, where in (('alpha_mode = "glass"', r"scene.toml:3: nodes\[0\].alpha_mode: unknown alpha mode 'glass'"),
                        ("alpha_cutoff = 1.5", r"scene.toml:3: nodes\[0\].alpha_cutoff: material alpha cutoff"),
                        ("vertex_colors = true", r"scene.toml:3: nodes\[0\].vertex_colors: .* no color data")):
        scene_path.write_text(f'[[nodes]]\nmesh = "cube24"\n{text}\n')
        with pytest.raises(glsandbox.SandboxError, match=where):
            load_scene(scene_path)


def test_a_scene_file_node_s_own_alpha_mode_wins_over_its_model_file_s(tmp_path: Path) -> None:
    two_material_glb(tmp_path / "two.glb")
    scene_path = tmp_path / "scene.toml"
    scene_path.write_text('[[nodes]]\nname = "m"\nmesh = "two.glb"\nalpha_mode = "opaque"\n')
    assert {n.name: n.material.alpha_mode for n in load_scene(scene_path).nodes} == {"m/paint": "opaque",
                                                                                     "m/glass": "opaque"}


def test_blended_parts_are_blended_in_the_mirror_too_after_the_opaque_ones_farthest_first() -> None:
    from glsandbox.planar import Mirror

    square = glsandbox.geometry.quad_list()
    glass = Material(color=(0, 0, 1, 0.5), alpha_mode="blend")
    cutout = Material(color=(1, 1, 1, 1), alpha_mode="mask", alpha_cutoff=0.5)
    # A mirror in the plane z = -5 facing +z; the eye at z = +3 (the default camera looks from +z).
    wall = Node("wall", square, glsandbox.transforms.translate(0, 0, -5), Material())
    near = Node("near", square, glsandbox.transforms.translate(0, 0, 2), glass)  # far from the mirror: farther in it
    far = Node("far", square, glsandbox.transforms.translate(0, 0, -3), glass)
    solid = Node("solid", square, np.eye(4), cutout)
    mirror = Mirror("wall", (0.0, 0.0, 1.0, 5.0), ("near", "solid", "far"))  # z + 5 = 0
    scene = Scene("s", nodes=(wall, near, solid, far), mirror=mirror)
    (reflection,) = [p for p in plan(scene).passes if p.kind == "reflection"]
    # Seen in the mirror, "near" (7 from the glass) lies farther than "far" (2 from it): it blends first.
    assert [(d.node, d.blend) for d in reflection.draws] == [("solid", False), ("near", True), ("far", True)]
    assert "ALPHA_MASK" in reflection.draws[0].program
    # The order depends on where things are: a plan kept between frames must see it change.
    from glsandbox.plan import motion_decisions

    swapped = Scene("s", nodes=(wall, Node("near", square, far.model, glass), solid, Node("far", square, near.model, glass)),
                    mirror=mirror)
    assert motion_decisions(scene) != motion_decisions(swapped)



@pytest.mark.slow
def test_a_cut_out_casts_a_planar_shadow_only_where_it_is_drawn(tmp_path: Path, gl) -> None:
    from glsandbox.planar import PlanarShadow
    from glsandbox.scene import Camera

    stencil = next(p for p in glsandbox.load_model(masked_glb(tmp_path / "m.glb")).parts if p.alpha_mode == "mask")
    floor = Node("floor", glsandbox.geometry.plane(8.0), np.eye(4), Material(color=(1, 1, 1, 1)))
    # The 2x2 square (half of it cut out) laid flat 1 above the floor, lit from up and to the right:
    # its shadow falls beside it, at x in -3..-1, seen from straight above.
    lay = glsandbox.transforms.translate(0, 1, 0) @ glsandbox.transforms.rotate_x(-np.pi / 2)
    shadow = PlanarShadow("floor", (0, 1, 0, 0), (2.0, 1.0, 0.0, 0.0), ("caster",), color=(0, 0, 0, 1))

    def black_pixels(material: Material) -> int:
        scene = Scene("s", nodes=(floor, Node("caster", stencil.mesh, lay, material)), planar_shadow=shadow,
                      camera=Camera(eye=(0.0, 10.0, 0.01)))
        image = np.asarray(gl.render_scene(scene, (64, 64)).image)
        return int((image[..., :3] == 0).all(axis=-1).sum())

    whole = black_pixels(Material(color=(1, 0, 0, 1)))
    cut = black_pixels(stencil.material())
    assert whole > 100
    assert 0.35 * whole < cut < 0.65 * whole  # the cut-away half casts nothing
    (step,) = [p for p in plan(Scene("s", nodes=(floor, Node("caster", stencil.mesh, lay, stencil.material())),
                                     planar_shadow=shadow)).passes if p.kind == "planar_shadow"]
    assert "CUTOUT_SHADOW" in step.describe()
