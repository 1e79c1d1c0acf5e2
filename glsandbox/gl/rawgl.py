"""The few raw OpenGL calls moderngl 5.13 does not offer, in one small module.

moderngl has no stencil API and its renderbuffers are depth-only, so the
depth-stencil attachment of offscreen targets and all stencil state are set
here, through the context's own function loader (EGL's, OSMesa's or glfw's)
and ctypes. Every function restores the bindings it changed.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable

import numpy as np

from glsandbox.errors import SandboxError

GL_FRAMEBUFFER = 0x8D40
GL_RENDERBUFFER = 0x8D41
GL_FRAMEBUFFER_BINDING = 0x8CA6  # also the draw framebuffer's binding
GL_READ_FRAMEBUFFER = 0x8CA8
GL_DRAW_FRAMEBUFFER = 0x8CA9
GL_READ_FRAMEBUFFER_BINDING = 0x8CAA
GL_COLOR_BUFFER_BIT = 0x4000
GL_NEAREST = 0x2600
GL_RENDERBUFFER_BINDING = 0x8CA7
GL_COLOR_ATTACHMENT0 = 0x8CE0
GL_DEPTH_ATTACHMENT = 0x8D00
GL_STENCIL_ATTACHMENT = 0x8D20
GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE = 0x8CD0
GL_NONE = 0
GL_DEPTH_STENCIL_ATTACHMENT = 0x821A
GL_FRAMEBUFFER_COMPLETE = 0x8CD5
GL_DEPTH_COMPONENT24 = 0x81A6
GL_DEPTH24_STENCIL8 = 0x88F0
GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE = 0x8216
GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE = 0x8217
GL_DITHER = 0x0BD0
GL_STENCIL_TEST = 0x0B90
GL_TEXTURE_WRAP_S = 0x2802
GL_TEXTURE_WRAP_T = 0x2803
# Stencil, depth and clip state (the mirror and shadow passes, glsandbox.gl.planar_state; reverse-Z, glsandbox.gl.depth).
GL_DEPTH_COMPONENT32F = 0x8CAC
GL_DEPTH32F_STENCIL8 = 0x8CAD
GL_NEVER, GL_LESS, GL_EQUAL, GL_LEQUAL, GL_GREATER, GL_NOTEQUAL, GL_GEQUAL, GL_ALWAYS = range(0x0200, 0x0208)
GL_KEEP = 0x1E00
GL_REPLACE = 0x1E01
GL_INCR = 0x1E02
GL_ZERO = 0
GL_INVERT = 0x150A
GL_STENCIL_BUFFER_BIT = 0x0400
GL_PACK_ALIGNMENT = 0x0D05
#: :meth:`RawGL.read_pixels`'s buffers: (GL format, GL type, numpy dtype, components a pixel).
PIXEL_READS = {
    "color": (0x1908, 0x1401, np.uint8, 4),  # GL_RGBA, GL_UNSIGNED_BYTE
    "depth": (0x1902, 0x1406, np.float32, 1),  # GL_DEPTH_COMPONENT, GL_FLOAT
    "stencil": (0x1901, 0x1401, np.uint8, 1),  # GL_STENCIL_INDEX, GL_UNSIGNED_BYTE
    "ids": (0x8228, 0x1405, np.uint32, 2),  # GL_RG_INTEGER, GL_UNSIGNED_INT (colour attachment 1)
}
GL_SCISSOR_TEST = 0x0C11
GL_LOWER_LEFT = 0x8CA1
GL_NEGATIVE_ONE_TO_ONE = 0x935E
GL_ZERO_TO_ONE = 0x935F
# Queries for the state snapshot (tests check every pass leaves it as found).
STATE_INTEGERS = {
    "stencil_func": 0x0B92, "stencil_value_mask": 0x0B93, "stencil_fail": 0x0B94,
    "stencil_pass_depth_fail": 0x0B95, "stencil_pass_depth_pass": 0x0B96, "stencil_ref": 0x0B97,
    "stencil_writemask": 0x0B98, "depth_func": 0x0B74, "depth_writemask": 0x0B72, "front_face": 0x0B46,
    "cull_face_mode": 0x0B45, "clip_origin": 0x935C, "clip_depth_mode": 0x935D,
    "blend_src_rgb": 0x80C9, "blend_dst_rgb": 0x80C8,
}
STATE_FLAGS = {"stencil_test": GL_STENCIL_TEST, "depth_test": 0x0B71, "cull_face": 0x0B44, "blend": 0x0BE2,
               "polygon_offset_fill": 0x8037, "scissor_test": GL_SCISSOR_TEST}
STATE_FLOATS = {"polygon_offset_factor": 0x8038, "polygon_offset_units": 0x2A00, "depth_clear_value": 0x0B73}
GL_COLOR_WRITEMASK = 0x0C23
GL_TEXTURE0 = 0x84C0
GL_ACTIVE_TEXTURE = 0x84E0
GL_SAMPLER_BINDING = 0x8919

_VOID = None
_UINT = ctypes.c_uint
_INT = ctypes.c_int
_SIGNATURES: dict[str, tuple] = {
    "glGenFramebuffers": (_VOID, _INT, ctypes.POINTER(_UINT)),
    "glDeleteFramebuffers": (_VOID, _INT, ctypes.POINTER(_UINT)),
    "glBindFramebuffer": (_VOID, _UINT, _UINT),
    "glCheckFramebufferStatus": (_UINT, _UINT),
    "glFramebufferRenderbuffer": (_VOID, _UINT, _UINT, _UINT, _UINT),
    "glGetFramebufferAttachmentParameteriv": (_VOID, _UINT, _UINT, _UINT, ctypes.POINTER(_INT)),
    "glGenRenderbuffers": (_VOID, _INT, ctypes.POINTER(_UINT)),
    "glDeleteRenderbuffers": (_VOID, _INT, ctypes.POINTER(_UINT)),
    "glBindRenderbuffer": (_VOID, _UINT, _UINT),
    "glRenderbufferStorageMultisample": (_VOID, _UINT, _INT, _UINT, _INT, _INT),
    "glGetIntegerv": (_VOID, _UINT, ctypes.POINTER(_INT)),
    "glEnable": (_VOID, _UINT),
    "glDisable": (_VOID, _UINT),
    "glIsEnabled": (ctypes.c_ubyte, _UINT),
    "glStencilFunc": (_VOID, _UINT, _INT, _UINT),
    "glStencilOp": (_VOID, _UINT, _UINT, _UINT),
    "glStencilMask": (_VOID, _UINT),
    "glClearStencil": (_VOID, _INT),
    "glClear": (_VOID, _UINT),
    "glSamplerParameteri": (_VOID, _UINT, _UINT, _INT),
    "glActiveTexture": (_VOID, _UINT),
    "glColorMask": (_VOID, ctypes.c_ubyte, ctypes.c_ubyte, ctypes.c_ubyte, ctypes.c_ubyte),
    "glDepthMask": (_VOID, ctypes.c_ubyte),
    "glClipControl": (_VOID, _UINT, _UINT),
    "glClearDepth": (_VOID, ctypes.c_double),
    "glScissor": (_VOID, _INT, _INT, _INT, _INT),
    "glGetFloatv": (_VOID, _UINT, ctypes.POINTER(ctypes.c_float)),
    "glReadPixels": (_VOID, _INT, _INT, _INT, _INT, _UINT, _UINT, ctypes.c_void_p),
    "glPixelStorei": (_VOID, _UINT, _INT),
    "glClearBufferuiv": (_VOID, _UINT, _INT, ctypes.c_void_p),
    "glReadBuffer": (_VOID, _UINT),
    "glBlitFramebuffer": (_VOID, _INT, _INT, _INT, _INT, _INT, _INT, _INT, _INT, _UINT, _UINT),
    "glBindTexture": (_VOID, _UINT, _UINT),
    "glTexImage2D": (_VOID, _UINT, _INT, _INT, _INT, _INT, _INT, _UINT, _UINT, ctypes.c_void_p),
    "glGetTexLevelParameteriv": (_VOID, _UINT, _INT, _UINT, ctypes.POINTER(_INT)),
    "glGetError": (_UINT,),
}
GL_TEXTURE_2D = 0x0DE1
GL_TEXTURE_BINDING_2D = 0x8069
GL_DEPTH_COMPONENT = 0x1902
GL_FLOAT = 0x1406
GL_TEXTURE_DEPTH_SIZE = 0x884A
GL_TEXTURE_DEPTH_TYPE = 0x8C16


class RawGL:
    """Typed ctypes entry points, loaded on first use from ``get_proc``."""

    def __init__(self, get_proc: Callable[[str], int]) -> None:
        self._get_proc = get_proc
        self._fns: dict[str, Callable] = {}

    def __getattr__(self, name: str) -> Callable:
        if not name.startswith("gl"):
            raise AttributeError(name)
        fn = self._fns.get(name)
        if fn is None:
            address = self._get_proc(name)
            if not address:
                raise SandboxError(f"OpenGL function {name} is not available from this context")
            restype, *argtypes = _SIGNATURES[name]
            fn = ctypes.CFUNCTYPE(restype, *argtypes)(address)
            self._fns[name] = fn
        setattr(self, name, fn)  # found as a plain attribute from now on: __getattr__ runs once per name
        return fn

    def get_integer(self, pname: int) -> int:
        value = _INT(0)
        self.glGetIntegerv(pname, ctypes.byref(value))
        return value.value

    def float_depth_texture(self, texture: int, size: tuple[int, int]) -> bool:
        """Give the 2D texture ``texture`` (moderngl's ``glo``) ``DEPTH_COMPONENT32F`` storage of
        ``size``, in place of moderngl's 24-bit fixed point; False (its storage as it was) where
        the context refuses. Restores the binding of the active texture unit."""
        bound = self.get_integer(GL_TEXTURE_BINDING_2D)
        while self.glGetError():  # errors left by others are not this call's
            pass
        self.glBindTexture(GL_TEXTURE_2D, texture)
        self.glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, size[0], size[1], 0, GL_DEPTH_COMPONENT,
                          GL_FLOAT, None)
        ok = self.glGetError() == 0
        self.glBindTexture(GL_TEXTURE_2D, bound)
        return ok

    def texture_depth_bits(self, texture: int) -> tuple[int, bool]:
        """``(bits, is_float)`` of the 2D depth texture ``texture``'s level 0."""
        bound = self.get_integer(GL_TEXTURE_BINDING_2D)
        self.glBindTexture(GL_TEXTURE_2D, texture)
        bits, kind = _INT(0), _INT(0)
        self.glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_DEPTH_SIZE, ctypes.byref(bits))
        self.glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_DEPTH_TYPE, ctypes.byref(kind))
        self.glBindTexture(GL_TEXTURE_2D, bound)
        return bits.value, kind.value == GL_FLOAT

    def disable_dither(self) -> None:
        """Dithering is on by default in OpenGL; golden images want it off."""
        self.glDisable(GL_DITHER)

    def create_depth_framebuffer(self, color_renderbuffer: int, size: tuple[int, int], samples: int,
                                 stencil: bool, depth: bool = True, float_depth: bool = False) -> tuple[int, int]:
        """A framebuffer with moderngl's colour renderbuffer and our depth(-stencil) one.

        Returns ``(framebuffer, depth_renderbuffer)`` GL names (0 when there is no depth).
        """
        old_fbo = self.get_integer(GL_FRAMEBUFFER_BINDING)
        old_rb = self.get_integer(GL_RENDERBUFFER_BINDING)
        fbo, rb = _UINT(0), _UINT(0)
        self.glGenFramebuffers(1, ctypes.byref(fbo))
        self.glBindFramebuffer(GL_FRAMEBUFFER, fbo.value)
        self.glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_renderbuffer)
        if depth or stencil:
            self.glGenRenderbuffers(1, ctypes.byref(rb))
            self.glBindRenderbuffer(GL_RENDERBUFFER, rb.value)
            if float_depth:  # reverse-Z wants a float depth buffer (glsandbox.transforms.reverse_z)
                fmt = GL_DEPTH32F_STENCIL8 if stencil else GL_DEPTH_COMPONENT32F
            else:
                fmt = GL_DEPTH24_STENCIL8 if stencil else GL_DEPTH_COMPONENT24
            self.glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, fmt, size[0], size[1])
            attachment = GL_DEPTH_STENCIL_ATTACHMENT if stencil else GL_DEPTH_ATTACHMENT
            self.glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, rb.value)
        status = self.glCheckFramebufferStatus(GL_FRAMEBUFFER)
        self.glBindRenderbuffer(GL_RENDERBUFFER, old_rb)
        self.glBindFramebuffer(GL_FRAMEBUFFER, old_fbo)
        if status != GL_FRAMEBUFFER_COMPLETE:
            self.delete_framebuffer(fbo.value, rb.value)
            raise SandboxError(f"offscreen framebuffer {size[0]}x{size[1]} (samples {samples}) "
                               f"is incomplete: status 0x{status:04X}")
        return fbo.value, rb.value

    def attach_color(self, fbo: int, index: int, renderbuffer: int) -> None:
        """Attach ``renderbuffer`` as colour attachment ``index`` of ``fbo`` (the X-ray's primitive
        ids: attachment 1); moderngl's ``detect_framebuffer`` then draws into every attachment."""
        old = self.get_integer(GL_FRAMEBUFFER_BINDING)
        self.glBindFramebuffer(GL_FRAMEBUFFER, fbo)
        self.glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + index, GL_RENDERBUFFER, renderbuffer)
        self.glBindFramebuffer(GL_FRAMEBUFFER, old)

    def clear_ids(self, rect: tuple[int, int, int, int]) -> None:
        """Clear colour attachment 1 (the primitive ids, unsigned integers) of the bound framebuffer
        to 0 inside ``rect``: a float clear colour leaves an integer attachment undefined."""
        self.glEnable(GL_SCISSOR_TEST)
        self.glScissor(*rect)
        zeros = (_UINT * 4)(0, 0, 0, 0)
        self.glClearBufferuiv(0x1800, 1, zeros)  # GL_COLOR, draw buffer 1
        self.glDisable(GL_SCISSOR_TEST)

    def attachment_bits(self, fbo: int) -> tuple[int, int]:
        """(depth bits, stencil bits) of a framebuffer's depth attachment."""
        old = self.get_integer(GL_FRAMEBUFFER_BINDING)
        self.glBindFramebuffer(GL_FRAMEBUFFER, fbo)
        bits = []
        for attachment, pname in ((GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE),
                                  (GL_STENCIL_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE)):
            kind, value = _INT(0), _INT(0)
            self.glGetFramebufferAttachmentParameteriv(
                GL_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, ctypes.byref(kind))
            if kind.value != GL_NONE:  # asking the size of a missing attachment is an error
                self.glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, attachment, pname, ctypes.byref(value))
            bits.append(value.value)
        self.glBindFramebuffer(GL_FRAMEBUFFER, old)
        return bits[0], bits[1]

    def sampler_wrap(self, sampler: int, mode: int) -> None:
        """Set a sampler object's s and t wrap modes (moderngl cannot set
        ``GL_MIRRORED_REPEAT``)."""
        self.glSamplerParameteri(sampler, GL_TEXTURE_WRAP_S, mode)
        self.glSamplerParameteri(sampler, GL_TEXTURE_WRAP_T, mode)

    def sampler_bindings(self, units: int = 4) -> tuple[int, ...]:
        """The sampler object bound to each of the first ``units`` texture units (0: none, the
        texture's own filter and wrap apply). GL reads the active unit's, so each unit is made
        active in turn and the active unit is put back."""
        active = self.get_integer(GL_ACTIVE_TEXTURE)
        bound = []
        for unit in range(units):
            self.glActiveTexture(GL_TEXTURE0 + unit)
            bound.append(self.get_integer(GL_SAMPLER_BINDING))
        self.glActiveTexture(active)
        return tuple(bound)

    def clear_stencil(self, rect: tuple[int, int, int, int], value: int = 0) -> None:
        """Clear the stencil of the bound framebuffer inside ``rect`` to ``value``
        (scissored, all bits writable for the clear; both restored after)."""
        self.glEnable(GL_SCISSOR_TEST)
        self.glScissor(*rect)
        self.glStencilMask(0xFF)
        self.glClearStencil(value)
        self.glClear(GL_STENCIL_BUFFER_BIT)
        self.glDisable(GL_SCISSOR_TEST)

    def blit_color(self, source: int, destination: int, size: tuple[int, int]) -> None:
        """Copy the colour of framebuffer ``source`` onto ``destination`` (0: the
        window), pixel for pixel. Colour only: moderngl's ``copy_framebuffer``
        copies depth too, which fails (GL_INVALID_OPERATION, nothing copied)
        when the depth formats differ, as a float-depth target's and a
        window's 24-bit one do."""
        old_read, old_draw = self.get_integer(GL_READ_FRAMEBUFFER_BINDING), self.get_integer(GL_FRAMEBUFFER_BINDING)
        self.glBindFramebuffer(GL_READ_FRAMEBUFFER, source)
        self.glBindFramebuffer(GL_DRAW_FRAMEBUFFER, destination)
        width, height = size
        self.glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST)
        self.glBindFramebuffer(GL_READ_FRAMEBUFFER, old_read)
        self.glBindFramebuffer(GL_DRAW_FRAMEBUFFER, old_draw)

    def read_stencil(self, fbo: int, size: tuple[int, int]) -> bytes:
        """The stencil values of a single-sample framebuffer, bottom row first."""
        old = self.get_integer(GL_FRAMEBUFFER_BINDING)
        self.glBindFramebuffer(GL_FRAMEBUFFER, fbo)
        data = ctypes.create_string_buffer(size[0] * size[1])
        alignment = self.get_integer(GL_PACK_ALIGNMENT)
        self.glPixelStorei(GL_PACK_ALIGNMENT, 1)  # rows of one byte a pixel, packed tight
        self.glReadPixels(0, 0, size[0], size[1], 0x1901, 0x1401, data)  # GL_STENCIL_INDEX, GL_UNSIGNED_BYTE
        self.glPixelStorei(GL_PACK_ALIGNMENT, alignment)
        self.glBindFramebuffer(GL_FRAMEBUFFER, old)
        return data.raw

    def read_pixels(self, fbo: int, size: tuple[int, int], what: str) -> np.ndarray:
        """One buffer of a single-sample framebuffer as an array, top row first: ``what`` is one of
        :data:`PIXEL_READS` (the X-ray's reads: ``color`` RGBA8, ``depth`` float32 0..1, ``stencil``
        uint8, ``ids`` two uint32 a pixel from colour attachment 1). GL state is put back."""
        fmt, kind, dtype, components = PIXEL_READS[what]
        width, height = size
        old = self.get_integer(GL_FRAMEBUFFER_BINDING)
        alignment = self.get_integer(GL_PACK_ALIGNMENT)
        self.glBindFramebuffer(GL_FRAMEBUFFER, fbo)
        self.glPixelStorei(GL_PACK_ALIGNMENT, 1)
        self.glReadBuffer(GL_COLOR_ATTACHMENT0 + (1 if what == "ids" else 0))
        out = np.empty((height, width, components), dtype=dtype)
        self.glReadPixels(0, 0, width, height, fmt, kind, out.ctypes.data)
        self.glReadBuffer(GL_COLOR_ATTACHMENT0)
        self.glPixelStorei(GL_PACK_ALIGNMENT, alignment)
        self.glBindFramebuffer(GL_FRAMEBUFFER, old)
        out = out[::-1]  # GL's bottom row first
        return out[..., 0] if components == 1 else out

    def bound_framebuffer(self) -> int:
        """The framebuffer object bound for drawing now."""
        return self.get_integer(GL_FRAMEBUFFER_BINDING)

    def state_snapshot(self) -> dict[str, object]:
        """The pipeline state the effect passes change, read back from GL."""
        state: dict[str, object] = {name: self.get_integer(pname) for name, pname in STATE_INTEGERS.items()}
        state.update({name: bool(self.glIsEnabled(cap)) for name, cap in STATE_FLAGS.items()})
        for name, pname in STATE_FLOATS.items():
            value = ctypes.c_float(0.0)
            self.glGetFloatv(pname, ctypes.byref(value))
            state[name] = value.value
        mask = (_INT * 4)()
        self.glGetIntegerv(GL_COLOR_WRITEMASK, mask)
        state["color_writemask"] = tuple(mask)
        return state

    def delete_framebuffer(self, fbo: int, renderbuffer: int) -> None:
        if renderbuffer:
            self.glDeleteRenderbuffers(1, ctypes.byref(_UINT(renderbuffer)))
        if fbo:
            self.glDeleteFramebuffers(1, ctypes.byref(_UINT(fbo)))
