"""The raster executor (glsandbox/gl/executor.py): what it keeps between draws and frames never
changes a picture, and it refuses what it cannot draw.

A program keeps its uniform values, so the executor writes a uniform only when its
bytes differ from the last ones written into that program; the lights' bytes are
made once per frame, the eye's once per view, a material texture is bound once per
run of draws that use it. Each check compares frames drawn by one long-lived
renderer (every cache warm, lessons and times interleaved) with the same frames
drawn by a fresh renderer on the same context (every cache empty).
"""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry
from glsandbox.frame import FrameRenderer
from glsandbox.lesson import find_lesson
from glsandbox.plan import plan
from glsandbox.scene import Node, Scene, Viewport

SIZE = (80, 60)
#: Lessons with lights (reflected ones too: the mirror), textures, overlays and split viewports.
LESSONS = ("phong", "mirror", "texture", "transform_order", "triangle", "indexed_cube")


def fresh_frame(gl, scene) -> np.ndarray:
    renderer = FrameRenderer(gl.host)
    try:
        return renderer.render_scene(scene, SIZE).image.copy()
    finally:
        renderer.close()


def test_frames_with_warm_caches_equal_frames_drawn_from_scratch(gl) -> None:
    # Interleaved, so every lesson's programs are entered with another lesson's values cached.
    for t in (0.0, 0.45, 1.3):
        for name in LESSONS:
            scene = find_lesson(name)().at(t).scene()
            warm = gl.render_scene(scene, SIZE).image
            assert np.array_equal(warm, fresh_frame(gl, scene)), f"{name} at time {t}"


@pytest.fixture
def uniform_writes(monkeypatch):
    """Every uniform write of the executor, by uniform name (moderngl's ``Uniform.write``)."""
    import moderngl

    writes: list[str] = []
    original = moderngl.Uniform.write

    def counted(self, data):
        writes.append(self.name)
        return original(self, data)

    monkeypatch.setattr(moderngl.Uniform, "write", counted)
    return writes


#: What differs from one draw to the next when draws share a program (a node's own matrix and colour).
PER_DRAW = {"m_model", "m_normal", "u_color"}


def test_a_frame_writes_only_the_uniforms_that_changed(gl, uniform_writes) -> None:
    lesson = find_lesson("phong")()
    gl.render(lesson.at(0.2), SIZE)  # every program has its values now
    uniform_writes.clear()
    gl.render(lesson.at(0.2), SIZE)
    # The same frame again: the camera, the lights and the materials are not written again.
    assert set(uniform_writes) <= PER_DRAW
    uniform_writes.clear()
    scene = lesson.at(0.7).scene()
    frame = gl.render_scene(scene, SIZE)  # the lights turn: their positions change
    nodes = {node.name: node for node in scene.nodes}
    lit = [draw for step in frame.plan.passes for draw in step.draws
           if draw.node in nodes and nodes[draw.node].material.lit]
    assert set(uniform_writes) - PER_DRAW == {"u_light_pos"}
    # Once per program that draws lit nodes, not once per lit draw.
    assert uniform_writes.count("u_light_pos") == len({draw.program for draw in lit}) < len(lit)


def test_a_texture_drawn_with_another_filter_is_sampled_with_it(gl) -> None:
    """The filter and wrap are set on the texture itself, only when they change: one image drawn
    nearest, then trilinear and mirrored, then nearest again, each frame as a fresh renderer draws it;
    and in one frame two nodes sharing the image with two filters."""
    from glsandbox import geometry
    from glsandbox.scene import Camera, Material, Node, Scene, Texture

    camera = Camera(eye=(0.0, 1.0, 2.5), target=(0.0, 0.0, -2.0))
    plane = geometry.plane(4.0)

    def scene(*samplings: tuple[str, str]) -> Scene:
        nodes = tuple(Node(f"floor{i}", plane, np.diag([1.0, 1.0, 1.0, 1.0]) if i == 0 else
                           np.array([[1.0, 0, 0, 0], [0, 1, 0, 0.5], [0, 0, 1, -4.0], [0, 0, 0, 1]]),
                           Material(texture=Texture("checker", filter=f, wrap=w)))
                      for i, (f, w) in enumerate(samplings))
        return Scene("sampling", nodes=nodes, camera=camera)

    nearest, smooth = ("nearest", "repeat"), ("mip_linear", "mirrored")
    frames = {}
    for sampling in (nearest, smooth, nearest, smooth):
        image = gl.render_scene(scene(sampling), SIZE).image.copy()
        assert np.array_equal(image, frames.setdefault(sampling, fresh_frame(gl, scene(sampling)))), sampling
    assert not np.array_equal(frames[nearest], frames[smooth])
    both = scene(nearest, smooth)
    assert np.array_equal(gl.render_scene(both, SIZE).image, fresh_frame(gl, both))


def test_a_kept_plan_drawn_with_other_parts_draws_those_parts(gl) -> None:
    """The executor prepares each plan's passes and draws once and keeps them while
    the plan object is the same. One plan drawn in turn with scenes that differ in a material's
    colour, a texture's image, a mesh, the lights and the frame's size draws each as a fresh renderer
    draws it: what was prepared is found again only for the same material, mesh and size."""
    from dataclasses import replace

    from glsandbox import geometry
    from glsandbox.scene import Camera, Light, Material, Node, Scene, Texture

    ball = Node("ball", geometry.sphere(), np.diag([1.2, 1.2, 1.2, 1.0]),
                Material((1.0, 0.3, 0.2, 1.0), shading="phong"))
    stripes = np.zeros((8, 8, 4), np.uint8)
    stripes[:, ::2] = (255, 255, 255, 255)
    stripes[:, 1::2] = (40, 200, 60, 255)
    box = Node("box", geometry.cube24(), np.array([[0.8, 0, 0, 1.8], [0, 0.8, 0, 0], [0, 0, 0.8, 0], [0, 0, 0, 1.0]]),
               Material(shading="phong", texture=Texture("stripes", image=stripes)))
    base = Scene("parts", nodes=(ball, box), lights=(Light((2.0, 3.0, 4.0)),), camera=Camera(eye=(0.0, 1.0, 6.0)))
    recolored = replace(base, nodes=(replace(ball, material=replace(ball.material, color=(0.2, 0.4, 1.0, 1.0))), box))
    # Another image under the same name: the plan names the texture only, the GL texture differs.
    retextured = replace(base, nodes=(ball, replace(box, material=replace(
        box.material, texture=Texture("stripes", image=np.ascontiguousarray(stripes.transpose(1, 0, 2)))))))
    reshaped = replace(base, nodes=(ball, replace(box, mesh=geometry.sphere())))
    relit = replace(base, lights=(Light((-3.0, 1.0, 2.0), (1.0, 0.9, 0.2)),))
    kept = plan(base)
    for scene in (recolored, retextured, reshaped, relit):
        assert plan(scene) == kept  # the same passes and programs: the one plan object draws them all
    pictures = {}
    for size in (SIZE, (64, 48), SIZE):
        target = gl.target(size, kept.buffers)
        for name, scene in (("base", base), ("recolored", recolored), ("retextured", retextured),
                            ("reshaped", reshaped), ("relit", relit), ("base", base)):
            gl.executor.render(scene, target.framebuffer, size, kept)
            image = target.read().copy()
            renderer = FrameRenderer(gl.host)
            try:
                assert np.array_equal(image, renderer.render_scene(scene, size).image), (name, size)
            finally:
                renderer.close()
            pictures.setdefault((name, size), image)
    for name in ("recolored", "retextured", "reshaped", "relit"):  # each change shows
        assert not np.array_equal(pictures[(name, SIZE)], pictures[("base", SIZE)]), name


def test_a_reflected_and_flattened_node_moved_in_place_is_drawn_where_it_is_now(gl) -> None:
    """The planar passes keep ``R @ model`` and the shadow's product by the model's content: a
    model array changed in place between frames is reflected and flattened where it is now."""
    from dataclasses import replace

    scene = find_lesson("mirror")().scene()
    model = np.array(next(n.model for n in scene.nodes if n.name == "cube"), dtype=np.float64)  # writable
    held = replace(scene, nodes=tuple(replace(n, model=model) if n.name == "cube" else n for n in scene.nodes))
    before = gl.render_scene(held, SIZE).image.copy()
    model[0, 3] += 0.4  # the same array, moved along x
    after = gl.render_scene(held, SIZE).image.copy()
    assert not np.array_equal(before, after)
    copied = replace(held, nodes=tuple(replace(n, model=model.copy()) if n.name == "cube" else n for n in held.nodes))
    assert np.array_equal(after, fresh_frame(gl, copied))  # a new array: nothing kept can stand in for it


def test_the_executor_draws_raster_viewports_only(gl) -> None:
    scene = Scene("ray", nodes=(Node("cube", geometry.cube()),), viewports=(Viewport(renderer="ray_numpy"),))
    target = gl.host.ctx.simple_framebuffer(SIZE)
    try:
        with pytest.raises(ValueError, match="the executor draws raster viewports only"):
            gl.executor.render(scene, target, SIZE)
    finally:
        target.release()

