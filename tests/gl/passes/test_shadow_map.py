"""The ``shadow_map`` pass's runner (glsandbox/gl/passes/shadow_map.py): it fits its light's frustum
to the scene's nodes, so a frame moved only by time is refused rather than drawn with a stale map."""

from __future__ import annotations

import pytest

from glsandbox import geometry, transforms
from glsandbox.gl.passes import runner
from glsandbox.gl.passes.shadow_map import RUNNER
from glsandbox.gl.shadow_textures import run_shadow_map_pass
from glsandbox.passes.plan_parts import Pass
from glsandbox.plan import plan
from glsandbox.scene import Light, Material, Node, Scene, ShadowMap

SIZE = (32, 32)


def test_the_runner_is_the_registrys_and_not_drawn_at_moved_models() -> None:
    assert runner("shadow_map") is RUNNER and RUNNER.run is run_shadow_map_pass and not RUNNER.moved
    assert RUNNER.state(Pass("shadow_map", -1)) == (frozenset(), frozenset())


def test_a_moved_frame_with_a_shadow_map_is_refused(gl) -> None:
    lit = Material(shading="phong")
    scene = Scene("shadowed", lights=(Light((0.0, 5.0, 0.0), shadow=ShadowMap(size=64)),),
                  nodes=(Node("floor", geometry.plane(3.0), material=lit),
                         Node("cube", geometry.cube(), transforms.translate(0.0, 1.0, 0.0), lit)))
    target = gl.host.ctx.simple_framebuffer(SIZE, samples=0)
    try:
        with pytest.raises(ValueError, match="has a pass that reads where the scene's nodes are"):
            gl.executor.render(scene, target, SIZE, plan(scene), moved=({}, scene.lights))
    finally:
        target.release()
