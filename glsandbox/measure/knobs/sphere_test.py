"""Ray-sphere tests (course section "Işın-Küre kesim testi"): the
course's geometric test against the numerically stable quadratic (Ray Tracing
Gems, chapter 7), on a unit sphere seen from farther and farther away.

The eye sits at the origin and the sphere's centre at a distance ``D`` along
(0.99, 0.7, -0.4), the lens narrowing with ``D`` so the sphere fills the same
part of every frame. The geometric test forms ``m² = l·l − s²``, two numbers
near ``D²`` subtracted: at ``D = 1e8`` their rounding (about 1 unit) is as big
as ``r² = 1``, so ``t`` loses every digit below the units, the hit point
leaves the sphere and the silhouette frays. The stable form gets ``m`` from a
vector difference and keeps ``t`` to float64's own rounding of ``D``.

Both are judged against the exact hit: the quadratic solved in 60-digit
decimal arithmetic from the same float64 inputs.
"""

from __future__ import annotations

import functools
from decimal import Decimal, localcontext

import numpy as np
from numpy.typing import NDArray

from glsandbox.measure.knob import Knob, PixelCount, Setting, register_knob
from glsandbox.measure.knobs._far import DIRECTION
from glsandbox.measure.render_context import RenderContext
from glsandbox.raytrace.sphere import Sphere
from glsandbox.raytrace.vec import dot, length

#: The sphere's radius, and how much of the frame's height it spans.
RADIUS = 1.0
FILL = 0.75
#: A hit whose ``t`` is off the exact one by more than this share of the radius is wrong.
T_TOLERANCE = 1e-6
#: Digits of the exact reference.
DIGITS = 60
#: Where the light comes from (a direction, from the sphere towards it).
LIGHT = np.array([-0.5, 0.8, 0.6]) / np.linalg.norm([-0.5, 0.8, 0.6])


@functools.lru_cache(maxsize=16)
def view(size: tuple[int, int], distance: float) -> tuple[Sphere, NDArray[np.float64]]:
    """The sphere at ``distance`` and one primary ray direction per pixel from the
    origin (not unit length), row by row: the sphere spans :data:`FILL` of the height."""
    forward = DIRECTION / np.linalg.norm(DIRECTION)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = RADIUS / FILL / distance  # tan of half the vertical field of view
    width, height = size
    x = ((np.arange(width) + 0.5) / width * 2.0 - 1.0) * half * width / height
    y = (1.0 - (np.arange(height) + 0.5) / height * 2.0) * half
    xx, yy = np.meshgrid(x, y)
    directions = forward + xx.reshape(-1, 1) * right + yy.reshape(-1, 1) * up
    return Sphere(distance * forward, RADIUS), directions


def geometric_many(sphere: Sphere, directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """The course's geometric test for rays from the origin, vectorized: the steps of
    :meth:`Sphere._intersect_geometric` (``l``, ``s``, ``m² = l·l − s²``, ``q``,
    ``t = s − q`` from outside), ``inf`` for a miss. ``t`` in units of ``directions``."""
    d_len = length(directions)
    d = directions / d_len[:, None]  # the course's Rd is a unit vector
    l = sphere.center - np.zeros(3)  # noqa: E741 (the course's l = C − O, with O the origin)
    s = dot(l, d)
    l2 = float(dot(l, l))
    r2 = sphere.radius * sphere.radius
    m2 = l2 - s * s
    hit = (m2 <= r2) & (s >= 0.0)  # the eye is outside the sphere: the entry point
    t = s - np.sqrt(np.where(hit, r2 - m2, 0.0))
    return np.where(hit & (t > 0.0), t / d_len, np.inf)


def stable_many(sphere: Sphere, directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """The stable test (:meth:`Sphere.intersect_many`) for rays from the origin."""
    return sphere.intersect_many(np.zeros(3), directions)


@functools.lru_cache(maxsize=16)
def exact_t(size: tuple[int, int], distance: float) -> NDArray[np.float64]:
    """The exact entry ``t`` of every ray (``inf``: a miss), from the float64 centre,
    radius and directions: ``t = (b − sqrt(b² − a·c))/a`` with ``a = d·d``, ``b = l·d``,
    ``c = l·l − r²``, in :data:`DIGITS`-digit decimals (every product of two doubles
    is exact there), rounded to float64 at the end."""
    sphere, directions = view(size, distance)
    out = np.full(len(directions), np.inf)
    with localcontext() as ctx:
        ctx.prec = DIGITS
        centre = [Decimal(float(v)) for v in sphere.center]
        r = Decimal(sphere.radius)
        c = sum(v * v for v in centre) - r * r
        for i, row in enumerate(directions.tolist()):
            d = [Decimal(v) for v in row]
            a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            b = d[0] * centre[0] + d[1] * centre[1] + d[2] * centre[2]
            disc = b * b - a * c
            if disc >= 0 and b > 0:
                out[i] = float((b - disc.sqrt()) / a)
    return out


TESTS = {"geometric": geometric_many, "stable": stable_many}


def shade(sphere: Sphere, directions: NDArray[np.float64], t: NDArray[np.float64], size: tuple[int, int]) -> np.ndarray:
    """Diffuse grey from the normal ``(P − C)/|P − C|`` at ``P = t·d``, black for a miss:
    a hit point off the sphere turns its normal, and the shading shows it."""
    hit = np.isfinite(t)
    points = np.where(hit[:, None], t[:, None], 0.0) * directions
    normal = points - sphere.center
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    level = 0.1 + 0.9 * np.clip(normal @ LIGHT, 0.0, 1.0)
    grey = np.where(hit, np.rint(255.0 * level), 0.0).astype(np.uint8)
    image = np.empty((len(t), 4), np.uint8)
    image[:, :3] = grey[:, None]
    image[:, 3] = 255
    return image.reshape(size[1], size[0], 4)


def wrong(t: NDArray[np.float64], exact: NDArray[np.float64], radius: float = RADIUS) -> NDArray[np.bool_]:
    """Rays whose answer is wrong: a hit against an exact miss or the reverse, or ``t``
    off by more than :data:`T_TOLERANCE` of the radius (the directions are unit length
    within 1e-9 here, so ``t`` is a distance)."""
    got, want = np.isfinite(t), np.isfinite(exact)
    both = got & want
    off = np.zeros_like(both)
    off[both] = np.abs(t[both] - exact[both]) > T_TOLERANCE * radius
    return (got != want) | off


def setting(test: str, distance: float) -> Setting:
    label = f"{test}, at {distance:g}"

    def render(c: RenderContext) -> np.ndarray:
        sphere, directions = view(c.size, distance)
        return shade(sphere, directions, TESTS[test](sphere, directions), c.size)

    def count(c: RenderContext) -> PixelCount:
        sphere, directions = view(c.size, distance)
        exact = exact_t(c.size, distance)
        return PixelCount(int(np.count_nonzero(wrong(TESTS[test](sphere, directions), exact))), len(exact))

    return Setting(label, render, "", count)


def exact_setting(distance: float) -> Setting:
    def render(c: RenderContext) -> np.ndarray:
        sphere, directions = view(c.size, distance)
        exact_t.cache_clear()  # timed: the exact solve itself, not a cached answer
        return shade(sphere, directions, exact_t(c.size, distance), c.size)

    def count(c: RenderContext) -> PixelCount:
        return PixelCount(0, c.size[0] * c.size[1])

    return Setting(f"exact ({DIGITS} digits), at {distance:g}", render, "", count)


KNOB = register_knob(Knob(
    name="sphere_test",
    title="Ray-sphere test: geometric against the stable quadratic",
    order=38,
    scene=(f"a sphere of radius {RADIUS:g} at a distance from the eye (at the origin) along (0.99, 0.7, -0.4), "
           f"the field of view narrowed so it spans {FILL:.0%} of the height at every distance; one primary "
           "ray per pixel, diffuse grey from the normal at the hit point"),
    settings=(
        setting("geometric", 1e2), setting("geometric", 1e4), setting("geometric", 1e6),
        setting("geometric", 1e7), setting("geometric", 1e8),
        setting("stable", 1e2), setting("stable", 1e8),
    ),
    reference=exact_setting(1e8),
    reference_note=(f"the exact hit at 1e8: the quadratic solved in {DIGITS}-digit decimals from the same float64 "
                    "centre, radius and directions (each setting's wrong pixels are counted against the exact "
                    "hit at its own distance; the pictures of every distance are the same view)"),
    quick=("geometric, at 10000", "geometric, at 1e+08", "stable, at 1e+08"),
    count_label="wrong px",
    count_of="px",
    notes=(
        f"wrong px (of the whole frame; the sphere covers about a third of it): a hit where the exact test "
        f"misses or the reverse, or a hit whose t is off the exact t by more than {T_TOLERANCE:g} of the "
        "radius (well above float64's rounding of t even at 1e8, where one unit in the last place of t is "
        "1.5e-8; the stable test stays within 1e-7 there).",
        "The geometric test's m² = l·l − s² cancels D² against D²: its error in t grows as D² (about "
        "eps·D²/r), a millionth of the radius near D = 1e4-1e5 and the whole radius at 1e8, where the "
        "silhouette frays and the shading breaks up. The stable form's error grows as eps·D (t's own "
        "rounding).",
        "The two cost about the same per ray; the exact reference is slow (Python decimals, one ray at a "
        "time) and there only to judge them.",
    ),
))
