"""Side by side: one lesson rendered with several values of its parameters.

``glsandbox compare LESSON --vary key=v1,v2,... [--vary key2=...]`` builds one
scene per combination of values and composes them into a single frame, one
tile per variant (a grid for two ``--vary``): the course's split screen, made
of viewports. Each variant's viewports are squeezed into its tile, its nodes
restricted to them, and each looks through its own camera, so every variant
renders exactly as it would alone (at the tile's size).

Variants that cannot share one frame (a stencil mirror, a planar shadow or
reverse-Z depth own the whole frame; lights belong to a whole scene) are
rendered one by one at their tile's size and placed in the frame instead
(:func:`stitch`), so every tile is still what that variant renders alone.

It then tells which variants give identical pictures and how far apart the
others are. Those figures come from each variant rendered alone at the tile
size *without its overlays* (``overlay=off``: no labels, matrices or helper lines such as
a trail; labels and matrices differ by design; the 3D
picture is what is compared), using :mod:`glsandbox.measure.metrics`.

Every value is parsed by its parameter and every scene is built before
anything renders, so a bad value is refused with nothing written.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.lesson import Lesson, Param
from glsandbox.measure import metrics
from glsandbox.overlay import Overlay, text_image
from glsandbox.scene import Node, Scene, Viewport

#: The tile labels' text colour (yellow, to stand apart from a lesson's own white text).
LABEL_COLOR = (255, 230, 60, 255)
#: More tiles than this would be unreadable, and slow.
MAX_TILES = 64


@dataclass(frozen=True)
class Vary:
    """One ``--vary key=v1,v2,...``: the parameter, the texts given and their parsed values."""

    param: Param
    texts: tuple[str, ...]
    values: tuple[object, ...]


@dataclass(frozen=True)
class Variant:
    """One tile: its settings, label and scene."""

    settings: tuple[tuple[str, str], ...]
    label: str
    scene: Scene
    #: The same variant with ``overlay=off`` (no text, figures or helper lines such as a
    #: trail): what the figures compare. None: the scene without its overlays.
    plain: Scene | None = None

    def bare(self) -> Scene:
        """The 3D picture alone, as the figures compare it."""
        return self.plain if self.plain is not None else replace(self.scene, overlays=())


@dataclass
class CompareResult:
    """The composed frame and the figures that compare the variants."""

    image: np.ndarray  # (H, W, 4) uint8, top row first
    variants: list[Variant]
    groups: list[list[int]]  # indices of variants with identical pictures
    pairs: list[dict[str, object]]  # one row per pair of groups: a, b and the metrics
    tile_size: tuple[int, int]
    #: With two or more distinct pictures: where the first two differ (see :func:`difference_image`).
    difference: np.ndarray | None = None

    def report(self) -> str:
        """The text ``glsandbox compare`` prints: identical groups, then the difference table."""
        labels = [v.label for v in self.variants]
        lines = [f"{len(labels)} variants, compared at {self.tile_size[0]}x{self.tile_size[1]} without overlays"]
        same = [g for g in self.groups if len(g) > 1]
        lines.append("identical: " + ("; ".join(" = ".join(labels[i] for i in g) for g in same) if same
                                      else "none"))
        lines.append("distinct pictures: " + str(len(self.groups)))
        if self.pairs:
            header = ("a", "b", "differing px", "max diff", "RMSE", "PSNR dB")
            rows = [header] + [(str(p["a"]), str(p["b"]), f"{100 * float(p['share']):.2f}%", str(p["max"]),
                                f"{float(p['rmse']):.4f}", f"{float(p['psnr']):.1f}") for p in self.pairs]
            widths = [max(len(r[c]) for r in rows) for c in range(len(header))]
            lines.append("pixel differences between the distinct pictures:")
            for r in rows:
                lines.append("  " + "  ".join(cell.ljust(widths[c]) if c < 2 else cell.rjust(widths[c])
                                               for c, cell in enumerate(r)))
        return "\n".join(lines)


def parse_vary(lesson_cls: type[Lesson], text: str) -> Vary:
    """Parse ``key=v1,v2,...`` against the lesson's parameters; every value is validated."""
    param, rest = lesson_cls.setting(text, "--vary", "key=value1,value2,...")
    texts = tuple(t.strip() for t in rest.split(","))
    if any(t == "" for t in texts):
        raise SandboxError(f"--vary {text!r}: empty value; give values separated by commas")
    values = tuple(param.parse(t, "--vary") for t in texts)
    return Vary(param, texts, values)


def build_variants(lesson_cls: type[Lesson], varies: list[str], settings: list[str]) -> tuple[list[Variant], int]:
    """Every combination's scene, built (and so validated) before any rendering.

    Returns the variants in row-major order and the number of grid columns.
    """
    if not varies:
        raise SandboxError("give at least one --vary key=v1,v2,...")
    if len(varies) > 2:
        raise SandboxError(f"--vary given {len(varies)} times; at most 2 (a grid)")
    parsed = [parse_vary(lesson_cls, v) for v in varies]
    keys = [v.param.name for v in parsed]
    if len(set(keys)) != len(keys):
        raise SandboxError(f"--vary {keys[0]} given twice; combine the values in one --vary")
    for item in settings:
        if item.partition("=")[0].strip() in keys:
            raise SandboxError(f"--set {item}: {item.partition('=')[0].strip()} is already varied by --vary")
    count = math.prod(len(v.texts) for v in parsed)
    if count > MAX_TILES:
        raise SandboxError(f"--vary makes {count} variants; at most {MAX_TILES}")
    base = lesson_cls.from_settings(settings)  # validates --set
    variants = []
    # Two --vary: the first runs across the columns, the second down the rows (row-major tiles).
    if len(parsed) == 1:
        combos = [((keys[0], t),) for t in parsed[0].texts]
    else:
        combos = [((keys[0], c), (keys[1], r)) for r in parsed[1].texts for c in parsed[0].texts]
    by_key = {v.param.name: dict(zip(v.texts, v.values)) for v in parsed}
    for combo in combos:
        values = {**base.values, **{k: by_key[k][t] for k, t in combo}}
        lesson = lesson_cls(**values)
        label = ", ".join(f"{k}={t}" for k, t in combo)
        plain = lesson_cls(**{**values, "overlay": False}).scene() if values.get("overlay", True) else None
        variants.append(Variant(tuple(combo), label, lesson.scene(), plain))
    columns = len(parsed[0].texts) if len(parsed) == 2 else math.ceil(math.sqrt(len(variants)))
    return variants, columns


def tile_rects(count: int, columns: int) -> list[tuple[float, float, float, float]]:
    """Tile rectangles (fractions, from the bottom left), row-major from the top left."""
    rows = math.ceil(count / columns)
    w, h = 1.0 / columns, 1.0 / rows
    return [((i % columns) * w, 1.0 - (i // columns + 1) * h, w, h) for i in range(count)]


def compose(variants: list[Variant], columns: int, size: tuple[int, int], labels: bool = True) -> Scene:
    """One scene with every variant in its tile: viewports mapped into the tile,
    nodes and overlays renamed and restricted to their variant's viewports."""
    viewports: list[Viewport] = []
    if len(variants) % columns:
        # A grid with empty cells: nothing would draw there, and a target reused
        # from an earlier frame (the window's, a shared renderer's) would show its
        # old pixels; a first black viewport clears the whole frame.
        viewports.append(Viewport(clear_color=(0.0, 0.0, 0.0, 1.0)))
    nodes: list[Node] = []
    overlays: list[Overlay] = []
    for index, (variant, tile) in enumerate(zip(variants, tile_rects(len(variants), columns))):
        scene = variant.scene
        reason = whole_frame_reason(scene)
        if reason is not None or scene.lights != variants[0].scene.lights:
            # Callers check :func:`composable` first and stitch such variants instead.
            raise SandboxError(f"compare: {scene.name!r} ({variant.label}) cannot share a frame with the other "
                               f"tiles: {reason or 'its lights differ'}")
        tx, ty, tw, th = tile
        first = len(viewports)
        for vp in scene.viewports:
            x, y, w, h = vp.rect
            viewports.append(Viewport(rect=(tx + x * tw, ty + y * th, w * tw, h * th),
                                      clear_color=vp.clear_color if vp.clear_color is not None else scene.clear_color,
                                      camera=vp.camera or scene.camera, label=vp.label,
                                      renderer=vp.renderer))
        mine = tuple(range(first, len(viewports)))
        for node in scene.nodes:
            views = mine if node.viewports is None else tuple(first + v for v in node.viewports)
            nodes.append(replace(node, name=f"{index}/{node.name}", viewports=views))
        for overlay in scene.overlays:
            # A frame-wide overlay goes to the variant's first viewport (the whole tile when it has one).
            region = first + (overlay.viewport or 0)
            overlays.append(replace(overlay, name=f"{index}/{overlay.name}", viewport=region))
        if labels:
            # The tile's label at its bottom-right, in frame pixels (tiles may hold several viewports).
            tile_px = Viewport(rect=tile).pixels(*size)
            image = text_image([variant.label], color=LABEL_COLOR)
            # Overlay positions count from the frame's top; the tile's bottom is size[1] - y there.
            position = (tile_px[0] + tile_px[2] - image.shape[1] - 3, size[1] - tile_px[1] - image.shape[0] - 3)
            overlays.append(Overlay(f"{index}/compare-label", image, None, position))
    return Scene(
        name="compare",
        nodes=tuple(nodes),
        camera=variants[0].scene.camera,
        # Lights are per scene, not per viewport: the first variant's light the
        # whole frame (the figures below render each variant alone, with its own).
        lights=variants[0].scene.lights,
        clear_color=variants[0].scene.clear_color,
        viewports=tuple(viewports),
        samples=max(v.scene.samples for v in variants),
        depth_test=any(v.scene.depth_test for v in variants),
        overlays=tuple(overlays),
    )


def whole_frame_reason(scene: Scene) -> str | None:
    """Why a scene cannot be one tile of a shared frame, or None.

    A mirror and a planar shadow own the frame's stencil bits, reverse-Z
    owns its depth convention (glClipControl): they belong to a whole frame.
    """
    if scene.mirror is not None:
        return "it has a stencil mirror"
    if scene.planar_shadow is not None:
        return "it has a planar shadow"
    if scene.depth_mode != "standard":
        return f"it uses {scene.depth_mode} depth"
    return None


def composable(variants: list[Variant]) -> str | None:
    """None when every variant can be a viewport of one frame; else why not.

    Besides whole-frame effects, lights are per scene, not per viewport: variants
    with different lights (e.g. ``--vary lights=0,1,2``) cannot share one frame.
    """
    for variant in variants:
        reason = whole_frame_reason(variant.scene)
        if reason is not None:
            return f"{variant.label}: {reason}"
        if variant.scene.lights != variants[0].scene.lights:
            return f"{variant.label}: its lights differ from {variants[0].label}'s"
    return None


def stitch(variants: list[Variant], columns: int, size: tuple[int, int], renderer,
           labels: bool = True) -> np.ndarray:
    """The frame made of tiles rendered one by one, each variant alone at its
    tile's size, then placed where :func:`compose` would have put its viewport."""
    frame = np.zeros((size[1], size[0], 4), dtype=np.uint8)
    for variant, tile in zip(variants, tile_rects(len(variants), columns)):
        x, y, w, h = Viewport(rect=tile).pixels(*size)
        if w <= 0 or h <= 0:
            continue
        top = size[1] - y - h  # tile rects count from the bottom, image rows from the top
        frame[top:top + h, x:x + w] = renderer.render_scene(variant.scene, (w, h)).image
        if labels:
            _paste(frame, text_image([variant.label], color=LABEL_COLOR), x + w - 3, top + h - 3)
    return frame


def _paste(frame: np.ndarray, image: np.ndarray, right: int, bottom: int) -> None:
    """Alpha-blend ``image`` into ``frame`` with its bottom-right corner at (right, bottom)."""
    h, w = image.shape[:2]
    x0, y0 = max(right - w, 0), max(bottom - h, 0)
    part = image[h - (bottom - y0):, w - (right - x0):].astype(np.float32)
    region = frame[y0:bottom, x0:right]
    alpha = part[..., 3:4] / 255.0
    region[..., :3] = np.round(part[..., :3] * alpha + region[..., :3] * (1.0 - alpha)).astype(np.uint8)
    region[..., 3] = 255


def group_identical(images: list[np.ndarray]) -> list[list[int]]:
    """Indices grouped by exactly equal pixels, in first-seen order."""
    groups: list[list[int]] = []
    for i, image in enumerate(images):
        for group in groups:
            if np.array_equal(images[group[0]], image):
                group.append(i)
                break
        else:
            groups.append([i])
    return groups


def difference_rows(images: list[np.ndarray], labels: list[str], groups: list[list[int]]) -> list[dict[str, object]]:
    """Metrics for every pair of groups (their first members)."""
    rows = []
    for g1, g2 in itertools.combinations(groups, 2):
        a, b = images[g1[0]], images[g2[0]]
        rows.append({"a": labels[g1[0]], "b": labels[g2[0]], "share": metrics.mismatch_share(a, b),
                     "max": metrics.max_abs_diff(a, b), "rmse": metrics.rmse(a, b), "psnr": metrics.psnr(a, b)})
    return rows


def compare(lesson_cls: type[Lesson], varies: list[str], settings: list[str], size: tuple[int, int],
            renderer) -> CompareResult:  # renderer: glsandbox.frame.HeadlessRenderer
    """Render the composed frame and compare the variants (see the module doc)."""
    variants, columns = build_variants(lesson_cls, varies, settings)
    return compare_variants(variants, columns, size, renderer)


def render_grid(variants: list[Variant], columns: int, size: tuple[int, int], renderer) -> np.ndarray:
    """The labelled tiles in one frame of ``size``: composed as viewports of one scene
    where the variants can share a frame, else rendered one by one and stitched."""
    if composable(variants) is None:
        return renderer.render_scene(compose(variants, columns, size), size).image
    return stitch(variants, columns, size, renderer)


def compare_variants(variants: list[Variant], columns: int, size: tuple[int, int], renderer,
                     advance: Callable[[int], object] = lambda n: None) -> CompareResult:
    """Render already built variants: the composed frame, then each alone for the figures.

    ``advance(n)`` is told as the work goes: ``len(variants)`` for the composed
    frame, then 1 per variant drawn alone (a progress bar's ``update``).
    """
    rows = math.ceil(len(variants) / columns)
    tile = (max(1, size[0] // columns), max(1, size[1] // rows))
    image = render_grid(variants, columns, size, renderer)
    advance(len(variants))
    alone = []
    for v in variants:
        alone.append(renderer.render_scene(v.bare(), tile).image.copy())
        advance(1)
    groups = group_identical(alone)
    labels = [v.label for v in variants]
    difference = difference_image(alone[groups[0][0]], alone[groups[1][0]]) if len(groups) > 1 else None
    return CompareResult(image, variants, groups, difference_rows(alone, labels, groups), tile, difference)


#: How much :func:`difference_image` amplifies: a difference of 64 levels is white.
DIFFERENCE_GAIN = 4


def difference_image(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Where two pictures differ: the largest channel difference per pixel, times
    :data:`DIFFERENCE_GAIN`, as grey on black (e.g. raster against ray: the
    shadows, the silhouettes of tessellated spheres, per-vertex lighting)."""
    d = np.abs(a[..., :3].astype(np.int16) - b[..., :3].astype(np.int16)).max(axis=2)
    grey = np.clip(d * DIFFERENCE_GAIN, 0, 255).astype(np.uint8)
    return np.dstack([grey, grey, grey, np.full_like(grey, 255)])


def default_out(lesson_name: str, given: str | None = None) -> Path:
    """``compare_LESSON.png``; for a lesson file, its whole name with the dot made ``_``
    (``compare_my_lesson_py.png``, ``compare_my_lesson_toml.png``), so comparing
    ``my_lesson.py`` and ``my_lesson.toml`` never writes one file over the other."""
    if given is not None and Path(given).suffix.lower() in (".py", ".toml"):
        return Path(f"compare_{Path(given).name.replace('.', '_')}.png")
    return Path(f"compare_{lesson_name}.png")
