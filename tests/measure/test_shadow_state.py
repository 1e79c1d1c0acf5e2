"""Lit or shadowed per pixel: the mask, the band along a shadow's edge, and the mismatch counts."""

from __future__ import annotations

import numpy as np

from glsandbox.measure.shadow_state import (SHADOW_STEP, edge_band, shadow_mask, state_mismatch,
                                            without_shadows)
from glsandbox.planar import PlanarShadow
from glsandbox.scene import Light, Scene, ShadowMap


def test_a_pixel_is_shadowed_when_its_largest_channel_loses_more_than_the_step() -> None:
    lit = np.full((1, 3, 4), 200, dtype=np.uint8)
    image = lit.copy()
    image[0, 1, 2] -= SHADOW_STEP  # exactly the step: not shadowed
    image[0, 2, 0] -= SHADOW_STEP + 1
    image[0, 0, 3] = 0  # alpha is not a colour
    np.testing.assert_array_equal(shadow_mask(image, lit), [[False, False, True]])


def test_the_edge_band_is_the_change_grown_by_its_width_in_every_direction() -> None:
    mask = np.zeros((9, 9), dtype=bool)
    mask[:, 5:] = True  # a vertical edge between columns 4 and 5
    band = edge_band(mask, width=2)
    assert band[:, 2:8].all() and not band[:, :2].any() and not band[:, 8:].any()
    assert not edge_band(np.ones((5, 5), dtype=bool)).any()  # no change, no band


def test_state_mismatch_counts_differences_on_and_off_the_references_edge() -> None:
    reference = np.zeros((10, 10), dtype=bool)
    reference[:, 5:] = True
    mask = reference.copy()
    mask[3, 5] = False  # on the edge: the techniques may disagree there
    mask[3, 0] = True  # far from it
    result = state_mismatch(mask, reference, width=1)
    assert (result.total, result.differ, result.off_edge, result.reference_shadowed) == (100, 2, 1, 50)
    assert result.share == 0.02


def test_without_shadows_takes_the_maps_and_the_planar_shadow_away() -> None:
    scene = Scene("s", lights=(Light((0.0, 5.0, 0.0), shadow=ShadowMap()),),
                  planar_shadow=PlanarShadow("floor", (0.0, 1.0, 0.0, 0.0), (0.0, 5.0, 0.0, 1.0), ("cube",)))
    bare = without_shadows(scene)
    assert bare.planar_shadow is None and all(light.shadow is None for light in bare.lights)
    assert scene.lights[0].shadow is not None  # the scene itself is unchanged
