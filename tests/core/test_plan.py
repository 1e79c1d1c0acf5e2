"""glsandbox.plan: what a scene's plan lists (buffers, programs, passes), pinned for the first
lessons. No GL."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.geometry import Mesh
from glsandbox.lesson import find_lesson
from glsandbox.plan import plan
from glsandbox.scene import Node, Scene

#: `glsandbox plan`'s text for the first three lessons.
PINNED_PLANS = {
    "clear_and_swap": """plan for clear_and_swap
buffers: colour RGBA8, no MSAA
programs:
  (none)
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1)
  2. clear viewport 1: colour (0.6, 0.125, 0, 1)""",
    "triangle": """plan for triangle
buffers: colour RGBA8, no MSAA
programs:
  basic[SOLID_COLOR]
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1)
  2. draw viewport 0 (no depth test): strip with basic[SOLID_COLOR]
  3. clear viewport 1: colour (0, 0.125, 0.6, 1)
  4. draw viewport 1 (no depth test): list with basic[SOLID_COLOR]""",
    "indexed_cube": """plan for indexed_cube
buffers: colour RGBA8, depth 24, no MSAA
programs:
  basic[VERTEX_COLOR]
passes:
  1. clear viewport 0: colour (0, 0.125, 0.6, 1) + depth
  2. draw viewport 0 (depth test): cube with basic[VERTEX_COLOR]""",
}


@pytest.mark.parametrize("name", sorted(PINNED_PLANS))
def test_lesson_plan_is_pinned(name: str) -> None:
    assert plan(find_lesson(name)().scene()).describe() == PINNED_PLANS[name]


def test_single_viewport_split_off_plans_one_clear() -> None:
    scene = find_lesson("clear_and_swap").from_settings(["split=off"]).scene()
    assert [p.kind for p in plan(scene).passes] == ["clear"]


def _svd_flat(points: np.ndarray) -> bool:
    """The rule itself: the smallest singular value of the centred points is at most 1e-9 of the largest."""
    singular = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    return bool(singular[2] <= 1e-9 * singular[0])


@pytest.mark.parametrize("thickness", [0.0, 1e-12, 1e-10, 1e-8, 1e-6, 1e-3, 1.0])
@pytest.mark.parametrize("placed", ["z=0", "tilted", "far"])
def test_one_mesh_gets_a_depth_buffer_exactly_when_it_is_not_flat(thickness: float, placed: str) -> None:
    # A mesh in one plane cannot hide parts of itself: no depth buffer. The plan's short cuts (a
    # coordinate 0.0 everywhere; the 3x3 Gram matrix when clearly not flat) must answer as the SVD does.
    rng = np.random.default_rng(7)
    points = rng.normal(size=(5000, 3)) * [1.0, 2.0, thickness]
    if placed == "tilted":
        points = points @ np.linalg.qr(rng.normal(size=(3, 3)))[0]
    elif placed == "far":
        points = points @ np.linalg.qr(rng.normal(size=(3, 3)))[0] + 1e4
    mesh = Mesh("cloud", points, np.arange(4998, dtype=np.uint32))
    scene = Scene("cloud", nodes=(Node("cloud", mesh),))
    flat = plan(scene).buffers.depth is False
    assert flat == _svd_flat(points)
    if thickness == 0.0 or thickness >= 1e-6:  # clearly flat (in a plane) or clearly not
        assert flat == (thickness == 0.0)
