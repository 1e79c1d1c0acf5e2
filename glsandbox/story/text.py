"""A ray-traced pixel's record as a story a student follows: numbered steps, the course's names.

The numbers are printed with six significant digits (``35``, not
``35.00000000000001``); a vector's components far below its largest are
printed as 0; a colour is in 0..1 with its 8-bit levels at the end.
Coordinates are the scene's (OpenGL, right-handed): the course's DirectX
points have ``z`` mirrored (the notes' (0, 21, 28) is (0, 21, −28) here).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from glsandbox.story.ray_pixel import Bounce, LightStep, PixelTrace, ShapeTest

__all__ = ["num", "render_story", "vec"]


def num(x: float | None, digits: int = 6) -> str:
    """A number with ``digits`` significant digits, ``-0`` printed as ``0``."""
    if x is None:
        return "none"
    if not math.isfinite(x):
        return "inf" if x > 0 else ("-inf" if x < 0 else "nan")
    text = f"{x:.{digits}g}"
    return "0" if text in ("-0", "0") else text


def vec(v: Sequence[float] | None, digits: int = 6) -> str:
    """``(x, y, z)``, components below 1e-12 of the largest printed as 0."""
    if v is None:
        return "none"
    big = max((abs(c) for c in v), default=0.0)
    return "(" + ", ".join("0" if abs(c) <= 1e-12 * big else num(c, digits) for c in v) + ")"


def _test_line(test: ShapeTest) -> str:
    head = f"{test.node} ({test.kind})"
    v = test.values
    if test.verdict == "box":
        return f"{head}: {test.why}"
    if test.kind == "sphere" and "s" in v:
        where = "" if v["space"] == "world" else " (in its own space, where it is the unit sphere)"
        parts = [f"C = {vec(v['C'])}, r = {num(v['r'])}{where}", f"l = C − R0 = {vec(v['l'])}",
                 f"s = l·Rd = {num(v['s'])}", f"m² = l·l − s² = {num(v['m2'])}"]
        if "q" in v:
            parts.append(f"q = √(r² − m²) = {num(v['q'])}")
        text = f"{head}: " + ", ".join(parts) + f"; {test.why}"
        if test.verdict == "hit":
            text += f" = {num(v['t_unit'])}"
            if abs(v["direction_length"] - 1.0) > 1e-12:
                text += f" along the unit Rd, t = {num(test.t)} along the ray as cast"
            return text + " → hit"
        return text + f" → {test.verdict}"
    if test.kind == "mesh":
        lines = [f"{head}: {test.why}" + (f", t = {num(test.t)} → hit" if test.verdict == "hit" else
                                           f" → {test.verdict}")]
        for tri in v.get("each", []):
            lines.append(f"   triangle {tri['triangle']}: plane N = {vec(tri['N'], 4)}, D = {num(tri['D'])}; "
                         f"N·Rd = {num(tri['N_dot_Rd'], 4)}, t = −(N·R0 + D)/(N·Rd) = {num(tri['t_plane'])}; "
                         f"u = {num(tri['u'], 4)}, v = {num(tri['v'], 4)} → {tri['verdict']}")
        if "each" not in v:
            one = v.get("hit") or v.get("nearest")
            if one is not None:
                lines.append(f"   triangle {one['triangle']}: plane D = {num(one['D'])}, t = {num(one['t_plane'])}, "
                             f"u = {num(one['u'], 4)}, v = {num(one['v'], 4)}")
        return "\n".join(lines)
    return f"{head}: {test.why} → {test.verdict}"


def _light_lines(light: LightStep, base: Sequence[float]) -> list[str]:
    lines = [f"light {light.index} at {vec(light.position)}, colour {vec(light.color, 3)}: "
             f"L = {vec(light.to_light, 4)}, N·L = {num(light.n_dot_l, 4)}"]
    if light.shadows and light.origin is not None:
        verdict = (f"blocked by {light.blocker} at s = {num(light.blocker_s, 4)} "
                   f"(t = {num((light.blocker_s or 0.0) * (light.distance or 0.0))} < {num(light.distance)}): "
                   "in shadow, only the ambient term stays") if light.blocked else \
            "nothing at 0 < s < 1 (s = 1 is the light): lit" + (" (no matter here: N·L ≤ 0)" if light.n_dot_l <= 0 else "")
        if light.blocked and light.blocker is None:
            verdict = "blocked: in shadow, only the ambient term stays"
        lines.append(f"   shadow ray (Gölge testi) from P moved {num(light.offset, 3)} off the surface to "
                     f"{vec(light.origin)}, distance {num(light.distance)} to the light: {verdict}")
    spec = "N·H" if light.blinn else "R·E"
    kd_diffuse = [light.kd * c for c in light.diffuse]
    ks_specular = [light.ks * c for c in light.specular]
    lines.append(f"   ka·ambient = ka·colour = {num(light.ka, 3)}·{vec(base, 4)} = {vec(light.ambient, 4)}")
    if light.n_dot_l <= 0.0:
        lines.append("   N·L ≤ 0: the light is behind the surface, no diffuse and no specular")
    else:
        lines.append(f"   kd·diffuse = kd·max(N·L, 0)·colour⊙light = {num(light.kd, 3)}·{num(light.n_dot_l, 4)}·"
                     f"{vec(base, 4)}⊙{vec(light.color, 3)} = {vec(kd_diffuse, 4)}")
        lines.append(f"   ks·specular = ks·max({spec}, 0)^{num(light.shininess)}·light = {num(light.ks, 3)}·"
                     f"{num(max(light.cosine, 0.0), 4)}^{num(light.shininess)}·{vec(light.color, 3)} = "
                     f"{vec(ks_specular, 4)}")
    shadowed = "  (in shadow: the ambient term alone)" if light.blocked else ""
    if light.given is not None:  # an exercise's phong gave the term (glsandbox.story.seams)
        lines.append(f"   the function's phong(N, L, E, 255·colour, ka, kd, ks, n)/255, each channel at most 1: "
                     f"{vec(light.term, 4)}")
        return lines
    lines.append(f"   ka·ambient + kd·diffuse + ks·specular, each channel at most 1: {vec(light.term, 4)}{shadowed}")
    return lines


def _bounce_lines(bounce: Bounce, step: list[int], trace: PixelTrace) -> list[str]:
    lines: list[str] = []

    def add(text: str) -> None:
        step[0] += 1
        lines.append(f"{step[0]}. {text}")

    name = "Primary ray (Bakış noktası → image plane)" if bounce.depth == 0 else \
        ("Reflected ray (Yansıma)" if trace.bounces[bounce.depth - 1].next == "reflection" else "Ray behind the surface")
    add(f"{name}, depth {bounce.depth}, weight {num(bounce.weight, 4)}: R = R0 + t·Rd, R0 = {vec(bounce.origin)}, "
        f"Rd = {vec(bounce.direction)}")
    add("Each shape's test (tDistances):")
    lines.extend(f"   {line}" for test in bounce.tests for line in _test_line(test).split("\n"))
    if bounce.hit is None:
        add(f"Nearest hit: none; the ray shows the background {vec(trace.background, 4)}, "
            f"times its weight: {vec(bounce.contribution, 4)}")
        return lines
    tri = f", triangle {bounce.triangle}" if bounce.triangle is not None else ""
    found = [f"{test.node} {num(test.t)}" for test in bounce.tests if test.verdict == "hit"]
    among = f" (the smallest t of {', '.join(found)})" if len(found) > 1 else ""
    add(f"Nearest hit (min_indis): {bounce.hit}{tri} at t = {num(bounce.t)}{among}, P = R0 + t·Rd = "
        f"{vec(bounce.point)}, normal N = {vec(bounce.normal, 4)}")
    base = bounce.base or [0.0, 0.0, 0.0]
    if not bounce.lit:
        add(f"Colour: {vec(base, 4)} (unlit: its own colour)")
    else:
        add(f"Phong (per light, summed): colour {vec(base, 4)}")
        for light in bounce.lights:
            lines.extend(f"   {line}" for line in _light_lines(light, base))
        add(f"Local colour: {vec(bounce.local, 4)}")
    if bounce.last and bounce.depth > 0:
        lines.append("   (the last bounce: its local colour stands in for what it would reflect)")
    if bounce.next == "reflection":
        following = trace.bounces[bounce.depth + 1] if bounce.depth + 1 < len(trace.bounces) else None
        direction = vec(following.direction) if following else "?"
        add(f"Reflectivity r = {num(bounce.reflectivity, 3)}: this ray adds w·(1 − r)·local = "
            f"{vec(bounce.contribution, 4)}; the reflected ray R = Rd − 2(Rd·N)N = {direction} carries w·r")
    elif bounce.next == "through":
        add(f"Coverage a = {num(bounce.coverage, 3)}: this ray adds w·a·local = {vec(bounce.contribution, 4)}; "
            "the ray goes on behind the surface with w·(1 − a)")
    else:
        add(f"Adds w·local = {vec(bounce.contribution, 4)}" + (" (no reflection)" if bounce.reflectivity == 0 else ""))
    return lines


def render_story(trace: PixelTrace) -> str:
    """The numbered story of a :class:`PixelTrace`."""
    who = {"ray": "the GLSL engine (float32) draws this viewport; this is the float64 reference "
                  "(renderer=ray_numpy), which may differ from it by a level",
           "ray_numpy": "the numpy engine (float64) draws this viewport"}[trace.renderer]
    where = "" if trace.viewport_size == trace.size else \
        f" (viewport {trace.viewport}, its pixel {trace.local_pixel[0]},{trace.local_pixel[1]})"
    lines = [f"{trace.title}: pixel {trace.pixel[0]},{trace.pixel[1]} of {trace.size[0]}x{trace.size[1]}{where}",
             f"({who}; reflections to depth {trace.max_depth}; scene coordinates, OpenGL's: the course's z is "
             "mirrored)"]
    lines.extend(f"note: {note}" for note in trace.notes)
    step = [0]
    for bounce in trace.bounces:
        lines.extend(_bounce_lines(bounce, step, trace))
    step[0] += 1
    levels = ", ".join(str(v) for v in trace.rgba8[:3])
    lines.append(f"{step[0]}. Final colour: the rays' shares added up = {vec(trace.color, 4)}, clamped to 0..1, "
                 f"⌊255·c + ½⌋ = ({levels}) in 8-bit levels")
    return "\n".join(lines)
