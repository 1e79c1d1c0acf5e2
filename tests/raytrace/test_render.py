"""render(scene, size, engine): the ray tracer on the rasterizer's Scene, both engines.

The gpu engine (GLSL, float32) must match the numpy engine (float64) on
every lesson scene: at most 0.5% of pixels may differ by more than 2 levels
in a channel (grazing rays and shadow edges), and none by more than 2
levels on average. Measured when written: at most 1 level anywhere.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support import far_triangle_scene

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.raytrace import Sphere
from glsandbox.frame import InteractiveResolution, trace_viewports
from glsandbox.raytrace.render import RenderStats, render
from glsandbox.raytrace.world import build_world, camera_rays
from glsandbox.scene import Camera, Light, Material, Node, Scene, Viewport

SIZE = (96, 72)
#: The gpu-versus-numpy tolerance (see the module docstring).
LEVELS = 2
MAX_BAD_SHARE = 0.005


def lit(color, **kw) -> Material:
    return Material(color=(*color, 1.0), shading="phong", **kw)


def sphere_node(name: str, center, radius: float, material: Material) -> Node:
    model = transforms.translate(*center) @ transforms.scale(radius, radius, radius)
    return Node(name, geometry.sphere(), model, material)


def mirror_scene() -> Scene:
    """A red sphere over a reflective ground, one light: shadow and reflection both show."""
    ground = Node("ground", geometry.plane(20.0), transforms.translate(0, -1, 0),
                  lit((0.5, 0.5, 0.5), reflectivity=0.5))
    ball = sphere_node("ball", (0, 0, 0), 1.0, lit((1.0, 0.2, 0.1)))
    return Scene("mirror", nodes=(ground, ball), camera=Camera(eye=(0, 2, 6)),
                 lights=(Light((2.0, 5.0, 2.0)),), clear_color=(0.2, 0.3, 0.6, 1.0))


def test_each_engine_finds_a_triangle_past_65535(engine):
    """One node of 70,000 triangles whose only visible one is the last (index 69,999): past
    llvmpipe's 65,535 loop iterations, which the gpu engine passes through the node's BVH."""
    image = engine.render(far_triangle_scene(), (32, 24))
    assert tuple(image[12, 16, :3]) == (230, 51, 51)  # the last triangle, its solid colour
    assert tuple(image[0, 0, :3]) == (0, 0, 0)
    assert (image[..., 3] == 255).all()


def test_numpy_render_matches_the_sphere_test_per_pixel():
    """The centre pixel of a sphere straight ahead is its colour at t = depth of its front."""
    ball = sphere_node("ball", (0, 0, 0), 1.0, Material(color=(0.0, 1.0, 0.0, 1.0)))
    scene = Scene("s", nodes=(ball,), camera=Camera(eye=(0, 0, 5)), clear_color=(0, 0, 0, 1))
    image = render(scene, (33, 33))
    assert tuple(image[16, 16]) == (0, 255, 0, 255)
    assert tuple(image[0, 0]) == (0, 0, 0, 255)
    eye, dirs = camera_rays(scene.camera, 33, 33)
    t = Sphere((0, 0, 0), 1.0).intersect_many(eye, dirs).reshape(33, 33)
    assert np.array_equal(np.isfinite(t), image[..., 1] == 255)


def test_shadows_and_reflections_change_the_picture():
    scene = mirror_scene()
    full = render(scene, SIZE)
    no_shadow = render(scene, SIZE, shadows=False)
    flat = render(scene, SIZE, max_depth=0)
    assert (np.abs(full.astype(int) - no_shadow).max(axis=2) > 10).mean() > 0.01
    assert (np.abs(full.astype(int) - flat).max(axis=2) > 10).mean() > 0.01
    stats = RenderStats()
    render(scene, SIZE, stats=stats)
    assert stats.primary == SIZE[0] * SIZE[1] and stats.shadow > 0 and stats.reflection > 0


def test_culling_options_do_not_change_closed_scenes():
    """Backface culling and AABB culling are accelerations: the same image."""
    lesson = find_lesson("indexed_cube")()
    scene = lesson.scene()
    reference = render(scene, SIZE, cull_backfaces=False, aabb=False)
    assert np.array_equal(render(scene, SIZE), reference)
    assert np.array_equal(render(scene, SIZE, cull_backfaces=True, aabb=True), reference)


def test_lamp_casts_no_shadow_for_its_own_light():
    lamp = Node("lamp", geometry.cube(), transforms.translate(0, 3, 0) @ transforms.scale(0.2, 0.2, 0.2),
                Material(color=(1, 1, 1, 1)))
    ground = Node("ground", geometry.plane(10.0), transforms.identity(), lit((1, 1, 1)))
    scene = Scene("lamp", nodes=(ground, lamp), camera=Camera(eye=(0, 5, 5)), lights=(Light((0, 3, 0)),))
    below = render(scene, (32, 32))
    assert below[24, 16, 0] > 60  # lit: the lamp around the light does not block it


@pytest.mark.parametrize("bad, message", [
    (dict(engine="cuda"), "unknown ray tracing engine"),
    (dict(engine="gpu"), "needs a ModernGL context"),
    (dict(max_depth=-1), "max_depth"),
])
def test_bad_arguments_are_one_line_errors(bad, message):
    with pytest.raises(SandboxError, match=message):
        render(mirror_scene(), SIZE, **bad)
    with pytest.raises(SandboxError, match="image size"):
        render(mirror_scene(), (0, 10))


def test_renderer_parameter_is_validated():
    with pytest.raises(SandboxError, match="renderer=opengl: expected one of raster, ray, ray_numpy"):
        find_lesson("phong").from_settings(["renderer=opengl"])
    with pytest.raises(SandboxError, match="unknown renderer"):
        Viewport(renderer="rays")


def test_interactive_resolution_is_coarse_while_moving():
    motion = InteractiveResolution(moving=0.25, settle=0.3)
    a = Scene("a", camera=Camera(eye=(0, 0, 5)))
    b = Scene("b", camera=Camera(eye=(0, 0, 4)))
    assert motion.resolution(a, now=0.0) == 1.0
    assert motion.resolution(b, now=0.1) == 0.25
    assert motion.resolution(b, now=0.2) == 0.25
    assert motion.resolution(b, now=0.5) == 1.0


def test_trace_viewports_leaves_raster_scenes_alone_and_replaces_ray_viewports():
    scene = find_lesson("phong")().scene()
    assert trace_viewports(scene, SIZE) is scene
    ray = find_lesson("phong")(renderer="ray_numpy").scene()
    traced = trace_viewports(ray, SIZE)
    assert traced.nodes == () and traced.overlays[0].name == "raytrace/0"
    assert np.array_equal(traced.overlays[0].image, render(scene, SIZE))


# --- with the shared GL context ---------------------------------------------------


@pytest.mark.parametrize("name", [cls.name for cls in all_lessons()] + ["mirror"])
def test_gpu_engine_matches_numpy_engine(gl, name):
    scene = mirror_scene() if name == "mirror" else find_lesson(name)().scene()
    gpu = render(scene, SIZE, "gpu", ctx=gl.host.ctx)
    ref = render(scene, SIZE, "numpy")
    diff = np.abs(gpu.astype(int) - ref.astype(int)).max(axis=2)
    assert (diff > LEVELS).mean() <= MAX_BAD_SHARE, f"{name}: {(diff > LEVELS).mean():.2%} pixels off"
    assert diff.mean() <= LEVELS


def test_gpu_engine_options_match(gl):
    scene = mirror_scene()
    for options in (dict(shadows=False), dict(max_depth=0), dict(aabb=False, cull_backfaces=False),
                    dict(analytic_spheres=False)):
        gpu = render(scene, SIZE, "gpu", ctx=gl.host.ctx, **options)
        ref = render(scene, SIZE, **options)
        diff = np.abs(gpu.astype(int) - ref.astype(int)).max(axis=2)
        assert (diff > LEVELS).mean() <= MAX_BAD_SHARE, options


def render_both_ways(gl, monkeypatch, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The gpu engine's image with the unrolled program (the scene is small) and
    with the general one (UNROLL_NODES = 0: no scene counts as small)."""
    from glsandbox.raytrace import gpu as gpu_engine

    tracer = gpu_engine.gpu_tracer(gl.host.ctx)
    tracer.forget_scenes()  # each way uploads the scene afresh
    unrolled = render(scene, SIZE, "gpu", ctx=gl.host.ctx)
    assert tracer._scenes[0].unrolled
    tracer.forget_scenes()
    with monkeypatch.context() as patch:
        patch.setattr(gpu_engine, "UNROLL_NODES", 0)
        general = render(scene, SIZE, "gpu", ctx=gl.host.ctx)
        assert not tracer._scenes[0].unrolled
    tracer.forget_scenes()
    return unrolled, general


def test_gpu_unrolled_and_general_programs_agree(gl, monkeypatch):
    """Small scenes get a program with their node list unrolled; larger ones the
    general loop over textures. Both trace the same picture."""
    for name in ("ray_phong", "phong"):
        scene = find_lesson(name)().scene()
        unrolled, general = render_both_ways(gl, monkeypatch, scene)
        diff = np.abs(unrolled.astype(int) - general.astype(int)).max(axis=2)
        assert diff.max() <= 1, name


def test_coincident_nodes_show_the_first_node_in_both_engines(gl, monkeypatch):
    """Two quads in one place: the course's tie rule keeps the first node hit, in
    numpy (float64), in the gpu's unrolled program and in its general one."""
    quad = transforms.rotate_x(math.radians(90.0)) @ transforms.scale(4.0, 1.0, 4.0)  # facing +z
    red, green = Material(color=(1.0, 0.0, 0.0, 1.0)), Material(color=(0.0, 1.0, 0.0, 1.0))
    scene = Scene("tie", nodes=(Node("first", geometry.plane(1.0), quad, red),
                                Node("second", geometry.plane(1.0), quad, green)),
                  camera=Camera(eye=(0.3, 0.2, 5.0)), clear_color=(0.0, 0.0, 0.0, 1.0))
    for image in (render(scene, SIZE, "numpy"), *render_both_ways(gl, monkeypatch, scene)):
        centre = image[SIZE[1] // 2 - 10:SIZE[1] // 2 + 10, SIZE[0] // 2 - 10:SIZE[0] // 2 + 10]
        assert (centre[..., 0] == 255).all() and (centre[..., 1] == 0).all()  # red, the first node


def test_lesson_renders_with_either_renderer(gl):
    """The hook: renderer=ray draws the traced image through the raster executor, texel for pixel."""
    cls = find_lesson("phong")
    traced = gl.render(cls(renderer="ray"), SIZE).image
    assert np.array_equal(traced[..., :3], render(cls().scene(), SIZE, "gpu", ctx=gl.host.ctx)[..., :3])
    raster = gl.render(cls(), SIZE).image
    assert not np.array_equal(traced, raster)


def test_compare_raster_against_ray(gl):
    from glsandbox.measure.compare import compare

    result = compare(find_lesson("indexed_cube"), ["renderer=raster,ray"], [], (192, 72), gl)
    assert [v.label for v in result.variants] == ["renderer=raster", "renderer=ray"]
    assert result.image.shape == (72, 192, 4)
    # The cube is the same cube: only edge pixels differ.
    share = float(result.pairs[0]["share"]) if result.pairs else 0.0
    assert share < 0.05
    assert math.isfinite(share)
    phong = compare(find_lesson("phong"), ["renderer=raster,ray"], [], (192, 72), gl)
    assert phong.difference is not None and phong.difference.shape == (72, 96, 4)
    assert phong.difference[..., 0].max() > 100  # the shadows only the ray tracer casts


def test_stencil_mirror_glass_reflects_in_the_ray_tracer():
    """The mirror lesson's glass (scene.mirror) reflects 1 - alpha of the light, as the raster blends it."""
    scene = find_lesson("mirror")().scene()
    assert scene.mirror is not None
    world = build_world(scene)
    glass = next(n for n in world.nodes if n.name == scene.mirror.node)
    alpha = next(n for n in scene.nodes if n.name == scene.mirror.node).material.color[3]
    assert glass.reflectivity == pytest.approx(1.0 - alpha) and glass.reflectivity > 0
