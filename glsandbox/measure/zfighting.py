"""Counting the z-fighting pixels of a planar shadow (course section "XMMatrixShadow,
shadowOffsetY": the shadow lifted against z-fighting).

A planar shadow lies on (or ``lift`` above) its receiver's plane; where the
depth buffer cannot tell the two apart, the receiver wins the depth test in
scattered pixels and the shadow shows holes: z-fighting. To count those
pixels exactly, both the frame and an *oracle* are drawn with the receiver
flat and unlit (one grey level, so a shadowed pixel is one known level):

- the frame: the scene as it is;
- the oracle: the same scene with the receiver moved ``drop`` units below
  its plane. The shadow is projected onto the plane whatever the receiver
  node does, so it then floats far above the receiver and cannot fight,
  and its footprint on screen is unchanged.

Pixels shadowed in the oracle but not in the frame lost the depth test to
the receiver. Used by the mirror lesson's tests and by the depth knob of
``glsandbox tradeoffs``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.scene import Material, Scene

#: The flat receiver's grey (0.8: level 204; the default shadow, black at alpha 0.5, makes it 102).
RECEIVER_GREY = 0.8
#: How far the oracle's receiver is moved below its plane.
ORACLE_DROP = 0.25


@dataclass(frozen=True)
class ZFighting:
    """The shadow's pixels (in the oracle) and how many of them the receiver won."""

    shadow: int
    fighting: int

    @property
    def share(self) -> float:
        """Fighting pixels as a share of the shadow's pixels (0 without a shadow)."""
        return self.fighting / self.shadow if self.shadow else 0.0


def flat_receiver(scene: Scene, drop: float = 0.0, grey: float = RECEIVER_GREY) -> Scene:
    """``scene`` with its shadow's receiver unlit and flat ``grey``, moved ``drop`` below its plane."""
    if scene.planar_shadow is None:
        raise SandboxError(f"scene {scene.name!r} has no planar shadow: nothing can z-fight")
    shadow = scene.planar_shadow
    down = -drop * np.asarray(shadow.plane[:3], dtype=np.float64)  # the plane's normal is unit length
    move = transforms.translate(*(float(c) for c in down))
    nodes = tuple(replace(n, model=move @ n.model, material=Material(color=(grey, grey, grey, 1.0)))
                  if n.name == shadow.receiver else n for n in scene.nodes)
    if not any(n.name == shadow.receiver for n in scene.nodes):
        raise SandboxError(f"shadow receiver {shadow.receiver!r} is not a node of scene {scene.name!r}")
    return replace(scene, nodes=nodes)


def shadow_level(scene: Scene, grey: float = RECEIVER_GREY) -> int:
    """The 8-bit level of a shadowed pixel of the flat receiver: the shadow colour blended once over ``grey``."""
    assert scene.planar_shadow is not None
    r, _, _, alpha = scene.planar_shadow.color
    return int(round(255.0 * (alpha * r + (1.0 - alpha) * grey)))


def shade_mask(image: np.ndarray, level: int, tolerance: int = 1) -> np.ndarray:
    """Pixels of an (H, W, 3 or 4) image whose RGB channels all lie within ``tolerance`` of ``level``."""
    rgb = np.asarray(image)[..., :3].astype(np.int16)
    return np.all(np.abs(rgb - level) <= tolerance, axis=-1)


def count_z_fighting(renderer: Any, scene: Scene, size: tuple[int, int]) -> ZFighting:
    """Render ``scene`` and its oracle with ``renderer`` (a :class:`~glsandbox.frame.HeadlessRenderer`)
    at ``size`` and count the z-fighting pixels of its planar shadow (see the module docstring)."""
    level = shadow_level(scene)
    frame = shade_mask(renderer.render_scene(flat_receiver(scene), size).image, level)
    oracle = shade_mask(renderer.render_scene(flat_receiver(scene, drop=ORACLE_DROP), size).image, level)
    return ZFighting(int(oracle.sum()), int((oracle & ~frame).sum()))
