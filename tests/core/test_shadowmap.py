"""Shadow maps without GL: which light casts, which nodes cast and receive, and the light's camera
(from the light at the casters' centre, near and far around every caster and receiver)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.scene import Light, Material, Node, Scene, ShadowMap, Viewport
from glsandbox.shadowmap import casters, casting_light, light_camera, receivers

LIT = Material(shading="phong")
SUN = Light((0.0, 10.0, 0.0), shadow=ShadowMap())


def scene(*nodes: Node, lights=(SUN,), viewports=None) -> Scene:
    extra = {} if viewports is None else {"viewports": viewports}
    return Scene("s", nodes=nodes, lights=lights, **extra)


def test_at_most_one_light_casts_a_shadow_map() -> None:
    plain = Light((1.0, 1.0, 1.0))
    assert casting_light(scene(lights=(plain,))) is None
    assert casting_light(scene(lights=(plain, SUN))) == 1
    with pytest.raises(SandboxError, match="lights 0, 1 all cast shadow maps"):
        casting_light(scene(lights=(SUN, SUN)))


def test_receivers_are_lit_built_in_raster_nodes_and_casters_those_that_cast() -> None:
    floor = Node("floor", geometry.cube(), material=LIT, casts_shadow=False)
    flat = Node("flat", geometry.cube())  # solid colour: not lit, so it does not look the map up
    own = Node("own", geometry.cube(), material=LIT, shader="my.glsl")  # its own shader: never a receiver
    hidden = Node("hidden", geometry.cube(), material=LIT, viewports=(1,))
    both = scene(floor, flat, own, hidden, viewports=(Viewport(), Viewport(renderer="ray")))
    assert [n.name for n in receivers(both)] == ["floor"]
    assert [n.name for n in casters(both)] == ["flat", "own"]  # hidden: only in the ray-traced viewport


def test_the_light_camera_looks_at_the_casters_and_encloses_every_corner() -> None:
    box = Node("box", geometry.cube(), material=LIT, model=transforms.translate(3.0, 1.0, 0.0))
    floor = Node("floor", geometry.cube(), material=LIT, casts_shadow=False,
                 model=transforms.translate(0.0, -1.0, 0.0) @ transforms.scale(10.0, 0.1, 10.0))
    view, proj = light_camera(scene(box, floor), SUN)
    # The caster's centre (3, 1, 0) lies on the view axis: straight ahead at x = y = 0.
    centre = transforms.transform_points(view, np.array([[3.0, 1.0, 0.0]]))[0]
    np.testing.assert_allclose(centre[:2], (0.0, 0.0), atol=1e-9)
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    for node in (box, floor):
        world = transforms.transform_points(node.model, corners * 2.0)  # the cube spans -1..1
        clip = (proj @ view @ np.c_[world, np.ones(len(world))].T).T
        depth = clip[:, 2] / clip[:, 3]
        assert (depth > -1.0).all() and (depth < 1.0).all(), node.name  # between near and far


def test_a_light_with_no_casters_looks_straight_down() -> None:
    view, _ = light_camera(scene(), SUN)
    below = transforms.transform_points(view, np.array([[0.0, 0.0, 0.0]]))[0]
    np.testing.assert_allclose(below, (0.0, 0.0, -10.0), atol=1e-9)  # the origin, 10 ahead
