"""OSMesa: Mesa's off-screen software context, the second headless backend.

glcontext has no OSMesa backend, so this makes an OSMesa core-profile context
current with ctypes (Debian's ``libosmesa6``) and hands moderngl a loader whose
``load_opengl_function`` answers with ``OSMesaGetProcAddress``. OSMesa always
needs a client-memory colour buffer; we render into framebuffer objects, so a
small one is enough.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import stat

from glsandbox.errors import SandboxError

OSMESA_RGBA = 0x1908
OSMESA_FORMAT = 0x22
OSMESA_DEPTH_BITS = 0x30
OSMESA_STENCIL_BITS = 0x31
OSMESA_ACCUM_BITS = 0x32
OSMESA_PROFILE = 0x33
OSMESA_CORE_PROFILE = 0x34
OSMESA_CONTEXT_MAJOR_VERSION = 0x36
OSMESA_CONTEXT_MINOR_VERSION = 0x37
GL_UNSIGNED_BYTE = 0x1401

INSTALL_HINT = "install it with: apt-get install libosmesa6"

#: The entry points used here: a library without them is not OSMesa.
REQUIRED_SYMBOLS = ("OSMesaCreateContextAttribs", "OSMesaMakeCurrent", "OSMesaGetProcAddress", "OSMesaDestroyContext")


def _missing_symbol(lib: ctypes.CDLL) -> str | None:
    """The first OSMesa entry point ``lib`` lacks, or None."""
    return next((name for name in REQUIRED_SYMBOLS if not hasattr(lib, name)), None)


def _load_library() -> ctypes.CDLL:
    """libOSMesa: ``GLSANDBOX_OSMESA`` (a path, for a custom Mesa build) or the system's."""
    override = os.environ.get("GLSANDBOX_OSMESA")
    if override:
        where = f"GLSANDBOX_OSMESA={override}"
        if os.sep in override:  # a path (a bare name is looked up by the dynamic loader)
            try:
                mode = os.stat(override).st_mode
            except OSError as exc:
                raise SandboxError(f"OSMesa backend unavailable: {where}: {exc.strerror}") from None
            if not stat.S_ISREG(mode):  # a named pipe would block the loader forever
                raise SandboxError(f"OSMesa backend unavailable: {where} is not a regular file") from None
        try:
            lib = ctypes.CDLL(override)
        except OSError as exc:
            reason = " ".join(str(exc).split())
            raise SandboxError(f"OSMesa backend unavailable: cannot load {where} ({reason})") from None
        missing = _missing_symbol(lib)
        if missing:
            raise SandboxError(f"OSMesa backend unavailable: {where} is not an OSMesa library (it has no {missing})")
        return lib
    names = ["libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"]
    found = ctypes.util.find_library("OSMesa")
    if found:
        names.insert(0, found)
    for name in names:
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        if _missing_symbol(lib) is None:
            return lib
    raise SandboxError(f"OSMesa backend unavailable: libOSMesa not found; {INSTALL_HINT}")


class OSMesaContext:
    """An OSMesa context made current on this thread, and moderngl's loader for it."""

    def __init__(self, size: tuple[int, int] = (16, 16)) -> None:
        lib = _load_library()
        lib.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
        lib.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int), ctypes.c_void_p]
        lib.OSMesaMakeCurrent.restype = ctypes.c_ubyte
        lib.OSMesaMakeCurrent.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_int]
        lib.OSMesaGetProcAddress.restype = ctypes.c_void_p
        lib.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
        lib.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]
        attributes = [
            OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
            OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
            OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0,
        ]
        handle = lib.OSMesaCreateContextAttribs((ctypes.c_int * len(attributes))(*attributes), None)
        if not handle:
            raise SandboxError("OSMesa backend unavailable: could not create an OpenGL 3.3 core context")
        self._lib = lib
        self._handle = handle
        self._buffer = (ctypes.c_ubyte * (4 * size[0] * size[1]))()
        self._size = size
        if not self.make_current():
            lib.OSMesaDestroyContext(handle)
            raise SandboxError("OSMesa backend unavailable: OSMesaMakeCurrent failed")

    def make_current(self) -> bool:
        """Bind this context (and its small client buffer) to this thread."""
        return bool(self._lib.OSMesaMakeCurrent(self._handle, self._buffer, GL_UNSIGNED_BYTE, *self._size))

    # moderngl's loader protocol
    def load_opengl_function(self, name: str) -> int:
        return self._lib.OSMesaGetProcAddress(name.encode("ascii")) or 0

    def load(self, name: str) -> int:
        return self.load_opengl_function(name)

    def release(self) -> None:
        if self._handle:
            self._lib.OSMesaDestroyContext(self._handle)
            self._handle = None

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: object) -> None:
        return None
