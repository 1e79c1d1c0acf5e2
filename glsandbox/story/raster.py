"""A rasterised pixel's story, pass by pass, from the frame's X-ray (:mod:`glsandbox.story.xray`).

For each pass of the Plan (named as ``glsandbox plan`` prints it) the pixel's colour,
depth and stencil before and after it: which passes wrote the pixel, what the stencil
test let through (the mirror's mark, the reflection drawn only where the stencil is 1,
the planar shadow blended once), where the depth test kept the nearer fragment, and a
blended pass's destination and result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from glsandbox.frame import FrameRenderer
from glsandbox.scene import Scene
from glsandbox.story.fragment import blend_values, fragment_values
from glsandbox.story.ray_pixel import locate_pixel
from glsandbox.story.text import num, vec
from glsandbox.story.xray import cleared_depth, pixel_passes, xray

__all__ = ["RasterTrace", "explain_raster_pixel", "render_raster_story"]


@dataclass
class RasterTrace:
    """One rasterised pixel, pass by pass (``passes``: :func:`~glsandbox.story.xray.pixel_passes`'s rows)."""

    title: str
    pixel: tuple[int, int]
    size: tuple[int, int]
    viewport: int
    passes: list[dict[str, Any]]
    rgba8: list[int]
    cleared_depth: float
    notes: list[str]

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)


def explain_raster_pixel(renderer: FrameRenderer, scene: Scene, size: tuple[int, int], pixel: tuple[int, int],
                         title: str = "") -> RasterTrace:
    """Draw ``scene``'s frame with its X-ray and tell pixel ``(x, y)`` (row 0 at the top) pass by pass."""
    index, _, _ = locate_pixel(scene, size, pixel)
    x = xray(renderer, scene, size, trace=False)  # the pixel is rasterised: the traced viewports are not its
    rows = pixel_passes(x, pixel)
    for row, picture in zip(rows, x.passes):
        step = picture.step
        row["kind"] = step.kind
        row["stencil_state"] = step.stencil.describe() if step.stencil is not None else None
        row["blended"] = "blended" in step.describe()
        row["nodes"] = [draw.node for draw in step.draws]
        state, before = step.stencil, row["stencil_before"]
        # The stencil test (course: DrawReflectionDSS): stencil & mask compared with ref & mask.
        row["stencil_passes"] = None if state is None or before is None else \
            (state.test == "always" or (before & state.mask) == (state.ref & state.mask))
        wrote_here = "colour" in row["wrote"] or "depth" in row["wrote"]
        row["fragment"] = fragment_values(scene, size, pixel, index, step.kind, row["node"], row["triangle"]) \
            if wrote_here and row.get("node") and row.get("triangle") is not None else None
        row["blend"] = blend_values(scene, step.kind, row["color_before"], row["color"]) \
            if "colour" in row["wrote"] else None
    return RasterTrace(title or scene.name, (int(pixel[0]), int(pixel[1])), (int(size[0]), int(size[1])), index,
                       rows, [int(v) for v in x.frame[pixel[1], pixel[0]]], cleared_depth(x), x.notes)


def _rgb(c: list[int]) -> str:
    return "(" + ", ".join(str(v) for v in c[:3]) + ")"


def _fragment_lines(row: dict[str, Any]) -> list[str]:
    """What the shader saw (the interpolated values) and a blend's inputs, under a pass's line."""
    lines = []
    f = row.get("fragment")
    if f:
        w = ", ".join(num(x, 4) for x in f["uvw"])
        seen = [f"world position {vec(f['position'])}"]
        if f.get("normal_unit"):
            seen.append(f"normal {vec(f['normal_unit'], 4)} (normalized; interpolated length "
                        f"{num(sum(x * x for x in f['normal']) ** 0.5, 4)})")
        if f.get("uv") is not None:
            seen.append(f"uv {vec(f['uv'], 4)}")
        lines.append(f"   the shader saw (perspective-correct weights {w} of vertices "
                     f"{', '.join(str(i) for i in f['vertices'])}): " + ", ".join(seen) + f"; depth {num(f['depth'])}")
    b = row.get("blend")
    if b:
        lines.append(f"   blend src·a + dst·(1 − a): src {vec(b['source'], 3)}, a = {num(b['alpha'], 3)} "
                     f"({b['alpha8']}/255 in the 8-bit target), dst "
                     f"{_rgb(b['destination'])} → {_rgb(b['result'])} (read back {_rgb(b['read_back'])})")
    return lines


def render_raster_story(trace: RasterTrace) -> str:
    """The numbered story of a :class:`RasterTrace`."""
    far = "0 (reverse-Z: the far plane is 0, nearer is larger)" if trace.cleared_depth < 0.5 else "1 (the far plane)"
    lines = [f"{trace.title}: pixel {trace.pixel[0]},{trace.pixel[1]} of {trace.size[0]}x{trace.size[1]}, rasterised "
             f"(viewport {trace.viewport}); the passes as `glsandbox plan` prints them",
             f"(depth is cleared to {far}; 8-bit colour levels)"]
    lines.extend(f"note: {note}" for note in trace.notes)
    for row in trace.passes:
        head = f"{row['pass']}. {row['name']}"
        if row["stencil_state"]:
            head += f" [stencil {row['stencil_state']}]"
        if row["nodes"]:
            head += f" ({', '.join(row['nodes'])})"
        wrote = row["wrote"]
        if row["kind"] == "clear":
            cleared = [f"colour {_rgb(row['color'])}"] + [f"{name} {num(row[name]) if name == 'depth' else row[name]}"
                                                          for name in ("depth", "stencil") if name in wrote]
            lines.append(f"{head}: cleared to " + ", ".join(cleared))
            continue
        if not wrote and row["stencil_passes"] is False:
            lines.append(f"{head}: the stencil test fails here (the stencil is {row['stencil_before']}): "
                         "nothing is drawn at this pixel")
            continue
        if not wrote:
            why = "nothing it drew covers this pixel, or what did failed the depth or stencil test"
            if row["stencil_passes"]:
                why = (f"the stencil test passes here ({row['stencil_before']}), but nothing it drew covers this "
                       "pixel, or what did failed the depth test")
            lines.append(f"{head}: left the pixel as it was: {why}")
            continue
        parts = []
        if "colour" in wrote:
            verb = "blended over" if row["blended"] else "replaced"
            who = f"; {row['node']}, triangle {row['triangle']}" if row.get("node") else ""
            parts.append(f"colour {_rgb(row['color_before'])} → {_rgb(row['color'])}"
                         + (f" ({verb} the colour before{who})" if row["kind"] != "clear" else ""))
        if "depth" in wrote:
            parts.append(f"depth {num(row['depth_before'])} → {num(row['depth'])}")
        if "stencil" in wrote:
            parts.append(f"stencil {row['stencil_before']} → {row['stencil']}")
        kept = [name for name in ("depth", "stencil") if name not in wrote and row[name] is not None
                and row["kind"] != "clear"]
        text = "; ".join(parts)
        if row["stencil_passes"]:
            text = f"the stencil test passes ({row['stencil_before']}); " + text
        if kept:
            text += "; " + ", ".join(f"{name} kept ({num(row[name]) if name == 'depth' else row[name]})"
                                     for name in kept)
        lines.append(f"{head}: {text}")
        lines.extend(_fragment_lines(row))
    lines.append(f"{len(trace.passes) + 1}. Final colour: {_rgb(trace.rgba8)} in 8-bit levels")
    return "\n".join(lines)
