"""GPU textures and samplers: upload once, bind per draw.

Course section "Texture Mapping": the pixel shader reads the texture through
a sampler state (the course's ``g_pSamplerLinear``). A texture is uploaded once
per content (a built-in image by name, a file by path, size and modification
time); the filter and wrap a draw asks for are set on the texture itself, only
when they differ from the ones it holds, so the same image is drawn with any
filter, which is what the lesson compares. (Sampler objects would say the same,
but on llvmpipe a draw that changes texture under a bound sampler object costs
about 30 us more of the main thread: issue 24.)

Rows are uploaded top row first, so texture coordinate t = 0 is the top of
the picture: the course's DirectX uv, with v growing downwards, works as is.
"""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.files import check_inside_sandbox
from glsandbox.gl.context import GLHost
from glsandbox.images import texture_levels
from glsandbox.scene import Texture

#: (min filter, mag filter) per :data:`glsandbox.scene.TEXTURE_FILTERS` name.
#: "mip_nearest" is bilinear within the nearest mip level
#: (``GL_LINEAR_MIPMAP_NEAREST``); "mip_linear" blends the two nearest levels
#: too (trilinear); "anisotropic" is trilinear with up to 16 samples along
#: the footprint's long axis. Magnification never uses mip levels.
FILTERS: dict[str, tuple[int, int]] = {
    "nearest": (moderngl.NEAREST, moderngl.NEAREST),
    "linear": (moderngl.LINEAR, moderngl.LINEAR),
    "mip_nearest": (moderngl.LINEAR_MIPMAP_NEAREST, moderngl.LINEAR),
    "mip_linear": (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR),
    "anisotropic": (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR),
}
#: GL wrap modes per :data:`glsandbox.scene.TEXTURE_WRAPS` name.
WRAPS: dict[str, int] = {"repeat": 0x2901, "mirrored": 0x8370, "clamp": 0x812F}
#: The anisotropy "anisotropic" asks for (clamped to what the context allows).
ANISOTROPY = 16.0


class TextureCache:
    """Textures and samplers of one context, made on first use."""

    def __init__(self, host: GLHost) -> None:
        self.host = host
        self.ctx = host.ctx
        self._textures: dict[tuple, moderngl.Texture] = {}
        self._sampling: dict[int, tuple[str, str]] = {}  # (filter, wrap) each texture holds, by its GL name

    @property
    def max_size(self) -> int:
        """The largest texture side this context accepts."""
        return int(self.ctx.info["GL_MAX_TEXTURE_SIZE"])

    def _key(self, spec: Texture) -> tuple:
        if spec.image is not None:
            return ("image", spec.digest)
        if not spec.is_file:
            return ("builtin", spec.source)
        path = Path(spec.source)
        check_inside_sandbox(path, "texture file")  # while grading: the submission's own files only
        try:
            stat = path.stat()
        except FileNotFoundError:
            raise SandboxError(f"texture file {path} not found") from None
        except OSError as exc:
            raise SandboxError(f"texture file {path} is not readable ({exc.strerror})") from None
        # A changed file (new size or time) is uploaded again.
        return ("file", str(path.resolve()), stat.st_size, stat.st_mtime_ns)

    def texture(self, spec: Texture) -> moderngl.Texture:
        """The GL texture for ``spec.source``, with its full mip chain."""
        key = self._key(spec)
        texture = self._textures.get(key)
        if texture is None:
            texture = self._upload(texture_levels(spec, self.max_size), spec.source)
            self._textures[key] = texture
        return texture

    def _upload(self, levels: list[np.ndarray], name: str) -> moderngl.Texture:
        height, width = levels[0].shape[:2]
        if max(width, height) > self.max_size:
            raise SandboxError(f"texture {name} is {width}x{height}, larger than this context allows "
                               f"({self.max_size}x{self.max_size})")
        texture = self.ctx.texture((width, height), 4, np.ascontiguousarray(levels[0]).tobytes())
        # glGenerateMipmap allocates and fills every level (box-filtered halves);
        # hand-drawn levels then overwrite the generated ones.
        texture.build_mipmaps()
        for level, image in enumerate(levels[1:], start=1):
            texture.write(np.ascontiguousarray(image).tobytes(), level=level)
        return texture

    def bind(self, spec: Texture, unit: int = 0) -> None:
        """Bind the texture to texture unit ``unit``, sampled with ``spec``'s filter and wrap."""
        texture = self.texture(spec)
        texture.use(unit)  # the active unit is ``unit`` now: glTexParameteri sets this texture's
        sampling = (spec.filter, spec.wrap)
        if self._sampling.get(texture.glo) != sampling:
            texture.filter = FILTERS[spec.filter]
            texture.anisotropy = min(ANISOTROPY, float(self.ctx.max_anisotropy)) \
                if spec.filter == "anisotropic" else 1.0
            texture.use(unit)  # moderngl set those on its own scratch unit
            self.host.raw.texture_wrap(WRAPS[spec.wrap])
            self._sampling[texture.glo] = sampling

    def release(self) -> None:
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()
        self._sampling.clear()
