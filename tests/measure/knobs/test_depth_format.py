"""The depth-format knob (glsandbox/measure/knobs/depth_format.py): fewer bits and nearer planes
fight more, reverse-Z float does not, and the model agrees with the rasterizer."""

from __future__ import annotations

import numpy as np
from support import knob_counts

from glsandbox.measure.knobs import depth_format
from glsandbox.measure.knobs._far import grown


def test_depth_format_counts_fight_where_the_buffer_cannot_resolve_the_lift() -> None:
    counts = knob_counts(depth_format.KNOB, (96, 72))

    def fights(fmt: str, near: float) -> int:
        return counts[depth_format.label(fmt, near)].pixels

    decal = counts[depth_format.label("24-bit", 0.01)].of
    assert decal > 100 and counts[depth_format.KNOB.reference.label].pixels == 0
    assert fights("16-bit", 0.01) > fights("24-bit", 0.01) > 0.3 * decal  # 16 bits fight more than 24
    assert fights("16-bit", 1.0) > fights("24-bit", 1.0)
    assert fights("24-bit", 0.01) > fights("24-bit", 0.1) >= fights("24-bit", 1.0)  # a nearer plane: worse
    assert fights("16-bit", 0.1) >= fights("16-bit", 1.0) > 0
    assert fights("reverse-Z float", 0.01) == 0  # float32's relative step at every depth
    assert fights("reverse-Z 24-bit", 0.01) > 0.3 * decal  # reverse-Z needs the float buffer
    assert fights("32-bit float", 0.01) > 0.3 * decal  # a float buffer alone does not help either


def test_depth_format_window_depths_and_storage() -> None:
    z = np.array([0.1, 1000.0])
    assert np.allclose(depth_format.window_depth(z, 0.1, reverse=False), [0.0, 1.0])
    assert np.allclose(depth_format.window_depth(z, 0.1, reverse=True), [1.0, 0.0])
    assert depth_format.stored(np.array([0.5 + 2.0**-30]), 16)[0] == 32768.0  # 0.5 * 65535 rounds up
    assert depth_format.stored(np.array([1.0 - 2.0**-30]), 0)[0] == 1.0  # float32 has no room just below 1
    # The model's z-fighting falls where one buffer step outgrows the decal's depth gap (about 0.01 here).
    step_24 = 90.0**2 / (0.01 * 2**24)
    assert step_24 > 0.01 > 90.0**2 / (0.1 * 2**24)


def test_depth_format_model_agrees_with_the_rasterizer(gl) -> None:
    # The two depth modes the rasterizer has, on the model's own scene (the floor drawn, then
    # the decal LIFT above it): it fights exactly where the model says a buffer step outgrows
    # the decal's depth gap (llvmpipe's own float32 interpolation moves the share, not the onset).
    from glsandbox import geometry, transforms
    from glsandbox.measure.zfighting import shade_mask
    from glsandbox.scene import Camera, Material, Node, Scene

    def scene(mode: str, near: float) -> Scene:
        grey = (0.8, 0.8, 0.8, 1.0)
        floor = Node("floor", geometry.plane(2 * depth_format.FLOOR_HALF), np.eye(4), Material(color=grey))
        decal = Node("decal", geometry.plane(2 * depth_format.DECAL_HALF),
                     transforms.translate(0.0, depth_format.LIFT, 0.0), Material(color=(0.4, 0.4, 0.4, 1)))
        up = np.radians(depth_format.ELEVATION)
        eye = depth_format.DISTANCE * np.array([0.0, np.sin(up), np.cos(up)])
        camera = Camera(eye=tuple(eye), target=(0.0, 0.0, 0.0), fov_y=depth_format.FOV, near=near,
                        far=depth_format.FAR)
        return Scene("decal", nodes=(floor, decal), camera=camera, depth_mode=mode, clear_color=(0, 0, 0, 1))

    size = (96, 72)
    shares = {}
    for mode, fmt, near in (("standard", "24-bit", 0.01), ("standard", "24-bit", 0.02), ("standard", "24-bit", 0.05),
                            ("standard", "24-bit", 1.0), ("reverse_z", "reverse-Z float", 0.01)):
        image = gl.render_scene(scene(mode, near), size).image
        decal, lost = (mask.reshape(size[1], size[0]) for mask in depth_format.fighting(size, fmt, near))
        inside = decal & ~grown(~decal)  # the decal's pixels away from its edge
        drawn = shade_mask(image, depth_format.DECAL_GREY)
        assert np.count_nonzero(drawn & ~decal) <= 0.05 * np.count_nonzero(decal), (mode, near)  # same footprint
        gl_lost = inside & shade_mask(image, depth_format.FLOOR_GREY)
        model_share = np.count_nonzero(lost & inside) / np.count_nonzero(inside)
        gl_share = np.count_nonzero(gl_lost) / np.count_nonzero(inside)
        shares[(mode, near)] = gl_share, model_share
        if near != 0.05:  # (see below)
            assert (gl_share > 0.0) == (model_share > 0.0), (mode, near, gl_share, model_share)
    # At near 0.05 the decal's depth gap is one 24-bit step (6e-8): the exact model rounds both
    # surfaces apart, while the rasterizer's float32 clip depths (two model matrices rounded
    # relative to the eye, one per surface) tie on 55% of the decal. The onset moves by one step
    # of near, not more: at 1.0 neither fights.
    assert shares[("standard", 0.05)][1] == 0.0 and shares[("standard", 1.0)] == (0.0, 0.0), shares
    assert min(shares[("standard", 0.01)]) > 0.5 and min(shares[("standard", 0.02)]) > 0.1
