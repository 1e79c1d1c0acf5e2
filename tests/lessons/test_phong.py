"""Lighting: the course's Phong numbers, the normal matrix, the lesson's plan and goldens.

Course sections "Phong boyama modeli" and "Lighting". The rendered checks
use scenes built to make one number readable from one pixel: a flat red
plane seen from straight above, one light far away in a known direction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.plan import plan
from glsandbox.scene import Camera, Light, Material, Node, Scene
from glsandbox.lessons.phong import LIGHT_COLORS, PhongLesson, light_positions

RED = (1.0, 0.0, 0.0, 1.0)
FAR = 1.0e4  # a point light this far away lights a small patch from one direction


def top_view_scene(light_direction: tuple[float, float, float], material: Material, size: float = 4.0) -> Scene:
    """A plane through the origin facing +y, seen from straight above, lit by
    one white light far away along ``light_direction``."""
    d = np.asarray(light_direction, dtype=np.float64)
    light = Light(tuple(FAR * d / np.linalg.norm(d)), (1.0, 1.0, 1.0))
    camera = Camera(eye=(0.0, 5.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0))
    return Scene("probe", nodes=(Node("plane", geometry.plane(size), np.eye(4), material),),
                 camera=camera, lights=(light,), clear_color=(0.0, 0.0, 0.0, 1.0))


def diffuse_only(shading: str = "phong", **extra) -> Material:
    """The diffuse term alone, with coefficient 1, so the pixel is max(N.L,0)*mesh."""
    return Material(color=RED, shading=shading, ambient=0.0, diffuse=1.0, specular=0.0, **extra)


def centre(image: np.ndarray) -> tuple[int, ...]:
    h, w = image.shape[:2]
    return tuple(int(c) for c in image[h // 2, w // 2, :3])


# --- the course's numbers ---------------------------------------------------


@pytest.mark.parametrize("shading", ["phong", "gouraud", "blinn_phong"])
def test_course_diffuse_example_204(gl, shading):
    # "N * toLight = 0.8; diffuseColor = 0.8 * (255,0,0) = (204,0,0)".
    # N = (0,1,0) and toLight = (0.6, 0.8, 0): N . toLight = 0.8.
    frame = gl.render_scene(top_view_scene((0.6, 0.8, 0.0), diffuse_only(shading)), (32, 32))
    assert centre(frame.image) == (204, 0, 0)


def test_light_along_the_normal_gives_full_diffuse(gl):
    # cos 0 = 1: the most light.
    frame = gl.render_scene(top_view_scene((0.0, 1.0, 0.0), diffuse_only()), (32, 32))
    assert centre(frame.image) == (255, 0, 0)


def test_light_at_ninety_degrees_gives_no_diffuse(gl):
    # cos 90° = 0: none (the plane's pixels are black, not the background's black by accident:
    # with ambient on, the same pixel is exactly the ambient colour).
    frame = gl.render_scene(top_view_scene((1.0, 0.0, 0.0), diffuse_only()), (32, 32))
    assert centre(frame.image) == (0, 0, 0)
    ambient = replace_material(diffuse_only(), ambient=1.0)
    frame = gl.render_scene(top_view_scene((1.0, 0.0, 0.0), ambient), (32, 32))
    assert centre(frame.image) == (255, 0, 0)


def replace_material(material: Material, **changes) -> Material:
    from dataclasses import replace

    return replace(material, **changes)


def test_course_coefficients_sum_and_clamp(gl):
    # 0.1*mesh + 0.4*diffuse + 0.3*specular with the light and the eye both on
    # the normal: D = mesh, and the reflection points straight back at the
    # eye, so R . toEye = 1 and S = the white light. Per light
    # min(0.1 + 0.4 + 0.3, 1) = 0.8 in red, 0.3 in green and blue (white highlight).
    material = Material(color=RED, shading="phong")
    frame = gl.render_scene(top_view_scene((0.0, 1.0, 0.0), material), (33, 33))
    r, g, b = centre(frame.image)
    assert abs(r - 0.8 * 255) <= 1 and abs(g - 0.3 * 255) <= 1 and abs(b - 0.3 * 255) <= 1


def mirror_point(light: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """Where on the plane y = 0 a ray from the light reflects into the eye:
    on the line from the eye to the light's mirror image below the plane."""
    image = light * np.array([1.0, -1.0, 1.0])
    t = eye[1] / (eye[1] - image[1])
    return eye + t * (image - eye)


@pytest.mark.parametrize("shading", ["phong", "blinn_phong"])
def test_specular_peak_lies_on_the_reflection_direction(gl, shading):
    light = np.array([2.0, 3.0, -1.0])
    eye = np.array([0.0, 4.0, 6.0])
    camera = Camera(eye=tuple(eye), target=(0.0, 0.0, 0.0))
    material = Material(color=RED, shading=shading, ambient=0.0, diffuse=0.0, specular=1.0)
    scene = Scene("specular", nodes=(Node("plane", geometry.plane(30.0), np.eye(4), material),),
                  camera=camera, lights=(Light(tuple(light)),), clear_color=(0.0, 0.0, 0.0, 1.0))
    size = 128
    image = gl.render_scene(scene, (size, size)).image[:, :, 1].astype(np.float64)  # green: specular only
    peak = image.max()
    assert peak >= 250  # R . toEye reaches 1 there
    rows, cols = np.nonzero(image >= peak - 1)
    found = np.array([cols.mean() + 0.5, rows.mean() + 0.5])
    # Project the mirror point to pixels (row 0 at the top).
    clip = camera.projection(1.0) @ camera.view() @ np.append(mirror_point(light, eye), 1.0)
    ndc = clip[:3] / clip[3]
    expected = np.array([(ndc[0] + 1) / 2 * size, (1 - ndc[1]) / 2 * size])
    assert np.linalg.norm(found - expected) < 1.5, (found, expected)


# --- normals ----------------------------------------------------------------


def test_normal_matrix_keeps_normals_perpendicular_under_non_uniform_scale():
    model = transforms.scale(1.8, 0.7, 0.9) @ transforms.rotate_z(0.4)
    rng = np.random.default_rng(4)
    for _ in range(20):
        n = rng.normal(size=3)
        tangent = np.cross(n, rng.normal(size=3))  # any vector in the surface
        world_tangent = model[:3, :3] @ tangent
        correct = transforms.normal_matrix(model) @ n
        naive = model[:3, :3] @ n  # the course's mul(Input.Norm, world)
        assert abs(np.dot(correct, world_tangent)) < 1e-9 * np.linalg.norm(correct) * np.linalg.norm(world_tangent)
        assert abs(np.dot(naive, world_tangent)) > 1e-6  # the naive one leans off the surface


def tilted_scaled_plane() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A plane turned 45° about x, then stretched 3x along y: (model, true normal, naive normal)."""
    model = transforms.scale(1.0, 3.0, 1.0) @ transforms.rotate_x(math.radians(45))
    n = np.array([0.0, 1.0, 0.0])
    true = transforms.normal_matrix(model) @ n
    naive = model[:3, :3] @ n
    return model, true / np.linalg.norm(true), naive / np.linalg.norm(naive)


@pytest.mark.parametrize("normals", ["correct", "naive"])
def test_rendered_normals_correct_versus_naive(gl, normals):
    # The light sits on the surface's true normal: the correct normals give
    # full diffuse, the naive ones cos(angle between the two) of it.
    model, true, naive = tilted_scaled_plane()
    material = diffuse_only(normals=normals)
    camera = Camera(eye=tuple(5.0 * true), target=(0.0, 0.0, 0.0))
    scene = Scene("normals", nodes=(Node("plane", geometry.plane(2.0), model, material),), camera=camera,
                  lights=(Light(tuple(FAR * true)),), clear_color=(0.0, 0.0, 0.0, 1.0))
    red = centre(gl.render_scene(scene, (32, 32)).image)[0]
    expected = 255 if normals == "correct" else 255 * float(np.dot(true, naive))
    assert abs(red - expected) <= 1, (red, expected)
    assert normals == "correct" or expected < 200  # the error is large, not a rounding


# --- the lesson -------------------------------------------------------------


def test_lights_orbit_in_opposite_directions_with_the_course_colours():
    assert LIGHT_COLORS == ((1.0, 1.0, 1.0), (1.0, 1.0, 0.0))
    before, after = light_positions(0.0, 1.0), light_positions(0.1, 1.0)
    turn = [math.atan2(b[2], b[0]) - math.atan2(a[2], a[0]) for a, b in zip(before, after)]
    assert turn[0] == pytest.approx(0.1) and turn[1] == pytest.approx(-0.1)
    scene = PhongLesson().scene()
    assert [l.color for l in scene.lights] == list(LIGHT_COLORS)


def test_phong_plan_is_pinned():
    assert plan(PhongLesson().scene()).describe() == "\n".join([
        "plan for phong",
        "buffers: colour RGBA8, depth 24, no MSAA",
        "programs:",
        "  basic[SOLID_COLOR]",
        "  phong[NUM_LIGHTS=2]",
        "passes:",
        "  1. clear viewport 0: colour (0, 0.125, 0.6, 1) + depth",
        "  2. draw viewport 0 (depth test): ground with phong[NUM_LIGHTS=2]; ellipsoid with phong[NUM_LIGHTS=2]; "
        "light0 with basic[SOLID_COLOR]; light1 with basic[SOLID_COLOR]",
    ])


@pytest.mark.parametrize("settings, program", [
    ({"lights": 1}, "phong[NUM_LIGHTS=1]"),
    ({"lights": 0}, "phong[NUM_LIGHTS=0]"),
    ({"shading": "gouraud"}, "phong[NUM_LIGHTS=2,PER_VERTEX]"),
    ({"shading": "blinn_phong", "normals": "naive"}, "phong[NUM_LIGHTS=2,BLINN,NAIVE_NORMALS]"),
])
def test_plan_variants_follow_the_parameters(settings, program):
    described = plan(PhongLesson(**settings).scene()).describe()
    assert program in described
    assert "texture" not in described  # an untextured lesson has no texture unit


def test_light_cubes_are_unlit_in_the_light_colour(gl):
    lesson = PhongLesson()
    scene = lesson.scene()
    frame = gl.render_scene(scene, (128, 128))
    for light in scene.lights:
        clip = scene.camera.projection(1.0) @ scene.camera.view() @ np.append(light.position, 1.0)
        x, y = (clip[0] / clip[3] + 1) / 2 * 128, (1 - clip[1] / clip[3]) / 2 * 128
        assert tuple(frame.image[int(y), int(x), :3]) == tuple(round(255 * c) for c in light.color)


def test_keys_toggle_terms_and_cycle_variants():
    lesson = PhongLesson()
    assert lesson.on_key("3") and lesson.values["specular"] is False
    assert lesson.scene().nodes[1].material.specular == 0.0
    assert lesson.on_key("4") and lesson.values["shading"] == "gouraud"
    assert lesson.on_key("5") and lesson.values["normals"] == "naive"
    assert not lesson.on_key("q")


def test_bad_material_values_are_refused():
    with pytest.raises(SandboxError, match="unknown normals 'sideways'"):
        Material(shading="phong", normals="sideways")
    with pytest.raises(SandboxError, match="specular"):
        Material(shading="phong", specular=-1.0)


# --- goldens ----------------------------------------------------------------

VARIANTS = {
    "phong": {},
    "gouraud": {"shading": "gouraud"},
    "blinn_phong": {"shading": "blinn_phong"},
    "naive_normals": {"normals": "naive"},
    "ambient_only": {"diffuse": False, "specular": False},
    "no_diffuse": {"diffuse": False},
    "no_specular": {"specular": False},
    "one_light": {"lights": 1},
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_phong_goldens(gl, golden, variant):
    frame = gl.render(PhongLesson(time=1.0, **VARIANTS[variant]), (256, 256))
    golden(frame.image, f"phong/{variant}")


def test_naive_normals_change_the_picture(gl):
    correct = gl.render(PhongLesson(), (128, 128)).image.astype(int)
    naive = gl.render(PhongLesson(normals="naive"), (128, 128)).image.astype(int)
    assert (np.abs(correct - naive).max(axis=2) > 8).sum() > 500
