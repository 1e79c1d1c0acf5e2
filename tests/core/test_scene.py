"""Bad values in scene files and in the scene's dataclasses (issue 12, second part).

Scene files: wrong types, deep nesting, the location said once, plain numbers,
the shadow's light one of the scene's lights. The dataclasses (used by lessons
and scene files alike): finite values within NUMBER_LIMIT, a lens the
rasterizer and the ray tracer both accept, lit nodes with normals, meshes with
what their material reads.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import NUMBER_LIMIT, SandboxError
from glsandbox.scene import Camera, Light, Material, Node, Scene, Texture, Viewport
from glsandbox.scene_file import load_scene
from support import EXAMPLES_DIR, assert_user_error, run_cli

ROOM = (EXAMPLES_DIR / "mirror_room.toml").read_text()


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


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
    # A lit mesh without normals is no mistake: both renderers shade it flat (tests/core/test_meshnormals.py).


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


# --- the scene's dataclasses ----------------------------------------------------------


@pytest.mark.parametrize(("make", "fragment"), [
    (lambda: Light((math.nan, 1.0, 0.0)), "light position must be finite, got (nan, 1.0, 0.0)"),
    (lambda: Light((0.0, 1.0, 0.0), (math.inf, 1.0, 1.0)), "light colour must be finite"),
    (lambda: Light((0.0, 1.0, 0.0), (-1.0, 1.0, 1.0)), "light colour must lie within 0..1e+06"),
    (lambda: Light((1e200, 0.0, 0.0)), "light position must lie within"),
    (lambda: Camera(fov_y=0.0), "camera fov_y must lie strictly between 0 and 180 degrees, got 0.0"),
    (lambda: Camera(fov_y=180.0), "camera fov_y must lie strictly between 0 and 180 degrees, got 180.0"),
    (lambda: Camera(fov_y=math.nan), "camera fov_y must be a finite number"),
    (lambda: Camera(eye=(0.0, 1e300, 10.0)), "camera eye must lie within"),
    (lambda: Camera(near=0.0), "camera near and far need 0 < near < far"),
    (lambda: Camera(far=1e300), "camera far must lie within"),
    (lambda: Camera(eye=(0.0, 0.0, 0.0), target=(0.0, 0.0, 0.0)), "camera eye and target are the same point"),
    (lambda: Material(color=(1.0, math.nan, 0.0, 1.0)), "material colour must be finite"),
    (lambda: Material(shininess=1e300), "material shininess must be a finite number in 0..1e+06"),
    (lambda: Node("big", geometry.cube(), transforms.scale(1e300, 1.0, 1.0)), "node 'big': model matrix entry"),
    (lambda: Node("nan", geometry.cube(), transforms.translate(math.nan, 0.0, 0.0)),
     "node 'nan': model matrix has a non-finite entry"),
    (lambda: Node("flat", geometry.sphere(), transforms.scale(1.0, 0.0, 1.0), Material(shading="phong")),
     "node 'flat': model matrix is singular"),
    (lambda: Node("thin", geometry.sphere(), transforms.scale(1.0, 1e-9, 1.0), Material(shading="phong")),
     "node 'thin': model matrix shrinks one direction to 1e-09"),
    (lambda: Node("quad", geometry.quad_list(), material=Material(texture=Texture("checker"))),
     "node 'quad': mesh 'quad_list' has no uv data, which a texture needs"),
    (lambda: Node("box", geometry.plane(1.0), material=Material(shading="vertex_color")),
     "node 'box': mesh 'plane' has no color data, which vertex_color shading needs"),
    (lambda: Viewport(rect=(0.5, 0.0, 0.6, 1.0)), "viewport rect (0.5, 0.0, 0.6, 1.0) must lie inside 0..1"),
    (lambda: Viewport(clear_color=(0.0, 0.0, math.inf, 1.0)), "viewport clear colour must be finite"),
    (lambda: Scene("s", clear_color=(2.0, 0.0, 0.0, 1.0)), "scene clear colour must lie within 0..1"),
])
def test_values_entering_the_data_model_are_checked(make, fragment: str) -> None:
    with pytest.raises(SandboxError) as info:
        make()
    assert fragment in str(info.value) and "\n" not in str(info.value) and "np." not in str(info.value)


def test_the_bound_is_one_constant() -> None:
    import glsandbox.lesson
    import glsandbox.scene

    assert glsandbox.lesson.NUMBER_LIMIT is NUMBER_LIMIT
    assert glsandbox.scene.MIN_SCALE == 1.0 / NUMBER_LIMIT


def test_a_flattened_unlit_node_is_still_drawn() -> None:
    node = Node("disc", geometry.sphere(), transforms.scale(1.0, 0.0, 1.0))  # unlit: no normals needed
    assert node.model[1, 1] == 0.0


def test_lists_given_to_a_scene_are_kept_as_tuples() -> None:
    """``Scene("s", nodes=[...])`` is natural Python; the renderers compare a scene's
    parts by identity and hash them, which a list would break (the gpu engine's
    upload cache did, with an AssertionError)."""
    node = Node("cube", geometry.cube())
    light = Light((1.0, 2.0, 3.0))
    scene = Scene("s", nodes=[node], lights=[light], viewports=[Viewport()])
    assert scene.nodes == (node,) and isinstance(scene.nodes, tuple)
    assert isinstance(scene.lights, tuple) and isinstance(scene.viewports, tuple)
