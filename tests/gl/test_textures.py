"""Textures and samplers of one context (glsandbox/gl/textures.py): a texture uploaded once per
source with its full mip chain, again when its file changes; a missing file or one larger than the
context allows refused naming it; one sampler per filter and wrap (course section "Texturing")."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.files import save_png
from glsandbox.gl.textures import TextureCache
from glsandbox.scene import Texture


def png(path: Path, size: int, value: int) -> Path:
    save_png(np.full((size, size, 4), value, dtype=np.uint8), path)
    return path


def test_a_source_is_uploaded_once_with_every_mip_level(gl) -> None:
    cache = TextureCache(gl.host)
    try:
        texture = cache.texture(Texture("checker"))
        assert cache.texture(Texture("checker", filter="nearest")) is texture  # filter and wrap are the sampler's
        width, height = texture.size
        assert len(texture.read(level=1)) == (width // 2) * (height // 2) * 4
        assert cache.texture(Texture("labels")) is not texture
    finally:
        cache.release()


def test_a_changed_file_is_uploaded_again_and_a_missing_one_is_refused(gl, tmp_path: Path) -> None:
    cache = TextureCache(gl.host)
    try:
        path = png(tmp_path / "wood.png", 8, 100)
        first = cache.texture(Texture(str(path)))
        assert cache.texture(Texture(str(path))) is first
        png(path, 16, 200)
        os.utime(path, ns=(os.stat(path).st_atime_ns, os.stat(path).st_mtime_ns + 1_000_000))
        again = cache.texture(Texture(str(path)))
        assert again is not first and again.size == (16, 16)
        with pytest.raises(SandboxError, match=r"texture file .*gone\.png not found"):
            cache.texture(Texture(str(tmp_path / "gone.png")))
    finally:
        cache.release()


def test_a_texture_larger_than_the_context_allows_is_refused_naming_it(gl) -> None:
    class Small(TextureCache):
        max_size = 4

    cache = Small(gl.host)
    try:
        with pytest.raises(SandboxError, match="texture big.png is 8x8, larger than this context allows \\(4x4\\)"):
            cache._upload([np.zeros((8, 8, 4), np.uint8)], "big.png")
    finally:
        cache.release()


def test_one_sampler_per_filter_and_wrap(gl) -> None:
    cache = TextureCache(gl.host)
    try:
        linear = cache.sampler(Texture("checker", filter="linear"))
        assert cache.sampler(Texture("labels", filter="linear")) is linear
        assert cache.sampler(Texture("checker", filter="linear", wrap="clamp")) is not linear
        assert cache.sampler(Texture("checker", filter="nearest")) is not linear
    finally:
        cache.release()
