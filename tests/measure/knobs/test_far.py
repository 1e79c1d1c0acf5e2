"""The precision knobs' shared scenes (glsandbox/measure/knobs/_far.py): a scene moved and scaled
far from the origin keeps its picture's geometry, the cube's contact shadow starts at its base,
and a mask grows by one pixel each way."""

from __future__ import annotations

import numpy as np

from glsandbox.measure.knobs._far import DIRECTION, contact_shadow, cube_on_floor, grown, moved, placed
from glsandbox.raytrace.render import render


def _points(scene) -> np.ndarray:
    """Every node's origin, every light, the eye and the target: what moving must shift."""
    return np.array([np.asarray(n.model)[:3, 3] for n in scene.nodes] + [light.position for light in scene.lights]
                    + [scene.camera.eye, scene.camera.target], dtype=float)


def test_moved_shifts_nodes_lights_and_cameras_by_the_same_offset() -> None:
    scene = cube_on_floor()
    far = moved(scene, 1e5)
    assert np.allclose(_points(far) - _points(scene), 1e5 * DIRECTION, rtol=0, atol=1e-9)
    assert np.abs(1e6 * DIRECTION).max() <= 1e6  # the scene API's limit holds at an offset of 1e6
    assert np.array_equal(_points(cube_on_floor(1e3)), _points(moved(scene, 1e3)))


def test_placed_scales_about_the_origin_then_moves() -> None:
    scene = cube_on_floor()
    small = placed(scene, 1e3, scale=1e-4)
    assert np.allclose(_points(small), 1e-4 * _points(scene) + 1e3 * DIRECTION, rtol=1e-12, atol=1e-9)
    assert small.camera.near == scene.camera.near * 1e-4 and small.camera.far == scene.camera.far * 1e-4
    assert placed(scene, 0.0) is scene


def test_the_contact_shadow_is_on_the_floor_and_the_same_far_away() -> None:
    size = (48, 36)
    trace = lambda s, sz, **o: render(s, sz, "numpy", **o)  # noqa: E731
    floor, shadow = contact_shadow(trace, 0.0, size)
    assert floor.sum() > 0.3 * floor.size and shadow.sum() > 20 and not (shadow & ~floor).any()
    far_floor, far_shadow = contact_shadow(trace, 1e3, size)  # float64 holds the picture at 1e3
    assert np.count_nonzero(far_shadow != shadow) <= 2 and np.count_nonzero(far_floor != floor) <= 4


def test_grown_adds_the_eight_neighbours() -> None:
    mask = np.zeros((5, 6), dtype=bool)
    mask[2, 3] = True
    expected = np.zeros_like(mask)
    expected[1:4, 2:5] = True
    assert np.array_equal(grown(mask), expected)
    corner = np.zeros((3, 3), dtype=bool)
    corner[0, 0] = True
    assert grown(corner).sum() == 4  # the edges clip the neighbourhood
