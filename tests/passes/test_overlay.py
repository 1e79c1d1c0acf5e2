"""The ``overlay`` pass (glsandbox/passes/overlay.py): one pass per region with overlays, the
viewports' in order and then the frame-wide one; none, and no overlay program, without overlays."""

from __future__ import annotations

import numpy as np

from glsandbox.overlay import Overlay
from glsandbox.passes.overlay import OVERLAY_PROGRAM, describe, overlay_passes
from glsandbox.scene import Scene, Viewport

PIXEL = np.zeros((1, 1, 4), dtype=np.uint8)
TWO = (Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0)))


def test_a_scene_without_overlays_has_no_overlay_pass() -> None:
    assert overlay_passes(Scene("plain")) == []


def test_one_pass_per_region_viewports_first_then_the_whole_frame() -> None:
    scene = Scene("s", viewports=TWO, overlays=(Overlay("title", PIXEL), Overlay("right", PIXEL, viewport=1),
                                                Overlay("left", PIXEL, viewport=0), Overlay("also_right", PIXEL, viewport=1)))
    steps = overlay_passes(scene)
    assert [(s.viewport, [d.node for d in s.draws]) for s in steps] == [
        (0, ["left"]), (1, ["right", "also_right"]), (-1, ["title"])]
    assert all(s.camera is None and not s.depth_test for s in steps)
    assert {d.program for s in steps for d in s.draws} == {OVERLAY_PROGRAM.key}


def test_the_line_names_the_region_and_the_overlays() -> None:
    scene = Scene("s", viewports=TWO, overlays=(Overlay("a", PIXEL, viewport=1), Overlay("b", PIXEL)))
    assert [describe(s) for s in overlay_passes(scene)] == [
        "overlay viewport 1 (blended, no depth test): a", "overlay frame (blended, no depth test): b"]
