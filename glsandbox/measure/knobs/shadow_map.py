"""Shadow techniques: the planar shadow and shadow maps of four sizes,
with and without percentage-closer filtering, against the ray tracer's exact
shadow rays on the ``shadow_map`` lesson's scene. The error counted in pixels
is the share whose lit/shadowed state differs from the rays'
(:mod:`glsandbox.measure.shadow_state`)."""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from glsandbox.measure.knob import Knob, PixelCount, Setting, lesson_scene, register_knob
from glsandbox.measure.knobs._far import placed
from glsandbox.measure.render_context import RenderContext
from glsandbox.measure.shadow_state import shadow_mask, state_mismatch, without_shadows
from glsandbox.scene import Scene

#: The map sizes measured.
SIZES = (256, 512, 1024, 2048)


def scene(**values: Any) -> Scene:
    return lesson_scene("shadow_map", time=1.0, **values)


#: Per render context: the shadowless frame and the rays' shadow mask (traced once per run).
_REFERENCE: weakref.WeakKeyDictionary[RenderContext, tuple[np.ndarray, np.ndarray]] = weakref.WeakKeyDictionary()


def reference_states(c: RenderContext) -> tuple[np.ndarray, np.ndarray]:
    if c not in _REFERENCE:
        unshadowed = c.raster(without_shadows(scene(show="map")))
        _REFERENCE[c] = unshadowed, shadow_mask(c.ray(scene(show="map"), "numpy"), unshadowed)
    return _REFERENCE[c]


def setting(label: str, note: str = "", at: float = 0.0, scale: float = 1.0, **values: Any) -> Setting:
    """A technique drawn for the picture errors, with its pixels of the wrong state counted;
    ``at`` and ``scale``: the scene placed there (:func:`~glsandbox.measure.knobs._far.placed`),
    its picture and states judged against the ones at the origin (they are the same picture)."""

    def drawn(c: RenderContext) -> np.ndarray:
        return c.raster(placed(scene(**values), at, scale))

    def count(c: RenderContext) -> PixelCount:
        unshadowed, traced = reference_states(c)
        found = state_mismatch(shadow_mask(drawn(c), unshadowed), traced)
        return PixelCount(found.differ, found.total)

    return Setting(label, drawn, note, count)


#: Where the default map is measured besides the origin: (label, offset, scale).
PLACES = (("at 1e5", 1e5, 1.0), ("at 9e5", 9e5, 1.0), ("x1e-4 at 1e3", 1e3, 1e-4))


KNOB = register_knob(Knob(
    name="shadow_map",
    title="Planar shadow and shadow maps vs the ray-traced shadow",
    order=65,
    scene=("shadow_map at time 1.0, one technique alone (show=planar or show=map): a floor, a turning cube, "
           "a sphere over it and a thin panel, one point light"),
    settings=(
        setting("planar shadow (stencil)", "XMMatrixShadow onto the floor only, black at alpha 0.5", show="planar"),
        *(setting(f"shadow map {size}, PCF {pcf}", show="map", size=str(size), pcf=str(pcf))
          for size in SIZES for pcf in (1, 3)),
        *(setting(f"shadow map 1024, PCF 3, {where}", "the scene moved (and scaled) as a whole", at=at, scale=scale,
                  show="map") for where, at, scale in PLACES),
    ),
    reference=Setting("ray tracer, numpy (float64)", lambda c: c.ray(scene(show="map"), "numpy")),
    reference_note=("the float64 numpy ray tracer on the same scene: a shadow ray towards the light from every "
                    "hit, ambient only where it is blocked; one ray per pixel"),
    quick=("planar shadow (stencil)", "shadow map 256, PCF 1", "shadow map 1024, PCF 3",
           "shadow map 1024, PCF 3, at 9e5"),
    monotone=tuple(f"shadow map {size}, PCF 1" for size in SIZES),
    count_label="wrong-state px",
    count_of="px",
    notes=(
        "wrong-state px: pixels lit where the rays find a blocker or shadowed where they do not, each frame "
        "judged against the same scene drawn without any shadow (more than 12 levels darker: shadowed).",
        "The planar shadow falls on the floor plane only (the sphere's shadow on the cube is missing) and "
        "keeps half the light (alpha 0.5), so its FLIP is high even where its state is right.",
        "A map's error shrinks with its size: a texel covers less floor, so its stair-stepped edge lies "
        "nearer the exact one. A point light casts hard shadows, which the rays draw exactly, so PCF's soft "
        "band a few texels wide scores worse against them in both counts and FLIP; it is there for the look "
        "(no stairs, no crawling edges as things move), and costs a 3x3 grid of lookups per pixel.",
        "The bias is the lesson's (2.5 + 2.5 tan θ texels of the map where the receiver is): no acne, no "
        "visible peter-panning (tests/lessons/test_shadow_map.py counts both).",
        "At 1e5, 9e5 and at 1e-4 of the size placed at 1e3 the same settings give the same states as at the "
        "origin: the transforms are formed in float64 relative to the eye (and the light), the light's "
        "frustum is fitted to the scene and the bias is counted in texels.",
    ),
))
