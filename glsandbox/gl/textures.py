"""GPU textures and samplers: upload once, bind per draw.

Course section "Texture Mapping": the pixel shader reads the texture through
a sampler state (the course's ``g_pSamplerLinear``). Here the image and the
sampler are separate GL objects too: a texture is uploaded once per content
(a built-in image by name, a file by path, size and modification time) and
a sampler object is made once per (filter, wrap); binding both to unit 0
draws the same image with any filter, which is what the lesson compares.

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
        self._samplers: dict[tuple[str, str], moderngl.Sampler] = {}

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
        # Textures are made on first use, within a frame whose earlier draws are still queued.
        # On Mesa's llvmpipe (22.3) a texture uploaded and mipmapped (glGenerateMipmap renders
        # each level) while a frame is in flight is left so that every later bind of it between
        # two draws flushes the frame and waits for the rasterizer: 4-15 ms of wall time and
        # +30-50 us of main-thread CPU per frame, for as long as the texture lives (the
        # texture lesson's cube). Finishing the queued work first (once per upload) leaves it an
        # ordinary texture, with the same pixels.
        self.ctx.finish()
        texture = self.ctx.texture((width, height), 4, np.ascontiguousarray(levels[0]).tobytes())
        # glGenerateMipmap allocates and fills every level (box-filtered halves);
        # hand-drawn levels then overwrite the generated ones.
        texture.build_mipmaps()
        for level, image in enumerate(levels[1:], start=1):
            texture.write(np.ascontiguousarray(image).tobytes(), level=level)
        return texture

    def sampler(self, spec: Texture) -> moderngl.Sampler:
        """The sampler object for ``(spec.filter, spec.wrap)``."""
        key = (spec.filter, spec.wrap)
        sampler = self._samplers.get(key)
        if sampler is None:
            anisotropy = min(ANISOTROPY, float(self.ctx.max_anisotropy)) if spec.filter == "anisotropic" else 1.0
            sampler = self.ctx.sampler(filter=FILTERS[spec.filter], anisotropy=anisotropy)
            # moderngl 5.13 keeps the sampler's GL name in ``_glo`` (no public ``glo``).
            self.host.raw.sampler_wrap(sampler._glo, WRAPS[spec.wrap])
            self._samplers[key] = sampler
        return sampler

    def bind(self, spec: Texture, unit: int = 0) -> None:
        """Bind the texture and its sampler to texture unit ``unit``."""
        texture = self.texture(spec)
        self.sampler(spec).use(unit)
        texture.use(unit)

    def unbind(self, unit: int = 0) -> None:
        """Unbind the sampler object, so later draws see plain texture state."""
        self.ctx.clear_samplers(unit, unit + 1)

    def release(self) -> None:
        for texture in self._textures.values():
            texture.release()
        for sampler in self._samplers.values():
            sampler.release()
        self._textures.clear()
        self._samplers.clear()
