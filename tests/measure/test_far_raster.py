"""The rasterizer far from the origin and at small scale (glsandbox/measure/far_raster.py):
a floor, a box, a sphere and a decal 0.002 above the floor, moved together to 0, 1e3, 1e5
and 9e5, and the same scene at 1e-4 of the size placed at 1e3. Against the picture at the
origin: triangle ids move at most on the edges, and the decal is whole. Against the ray
tracer's shadow rays: the shadow map's lit/shadowed state differs only within the edge band."""

from __future__ import annotations

import numpy as np
import pytest
from support import on_backend, renderer_backend, shadow_depth_formats

from glsandbox.measure import far_raster
from glsandbox.measure.far_raster import OFFSETS, SMALL

#: (offset, scale) of each oracle scene, named as the docs' table.
PLACES = [pytest.param(o, 1.0, id=f"at{o:g}") for o in OFFSETS] + [pytest.param(SMALL[1], SMALL[0], id="1e-4at1e3")]
#: The same places as plain (offset, scale) pairs.
PLACE_VALUES = [tuple(p.values) for p in PLACES]
#: Id pixels that may change along the edges (a vertex rounded to a neighbouring pixel centre).
EDGE_PIXELS = 20


def test_the_id_picture_decodes_every_triangle_it_draws(gl) -> None:
    scene = far_raster.oracle_scene()
    ids = far_raster.id_picture(gl, scene, (256, 192))
    triangles = far_raster.node_triangles(scene)
    seen = set(np.unique(ids)) - {-1}
    # The floor, the box, the decal and most of the sphere's facing triangles, nothing else.
    for name in ("floor", "box", "decal", "sphere"):
        assert seen & set(triangles[name]), name
    assert seen <= set(range(sum(len(r) for r in triangles.values())))
    assert np.count_nonzero(ids == -1) < 0.5 * ids.size  # the sky, above the floor's far edge
    assert np.count_nonzero(np.isin(ids, triangles["decal"])) > 500


def test_compare_ids_counts_a_moved_edge_and_a_lost_decal() -> None:
    origin = np.full((20, 20), 1)
    origin[4:16, 4:16] = 7  # the decal
    far = origin.copy()
    far[4:16, 16] = 7  # its right edge one pixel further: on the edges
    far[10, 10] = 1  # the floor wins inside it: off the edges, and a decal pixel lost
    found = far_raster.compare_ids(far, origin, range(7, 8))
    assert (found.moved, found.off_edge, found.decal, found.decal_lost) == (13, 1, 144, 1)


@pytest.fixture(scope="module")
def far(backend, gl_renderer) -> dict:
    """Every place's :class:`~glsandbox.measure.far_raster.IdShift` and
    :class:`~glsandbox.measure.far_raster.ShadowState` on ``backend``, and whether its shadow
    maps held float depth, measured in one go (one subprocess for the other backend)."""
    calls = ([(far_raster.id_shift, place) for place in PLACE_VALUES]
             + [(far_raster.shadow_state, place) for place in PLACE_VALUES] + [(shadow_depth_formats, ()),
                                                                               (renderer_backend, ())])
    *found, on = on_backend(backend, gl_renderer, calls)
    assert on == backend
    n = len(PLACE_VALUES)
    return {"ids": dict(zip(PLACE_VALUES, found[:n])), "shadow": dict(zip(PLACE_VALUES, found[n:2 * n])),
            "float_depth": found[-1], "backend": backend}


@pytest.mark.parametrize("offset, scale", PLACES)
def test_raster_triangle_ids_stay_put_far_from_the_origin(far, offset, scale) -> None:
    found = far["ids"][offset, scale]
    # Measured on EGL and on OSMesa alike: 0 pixels move at every place (transforms formed in
    # float64 relative to the eye); in float32 world transforms 453 at 1e5, 3,202 at 9e5, 7,576
    # for the small scene, and the decal lost 85 of its 1,038 pixels at 9e5 and 163 in the small scene.
    where = f"{far['backend']}, at {offset:g} x{scale:g}: {found}"
    assert found.decal > 500
    assert found.moved <= EDGE_PIXELS and found.off_edge == 0, where
    assert found.decal_lost == 0, where


def test_the_shadow_maps_hold_float_depth_on_each_backend(far) -> None:
    # Mesa's EGL and OSMesa (llvmpipe, OpenGL 4.5 core) both give DEPTH_COMPONENT32F; a
    # context without it would fall back to 24-bit fixed point (glsandbox/gl/shadow_textures.py),
    # and this says so rather than the far-away rows below passing or failing unexplained.
    assert far["float_depth"] == {True}, f"{far['backend']}: 32-bit float shadow depth {far['float_depth']}"


@pytest.mark.parametrize("offset, scale", PLACES)
def test_shadow_map_states_match_the_shadow_rays_far_from_the_origin(far, offset, scale) -> None:
    found = far["shadow"][offset, scale]
    assert found.shadowed > 800  # the box's and the sphere's shadows on the floor
    # Measured on EGL and on OSMesa alike: 58 pixels differ at every place, all within 2 pixels
    # of an edge (PCF's soft steps, the tessellated sphere's outline against the exact one). In
    # float32 world transforms with a world-unit bias: 75 off the edges at 1e5, 23,591 at 9e5
    # (acne), and at 1e-4 scale no shadow at all (465 off the edges).
    assert found.differ <= 100 and found.off_edge == 0, f"{far['backend']}, at {offset:g} x{scale:g}: {found}"
