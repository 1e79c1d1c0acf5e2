"""Uniform bytes: the matrices, the eye, the material and the lights as the shaders read
them (course sections "World, View, Projection" and "Lighting"), each made once and looked up
by content, and what a program was last given, so that a draw writes only what changed."""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable

import numpy as np

from glsandbox import transforms
from glsandbox.scene import Material

class PassCamera:
    """A pass's view and projection, with what the draws need from them made
    once per pass instead of once per draw: the uniform bytes, and the eye
    (only lit draws ask for it).

    Camera-relative: float32 keeps 24 bits, so a model matrix holding a
    translation of 1e5 rounds it to 0.008 units, and the view's translation
    undoes it in float32 again: a scene far from the origin shakes and its
    decals z-fight (docs/numerics.md). So every product that holds a large
    translation is formed in float64 on the CPU, relative to the pass's
    ``origin`` (the eye; a shadow map's pass: the light): the shader's
    ``m_model`` is ``T(-origin) @ model`` (:data:`_MODEL_BYTES`), its ``m_view``
    ``view @ T(origin)`` (a rotation: no translation left to round), the eye
    sits at 0 and the lights are relative to it. The shader's "world" is the
    world moved so that the origin is at 0: lighting, depth and clip are the
    same (a translation changes no direction or distance).
    """

    __slots__ = ("view", "proj", "origin", "origin_bytes", "view_bytes", "proj_bytes", "_eye_bytes")

    def __init__(self, view: np.ndarray, proj: np.ndarray, origin: np.ndarray | None = None) -> None:
        self.view, self.proj = view, proj
        view = np.asarray(view, dtype=np.float64)
        self.origin = eye_position(view) if origin is None else np.asarray(origin, dtype=np.float64)
        self.origin_bytes = self.origin.tobytes()
        moved = view.copy()
        moved[:, 3] += view[:, :3] @ self.origin  # view @ T(origin)
        self.view_bytes, self.proj_bytes = transforms.gl_bytes(moved), transforms.gl_bytes(proj)
        self._eye_bytes: bytes | None = None

    @property
    def eye_bytes(self) -> bytes:
        """``u_eye``'s uniform bytes: the eye relative to the origin (0 when the origin is the eye)."""
        if self._eye_bytes is None:
            self._eye_bytes = (_eye(np.asarray(self.view, dtype=np.float64).tobytes()) - self.origin).astype(
                "f4").tobytes()
        return self._eye_bytes


#: Uniform bytes of material colours: a lesson rebuilding its scene each frame
#: makes new Materials with the same few colours.
_COLOR_BYTES: dict[tuple[float, ...], bytes] = {}


def _color_bytes(color: tuple[float, ...]) -> bytes:
    data = _COLOR_BYTES.get(color)
    if data is None:
        data = _COLOR_BYTES[color] = np.asarray(color, dtype="f4").tobytes()
    return data


def _float_bytes(value: float) -> bytes:
    return struct.pack("f", value)


#: ``u_texture``'s value: the material texture is on unit 0.
_UNIT_0 = struct.pack("i", 0)


def _material_bytes(material: Material) -> tuple[tuple[str, bytes], ...]:
    """The coefficients of the course's ``0.1*mesh + 0.4*diffuse + 0.3*specular`` and the
    exponent (32) as uniform bytes; a zero coefficient switches its term off."""
    return _coefficient_bytes(material.ambient, material.diffuse, material.specular, material.shininess)


@functools.lru_cache(maxsize=256)
def _coefficient_bytes(ambient: float, diffuse: float, specular: float,
                       shininess: float) -> tuple[tuple[str, bytes], ...]:
    """:func:`_material_bytes` made once per set of coefficients (a scene has a few)."""
    return (("u_ambient", _float_bytes(ambient)), ("u_diffuse", _float_bytes(diffuse)),
            ("u_specular", _float_bytes(specular)), ("u_shininess", _float_bytes(shininess)))


@functools.lru_cache(maxsize=64)
def _eye(view: bytes) -> np.ndarray:
    """The eye position (float64) of a float64 view matrix given as bytes."""
    return eye_position(np.frombuffer(view).reshape(4, 4))


#: Entries each of :data:`_MODEL_BYTES` and :data:`_NORMAL_BYTES` keeps; past it, it starts
#: again (a moving node adds one per frame).
_MATRICES_KEPT = 1024


class _MatrixBytes(dict):
    """Uniform bytes by the C-order bytes of a float64 4x4 model matrix, each made on its first
    lookup (``cache[content]``: a plain subscript, no method call, for a matrix seen before)
    by ``convert`` of the matrix read back from ``content``."""

    def __init__(self, convert: Callable[[np.ndarray], bytes]) -> None:
        super().__init__()
        self.convert = convert

    def __missing__(self, content: bytes) -> bytes:
        if len(self) >= _MATRICES_KEPT:
            self.clear()
        data = self[content] = self.convert(np.frombuffer(content).reshape(4, 4))
        return data


def _relative_model_bytes(key: bytes) -> bytes:
    """``m_model``'s bytes for ``key``: a float64 model matrix's 128 bytes, then the pass origin's
    24 (:class:`PassCamera`; none: the origin at 0): ``T(-origin) @ model`` formed in float64,
    rounded to float32 once."""
    matrix = np.frombuffer(key[:128]).reshape(4, 4)
    if len(key) == 128:
        return transforms.gl_bytes(matrix)
    relative = matrix.copy()
    # Row i − o_i·row 3 for the first three rows (T(-o)'s rows), row 3 kept: the same products and
    # differences as ``matrix - outer((o, 0), row 3)``, without numpy's Python-level wrappers
    # (outer, append), which cost more than the arithmetic on a 4x4 (a moving node, every frame).
    relative[:3] -= np.frombuffer(key[128:])[:, None] * matrix[3]
    return transforms.gl_bytes(relative)


class _RelativeBytes(dict):
    """:func:`_relative_model_bytes` by key, each made on its first lookup (a plain subscript)."""

    def __missing__(self, key: bytes) -> bytes:
        if len(self) >= _MATRICES_KEPT:
            self.clear()
        data = self[key] = _relative_model_bytes(key)
        return data


#: ``m_model``'s uniform bytes by the float64 model matrix's bytes and the pass origin's, and
#: ``m_normal``'s by the model's alone (a translation does not turn a normal) (see
#: :meth:`Executor.draw_node`): a node that does not move, seen from an eye that does not,
#: converts its matrix, and inverts it, once; an array changed in place between frames has
#: other bytes, so it is converted again.
_MODEL_BYTES = _RelativeBytes()
_NORMAL_BYTES = _MatrixBytes(lambda matrix: transforms.gl_bytes(transforms.normal_matrix(matrix)))


class _Written(dict):
    """The uniform bytes last written into one program, by uniform name (and the ``#`` keys
    below); a name never written gives None (``written[name]``: a subscript, not a ``get`` call)."""

    def __missing__(self, name: str) -> None:
        return None



#: A key of a program's ``written`` dict that names no uniform: the constants tuple of the
#: prepared draw that wrote its material's uniforms last (see :meth:`Executor.draw_node`).
_CONSTANTS = "#constants"
#: The PassCamera whose view and projection a program holds (its ``written`` dict's key, like
#: :data:`_CONSTANTS`): draws through the same camera skip comparing them.
_CAMERA = "#camera"
#: The PassCamera whose eye position a program holds (lit draws only write it).
_EYE = "#eye"
#: A model matrix of this dtype is converted and compared as it is.
_FLOAT64 = np.dtype(np.float64)


def _constants_change(written: dict[str, bytes], last: tuple | None,
                      constants: tuple[tuple[str, bytes], ...]) -> tuple[tuple[str, bytes], ...]:
    """What a draw writes of its material's ``constants`` into a program that holds ``last``'s (the
    constants a draw wrote last; None: not known, so the program's ``written`` bytes are compared):
    the entries whose bytes differ (walls of one program that differ only in colour: ``u_color``)."""
    held = written if last is None else dict(last)
    return tuple((name, data) for name, data in constants if held.get(name) != data)


class _NoUniform:
    """What :class:`_Uniforms` gives for a name the program lacks (a term the compiler removed)."""

    @staticmethod
    def write(data: bytes) -> None:
        pass


class _Uniforms(dict):
    """A program's uniforms by name; a name it lacks gives :class:`_NoUniform` (nothing written)."""

    def __missing__(self, name: str) -> type[_NoUniform]:
        return _NoUniform



# --- lighting uniforms (course section "Lighting") --------------------------


def eye_position(view: np.ndarray) -> np.ndarray:
    """The camera position in world space: the view matrix maps it to the
    origin, so it is the translation column of the inverse view matrix (the
    course's ``vEyePos``)."""
    return np.linalg.inv(np.asarray(view, dtype=np.float64))[:3, 3]


def material_constants(material: Material, lit: bool) -> tuple[tuple[str, bytes], ...]:
    """The uniform bytes a draw of ``material`` writes that no position changes: its colour,
    (lit) the coefficients of the course's formula, the alpha cutoff, the texture's unit."""
    constants = [("u_color", _color_bytes(material.color))]
    if lit:
        constants += _material_bytes(material)
    constants.append(("u_alpha_cutoff", _float_bytes(material.alpha_cutoff)))
    if material.texture is not None:
        constants.append(("u_texture", _UNIT_0))
    found = tuple(constants)
    kept = _KEPT_CONSTANTS.get(found)
    if kept is None:
        if len(_KEPT_CONSTANTS) >= _MATRICES_KEPT:
            _KEPT_CONSTANTS.clear()
        kept = _KEPT_CONSTANTS[found] = found
    return kept


#: Each set of material constants once (by value): draws whose materials write the same bytes (a
#: scene's white textured ground and cube, one program's two quads) share one tuple, so the
#: executor sees that the program holds them already (``written[_CONSTANTS] is`` the draw's:
#: :meth:`~glsandbox.gl.executor.Executor.draw_node`) and compares nothing.
_KEPT_CONSTANTS: dict[tuple[tuple[str, bytes], ...], tuple[tuple[str, bytes], ...]] = {}
