"""Phong boyama modeli and Yansıma vektörü: shading one hit, reflecting a ray.

Phong (the course's form)::

    pixelColor = ka·ambientColor + kd·diffuseColor + ks·specularColor,
    ka + kd + ks = 1

- ambient: the object's own colour (a stand-in for light bounced off other
  objects, which a plain ray tracer does not follow);
- diffuse: ``cos θ = N·toLight`` (clamped to ``[0, 1]``) times the object's
  colour, independent of the eye. Worked example #7: ``N·toLight = 0.8`` on
  ``(255, 0, 0)`` gives ``(204, 0, 0)``;
- specular: ``(reflected·toEye)^shininess`` (clamped), where ``reflected`` is
  the direction *to the light* mirrored about ``N``; it depends on the eye.

Colours are in whatever unit the caller uses (the course uses 0-255); the
light colour is a per-channel factor in ``[0, 1]`` (``(1, 1, 1)`` = white) that
tints the diffuse and specular terms. The specular highlight has the light's
colour: ``light_color ⊙ specular_color``, with ``specular_color`` white in the
course's units, ``(255, 255, 255)``; pass ``(1, 1, 1)`` for 0-1 colours.

Reflection: ``R = Rd − 2(Rd·N)N`` for a unit ``N``. Worked example #5:
``Rd = (0, 0.6, 0.8)``, ``N = (0, 0.28, −0.96)``: ``Rd·N = −0.6``,
``R = (0, 0.936, −0.352)``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.vec import Vec3, as_vec3, dot, normalize

__all__ = ["diffuse_factor", "phong", "reflect", "specular_factor"]

_WHITE_255 = (255.0, 255.0, 255.0)


def reflect(direction: ArrayLike, normal: ArrayLike) -> Vec3:
    """Yansıma vektörü: ``Rd − 2(Rd·N)N``.

    ``normal`` is normalized first (the formula assumes ``|N| = 1``), so any
    non-zero normal of the surface works; ``direction`` keeps its length.
    Reflecting twice about the same normal gives ``direction`` back.
    Works on one vector or on ``(..., 3)`` batches.
    """
    d = np.asarray(direction, dtype=np.float64)
    n = normalize(normal)
    return d - 2.0 * np.asarray(dot(d, n))[..., None] * n


def diffuse_factor(normal: ArrayLike, to_light: ArrayLike) -> float:
    """``max(0, N·toLight)`` with both normalized: the diffuse katsayı, in ``[0, 1]``."""
    return max(0.0, float(dot(normalize(as_vec3(normal, "normal")), normalize(as_vec3(to_light, "to_light")))))


def specular_factor(normal: ArrayLike, to_light: ArrayLike, to_eye: ArrayLike, shininess: float) -> float:
    """``max(0, reflected·toEye)^shininess``; 0 when the light is behind the surface.

    ``reflected = reflect(−toLight, N) = 2(N·L)N − L``: the light's direction
    mirrored about the normal.
    """
    n = normalize(as_vec3(normal, "normal"))
    light = normalize(as_vec3(to_light, "to_light"))
    eye = normalize(as_vec3(to_eye, "to_eye"))
    if float(dot(n, light)) <= 0.0:
        return 0.0
    r_dot_e = float(dot(reflect(-light, n), eye))
    return float(max(0.0, r_dot_e) ** float(shininess))


def phong(
    normal: ArrayLike,
    to_light: ArrayLike,
    to_eye: ArrayLike,
    color: ArrayLike,
    light_color: ArrayLike,
    ka: float,
    kd: float,
    ks: float,
    shininess: float,
    *,
    specular_color: ArrayLike = _WHITE_255,
) -> NDArray[np.float64]:
    """Phong colour of one hit: ``ka·color + kd·(N·L)·color⊙light + ks·(R·E)^n·light⊙specular``.

    ``normal``, ``to_light`` (hit point to light) and ``to_eye`` (hit point to
    the eye) are normalized here. ``ka, kd, ks`` must be in ``[0, 1]`` and sum
    to 1 (to within 1e-9); otherwise :class:`RayTraceError` (a ``ValueError``)
    names the values. Returns a float64 ``(3,)`` colour, unclamped (with the
    sum rule and a light colour in ``[0, 1]`` it never exceeds the brightest
    of ``color`` and ``specular_color``).
    """
    coefficients = {"ka": float(ka), "kd": float(kd), "ks": float(ks)}
    total = sum(coefficients.values())
    named = ", ".join(f"{k}={v!r}" for k, v in coefficients.items())
    if any(not (0.0 <= v <= 1.0) for v in coefficients.values()):
        raise RayTraceError(f"Phong coefficients must each be in [0, 1], got {named}")
    if not math.isclose(total, 1.0, rel_tol=0.0, abs_tol=1e-9):
        raise RayTraceError(f"Phong needs ka + kd + ks = 1, got {named} (sum {total!r})")
    if not (math.isfinite(float(shininess)) and float(shininess) >= 0.0):
        raise RayTraceError(f"shininess must be a finite number >= 0, got {shininess!r}")
    c = as_vec3(color, "color")
    light = as_vec3(light_color, "light_color")
    spec_c = as_vec3(specular_color, "specular_color")
    ambient = c
    diffuse = diffuse_factor(normal, to_light) * c * light
    specular = specular_factor(normal, to_light, to_eye, shininess) * light * spec_c
    return ka * ambient + kd * diffuse + ks * specular
