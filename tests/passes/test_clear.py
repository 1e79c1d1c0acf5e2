"""The ``clear`` pass (glsandbox/passes/clear.py): a viewport's own clear colour, else the scene's,
and depth and stencil only where the frame has them; the line ``glsandbox plan`` prints for it."""

from __future__ import annotations

from glsandbox.passes.clear import clear_pass, describe
from glsandbox.scene import Scene, Viewport

TWO = Scene("two", clear_color=(0.1, 0.2, 0.3, 1.0),
            viewports=(Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0), clear_color=(1.0, 0.0, 0.0, 1.0))))


def test_a_viewport_clears_to_its_own_colour_else_the_scenes() -> None:
    assert clear_pass(TWO, 0, True, False).clear_color == (0.1, 0.2, 0.3, 1.0)
    assert clear_pass(TWO, 1, True, False).clear_color == (1.0, 0.0, 0.0, 1.0)


def test_depth_and_stencil_are_cleared_only_when_asked_and_the_pass_has_no_camera() -> None:
    step = clear_pass(TWO, 1, False, True)
    assert (step.kind, step.viewport, step.clear_depth, step.clear_stencil, step.camera) == ("clear", 1, False, True, None)
    assert step.draws == ()


def test_the_line_names_the_viewport_and_what_is_cleared() -> None:
    assert describe(clear_pass(TWO, 0, True, True)) == "clear viewport 0: colour (0.1, 0.2, 0.3, 1) + depth + stencil"
    assert describe(clear_pass(TWO, 1, False, False)) == "clear viewport 1: colour (1, 0, 0, 1)"
