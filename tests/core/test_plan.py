"""glsandbox.plan: what a scene's plan lists (buffers, programs, passes), pinned for the first
lessons. No GL."""

from __future__ import annotations

import pytest

from glsandbox.lesson import find_lesson
from glsandbox.plan import plan

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
