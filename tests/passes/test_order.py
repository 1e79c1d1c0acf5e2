"""Blended parts are drawn farthest first, by the distance of their box's centre from the eye,
and seen in a mirror, from the eye's mirror image."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.passes.order import distance, farthest_first, mirrored_eye
from glsandbox.planar import Mirror
from glsandbox.scene import Camera, Node


def test_distance_is_from_the_eye_to_the_world_centre_of_the_box() -> None:
    # A unit cube's box is centred at its origin; moved to (0, 0, -5), seen from (0, 0, 3): 8 away.
    node = Node("cube", geometry.cube(), model=transforms.translate(0.0, 0.0, -5.0))
    assert distance(node, Camera(eye=(0.0, 0.0, 3.0))) == pytest.approx(8.0)
    assert distance(node, np.array([3.0, 0.0, -5.0])) == pytest.approx(3.0)  # an eye position works too


def test_distance_uses_the_box_centre_not_the_vertex_average() -> None:
    # Three points at x = 0 and one at x = 4: the average is x = 1, the box's centre x = 2.
    mesh = geometry.Mesh("lopsided", np.array([[0.0, 0, 0], [0, 1, 0], [0, 0, 1], [4, 0, 0]]),
                         np.array([0, 1, 2, 0, 2, 3], dtype=np.uint32))
    assert distance(Node("n", mesh), np.array([2.0, 0.5, 10.5])) == pytest.approx(10.0)


def test_farthest_first_orders_the_pairs_and_keeps_what_rides_along() -> None:
    nodes = [Node(name, geometry.cube(), model=transforms.translate(0.0, 0.0, z)) for name, z in
             (("near", 2.0), ("far", -20.0), ("middle", -5.0))]
    ordered = farthest_first([(n, n.name.upper()) for n in nodes], Camera(eye=(0.0, 0.0, 5.0)))
    assert [extra for _, extra in ordered] == ["FAR", "MIDDLE", "NEAR"]


def test_the_mirrored_eye_is_the_eye_reflected_in_the_mirror_plane() -> None:
    floor = Mirror("floor", (0.0, 1.0, 0.0, 0.0), ("cube",))  # the plane y = 0
    np.testing.assert_allclose(mirrored_eye(floor, Camera(eye=(1.0, 3.0, 10.0))), (1.0, -3.0, 10.0))
