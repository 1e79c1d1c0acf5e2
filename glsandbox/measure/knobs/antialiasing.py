"""Anti-aliasing (course section "Viewport"/rasterisation: one sample per pixel
centre makes staircase edges): none, MSAA and supersampling, against 8x8
supersampling. The cube at a turn that shows three faces."""

from __future__ import annotations

from glsandbox.measure.knob import Knob, Setting, lesson_scene, register_knob
from glsandbox.measure.render_context import REFERENCE_FACTOR as REF
from glsandbox.scene import Scene


def cube() -> Scene:
    return lesson_scene("indexed_cube", time=0.5)


KNOB = register_knob(Knob(
    name="antialiasing",
    title="Anti-aliasing",
    order=10,
    scene="indexed_cube at time 0.5 (edges of the course cube against the clear colour)",
    settings=(
        Setting("none", lambda c: c.raster(cube())),
        Setting("MSAA 4x", lambda c: c.raster(cube(), samples=4), "4 coverage samples, one shade per pixel"),
        Setting("SSAA 2x", lambda c: c.raster(cube(), factor=2), "render 2x2 larger, box-filter down"),
        Setting("SSAA 3x", lambda c: c.raster(cube(), factor=3)),
        Setting("SSAA 4x", lambda c: c.raster(cube(), factor=4)),
    ),
    reference=Setting(f"SSAA {REF}x", lambda c: c.raster(cube(), factor=REF)),
    reference_note=f"{REF}x{REF} supersampling ({REF * REF} samples per pixel, box filter)",
    quick=("none", "MSAA 4x", "SSAA 2x", "SSAA 4x"),
    monotone=("none", "SSAA 2x", "SSAA 3x", "SSAA 4x"),
))
