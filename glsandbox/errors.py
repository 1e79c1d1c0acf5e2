"""The one error type users see, and the checks that raise it for numbers.

Every user mistake (bad order string, bad scene file, missing texture, a shader
that does not compile, no GL available, ...) raises :class:`SandboxError` with a
one-line message naming the file, line or value. The CLI prints
``error: <message>`` and exits with status 2; nothing half-written is left.

Numbers entering a scene (``--set`` values, scene files, the scene's
dataclasses) are finite and within :data:`NUMBER_LIMIT`
(:func:`check_number`, :func:`check_numbers`); messages show values with
:func:`plain`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: The largest magnitude a number entering a scene may have: ``--set`` values
#: (unless a parameter says otherwise), scene-file numbers, and the positions,
#: scales, camera and colours the scene's dataclasses accept. Squares and
#: products of such numbers stay finite in float32 (the GPU) and exact enough
#: in float64, so nothing overflows into a silent miss.
NUMBER_LIMIT = 1e6


class SandboxError(Exception):
    """A user-facing error with a one-line message."""

    def __init__(self, message: str) -> None:
        # Keep the promise of one line: fold the newlines (and tabs) a library
        # gave us into spaces, and show every other control or line-separator
        # character of a value the user typed as an escape (``\x1e``), since
        # a reader splitting lines (``str.splitlines``) would break there too.
        text = " ".join(str(message).replace("\t", " ").replace("\r\n", "\n").replace("\r", "\n").split("\n"))
        super().__init__("".join(c if c.isprintable() else ascii(c)[1:-1] for c in text).strip())


def plain(value: Any, limit: int = 80) -> str:
    """``value`` as a message shows it: numpy numbers as plain numbers
    (``1.0``, not ``np.float64(1.0)``), arrays as lists, and anything longer
    than ``limit`` characters or nested deeper than a few levels cut short."""

    class Shown:  # a stand-in whose repr is the given text
        def __init__(self, text: str) -> None:
            self.text = text

        def __repr__(self) -> str:
            return self.text

    def convert(v: Any, depth: int) -> Any:
        if hasattr(v, "tolist") and callable(v.tolist):  # numpy scalars and arrays
            v = v.tolist()
        if isinstance(v, (list, tuple)):
            if depth > 3:
                return Shown("[...]")
            items = [convert(x, depth + 1) for x in v[:9]] + ([Shown("...")] if len(v) > 9 else [])
            return tuple(items) if isinstance(v, tuple) else items
        if isinstance(v, dict):
            return Shown("{...}" if v else "{}")
        return v

    text = " ".join(repr(convert(value, 0)).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def check_number(value: object, what: str, low: float = -NUMBER_LIMIT, high: float = NUMBER_LIMIT) -> float:
    """``value`` as a float, or a one-line :class:`SandboxError` naming ``what`` and the value."""
    if isinstance(value, (str, bytes, bool)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SandboxError(f"{what} must be a number, got {plain(value)}")
    number = float(value)
    if not math.isfinite(number):
        raise SandboxError(f"{what} must be a finite number, got {plain(value)}")
    if not low <= number <= high:
        raise SandboxError(f"{what} must lie within {low:g}..{high:g}, got {plain(value)}")
    return number


def check_numbers(value: object, what: str, counts: tuple[int, ...] = (3,), low: float = -NUMBER_LIMIT,
                  high: float = NUMBER_LIMIT) -> tuple[float, ...]:
    """A tuple of ``counts`` numbers (floats), each checked as :func:`check_number` does."""
    # The common case, checked every frame: a tuple of floats in range (a NaN fails
    # the comparison, so it takes the slow path below and gets its message).
    if type(value) is tuple and len(value) in counts:
        for v in value:  # (a loop, not all() over a generator: this runs for every moved light every frame)
            if type(v) is not float or not low <= v <= high:
                break
        else:
            return value
    try:
        items = list(value)  # type: ignore[call-overload]
    except TypeError:
        items = None
    if isinstance(value, (str, bytes)) or items is None or len(items) not in counts:
        want = " or ".join(str(c) for c in counts)
        raise SandboxError(f"{what} must be {want} numbers, got {plain(value)}")
    for item in items:
        if isinstance(item, (str, bytes, bool)) or not isinstance(item, (int, float, np.integer, np.floating)):
            raise SandboxError(f"{what} must be {len(items)} numbers, got {plain(value)}")
        if not math.isfinite(float(item)):
            raise SandboxError(f"{what} must be finite, got {plain(value)}")
        if not low <= float(item) <= high:
            raise SandboxError(f"{what} must lie within {low:g}..{high:g}, got {plain(value)}")
    return tuple(float(v) for v in items)


def parse_size_text(text: str, where: str) -> tuple[int, int]:
    """``WxH`` -> (W, H), refusing anything else with ``where`` named (``--size``, a rubric's ``size``)."""
    w, sep, h = str(text).lower().partition("x")
    try:
        size = (int(w), int(h))
    except ValueError:
        size = (0, 0)
    if not sep or size[0] <= 0 or size[1] <= 0 or max(size) > 16384:
        raise SandboxError(f"{where} {text!r}: expected WIDTHxHEIGHT with positive integers, e.g. 640x480")
    return size
