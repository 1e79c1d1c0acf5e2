"""Shadow maps on the GPU (glsandbox/gl/shadow_textures.py): one depth texture per light and size,
kept between frames and sampled with a comparison; a receiver's light matrix taken relative to its
pass's origin in float64 (M @ T(origin)), made once per origin."""

from __future__ import annotations

import struct

import numpy as np

from glsandbox import transforms
from glsandbox.gl.shadow_textures import ShadowMaps
from glsandbox.scene import ShadowMap


def test_a_lights_map_is_one_depth_texture_per_size_compared_and_kept(gl) -> None:
    maps = ShadowMaps(gl.host.ctx, gl.host.raw)
    try:
        texture, framebuffer = maps.target(0, 64)
        assert maps.target(0, 64) == (texture, framebuffer)
        assert maps.target(0, 128)[0] is not texture and maps.target(1, 64)[0] is not texture
        assert texture.size == (64, 64) and texture.compare_func == "<=" and not texture.repeat_x
        assert framebuffer.depth_attachment is texture and framebuffer.color_attachments == ()
        assert set(maps.float_depth) == {(0, 64), (0, 128), (1, 64)}
    finally:
        maps.release()


def test_a_receivers_light_matrix_is_relative_to_its_passs_origin(gl) -> None:
    maps = ShadowMaps(gl.host.ctx, gl.host.raw)
    try:
        texture, _ = maps.target(0, 64)
        matrix = transforms.perspective(90.0, 1.0, 0.5, 50.0) @ transforms.look_at((1e5, 10.0, 0.0), (1e5, 0.0, 0.0),
                                                                                  (0.0, 0.0, -1.0))
        maps.drawn(0, texture, matrix, ShadowMap(size=64), footprint=0.25)
        origin = np.array([1e5, 2.0, 3.0])
        uniforms = dict(maps.use(0, 1, origin))
        relative = np.frombuffer(uniforms["u_shadow_matrix"], dtype="f4").reshape(4, 4).T  # column-major in GL
        assert np.allclose(relative, matrix @ transforms.translate(*origin), rtol=1e-6, atol=1e-6)
        assert uniforms["u_shadow_footprint"] == struct.pack("f", 0.25)
        assert dict(maps.use(0, 1, origin))["u_shadow_matrix"] is uniforms["u_shadow_matrix"]  # made once
        assert dict(maps.use(0, 1))["u_shadow_matrix"] == transforms.gl_bytes(matrix)
    finally:
        maps.release()
