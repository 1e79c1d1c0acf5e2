"""The ``shadow_map`` pass's runner (glsandbox/gl/passes/shadow_map.py): it fits its light's frustum
to the casters at the frame's models, so a frame moved only by time is drawn from the models handed over."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from glsandbox import geometry, transforms
from glsandbox.gl.passes import runner
from glsandbox.gl.passes.shadow_map import RUNNER
from glsandbox.gl.shadow_textures import run_shadow_map_pass
from glsandbox.passes.plan_parts import Pass
from glsandbox.plan import plan
from glsandbox.scene import Light, Material, Node, Scene, ShadowMap

SIZE = (32, 32)


def test_the_runner_is_the_registrys_and_drawn_at_moved_models() -> None:
    assert runner("shadow_map") is RUNNER and RUNNER.run is run_shadow_map_pass and RUNNER.moved
    assert RUNNER.state(Pass("shadow_map", -1)) == (frozenset(), frozenset())


def test_a_moved_frame_with_a_shadow_map_is_the_moved_scenes(gl) -> None:
    """The cube handed over raised by 1.5 casts the shadow the scene with it raised there casts
    (the light's frustum fitted to it where it is moved, not where the scene has it)."""
    lit = Material(shading="phong")
    scene = Scene("shadowed", lights=(Light((0.0, 5.0, 0.0), shadow=ShadowMap(size=64)),),
                  nodes=(Node("floor", geometry.plane(3.0), material=lit),
                         Node("cube", geometry.cube(), transforms.translate(0.0, 1.0, 0.0), lit)))
    raised = transforms.translate(0.3, 2.5, 0.0)
    moved = replace(scene, nodes=(scene.nodes[0], replace(scene.nodes[1], model=raised)))
    target = gl.host.ctx.simple_framebuffer(SIZE, samples=0)
    try:
        images = []
        for drawn, handed in ((scene, ({"cube": raised}, scene.lights)), (moved, None)):
            target.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
            gl.executor.render(drawn, target, SIZE, plan(moved), moved=handed)
            images.append(np.frombuffer(target.read(components=4), np.uint8).copy())
        assert np.array_equal(*images)
        target.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        gl.executor.render(scene, target, SIZE, plan(scene))
        assert not np.array_equal(np.frombuffer(target.read(components=4), np.uint8), images[0])
    finally:
        target.release()
