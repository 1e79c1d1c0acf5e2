"""Scenes far from the origin, shared by the precision knobs and their tests.

:func:`moved` translates a whole Scene (nodes, lights, cameras) by an offset,
:func:`placed` scales it first;
:func:`cube_on_floor` is a unit cube resting on a floor, lit from the side,
whose shadow starts at its base (a contact shadow); :func:`contact_shadow`
says which floor pixels a shadow ray darkens.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from glsandbox import geometry, transforms
from glsandbox.scene import Camera, Light, Material, Node, Scene

#: Where a scene is moved: three different components, so no coordinate stays
#: small; the largest stays within the scene API's 1e6 at an offset of 1e6.
DIRECTION = np.array([0.99, 0.7, -0.4])


def moved(scene: Scene, offset: float) -> Scene:
    """``scene`` with every node, light and camera translated by ``offset·DIRECTION``."""
    shift = offset * DIRECTION
    matrix = transforms.translate(*shift)
    nodes = tuple(dataclasses.replace(node, model=matrix @ np.asarray(node.model)) for node in scene.nodes)
    lights = tuple(dataclasses.replace(light, position=tuple(np.asarray(light.position) + shift))
                   for light in scene.lights)

    def cam(camera: Camera | None) -> Camera | None:
        if camera is None:
            return None
        return dataclasses.replace(camera, eye=tuple(np.asarray(camera.eye) + shift),
                                   target=tuple(np.asarray(camera.target) + shift))

    viewports = tuple(dataclasses.replace(vp, camera=cam(vp.camera)) for vp in scene.viewports)
    camera = cam(scene.camera)
    assert camera is not None
    return dataclasses.replace(scene, nodes=nodes, lights=lights, camera=camera, viewports=viewports)


def placed(scene: Scene, offset: float, scale: float = 1.0) -> Scene:
    """``scene`` scaled by ``scale`` about the origin (cameras' near and far too), then
    :func:`moved` by ``offset``: the same picture, wherever and however large."""
    if scale != 1.0:
        grow = transforms.scale(scale, scale, scale)
        nodes = tuple(dataclasses.replace(node, model=grow @ np.asarray(node.model)) for node in scene.nodes)
        lights = tuple(dataclasses.replace(light, position=tuple(scale * np.asarray(light.position)))
                       for light in scene.lights)

        def cam(camera: Camera | None) -> Camera | None:
            if camera is None:
                return None
            return dataclasses.replace(camera, eye=tuple(scale * np.asarray(camera.eye)),
                                       target=tuple(scale * np.asarray(camera.target)),
                                       near=camera.near * scale, far=camera.far * scale)

        viewports = tuple(dataclasses.replace(vp, camera=cam(vp.camera)) for vp in scene.viewports)
        camera = cam(scene.camera)
        assert camera is not None
        scene = dataclasses.replace(scene, nodes=nodes, lights=lights, camera=camera, viewports=viewports)
    return moved(scene, offset) if offset else scene


def cube_on_floor(offset: float = 0.0) -> Scene:
    """A unit cube resting exactly on a 12x12 floor (touching it along its base), a
    light up and to the side: the cube's shadow starts at its base. Moved by ``offset``."""
    lit: dict[str, Any] = dict(shading="phong", ambient=0.1, diffuse=0.9, specular=0.0)
    floor = Node("floor", geometry.plane(12.0), np.eye(4), Material(color=(0.8, 0.8, 0.8, 1.0), **lit))
    cube = Node("cube", geometry.cube(), transforms.translate(0.0, 0.5, 0.0) @ transforms.scale(0.5, 0.5, 0.5),
                Material(color=(0.9, 0.3, 0.2, 1.0), **lit))
    camera = Camera(eye=(1.5, 3.0, 3.5), target=(-1.0, 0.0, -0.5), near=0.01, far=100.0)
    scene = Scene("contact", nodes=(floor, cube), camera=camera, lights=(Light((2.5, 1.8, 1.2)),),
                  clear_color=(0.0, 0.0, 0.0, 1.0))
    return moved(scene, offset) if offset else scene


def contact_shadow(trace: Callable[..., np.ndarray], at: float, size: tuple[int, int],
                   **options: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(floor, shadowed)`` of :func:`cube_on_floor` moved by ``at``: the floor's pixels
    (grey, where the red cube is not), and those of them a shadow ray darkens.
    ``trace(scene, size, **options)`` renders (an engine)."""
    scene = cube_on_floor(at)
    lit = trace(scene, size, shadows=False, max_depth=0, **options)[..., :3].astype(int)
    shaded = trace(scene, size, shadows=True, max_depth=0, **options)[..., :3].astype(int)
    floor = (np.abs(lit[..., 0] - lit[..., 2]) <= 2) & (lit[..., 0] > 0)
    return floor, floor & (np.abs(lit - shaded).max(axis=-1) > 8)


def grown(mask: np.ndarray) -> np.ndarray:
    """``mask`` and its 8 neighbours (a boundary may move by a pixel)."""
    padded = np.pad(mask, 1)
    out = np.zeros_like(mask)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out |= padded[dy:dy + mask.shape[0], dx:dx + mask.shape[1]]
    return out
