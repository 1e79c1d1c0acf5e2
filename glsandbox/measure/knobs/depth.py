"""Depth precision (course section "The stencil Test": ``shadowOffsetY``):
the planar shadow against its floor, near plane, lift, polygon offset and
reverse-Z; the error is the z-fighting pixels of the shadow
(:mod:`glsandbox.measure.zfighting`)."""

from __future__ import annotations

from typing import Any

from glsandbox.measure.knob import Knob, PixelCount, Setting, lesson_scene, register_knob
from glsandbox.measure.render_context import RenderContext
from glsandbox.scene import Scene

#: Where the depth knob looks from: 90 units away through a 5.7° lens (the
#: room fills about the same part of the frame as from 10.5 units at 45°),
#: far plane 200. There a 24-bit buffer cannot resolve the course's 0.005
#: lift (it holds to a distance of about 29); the issue-5 tests pin it.
DEPTH_VIEW: dict[str, Any] = dict(mirror="off", distance=90.0, fov=5.7, far=200.0, time=0.0)


def scene(**values: Any) -> Scene:
    return lesson_scene("mirror", **DEPTH_VIEW, **values)


def setting(label: str, note: str = "", **values: Any) -> Setting:
    """A setting drawn lit for the picture errors, with its z-fighting pixels counted."""

    def count(c: RenderContext) -> PixelCount:
        from glsandbox.measure.zfighting import count_z_fighting

        found = count_z_fighting(c.renderer, scene(**values), c.size)
        return PixelCount(found.fighting, found.shadow)

    return Setting(label, lambda c: c.raster(scene(**values)), note, count)


KNOB = register_knob(Knob(
    name="depth",
    title="Depth precision",
    order=50,
    scene=("mirror (no mirror, time 0) seen from 90 units away (fov 5.7, near 0.01, far 200): the cube's "
           "planar shadow on the floor"),
    settings=(
        setting("standard 24-bit, lift 0.005, no offset", "the course's shadowOffsetY alone",
                depth="standard", offset=False),
        setting("standard 24-bit, lift 0, no offset", depth="standard", offset=False, lift=0.0),
        setting("standard 24-bit, lift 0.005, near 0.1", "a 10x nearer plane: 10x the depth slope",
                depth="standard", offset=False, near=0.1),
        setting("standard 24-bit, lift 0.005, polygon offset", depth="standard", offset=True),
        setting("reverse-Z float, lift 0, no offset", depth="reverse_z", offset=False, lift=0.0),
        setting("reverse-Z float, lift 0.005, no offset", depth="reverse_z", offset=False),
    ),
    reference=setting("default: reverse-Z float, lift 0.005, polygon offset", depth="reverse_z", offset=True),
    reference_note=("the lesson's default, reverse-Z (32-bit float depth, glClipControl 0..1) with polygon "
                    "offset and the course's 0.005 lift, which has no z-fighting pixel at any distance "
                    "(tests/lessons/test_mirror.py)"),
    count_label="z-fighting px",
    count_of="shadow px",
    notes=(
        "z-fighting px: shadow pixels the floor wins in the depth test (glsandbox.measure.zfighting: the frame "
        "drawn with a flat unlit floor against an oracle whose floor is lowered 0.25, where the shadow "
        "cannot fight). RMSE, PSNR and FLIP compare the lit frame with the reference's lit frame.",
        "Depth d = A + B/z has slope near/z²: with near 0.01 a 24-bit buffer (step 2^-24) cannot tell "
        "0.005 apart beyond about z = 29, so the course's lift alone fights here and holds in the room "
        "(distance 10.5); no lift fights everywhere, whatever the buffer.",
        "Each remedy alone holds: a 10x nearer plane, reverse-Z's float buffer, or polygon offset.",
    ),
))
