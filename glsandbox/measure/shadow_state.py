"""Lit or shadowed, per pixel: how a shadow technique's picture is scored
against the ray tracer's exact shadow rays on the same Scene.

A pixel is *shadowed* when it is clearly darker than the same scene drawn
with no shadow at all (the light's shadow map and the planar shadow taken
away): a shadow removes the light's diffuse and specular terms, which is more
than :data:`SHADOW_STEP` levels wherever the light reaches a surface at a
useful angle. Two pictures' states are then compared pixel by pixel; along a
shadow's edge the techniques legitimately disagree by a pixel or two (a map's
texels, PCF's soft steps, the planar shadow's polygon edge), so mismatches
are counted inside and outside an :func:`edge_band` of the reference's edges.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from glsandbox.scene import Scene

#: Levels (of 255, largest channel) a pixel must lose to count as shadowed.
SHADOW_STEP = 12


def without_shadows(scene: Scene) -> Scene:
    """``scene`` with neither shadow maps nor a planar shadow."""
    lights = tuple(replace(light, shadow=None) for light in scene.lights)
    return replace(scene, lights=lights, planar_shadow=None)


def shadow_mask(image: np.ndarray, unshadowed: np.ndarray, step: int = SHADOW_STEP) -> np.ndarray:
    """True where ``image`` is darker than ``unshadowed`` by more than ``step`` levels."""
    loss = unshadowed[..., :3].astype(np.int16) - image[..., :3].astype(np.int16)
    return loss.max(axis=-1) > step


def edge_band(mask: np.ndarray, width: int = 2) -> np.ndarray:
    """Pixels within ``width`` pixels (a square neighbourhood) of a change in ``mask``."""
    edges = np.zeros_like(mask)
    edges[:, 1:] |= mask[:, 1:] != mask[:, :-1]
    edges[:, :-1] |= mask[:, 1:] != mask[:, :-1]
    edges[1:, :] |= mask[1:, :] != mask[:-1, :]
    edges[:-1, :] |= mask[1:, :] != mask[:-1, :]
    band = edges.copy()
    for _ in range(width):  # grow by one pixel in each of the 8 directions
        grown = band.copy()
        grown[1:, :] |= band[:-1, :]
        grown[:-1, :] |= band[1:, :]
        grown[:, 1:] |= band[:, :-1]
        grown[:, :-1] |= band[:, 1:]
        grown[1:, 1:] |= band[:-1, :-1]
        grown[:-1, :-1] |= band[1:, 1:]
        grown[1:, :-1] |= band[:-1, 1:]
        grown[:-1, 1:] |= band[1:, :-1]
        band = grown
    return band


@dataclass(frozen=True)
class StateMismatch:
    """Pixels whose lit/shadowed state differs from the reference's."""

    total: int  # every pixel of the picture
    differ: int  # state differs
    off_edge: int  # ... outside the reference's edge band
    reference_shadowed: int

    @property
    def share(self) -> float:
        return self.differ / self.total if self.total else 0.0


def state_mismatch(mask: np.ndarray, reference: np.ndarray, width: int = 2) -> StateMismatch:
    differ = mask != reference
    return StateMismatch(int(mask.size), int(differ.sum()), int((differ & ~edge_band(reference, width)).sum()),
                         int(reference.sum()))
