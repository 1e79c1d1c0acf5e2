"""The ``model`` lesson draws a file's parts as the file describes them, in the rasterizer
and in both ray engines: each part's colour is read from the frame at the place the camera
sees it (the models are written by tests/support.py)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from glsandbox.scene import Node, Scene
from support import (coloured_ply, double_sided_glb, masked_glb, reversed_obj, run_cli, two_material_glb,
                     two_textures_glb, two_usemtl_obj)

SIZE = (160, 120)
#: The three renderers: the rasterizer, the GLSL ray tracer, the numpy (float64) ray tracer.
RENDERERS = {"raster": dict(view="raster"), "ray": dict(view="ray"),
             "ray_numpy": dict(view="ray", renderer="ray_numpy")}


def frame_and_scene(gl, path: Path, renderer: str, **values: object) -> tuple[np.ndarray, Scene]:
    from glsandbox.lessons.model import ModelLesson

    lesson = ModelLesson(mesh=str(path), **RENDERERS[renderer], **values)
    return gl.render(lesson, SIZE).image.astype(int), lesson.scene()


def node(scene: Scene, name: str) -> Node:
    return next(n for n in scene.nodes if n.name == name)


def colour_at(image: np.ndarray, scene: Scene, owner: Node, point: tuple[float, float, float]) -> np.ndarray:
    """The rgb of the pixel where ``point`` (in ``owner``'s model space) lands, through the scene's camera."""
    height, width = image.shape[:2]
    world = np.asarray(owner.model, dtype=np.float64) @ np.append(point, 1.0)
    clip = scene.camera.projection(width / height) @ scene.camera.view() @ world
    x, y = clip[:2] / clip[3]
    return image[int((1.0 - y) / 2.0 * height), int((x + 1.0) / 2.0 * width), :3]


def centre_z(scene: Scene, name: str) -> float:
    """The depth (model space) at which a flat part lies, after the lesson's fit."""
    return float(np.asarray(node(scene, name).mesh.positions)[:, 2].mean())


@pytest.mark.parametrize("renderer", RENDERERS)
def test_a_gltf_opaque_part_and_a_blended_part_in_front_of_it(gl, tmp_path: Path, renderer: str) -> None:
    image, scene = frame_and_scene(gl, two_material_glb(tmp_path / "two.glb"), renderer)
    paint, glass = node(scene, "model/paint"), node(scene, "model/glass")
    z_paint, z_glass = centre_z(scene, "model/paint"), centre_z(scene, "model/glass")
    red = colour_at(image, scene, paint, (-0.6, 0.0, z_paint))  # the opaque red part alone
    blue = colour_at(image, scene, glass, (0.6, 0.0, z_glass))  # the glass over the background
    both = colour_at(image, scene, glass, (0.0, 0.0, z_glass))  # the glass over the red part
    assert red[0] > red[2] + 60, red
    assert blue[2] > blue[0] + 20, blue
    # Half blue, half what lies behind: redder than the glass alone, bluer than the paint alone.
    assert both[0] > blue[0] + 30 and both[2] > red[2] + 30, (red, blue, both)


@pytest.mark.parametrize("renderer", RENDERERS)
def test_a_double_sided_plane_is_seen_from_behind_and_a_single_sided_one_is_not(gl, tmp_path: Path,
                                                                                renderer: str) -> None:
    image, scene = frame_and_scene(gl, double_sided_glb(tmp_path / "leaf.glb"), renderer)
    leaf = colour_at(image, scene, node(scene, "model"), (0.0, 0.0, 0.0))
    # Lit from the front it shows (the normal reversed for the side seen), not dark.
    assert leaf[1] > leaf[0] + 40 and leaf[1] > leaf[2] + 40 and leaf[1] > 80, leaf
    image, scene = frame_and_scene(gl, double_sided_glb(tmp_path / "one.glb", double_sided=False), renderer)
    behind = colour_at(image, scene, node(scene, "model"), (0.0, 0.0, 0.0))
    assert not behind[1] > behind[0] + 40, behind  # culled: the sky or the floor behind it


@pytest.mark.parametrize("renderer", RENDERERS)
def test_each_part_shows_its_own_texture(gl, tmp_path: Path, renderer: str) -> None:
    image, scene = frame_and_scene(gl, two_textures_glb(tmp_path / "boat.glb"), renderer)
    hull = colour_at(image, scene, node(scene, "model/hull"), (-0.5, 0.0, 0.0))
    sail = colour_at(image, scene, node(scene, "model/sail"), (0.5, 0.0, 0.0))
    assert hull[0] > hull[2] + 60, hull
    assert sail[2] > sail[0] + 40, sail


@pytest.mark.parametrize("renderer", RENDERERS)
def test_an_obj_with_two_usemtl_groups_shows_each_kd(gl, tmp_path: Path, renderer: str) -> None:
    image, scene = frame_and_scene(gl, two_usemtl_obj(tmp_path), renderer)
    red = colour_at(image, scene, node(scene, "model/red"), (-0.5, 0.0, 0.0))
    blue = colour_at(image, scene, node(scene, "model/blue"), (0.5, 0.0, 0.0))
    assert red[0] > red[2] + 60, red
    assert blue[2] > blue[0] + 40, blue


@pytest.mark.parametrize("shading", ["phong", "gouraud"])
@pytest.mark.parametrize("renderer", RENDERERS)
def test_ply_vertex_colours_tint_the_lit_colour(gl, tmp_path: Path, renderer: str, shading: str) -> None:
    from glsandbox.lessons.model import ModelLesson

    lesson = ModelLesson(mesh=str(coloured_ply(tmp_path / "c.ply")), **RENDERERS[renderer])
    scene = lesson.scene()
    tinted = tuple(dataclasses.replace(n, material=dataclasses.replace(n.material, shading=shading))
                   if n.name == "model" else n for n in scene.nodes)
    scene = dataclasses.replace(scene, nodes=tinted)
    image = gl.render_scene(scene, SIZE).image.astype(int)
    model = node(scene, "model")
    assert model.material.vertex_colors
    left = colour_at(image, scene, model, (-0.5, 0.0, 0.0))
    right = colour_at(image, scene, model, (0.5, 0.0, 0.0))
    assert left[0] > left[2] + 60, left
    assert right[2] > right[0] + 40, right


@pytest.mark.parametrize("renderer", RENDERERS)
def test_an_open_mesh_wound_the_wrong_way_round_is_seen(gl, tmp_path: Path, renderer: str) -> None:
    image, scene = frame_and_scene(gl, reversed_obj(tmp_path), renderer)
    green = colour_at(image, scene, node(scene, "model"), (0.0, 0.0, 0.0))
    assert green[1] > green[0] + 40 and green[1] > 80, green


@pytest.mark.parametrize("renderer", RENDERERS)
def test_an_alpha_mask_cuts_the_texture_s_transparent_half_away(gl, tmp_path: Path, renderer: str) -> None:
    image, scene = frame_and_scene(gl, masked_glb(tmp_path / "mask.glb"), renderer)
    stencil = node(scene, "model/stencil")
    z = centre_z(scene, "model/stencil")
    cut = colour_at(image, scene, stencil, (-0.5, 0.0, z))  # alpha 0: the red wall behind shows
    kept = colour_at(image, scene, stencil, (0.5, 0.0, z))  # alpha 1: the white stencil
    assert cut[0] > cut[2] + 60, cut
    assert kept[2] > 80 and abs(int(kept[0]) - int(kept[2])) < 80, kept


def test_the_turning_model_is_traced_coarse_and_a_still_one_at_full_resolution() -> None:
    """The window's rule (InteractiveResolution): a picture that moves (here the model turning,
    not the camera) is traced coarse, so a big model keeps the window answering."""
    from glsandbox.frame import InteractiveResolution
    from glsandbox.lessons.model import ModelLesson

    motion = InteractiveResolution(moving=0.25, settle=0.3)
    assert motion.resolution(ModelLesson(time=0.0).scene(), now=0.0) == 1.0
    assert motion.resolution(ModelLesson(time=0.1).scene(), now=0.1) == 0.25  # it turned
    assert motion.resolution(ModelLesson(time=0.1).scene(), now=0.2) == 0.25  # still settling
    assert motion.resolution(ModelLesson(time=0.1).scene(), now=0.5) == 1.0  # still for 0.4 s


def test_the_glsl_ray_tracer_traces_parts_beyond_its_texture_slots_with_their_colour(gl, capsys) -> None:
    """Five textured nodes, one texture each: the GLSL engine has four samplers, so the fifth
    node is traced with its colour alone (white here), and one warning line says so."""
    from glsandbox import Camera, Light, Material, Texture, Viewport, geometry, transforms
    from glsandbox.raytrace.gpu import MAX_TEXTURES

    def red_image(shade: int) -> np.ndarray:
        image = np.zeros((2, 2, 4), dtype=np.uint8)
        image[..., 0], image[..., 3] = shade, 255
        return image

    square = geometry.cube24()
    nodes = tuple(Node(f"tile{i}", square, transforms.translate(2.5 * i - 5.0, 0.0, 0.0),
                       Material(texture=Texture(f"red{i}", filter="nearest", image=red_image(200 + i))))
                  for i in range(MAX_TEXTURES + 1))
    scene = Scene("tiles", nodes=nodes, camera=Camera(eye=(0.0, 0.0, 14.0)), lights=(Light((0.0, 5.0, 9.0)),),
                  viewports=(Viewport(renderer="ray"),))
    image = gl.render_scene(scene, (200, 60)).image.astype(int)
    colours = [colour_at(image, scene, n, (0.0, 0.0, 1.0)) for n in nodes]  # each cube's front face
    assert all(c[0] > 150 and c[1] < 40 for c in colours[:MAX_TEXTURES]), colours
    assert colours[MAX_TEXTURES][1] > 150, colours  # white: its colour alone
    said = "the GLSL ray tracer samples at most 4 textures per viewport; tile4 traced"
    assert capsys.readouterr().err.count(said) == 1


def test_up_z_stands_a_z_up_file_upright(tmp_path: Path) -> None:
    """A tall thin box along the file's z: with up=z the lesson turns it so that it stands along y."""
    import trimesh

    from glsandbox.lessons.model import ModelLesson

    trimesh.creation.box((0.2, 0.2, 2.0)).export(tmp_path / "post.stl")
    for up, axis in (("y", 2), ("z", 1)):
        scene = ModelLesson(mesh=str(tmp_path / "post.stl"), up=up, view="raster").scene()
        model = node(scene, "model")
        corners = np.asarray(model.mesh.positions) @ np.asarray(model.model)[:3, :3].T
        extent = corners.max(axis=0) - corners.min(axis=0)
        assert int(np.argmax(extent)) == axis, (up, extent)


def test_render_and_plan_say_what_the_file_holds_that_is_not_drawn(tmp_path: Path) -> None:
    """One warning line naming the file and the part, with exit 0 and the picture written."""
    path = two_usemtl_obj(tmp_path, extra_mtl="map_Kd nowhere.png\n")
    line = f"warning: model file {path}, part 'blue': its texture nowhere.png (missing or unreadable) not drawn"
    out = tmp_path / "two.png"
    run = run_cli("render", "model", "--set", f"mesh={path}", "--size", "64x48", "--out", str(out))
    assert run.returncode == 0 and out.is_file(), run
    assert run.stderr.splitlines() == [line]
    run = run_cli("plan", "model", "--set", f"mesh={path}")
    assert run.returncode == 0 and run.stdout.splitlines()[-1] == line, run

