"""The raw OpenGL calls moderngl does not offer (glsandbox/gl/rawgl.py), on the shared context:
a depth-stencil attachment of the bits asked for, stencil cleared in a rectangle and read back,
buffers read top row first, the state snapshot, and every binding put back."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.gl import rawgl

SIZE = (8, 6)


@pytest.fixture
def target(gl):
    """``(raw, fbo, colour renderbuffer)``: an 8x6 framebuffer with a 24/8 depth-stencil attachment."""
    ctx, raw = gl.host.ctx, gl.host.raw
    colour = ctx.renderbuffer(SIZE)
    fbo, depth = raw.create_depth_framebuffer(colour.glo, SIZE, 0, stencil=True)
    yield raw, fbo, colour
    raw.delete_framebuffer(fbo, depth)
    colour.release()


def _bindings(raw) -> tuple[int, int, int]:
    return (raw.get_integer(rawgl.GL_FRAMEBUFFER_BINDING), raw.get_integer(rawgl.GL_READ_FRAMEBUFFER_BINDING),
            raw.get_integer(rawgl.GL_RENDERBUFFER_BINDING))


@pytest.mark.parametrize("stencil,depth,bits", [(True, True, (24, 8)), (False, True, (24, 0)), (False, False, (0, 0))])
def test_the_depth_attachment_has_the_bits_asked_for(gl, stencil: bool, depth: bool, bits) -> None:
    ctx, raw = gl.host.ctx, gl.host.raw
    colour = ctx.renderbuffer(SIZE)
    before = _bindings(raw)
    fbo, renderbuffer = raw.create_depth_framebuffer(colour.glo, SIZE, 0, stencil=stencil, depth=depth)
    try:
        assert _bindings(raw) == before and fbo > 0 and (renderbuffer > 0) == (depth or stencil)
        assert raw.attachment_bits(fbo) == bits and _bindings(raw) == before
    finally:
        raw.delete_framebuffer(fbo, renderbuffer)
        colour.release()


def test_a_stencil_cleared_in_a_rectangle_reads_back_there(target) -> None:
    raw, fbo, _ = target
    before, mask = raw.bound_framebuffer(), raw.get_integer(rawgl.STATE_INTEGERS["stencil_writemask"])
    raw.glBindFramebuffer(rawgl.GL_FRAMEBUFFER, fbo)
    raw.clear_stencil((0, 0, *SIZE), 0)
    raw.clear_stencil((2, 1, 3, 2), 5)  # x, y (from the bottom), width, height
    raw.glBindFramebuffer(rawgl.GL_FRAMEBUFFER, before)
    raw.glStencilMask(mask)
    assert not raw.glIsEnabled(rawgl.GL_SCISSOR_TEST)
    bottom_first = np.frombuffer(raw.read_stencil(fbo, SIZE), dtype=np.uint8).reshape(SIZE[1], SIZE[0])
    expected = np.zeros((SIZE[1], SIZE[0]), dtype=np.uint8)
    expected[1:3, 2:5] = 5
    assert np.array_equal(bottom_first, expected)
    assert np.array_equal(raw.read_pixels(fbo, SIZE, "stencil"), expected[::-1])  # top row first
    assert raw.bound_framebuffer() == before


def test_colour_reads_top_row_first(gl, target) -> None:
    raw, fbo, colour = target
    ctx = gl.host.ctx
    framebuffer = ctx.framebuffer(color_attachments=[colour])
    framebuffer.clear(0.0, 0.0, 1.0, 1.0)
    framebuffer.clear(1.0, 0.0, 0.0, 1.0, viewport=(0, 0, SIZE[0], 2))  # the two bottom rows red
    pixels = raw.read_pixels(fbo, SIZE, "color")
    assert pixels.shape == (SIZE[1], SIZE[0], 4) and pixels.dtype == np.uint8
    assert (pixels[-2:, :, 0] == 255).all() and (pixels[:-2, :, 2] == 255).all() and (pixels[:-2, :, 0] == 0).all()
    framebuffer.release()


def test_the_state_snapshot_reads_what_was_set(gl) -> None:
    raw = gl.host.raw
    state = raw.state_snapshot()
    assert set(state) == {*rawgl.STATE_INTEGERS, *rawgl.STATE_FLAGS, *rawgl.STATE_FLOATS, "color_writemask"}
    raw.glEnable(rawgl.GL_SCISSOR_TEST)
    try:
        assert raw.state_snapshot()["scissor_test"] is True and state["scissor_test"] is False
    finally:
        raw.glDisable(rawgl.GL_SCISSOR_TEST)
    assert raw.state_snapshot() == state


def test_an_entry_point_the_context_lacks_is_one_line() -> None:
    raw = rawgl.RawGL(lambda name: 0)
    with pytest.raises(SandboxError, match="OpenGL function glEnable is not available from this context"):
        raw.glEnable(rawgl.GL_SCISSOR_TEST)
    with pytest.raises(AttributeError):
        raw.enable  # noqa: B018 (only gl* names are entry points)
