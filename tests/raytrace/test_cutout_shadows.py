"""A cut-out's shadow, in every shadow technique: a double-sided square whose texture is
transparent on its left half hangs over a floor, lit from up and to the right. Both ray engines
(each path: scan and BVH), the planar shadow and the shadow map darken the floor where
the square's opaque half shadows it, and nowhere else; a blended square and a cut-out
cut away everywhere cast no shadow in any of them (docs/models.md, "Materials: a model as its
file describes it")."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.measure.shadow_state import shadow_mask, state_mismatch, without_shadows
from glsandbox.planar import PlanarShadow
from glsandbox.plan import CUTOUT_SHADOW_PROGRAM, plan
from glsandbox.raytrace.world import camera_rays
from glsandbox.scene import Camera, Light, Material, Node, Scene, ShadowMap, Texture

SIZE = (96, 96)
LIGHT = (6.0, 3.0, 0.0)
HEIGHT = 1.0  # the square's height above the floor


def half_texture(alpha: int = 0) -> Texture:
    """4x4 white texels, the left two columns (u < 0.5) of alpha ``alpha``, the rest opaque."""
    image = np.full((4, 4, 4), 255, dtype=np.uint8)
    image[:, :2, 3] = alpha
    return Texture(source=f"half{alpha}", filter="nearest", image=image)


#: The square's materials: (material, which part of the square casts a shadow: its x range).
CASTERS = {
    "opaque": (Material(color=(1.0, 0.2, 0.2, 1.0)), (-1.0, 1.0)),
    "cut_out": (Material(texture=half_texture(), alpha_mode="mask", alpha_cutoff=0.5), (0.0, 1.0)),
    "blended": (Material(color=(1.0, 0.2, 0.2, 0.5), alpha_mode="blend"), None),
    "transparent_texels": (Material(texture=Texture(source="clear", filter="nearest",
                                                    image=np.zeros((4, 4, 4), dtype=np.uint8)),
                                    alpha_mode="mask"), None),
    "colour_below_cutoff": (Material(color=(1.0, 1.0, 1.0, 0.3), texture=half_texture(), alpha_mode="mask"), None),
}


def scene(material: Material, technique: str = "ray") -> Scene:
    """The floor (lit, receiving) and the 2x2 square 1 above it, double-sided (seen by
    shadow rays, the planar shadow and the shadow map alike), its shadow falling left of
    it, seen from straight above."""
    floor = Node("floor", geometry.plane(12.0), np.eye(4), Material(color=(1.0, 1.0, 1.0, 1.0), shading="phong"))
    square = Node("square", geometry.plane(2.0), transforms.translate(0.0, HEIGHT, 0.0),
                  replace(material, shading="phong", double_sided=True))
    light = Light(LIGHT, shadow=ShadowMap(size=2048) if technique == "map" else None)
    planar = PlanarShadow("floor", (0.0, 1.0, 0.0, 0.0), (*LIGHT, 1.0), ("square",), color=(0.0, 0.0, 0.0, 1.0)) \
        if technique == "planar" else None
    return Scene("cutout", nodes=(floor, square), lights=(light,), planar_shadow=planar,
                 camera=Camera(eye=(-1.5, 10.0, 0.01), target=(-1.5, 0.0, 0.0)))


def on_plane(y: float) -> np.ndarray:
    """Where each pixel's camera ray (pixel centres) meets the plane at height ``y``: ``(H·W, 3)``."""
    eye, d = camera_rays(scene(Material()).camera, *SIZE)
    return eye + ((y - eye[1]) / d[:, 1])[:, None] * d


#: The pixels where the square hides the floor (the comparison leaves them out).
SQUARE = ((np.abs(on_plane(HEIGHT)[:, 0]) < 1.0) & (np.abs(on_plane(HEIGHT)[:, 2]) < 1.0)).reshape(SIZE[::-1])


def expected_shadow(xs: tuple[float, float] | None) -> np.ndarray:
    """The floor pixels in the shadow of the square's part over ``xs``: its corners
    projected from the point light onto the floor (a scaling about the light)."""
    if xs is None:
        return np.zeros(SIZE[::-1], dtype=bool)
    floor = on_plane(0.0)
    grow = LIGHT[1] / (LIGHT[1] - HEIGHT)
    lo, hi = (LIGHT[0] + (x - LIGHT[0]) * grow for x in xs)
    inside = (floor[:, 0] > lo) & (floor[:, 0] < hi) & (np.abs(floor[:, 2]) < grow)
    return inside.reshape(SIZE[::-1]) & ~SQUARE


def check(mask: np.ndarray, xs: tuple[float, float] | None, edge_pixels: int) -> None:
    """``mask`` is the expected shadow but along its edges (``edge_pixels`` at most off them)."""
    expected = expected_shadow(xs)
    mask = mask & ~SQUARE
    found = state_mismatch(mask, expected)
    assert found.off_edge <= edge_pixels, (found, int(mask.sum()), int(expected.sum()))
    # About the expected area: within 10% (a shadow at all where one is expected).
    assert abs(int(mask.sum()) - int(expected.sum())) <= 0.1 * expected.sum() + edge_pixels, \
        (int(mask.sum()), int(expected.sum()))


def test_the_expected_shadows_are_the_opaque_half_of_the_whole_square() -> None:
    whole, half = expected_shadow((-1.0, 1.0)).sum(), expected_shadow((0.0, 1.0)).sum()
    assert whole > 1000 and abs(2 * half - whole) <= 0.05 * whole, (whole, half)
    assert not (expected_shadow((-1.0, 1.0)) & SQUARE).any() and SQUARE.sum() > 300


@pytest.mark.parametrize("caster", CASTERS)
def test_the_ray_engines_shadow_only_where_the_part_is_drawn(engine_path, caster: str) -> None:
    material, xs = CASTERS[caster]
    shadowed = engine_path(scene(material), SIZE)
    lit = engine_path(scene(material), SIZE, shadows=False)
    check(shadow_mask(shadowed, lit), xs, edge_pixels=0)


@pytest.mark.parametrize("technique", ["planar", "map"])
@pytest.mark.parametrize("caster", CASTERS)
def test_the_planar_shadow_and_the_shadow_map_agree_with_the_shadow_rays(gl, technique: str, caster: str) -> None:
    material, xs = CASTERS[caster]
    frame = scene(material, technique)
    shadowed = gl.render_scene(frame, SIZE).image.copy()
    lit = gl.render_scene(without_shadows(frame), SIZE).image.copy()
    # The planar shadow's polygon edge is exact; the map's texels and PCF step along it.
    check(shadow_mask(shadowed, lit), xs, edge_pixels=0 if technique == "planar" else 8)


def test_the_plan_draws_a_cut_out_caster_by_its_texels_and_leaves_blended_and_cut_away_ones_out() -> None:
    for technique, kind in (("planar", "planar_shadow"), ("map", "shadow_map")):
        programs = {}
        for caster, (material, _) in CASTERS.items():
            (step,) = [p for p in plan(scene(material, technique)).passes if p.kind == kind]
            programs[caster] = {d.node: d.program for d in step.draws}.get("square")
        assert programs["cut_out"] == CUTOUT_SHADOW_PROGRAM.key, technique
        assert programs["opaque"] is not None and programs["opaque"] != CUTOUT_SHADOW_PROGRAM.key
        assert programs["blended"] is None and programs["colour_below_cutoff"] is None
        assert programs["transparent_texels"] == CUTOUT_SHADOW_PROGRAM.key  # its texels decide: none drawn


@pytest.mark.parametrize("layout", ["triangle_loop", "general_loops"])
def test_the_gpu_engine_s_other_node_layouts_shadow_by_the_texels_too(gl, monkeypatch, layout: str) -> None:
    """The small scenes above are unrolled one triangle at a time (TRI); here the square is
    a node loop (MESH), then every node is read from the records (the general program)."""
    from glsandbox.raytrace import gpu as gpu_engine
    from glsandbox.raytrace import render

    tracer = gpu_engine.gpu_tracer(gl.host.ctx)
    tracer.forget_scenes()
    monkeypatch.setattr(gpu_engine, "UNROLL_TRIS", 0)
    if layout == "general_loops":
        monkeypatch.setattr(gpu_engine, "UNROLL_NODES", 0)
    try:
        material, xs = CASTERS["cut_out"]
        shadowed = render(scene(material), SIZE, "gpu", ctx=gl.host.ctx)
        lit = render(scene(material), SIZE, "gpu", ctx=gl.host.ctx, shadows=False)
    finally:
        tracer.forget_scenes()
    check(shadow_mask(shadowed, lit), xs, edge_pixels=0)
