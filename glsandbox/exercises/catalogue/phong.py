"""Phong boyama modeli: the colour of one hit lit by one white light."""

from __future__ import annotations

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import hemisphere
from glsandbox.exercises.plain import unit

DOC = """Phong boyama modeli (Phong shading), course section "Phong boyama modeli".

The colour of a surface point with unit normal N, lit by one white light
(colour (1, 1, 1)), seen from the eye:

    L = to_light / |to_light|,  E = to_eye / |to_eye|,  N = normal / |normal|
    R = 2(N·L)N - L                          (the light's direction mirrored)
    colour = ka·C + kd·max(0, N·L)·C + ks·max(0, R·E)^shininess·(255, 255, 255)

with C = `color` (0..255 each) and the specular term 0 when N·L <= 0 (the
light is behind the surface). The ray tracer's coefficients sum to one:
ka + kd + ks = 1. Return the colour as three numbers (not clamped, not rounded).

Worked example (the notes' #7): N·L = 0.8 on red, C = (255, 0, 0), with
ka = 0, kd = 1, ks = 0: (204, 0, 0).
"""


def reference(normal, to_light, to_eye, color, ka, kd, ks, shininess):  # noqa: ANN001, ANN201, PLR0913
    """The engine's :func:`glsandbox.raytrace.shading.phong` under a white light."""
    from glsandbox.raytrace.shading import phong

    return phong(normal, to_light, to_eye, color, (1.0, 1.0, 1.0), ka, kd, ks, shininess)




def _phong(normal, to_light, to_eye, color, ka, kd, ks, shininess, *, clamp_diffuse=True,  # noqa: ANN001, ANN202
           gate=True, clamp_specular=True, sign=1.0, unit_light=True):
    n = unit(normal)
    light = unit(to_light) if unit_light else list(to_light)
    eye = unit(to_eye)
    nl = sum(a * b for a, b in zip(n, light, strict=True))
    r = [sign * (2 * nl * a - b) for a, b in zip(n, light, strict=True)]
    re = sum(a * b for a, b in zip(r, eye, strict=True))
    diffuse = max(0.0, nl) if clamp_diffuse else nl
    base = max(0.0, re) if clamp_specular else re
    specular = 0.0 if (gate and nl <= 0) else base ** shininess
    return tuple(ka * c + kd * diffuse * c + ks * specular * 255.0 for c in color)


def diffuse_unclamped(*args):  # noqa: ANN002, ANN201
    return _phong(*args, clamp_diffuse=False)


def specular_behind(*args):  # noqa: ANN002, ANN201
    return _phong(*args, gate=False)


def reflected_wrong_way(*args):  # noqa: ANN002, ANN201
    return _phong(*args, sign=-1.0)


def light_not_normalized(*args):  # noqa: ANN002, ANN201
    return _phong(*args, unit_light=False)


MISTAKES = (
    Mistake("diffuse_unclamped", "max(0, N·L) is missing: where the light is behind the surface N·L < 0 and your "
            "diffuse term subtracts colour.", diffuse_unclamped),
    Mistake("specular_behind", "a surface facing away from the light (N·L <= 0) has no highlight: your specular "
            "term shines through from behind.", specular_behind),
    Mistake("reflected_wrong_way", "R = 2(N·L)N - L mirrors the light's direction about the normal; yours points "
            "the opposite way, so the highlight is on the wrong side.", reflected_wrong_way),
    Mistake("light_not_normalized", "normalize the vector to the light: N·L is a cosine only for unit vectors "
            "(here to_light is not one).", light_not_normalized),
)

RED = (255.0, 0.0, 0.0)
N_UP = (0.0, 0.0, 1.0)
L = (0.0, 0.6, 0.8)
MIRROR = (0.0, -0.6, 0.8)  # 2(N·L)N - L: the eye on the mirrored light ray

VISIBLE = (
    Case("the notes' #7: N·L = 0.8 on red, diffuse only", (N_UP, L, N_UP, RED, 0.0, 1.0, 0.0, 32.0),
         (204.0, 0.0, 0.0)),
    Case("ka 0.1, kd 0.6, ks 0.3, the eye on the mirrored ray (R·E = 1)", (N_UP, L, MIRROR, RED, 0.1, 0.6, 0.3,
                                                                          32.0), (224.4, 76.5, 76.5)),
)


def hidden() -> list[Case]:
    """The light behind (N·L < 0), the eye away from the highlight (R·E < 0), lengths other than 1."""
    below = (0.0, 0.6, -0.8)
    return [
        Case("the light behind the surface: ambient only", (N_UP, below, N_UP, RED, 0.1, 0.6, 0.3, 32.0),
             (25.5, 0.0, 0.0), group="behind"),
        Case("the light behind, the eye where its mirror would be", (N_UP, below, (0.0, -0.6, -0.8), RED, 0.1,
                                                                      0.6, 0.3, 32.0), (25.5, 0.0, 0.0),
             group="behind"),
        Case("the eye on the far side of the highlight: R·E < 0", (N_UP, L, (0.0, 0.6, -0.8), RED, 0.1, 0.6, 0.3,
                                                                    2.0), (25.5 + 0.6 * 0.8 * 255.0, 0.0, 0.0),
             group="specular"),
        Case("an odd exponent with R·E < 0", (N_UP, L, (0.0, 1.0, 0.0), RED, 0.1, 0.6, 0.3, 3.0),
             (25.5 + 0.6 * 0.8 * 255.0, 0.0, 0.0), group="specular"),
        Case("vectors of length 10", ((0.0, 0.0, 10.0), (0.0, 6.0, 8.0), (0.0, -6.0, 8.0), RED, 0.1, 0.6, 0.3,
                                      32.0), (224.4, 76.5, 76.5), group="lengths"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """A hemisphere of normals, the light up and to the left (not a unit vector), the eye to the right."""
    light, eye, color = (-2.0, 1.2, 1.0), (0.8, 0.0, 0.6), (255.0, 128.0, 64.0)
    return [(tuple(float(x) for x in normal), light, eye, color, 0.1, 0.6, 0.3, 8.0) for normal in hemisphere(n)]



EXERCISE = Exercise(
    name="phong", function="phong",
    params=("normal", "to_light", "to_eye", "color", "ka", "kd", "ks", "shininess"),
    section="Phong boyama modeli", term="Phong boyama, ortam / yayılma / parlama",
    summary="ka·C + kd·max(0, N·L)·C + ks·max(0, R·E)^n·255 for one white light",
    doc=DOC, example="list(phong((0, 0, 1), (0, 0.6, 0.8), (0, 0, 1), (255, 0, 0), 0, 1, 0, 32)) == [204, 0, 0]",
    returns="vec3", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("a hemisphere of normals (seen from above) lit from the upper left, the eye to the right",
                _probe_inputs, shade=lambda c: (c[0] + c[1] + c[2]) / 765.0, resolution=64),
    mistakes=MISTAKES, order=70,
)
