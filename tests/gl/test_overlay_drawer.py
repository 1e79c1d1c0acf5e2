"""The overlays' drawer (glsandbox/gl/overlay_drawer.py): each image lands texel for pixel at its
placement, blended with straight alpha over the frame and clipped to its region; its texture is
kept per overlay name, written again in place when the pixels change at the same size."""

from __future__ import annotations

import numpy as np

from glsandbox.gl.overlay_drawer import OverlayDrawer
from glsandbox.overlay import Overlay
from glsandbox.passes.overlay import OVERLAY_PROGRAM
from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.scene import Scene

SIZE = (16, 8)


def solid(w: int, h: int, rgba) -> np.ndarray:
    return np.tile(np.array(rgba, dtype=np.uint8), (h, w, 1))


def drawn(gl, *overlays: Overlay) -> np.ndarray:
    """The frame (top row first) after one overlay pass of ``overlays`` over black."""
    ctx = gl.host.ctx
    program = gl.executor.program(OVERLAY_PROGRAM)
    target = ctx.simple_framebuffer(SIZE)
    drawer = OverlayDrawer(ctx)
    try:
        target.use()
        target.clear(0.0, 0.0, 0.0, 1.0)
        scene = Scene("labels", overlays=overlays)
        step = Pass("overlay", -1, draws=tuple(Draw(o.name, OVERLAY_PROGRAM.key, False) for o in overlays), camera=None)
        drawer.draw(scene, step, target, SIZE, program)
        pixels = np.frombuffer(target.read(components=4), dtype=np.uint8).reshape(SIZE[1], SIZE[0], 4)
    finally:
        drawer.release()
        target.release()
    return pixels[::-1]


def test_an_image_lands_texel_for_pixel_at_its_placement(gl) -> None:
    image = solid(4, 3, (255, 0, 0, 255))
    image[0, 0] = (0, 255, 0, 255)  # its top-left texel
    frame = drawn(gl, Overlay("box", image, position=(2, 1)))
    assert (frame[1:4, 2:6, :3] == image[..., :3]).all()
    outside = np.ones(frame.shape[:2], bool)
    outside[1:4, 2:6] = False
    assert (frame[outside][:, :3] == 0).all()


def test_a_half_transparent_image_is_blended_over_the_frame(gl) -> None:
    frame = drawn(gl, Overlay("glass", solid(2, 2, (255, 255, 255, 128)), position=(0, 0)))
    assert np.all(np.abs(frame[:2, :2, :3].astype(int) - 128) <= 1)


def test_textures_are_kept_per_name_and_written_again_in_place(gl) -> None:
    drawer = OverlayDrawer(gl.host.ctx)
    try:
        first = solid(3, 2, (10, 20, 30, 255))
        first.setflags(write=False)
        texture = drawer._texture(Overlay("label", first), first)
        assert drawer._texture(Overlay("label", first), first) is texture
        assert drawer._texture(Overlay("label", first.copy()), first.copy()) is texture  # equal pixels
        changed = solid(3, 2, (40, 50, 60, 255))
        assert drawer._texture(Overlay("label", changed), changed) is texture  # the same size: new texels
        assert np.frombuffer(texture.read(), dtype=np.uint8)[:4].tolist() == [40, 50, 60, 255]
        wider = solid(5, 2, (1, 2, 3, 255))
        assert drawer._texture(Overlay("label", wider), wider) is not texture
        assert drawer._texture(Overlay("other", first), first) is not drawer._texture(Overlay("label", wider), wider)
    finally:
        drawer.release()
