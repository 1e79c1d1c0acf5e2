"""TOML scene files: a valid one loads; each mistake names the file and line (wrong types,
deep nesting, the location said once, plain numbers, the shadow's light one of the
scene's lights)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support import EXAMPLES_DIR, assert_user_error, run_cli

from glsandbox.errors import SandboxError
from glsandbox.plan import plan
from glsandbox.scene_file import load_scene

GOOD = """\
name = "two boxes"
clear_color = [0.1, 0.1, 0.1]

[camera]
eye = [0, 3, 10]
fov_y = 45

[[nodes]]
name = "left"
mesh = "cube"
translate = [-2, 0, 0]

[[nodes]]
name = "right"
mesh = "cube"
order = "TRS"
scale = [0.5, 1, 0.5]
translate = [2, 0, 0]
rotate = [0, 90, 0]
color = [1, 0, 0]
shading = "solid"
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def test_a_valid_scene_loads_with_its_transforms(tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path, GOOD))
    assert scene.name == "two boxes"
    assert [n.name for n in scene.nodes] == ["left", "right"]
    assert scene.clear_color == (0.1, 0.1, 0.1, 1.0)
    # TRS: translate, then rotate about y by 90°, then scale: (2,0,0) -> (0,0,-2) -> (0,0,-1).
    np.testing.assert_allclose(scene.nodes[1].model[:3, 3], (0, 0, -1), atol=1e-12)
    assert scene.nodes[0].material.shading == "vertex_color"
    assert plan(scene).buffers.depth


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("name = \n", r"scene.toml:1: malformed TOML"),
        ("[[nodes]]\nmesh = \"cbe\"\n", r"scene.toml:2: nodes\[0\].mesh: unknown mesh 'cbe'"),
        ("[[nodes]]\nmesh = \"cube\"\n\n[[nodes]]\nmesh = \"cube\"\norder = \"SST\"\n",
         r"scene.toml:6: nodes\[1\].order: .*valid orders"),
        ("[[nodes]]\nmesh = \"cube\"\ncolor = [2, 0, 0]\n", r"scene.toml:3: nodes\[0\].color: colour channels"),
        ("[[nodes]]\nmesh = \"cube\"\nscale = [1, 1]\n", r"scene.toml:3: nodes\[0\].scale: expected a list of 3"),
        ("[[nodes]]\nmesh = \"cube\"\nspin = 3\n", r"scene.toml:3: nodes\[0\].spin: unknown key"),
        ("[camera]\neye = [0, 0, 0]\ntarget = [0, 5, 0]\n", r"scene.toml:1: camera: .*parallel"),
        ("[[nodes]]\nname = \"x\"\n", r"scene.toml:1: nodes\[0\]: every node needs mesh"),
        ("[[nodes]]\nmesh = \"triangle\"\nshading = \"vertex_color\"\n",
         r"scene.toml:3: nodes\[0\].shading: mesh 'triangle' has no vertex colours"),
    ],
)
def test_scene_errors_name_file_and_line(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(SandboxError, match=expected) as info:
        load_scene(write(tmp_path, text))
    assert "\n" not in str(info.value)


def test_missing_scene_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(SandboxError, match="scene file .*nothere.toml not found"):
        load_scene(tmp_path / "nothere.toml")


LIT = """\
[[lights]]
position = [2, 4, 3]

[[nodes]]
mesh = "cube24"
shading = "blinn_phong"
ambient = 0.2
specular = 0.0
shininess = 8
normals = "naive"
texture = "images/wood.png"
filter = "nearest"
wrap = "clamp"
"""


def wood(tmp_path: Path) -> None:
    """The image the LIT scene names, so that it loads (a scene file's texture is read with it)."""
    from PIL import Image

    (tmp_path / "images").mkdir(exist_ok=True)
    Image.new("RGBA", (4, 4), (120, 80, 40, 255)).save(tmp_path / "images/wood.png")


def test_lit_textured_nodes_load_with_paths_relative_to_the_scene_file(tmp_path: Path) -> None:
    wood(tmp_path)
    node = load_scene(write(tmp_path, LIT)).nodes[0]
    m = node.material
    assert (m.shading, m.ambient, m.diffuse, m.specular, m.shininess, m.normals) == (
        "blinn_phong", 0.2, 0.4, 0.0, 8.0, "naive")
    assert m.texture is not None
    assert (m.texture.source, m.texture.filter, m.texture.wrap) == (str(tmp_path / "images/wood.png"), "nearest",
                                                                     "clamp")
    plan_text = plan(load_scene(write(tmp_path, LIT))).describe()
    assert "NUM_LIGHTS=1" in plan_text and "texture unit 0" in plan_text


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("filter = \"nearest\"", "filter = \"bicubic\""), r"scene.toml:12: nodes\[0\].filter: unknown texture filter"),
        (("wrap = \"clamp\"", "wrap = \"tile\""), r"scene.toml:13: nodes\[0\].wrap: unknown texture wrap"),
        (("ambient = 0.2", "ambient = -1"), r"scene.toml:7: nodes\[0\].ambient: material ambient must be"),
        (("normals = \"naive\"", "normals = \"bent\""), r"scene.toml:10: nodes\[0\].normals: unknown normals"),
        (("texture = \"images/wood.png\"\n", ""), r"scene.toml:11: nodes\[0\].filter: needs texture"),
    ],
)
def test_material_errors_name_the_line(tmp_path: Path, change: tuple[str, str], expected: str) -> None:
    wood(tmp_path)
    with pytest.raises(SandboxError, match=expected):
        load_scene(write(tmp_path, LIT.replace(*change)))


@pytest.mark.parametrize(("make", "reason"), [
    (None, "not found"),
    (lambda p: p.write_bytes(b"not a picture"), "is not an image Pillow can read"),
    (lambda p: p.mkdir(), "is a folder, expected an image file"),
])
def test_a_texture_that_fails_to_load_names_the_scene_file_and_line(tmp_path: Path, make, reason: str) -> None:
    (tmp_path / "images").mkdir()
    if make is not None:
        make(tmp_path / "images" / "wood.png")
    message = error_of(tmp_path, LIT)
    assert message.startswith("scene.toml:11: nodes[0].texture: texture file "), message
    assert "images/wood.png" in message and reason in message


def test_a_scene_files_missing_texture_is_one_error_line_through_the_cli(tmp_path: Path) -> None:
    path = write(tmp_path, '[[nodes]]\nmesh = "cube24"\n\ntexture = "box"\n')
    out = tmp_path / "x.png"
    assert_user_error(run_cli("render", str(path), "--size", "16x16", "--out", str(out)),
                      f"{path}:4: nodes[0].texture: texture file {tmp_path / 'box'} not found")
    assert not out.exists()


def test_a_lit_scene_file_renders_lit(tmp_path: Path, gl) -> None:
    from glsandbox.lesson import scene_file_lesson

    path = write(tmp_path, '[[lights]]\nposition = [0, 0, 5]\n\n[[nodes]]\nmesh = "cube24"\nshading = "phong"\n'
                           'color = [1, 0, 0]\n\n[camera]\neye = [0, 0, 6]\n')
    image = gl.render(scene_file_lesson(path)(), (64, 64)).image
    # Facing the light head on: 0.1 ambient + 0.4 diffuse + specular on red, clamped.
    r, g, b, _ = image[32, 32]
    assert r > 150 and g < r and b < r


# --- the mirror and the shadow in a scene file ([mirror], [shadow], depth_mode) ---

ROOM = (EXAMPLES_DIR / "mirror_room.toml").read_text()


def without_table(text: str, table: str) -> str:
    """The file with one ``[table]`` (its header up to the next blank line or the end) removed."""
    start = text.index(f"[{table}]")
    end = text.find("\n\n", start)
    return text[:start] + (text[end:] if end >= 0 else "")


def test_the_example_room_loads_its_mirror_shadow_and_depth_mode(tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path, ROOM))
    assert scene.depth_mode == "reverse_z"
    assert scene.mirror is not None and scene.planar_shadow is not None
    assert (scene.mirror.node, scene.mirror.reflected, scene.mirror.stencil) == ("glass", ("box", "floor"), True)
    assert scene.mirror.plane == (0.0, 0.0, 1.0, 4.0)
    shadow = scene.planar_shadow
    assert (shadow.receiver, shadow.casters, shadow.light) == ("floor", ("box",), (-2, 5, 2, 1))
    assert (shadow.lift, shadow.polygon_offset, shadow.stencil) == (0.005, True, True)
    frame_plan = plan(scene)
    assert [p.kind for p in frame_plan.passes] == ["clear", "draw", "mark_mirror", "reflection", "mirror_surface",
                                                   "planar_shadow"]
    assert frame_plan.buffers.stencil and frame_plan.buffers.float_depth
    # Without the two tables the plan has neither their passes nor the stencil.
    plain = plan(load_scene(write(tmp_path, without_table(without_table(ROOM, "mirror"), "shadow"))))
    assert [p.kind for p in plain.passes] == ["clear", "draw"] and not plain.buffers.stencil


def test_the_example_room_shows_its_reflection_and_shadow(tmp_path: Path, gl) -> None:
    from glsandbox.lesson import scene_file_lesson

    def render(text: str, name: str) -> np.ndarray:
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        return gl.render(scene_file_lesson(path)(), (160, 120)).image[..., :3].astype(int)

    room = render(ROOM, "room")
    no_mirror = render(without_table(ROOM, "mirror"), "no_mirror")
    no_shadow = render(without_table(ROOM, "shadow"), "no_shadow")
    # The mirror changes only the glass (the reflected box and floor appear in it) ...
    changed = np.any(room != no_mirror, axis=-1)
    assert changed.sum() > 300
    rows, cols = np.nonzero(changed)
    assert rows.min() > 15 and rows.max() < 55 and cols.min() > 80 and cols.max() < 120  # the glass, top middle
    # ... and the shadow only darkens the floor beside the box.
    darker = np.all(room <= no_shadow, axis=-1) & np.any(room < no_shadow, axis=-1)
    assert darker.sum() > 50 and np.array_equal(darker, np.any(room != no_shadow, axis=-1))


def line_of(text: str, fragment: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), start=1) if fragment in line)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (('reflected = ["box", "floor"]', 'reflected = ["box", "ghost"]'),
         r"mirror.reflected: no node is named 'ghost'"),
        (('reflected = ["box", "floor"]', 'reflected = ["box", "glass"]'), r"mirror.reflected: .*cannot reflect itself"),
        (('node = "glass"', 'node = 3'), r"mirror.node: needs node"),
        (('plane = [0, 0, 1, 4] ', 'tilt = 1 '), r"mirror.tilt: unknown key"),
        (('light = [-2, 5, 2, 1]', 'light = [1, 0, 0, 0]'), r"shadow.light: .*parallel"),
        (('casters = ["box"]', 'casters = "box"'), r"shadow.casters: expected a list of node names"),
        (('depth_mode = "reverse_z"', 'depth_mode = "inverse"'), r"depth_mode: unknown depth mode 'inverse'"),
    ],
)
def test_mirror_and_shadow_errors_name_the_line(tmp_path: Path, change: tuple[str, str], expected: str) -> None:
    old, new = change
    assert old in ROOM
    text = ROOM.replace(old, new)
    key_line = line_of(text, new.split("=")[0].strip() + " =")
    with pytest.raises(SandboxError, match=rf"scene.toml:{key_line}: {expected}") as info:
        load_scene(write(tmp_path, text))
    assert "\n" not in str(info.value)


def error_of(tmp_path: Path, text: str) -> str:
    with pytest.raises(SandboxError) as info:
        load_scene(write(tmp_path, text))
    message = str(info.value)
    assert "\n" not in message
    return message.replace(f"{tmp_path}/", "")  # "scene.toml:3: ..."


# --- scene files: nesting and types ------------------------------------------------


def test_a_deeply_nested_file_is_one_error_line_through_the_cli(tmp_path: Path) -> None:
    scene = tmp_path / "deep.toml"
    scene.write_text("a = " + "[" * 2000 + "]" * 2000 + "\n")  # 4 KB: tomllib recursed into a RecursionError
    out = tmp_path / "x.png"
    assert_user_error(run_cli("render", str(scene), "--out", str(out)), f"{scene}:1: malformed TOML",
                      "nested too deeply")
    assert not out.exists()


def test_a_number_where_a_table_belongs_names_file_line_and_key_through_the_cli(tmp_path: Path) -> None:
    scene = tmp_path / "nodes.toml"
    scene.write_text('name = "x"\nnodes = [1, 2]\n')  # was a TypeError traceback
    assert_user_error(run_cli("render", str(scene), "--out", str(tmp_path / "x.png")),
                      f"{scene}:2: nodes[0]: expected a table")


@pytest.mark.parametrize(("text", "expected"), [
    ("nodes = [1, 2]\n", "scene.toml:1: nodes[0]: expected a table"),
    ('nodes = [{mesh = "cube"}, "cube"]\n', "scene.toml:1: nodes[1]: expected a table"),
    ("lights = [[1, 2, 3]]\n", "scene.toml:1: lights[0]: expected a table"),
    ("viewports = [0.5]\n", "scene.toml:1: viewports[0]: expected a table"),
    ("camera = 5\n", "scene.toml:1: camera: expected a [camera] table, got 5"),
    ('camera = {eye = "x"}\n', "scene.toml:1: camera.eye: expected a list of 3 finite numbers, got 'x'"),
    ("camera.fov_y = [45]\n", "scene.toml:1: camera.fov_y: expected a finite number"),
    ("mirror = [1]\n", "scene.toml:1: mirror: expected a [mirror] table"),
    ("name = [1]\n", "scene.toml:1: name: expected text"),
    ("depth_mode = 1\n", "scene.toml:1: depth_mode: expected text"),
    ('[[nodes]]\nmesh = "cube"\nname = 3\n', "scene.toml:3: nodes[0].name: expected text"),
    ('[[nodes]]\nmesh = "cube"\norder = 3\n', "scene.toml:3: nodes[0].order: expected text"),
    ('[[nodes]]\nmesh = "cube"\nshading = ["solid"]\n', "scene.toml:3: nodes[0].shading: expected text"),
    ('[[nodes]]\nmesh = "cube24"\nshading = "phong"\nnormals = 1\n', "scene.toml:4: nodes[0].normals: expected text"),
    ('[[nodes]]\nmesh = "cube24"\ntexture = "checker"\nfilter = 2\n', "scene.toml:4: nodes[0].filter: expected text"),
    ('[[nodes]]\nmesh = "cube"\nviewports = [true]\n', "scene.toml:3: nodes[0].viewports: expected a list"),
    ('[[nodes]]\nmesh = "cube"\nscale = {x = 1}\n', "scene.toml:3: nodes[0].scale: expected a list of 3 finite"),
    ('[[viewports]]\nlabel = 1\n', "scene.toml:2: viewports[0].label: expected text"),
    ("[[lights]]\nposition = 5\n", "scene.toml:2: lights[0].position: expected a list of 3"),
])
def test_a_wrong_type_anywhere_names_file_line_and_key(tmp_path: Path, text: str, expected: str) -> None:
    assert error_of(tmp_path, text).startswith(expected)


@pytest.mark.parametrize(("text", "expected"), [
    ('[[nodes]]\nmesh = "cube"\ncolor = [2, 0, 0]\n', "scene.toml:3: nodes[0].color: colour channels"),
    ('[[nodes]]\nmesh = "cube"\ncolor = [0, 0, 0]\nshading = "solid"\nambient = -1\n',
     "scene.toml:5: nodes[0].ambient: material ambient"),
    (ROOM.replace("# lift = 0.005,", "lift = -1 #"), "shadow.lift: shadow lift must be"),
    (ROOM.replace("# lift = 0.005,", "color = [0, 0, 2, 1] #"), "shadow.color: shadow colour"),
    (ROOM.replace("# lift = 0.005,", "stencil = 1 #"), "shadow.stencil: expected true or false"),
    (ROOM.replace("# stencil = false", "stencil = 0"), "mirror.stencil: expected true or false"),
])
def test_scene_errors_say_their_location_once(tmp_path: Path, text: str, expected: str) -> None:
    message = error_of(tmp_path, text)
    assert message.count("scene.toml") == 1, message  # was "c.toml:1: nodes[0]: c.toml:3: nodes[0].color: ..."
    assert expected in message


@pytest.mark.parametrize("text", [
    "[camera]\neye = [1, 2, 3]\ntarget = [1, 2, 3]\n",
    "[camera]\neye = [0, 0, 0]\ntarget = [0, 5, 0]\n",
    ROOM.replace("plane = [0, 1, 0, 0]", "plane = [0, 0, 0, 1]"),
    ROOM.replace("light = [-2, 5, 2, 1]", "light = [1, 0, 0, 0]"),
])
def test_messages_show_plain_numbers(tmp_path: Path, text: str) -> None:
    message = error_of(tmp_path, text)
    assert "np." not in message and "float64" not in message, message


def test_numbers_beyond_the_limit_are_refused_where_they_enter(tmp_path: Path) -> None:
    assert error_of(tmp_path, "[[lights]]\nposition = [1e200, 0, 0]\n").startswith(
        "scene.toml:2: lights[0].position: numbers must lie within +-1e+06")
    assert error_of(tmp_path, "[camera]\nfar = 1e300\n").startswith("scene.toml:2: camera.far: must lie within")
    # Each number within the bound, their product (translate, then scale) not: the node is named.
    message = error_of(tmp_path, '[[nodes]]\nname = "far"\nmesh = "cube"\norder = "TSR"\nscale = [1e6, 1, 1]\n'
                                 'translate = [1e6, 0, 0]\n')
    assert message.startswith("scene.toml:5: nodes[0].scale: node 'far': model matrix entry")


def test_a_mesh_without_what_its_material_reads_is_named_in_the_file(tmp_path: Path) -> None:
    # The executor refused it while drawing, naming neither the file nor the node.
    assert error_of(tmp_path, '[[nodes]]\nmesh = "quad_list"\ntexture = "checker"\n').startswith(
        "scene.toml:3: nodes[0].texture: node 'node0': mesh 'quad_list' has no uv data, which a texture needs")
    # A lit mesh without normals is no mistake: both renderers shade it flat (tests/mesh/test_normals.py).


def test_a_flattened_lit_node_names_the_file_and_the_node(tmp_path: Path) -> None:
    message = error_of(tmp_path, '[[lights]]\nposition = [1, 2, 3]\n\n[[nodes]]\nname = "ball"\nmesh = "sphere"\n'
                                 'scale = [1, 0, 1]\nshading = "phong"\n')
    assert message.startswith("scene.toml:7: nodes[0].scale: node 'ball': model matrix is singular")


# --- the shadow's light is one of the scene's lights -------------------------------


def test_a_shadow_light_that_is_none_of_the_lights_is_refused_with_its_line(tmp_path: Path) -> None:
    text = ROOM.replace("light = [-2, 5, 2, 1]", "light = [-2, 6, 2, 1]")
    line = next(i for i, t in enumerate(text.splitlines(), start=1) if t.startswith("light = [-2, 6, 2, 1]"))
    message = error_of(tmp_path, text)
    assert message.startswith(f"scene.toml:{line}: shadow.light: the shadow's point light at (-2.0, 6.0, 2.0) is "
                              "none of the scene's lights ((-2.0, 5.0, 2.0))"), message


def test_a_shadow_light_may_be_a_light_or_a_direction_towards_one(tmp_path: Path) -> None:
    assert load_scene(write(tmp_path, ROOM)).planar_shadow.light == (-2.0, 5.0, 2.0, 1.0)
    # Left out with exactly one light: that light.
    only = load_scene(write(tmp_path, ROOM.replace("light = [-2, 5, 2, 1] ", "# light")))
    assert only.planar_shadow.light == (-2.0, 5.0, 2.0, 1.0)
    # A directional shadow light pointing at a light far away (the mirror lesson's far light).
    far = ROOM.replace("position = [-2, 5, 2]", "position = [-2000, 5000, 2000]").replace(
        "light = [-2, 5, 2, 1]", "light = [-2, 5, 2, 0]")
    assert load_scene(write(tmp_path, far)).planar_shadow.light[3] == 0.0
    # Left out with two lights: which one is not guessed.
    two = ROOM.replace("light = [-2, 5, 2, 1] ", "# light").replace(
        "[[lights]]\nposition = [-2, 5, 2]\n", "[[lights]]\nposition = [-2, 5, 2]\n\n[[lights]]\nposition = [1, 1, 1]\n")
    assert "shadow: needs light = " in error_of(tmp_path, two)
