"""Bad values in the scene's dataclasses, used by lessons and
scene files alike: finite values within NUMBER_LIMIT, a lens the rasterizer and the ray
tracer both accept, lit nodes with normals, meshes with what their material reads.
(Scene files' own mistakes: tests/core/test_scene_file.py.)"""

from __future__ import annotations

import math

import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import NUMBER_LIMIT, SandboxError
from glsandbox.scene import Camera, Light, Material, Node, Scene, Texture, Viewport

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
