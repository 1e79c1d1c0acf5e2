"""Counting a planar shadow's z-fighting pixels: the flat receiver, its shadow's level, the oracle."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from glsandbox import geometry
from glsandbox.errors import SandboxError
from glsandbox.measure.zfighting import (ORACLE_DROP, RECEIVER_GREY, ZFighting, count_z_fighting, flat_receiver,
                                         shade_mask, shadow_level)
from glsandbox.planar import PlanarShadow
from glsandbox.scene import Node, Scene

SHADOW = PlanarShadow("floor", (0.0, 1.0, 0.0, 0.0), (0.0, 5.0, 0.0, 1.0), ("cube",))
SCENE = Scene("s", nodes=(Node("floor", geometry.cube()), Node("cube", geometry.cube())), planar_shadow=SHADOW)


def test_the_flat_receiver_is_grey_unlit_and_dropped_along_the_planes_normal() -> None:
    dropped = flat_receiver(SCENE, drop=0.25)
    floor, cube = dropped.nodes
    assert floor.material.color == (RECEIVER_GREY,) * 3 + (1.0,) and floor.material.shading == "solid"
    np.testing.assert_allclose(floor.model[:3, 3], (0.0, -0.25, 0.0))
    assert cube is SCENE.nodes[1]  # the casters stay as they are


def test_a_scene_without_a_shadow_or_its_receiver_is_refused() -> None:
    with pytest.raises(SandboxError, match="has no planar shadow"):
        flat_receiver(Scene("bare"))
    with pytest.raises(SandboxError, match="shadow receiver 'floor' is not a node"):
        flat_receiver(Scene("s", nodes=(Node("cube", geometry.cube()),), planar_shadow=SHADOW))


def test_the_shadow_level_is_its_colour_blended_once_over_the_grey() -> None:
    assert shadow_level(SCENE) == 102  # black at alpha 0.5 over 0.8: 0.4 of 255
    mask = shade_mask(np.array([[[101, 102, 103, 0], [102, 102, 104, 255]]], dtype=np.uint8), 102)
    np.testing.assert_array_equal(mask, [[True, False]])


def test_the_count_is_the_oracles_shadow_pixels_the_frame_lost() -> None:
    @dataclass
    class Frame:
        image: np.ndarray

    class Renderer:  # draws the shadow in three pixels of the oracle and two of those in the frame
        def render_scene(self, scene: Scene, size: tuple[int, int]) -> Frame:
            dropped = scene.nodes[0].model[1, 3] == -ORACLE_DROP
            image = np.full((size[1], size[0], 4), 204, dtype=np.uint8)
            image[0, :3 if dropped else 2, :3] = 102
            return Frame(image)

    result = count_z_fighting(Renderer(), SCENE, (4, 2))
    assert result == ZFighting(shadow=3, fighting=1) and result.share == pytest.approx(1 / 3)
