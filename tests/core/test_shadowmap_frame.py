"""The shadow map's light camera (glsandbox/shadowmap.py): fitted to the casters and
receivers, at most ShadowMap.fov wide, and the same at every scale and place."""

from __future__ import annotations

import math

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.measure.far_raster import oracle_scene
from glsandbox.scene import Camera, Light, Material, Node, Scene, ShadowMap
from glsandbox.shadowmap import LightFrame, light_frame

LIT = Material(shading="phong")


def box_over_floor(box: float, floor: float, fov: float = 90.0, box_receives: bool = True) -> Scene:
    """A box of half-size ``box`` centred 1 above a ``floor``-wide floor (which casts nothing),
    the light 5 above the floor."""
    nodes = (Node("floor", geometry.plane(1.0), transforms.scale(floor, 1.0, floor), LIT, casts_shadow=False),
             Node("box", geometry.cube24(), transforms.translate(0.0, 1.0, 0.0) @ transforms.scale(box, box, box),
                  LIT, receives_shadow=box_receives))
    return Scene("fit", nodes=nodes, camera=Camera(), lights=(Light((0.0, 5.0, 0.0), shadow=ShadowMap(fov=fov)),))


def test_a_small_caster_gets_a_narrow_frustum_and_a_wide_one_the_fov_cap() -> None:
    small = light_frame(box_over_floor(0.2, 8.0), box_over_floor(0.2, 8.0).lights[0])
    # The box's top corners at 3.8 below the light, 0.2 off the axis: tan 0.0526, with the 2%
    # margin, rounded up by at most 1/8 octave (9%).
    tight = 0.2 / 3.8 * 1.02
    assert tight <= small.tan_half <= tight * 2 ** 0.125
    wide = box_over_floor(4.0, 8.0, fov=60.0)
    assert light_frame(wide, wide.lights[0]).tan_half == pytest.approx(math.tan(math.radians(30.0)))


def test_a_small_receiver_narrows_the_frustum_below_its_caster() -> None:
    # A wide box over a small floor, the box receiving nothing: shadows fall on the floor only.
    scene = box_over_floor(3.0, 0.5, box_receives=False)
    frame = light_frame(scene, scene.lights[0])
    tight = 0.25 / 5.0 * 1.02  # the floor's corners at 5 below, 0.25 off the axis
    assert tight <= frame.tan_half <= tight * 2 ** 0.125
    assert frame.footprint(1024) == pytest.approx(2 * frame.tan_half / 1024)


def projected(frame: LightFrame, points: np.ndarray) -> np.ndarray:
    homogeneous = np.c_[points, np.ones(len(points))] @ (frame.proj @ frame.view).T
    return homogeneous[:, :3] / homogeneous[:, 3:]


@pytest.mark.parametrize("offset, scale", [(1e5, 1.0), (9e5, 1.0), (1e3, 1e-4)])
def test_the_light_camera_is_the_same_at_every_place_and_scale(offset, scale) -> None:
    here, there = oracle_scene(), oracle_scene(offset, scale)
    near, far = light_frame(here, here.lights[0]), light_frame(there, there.lights[0])
    assert far.tan_half == pytest.approx(near.tan_half, rel=1e-6)
    # The same corner lands on the same texel and depth (float64 throughout).
    corner = np.array([[0.2, 0.0, 1.6]])
    moved = scale * corner + offset * np.array([0.99, 0.7, -0.4])
    assert np.allclose(projected(far, moved), projected(near, corner), atol=1e-6)
