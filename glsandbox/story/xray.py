"""The X-ray of a rasterised frame: the target's colour, depth and stencil after every pass.

:func:`xray` draws one frame of a Scene on a :class:`~glsandbox.frame.FrameRenderer`
with the executor's ``after_pass`` hook: after each pass of the Plan (the passes
``glsandbox plan`` prints) the target is read back (:mod:`glsandbox.gl.rawgl`, the one
raw-GL module). :func:`write_xray` writes each pass's pictures and a contact sheet
(``glsandbox render LESSON --xray DIR``); :func:`pixel_passes` tells one pixel's story
pass by pass: which passes wrote it, its depth and stencil before and after.

The frame is drawn without MSAA (a multisampled target cannot be read pixel by pixel):
an MSAA scene's X-ray is of its frame with ``samples = 0``.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.errors import SandboxError
from glsandbox.files import save_png
from glsandbox.frame import FrameRenderer, with_samples
from glsandbox.overlay import text_image
from glsandbox.plan import Pass
from glsandbox.scene import Scene

__all__ = ["PassPicture", "XRay", "pass_name", "pixel_passes", "xray", "write_xray"]


def pass_name(step: Pass) -> str:
    """A pass's name as ``glsandbox plan`` prints it, up to its details (``mark mirror viewport 0``)."""
    return step.describe().split(" (", 1)[0].split(":", 1)[0]


@dataclass
class PassPicture:
    """The target after one pass: ``color`` (H, W, 4) uint8, ``depth`` (H, W) float32 in 0..1
    (None without a depth buffer), ``stencil`` (H, W) uint8 (None without one), ``ids`` (H, W, 2)
    uint32: the node (its place in the scene's nodes + 1, 0 for none) and the triangle of the
    last fragment written there; top row first."""

    number: int
    name: str
    description: str
    step: Pass
    color: NDArray[np.uint8]
    depth: NDArray[np.float32] | None
    stencil: NDArray[np.uint8] | None
    ids: NDArray[np.uint32] | None = None


@dataclass
class XRay:
    """A frame's passes (:class:`PassPicture` each, in order) and the frame they make."""

    passes: list[PassPicture]
    frame: NDArray[np.uint8]
    notes: list[str] = field(default_factory=list)
    #: The nodes the ids number: ``node_names[k - 1]`` is node ``k``.
    node_names: list[str] = field(default_factory=list)

    def rebuilt(self) -> NDArray[np.uint8]:
        """The frame put together again from the passes: each pass's pixels where it
        changed the colour, over what the passes before it left (the first over black)."""
        out = np.zeros_like(self.frame)
        previous = np.zeros_like(self.frame)
        for picture in self.passes:
            changed = np.any(picture.color != previous, axis=2)
            out[changed] = picture.color[changed]
            previous = picture.color
        return out


#: The X-ray renderers (primitive ids on), one per renderer X-rayed with, on its context.
_ID_RENDERERS: weakref.WeakKeyDictionary[FrameRenderer, FrameRenderer] = weakref.WeakKeyDictionary()


def id_renderer(renderer: FrameRenderer) -> FrameRenderer:
    """A renderer on ``renderer``'s context drawing with the primitive-id target (its own
    programs and targets, made once and kept while ``renderer`` lives)."""
    if renderer.primitive_ids:
        return renderer
    kept = _ID_RENDERERS.get(renderer)
    if kept is None:
        kept = _ID_RENDERERS[renderer] = FrameRenderer(renderer.host, primitive_ids=True)
    return kept


def xray(renderer: FrameRenderer, scene: Scene, size: tuple[int, int], trace: bool = True) -> XRay:
    """Draw one frame of ``scene`` at ``size`` on ``renderer``'s context and keep the target after
    every pass, with the primitive ids (:func:`id_renderer`). ``trace=False`` leaves the
    ray-traced viewports blank (their clear colour; the passes are the same): a rasterised
    pixel's story needs only its own viewport, and tracing another one costs more than the frame."""
    notes = []
    if scene.samples:
        notes.append(f"drawn without MSAA (the scene asks for {scene.samples}x): a multisampled "
                     "target cannot be read pixel by pixel")
        scene = with_samples(scene, 0)
    drawer = id_renderer(renderer)
    raw = drawer.host.raw
    width, height = size
    pictures: list[PassPicture] = []

    def after_pass(index: int, step: Pass) -> None:
        if step.target != "frame":  # a shadow map's own depth texture: not the frame's buffers
            notes.append(f"{pass_name(step)} draws into {step.target}, not the frame: not pictured")
            return
        fbo = raw.bound_framebuffer()
        if step.kind == "clear" and drawer.executor.pass_rect is not None:
            raw.clear_ids(drawer.executor.pass_rect)  # integer ids: a float clear leaves them undefined
        depth_bits, stencil_bits = raw.attachment_bits(fbo)
        color = raw.read_pixels(fbo, size, "color")
        depth = raw.read_pixels(fbo, size, "depth") if depth_bits else None
        previous = pictures[-1] if pictures else None
        if not stencil_bits:
            stencil = None
        elif step.stencil is None and step.kind != "clear" and previous is not None:
            stencil = previous.stencil  # no stencil test, no stencil writes: what the pass before left
        else:
            stencil = raw.read_pixels(fbo, size, "stencil")
        ids = raw.read_pixels(fbo, size, "ids") if drawer.primitive_ids else None
        pictures.append(PassPicture(len(pictures) + 1, pass_name(step), step.describe(), step, color, depth, stencil,
                                    ids))

    drawer.host.make_current()
    traced = scene
    if any(vp.renderer != "raster" for vp in scene.viewports):
        from glsandbox.frame import trace_viewports

        traced = trace_viewports(scene, size, drawer.host.ctx) if trace else _blank_traced(scene, size, notes)
    _, target = drawer.draw(traced, size, after_pass=after_pass)
    frame = np.array(target.read())
    return XRay(pictures, frame, notes, [node.name for node in traced.nodes])


def _blank_traced(scene: Scene, size: tuple[int, int], notes: list[str]) -> Scene:
    """``scene`` as :func:`~glsandbox.frame.trace_viewports` makes it, each traced image its viewport's
    clear colour (the same passes, nothing traced)."""
    from glsandbox.overlay import Overlay
    from glsandbox.plan import traced_image_name, traced_scene

    images = {}
    for i, vp in enumerate(scene.viewports):
        w, h = vp.pixels(*size)[2:]
        if vp.renderer != "raster" and w > 0 and h > 0:
            blank = np.zeros((h, w, 4), dtype=np.uint8)
            blank[...] = np.round(np.clip(np.asarray(vp.clear_color if vp.clear_color is not None else scene.clear_color,
                                                  dtype=np.float64), 0.0, 1.0) * 255.0)
            blank[..., 3] = 255
            images[i] = Overlay(traced_image_name(i), blank, viewport=i, position=(0, 0), scalable=False)
    if images:
        notes.append(f"the ray-traced viewport{'s' if len(images) > 1 else ''} "
                     f"{', '.join(str(i) for i in images)} left untraced (its clear colour): this pixel is not in it")
    return traced_scene(scene, images)


# --- pictures ------------------------------------------------------------------


def depth_picture(depth: NDArray[np.float32], far: float = 1.0) -> NDArray[np.uint8]:
    """Depth as grey: the cleared value ``far`` (1.0, or 0.0 with reverse-Z) white, the nearest
    drawn depth black, the drawn range stretched between (a perspective depth crowds near the
    far value: shown as it is it would all look cleared)."""
    drawn = depth != far
    grey = np.full(depth.shape, 255, dtype=np.uint8)
    if drawn.any():
        values = depth[drawn]
        near_end = float(values.max()) if far < 0.5 else float(values.min())  # reverse-Z: near is 1
        far_end = float(values.min()) if far < 0.5 else float(values.max())
        span = (far_end - near_end) or 1.0
        grey[drawn] = np.round(200.0 * np.clip((values - near_end) / span, 0.0, 1.0)).astype(np.uint8)
    return _rgba(grey)


def cleared_depth(x: XRay) -> float:
    """The value the frame's depth is cleared to (the most common one after the first pass
    that has depth): 1.0, or 0.0 with reverse-Z."""
    for picture in x.passes:
        if picture.depth is not None:
            values, counts = np.unique(picture.depth, return_counts=True)
            return float(values[np.argmax(counts)])
    return 1.0


#: Stencil values as colours: 0 black, then distinct colours for the bits the passes use.
_STENCIL_COLORS = np.array([[0, 0, 0], [230, 60, 60], [60, 200, 90], [240, 220, 60], [70, 120, 240],
                            [220, 90, 220], [60, 210, 220], [250, 250, 250]], dtype=np.uint8)


def stencil_picture(stencil: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Stencil values as colours (0 black, 1 red, 2 green, 3 yellow, ...; above 7 white)."""
    rgb = _STENCIL_COLORS[np.minimum(stencil, len(_STENCIL_COLORS) - 1)]
    return np.concatenate([rgb, np.full((*stencil.shape, 1), 255, dtype=np.uint8)], axis=2)


def _rgba(grey: NDArray[np.uint8]) -> NDArray[np.uint8]:
    return np.concatenate([np.repeat(grey[..., None], 3, axis=2), np.full((*grey.shape, 1), 255, np.uint8)], axis=2)


def _slug(text: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in text).strip("_")


def contact_sheet(x: XRay, thumb_width: int = 240) -> NDArray[np.uint8]:
    """One picture: a row per pass (its number and name, then colour | depth | stencil)."""
    height, width = x.frame.shape[:2]
    step = max(1, -(-width // thumb_width))  # every step-th pixel: a thumbnail no wider than thumb_width
    rows = []
    far = cleared_depth(x)
    for picture in x.passes:
        tiles = [picture.color]
        if picture.depth is not None:
            tiles.append(depth_picture(picture.depth, far))
        if picture.stencil is not None:
            tiles.append(stencil_picture(picture.stencil))
        small = [tile[::step, ::step] for tile in tiles]
        label = np.asarray(text_image([f"{picture.number}. {picture.name}"]))
        th, tw = small[0].shape[:2]
        row_h = th + label.shape[0] + 4
        row_w = max(len(small) * (tw + 4), label.shape[1])
        row = np.full((row_h, row_w, 4), 40, dtype=np.uint8)
        row[..., 3] = 255
        row[:label.shape[0], :label.shape[1]] = label
        for k, tile in enumerate(small):
            row[label.shape[0] + 2:label.shape[0] + 2 + th, k * (tw + 4):k * (tw + 4) + tw] = tile
        rows.append(row)
    if not rows:
        return x.frame.copy()
    sheet_w = max(r.shape[1] for r in rows)
    sheet = np.full((sum(r.shape[0] for r in rows), sheet_w, 4), 40, dtype=np.uint8)
    sheet[..., 3] = 255
    y = 0
    for row in rows:
        sheet[y:y + row.shape[0], :row.shape[1]] = row
        y += row.shape[0]
    return sheet


def write_xray(x: XRay, folder: Path) -> list[Path]:
    """Each pass's ``NN_name_color.png`` (and ``_depth``, ``_stencil``), and ``contact_sheet.png``,
    in ``folder`` (made if missing; each file written whole or not at all)."""
    if folder.exists() and not folder.is_dir():
        raise SandboxError(f"--xray {folder}: is a file, expected a folder")
    written = []
    far = cleared_depth(x)
    for picture in x.passes:
        stem = f"{picture.number:02d}_{_slug(picture.name)}"
        written.append(save_png(picture.color, folder / f"{stem}_color.png"))
        if picture.depth is not None:
            written.append(save_png(depth_picture(picture.depth, far), folder / f"{stem}_depth.png"))
        if picture.stencil is not None:
            written.append(save_png(stencil_picture(picture.stencil), folder / f"{stem}_stencil.png"))
    written.append(save_png(contact_sheet(x), folder / "contact_sheet.png"))
    return written


# --- one pixel, pass by pass ----------------------------------------------------


def pixel_passes(x: XRay, pixel: tuple[int, int]) -> list[dict[str, Any]]:
    """Pixel ``(x, y)`` (row 0 at the top) pass by pass: for each pass its colour, depth and
    stencil before and after, which of them it wrote, and the node and triangle of the last
    fragment that wrote the colour there so far (the primitive ids)."""
    px, py = pixel
    out = []
    before_color, before_depth, before_stencil = [0, 0, 0, 0], None, None
    for picture in x.passes:
        color = picture.color[py, px].tolist()
        depth = None if picture.depth is None else float(picture.depth[py, px])
        stencil = None if picture.stencil is None else int(picture.stencil[py, px])
        wrote = [name for name, a, b in (("colour", before_color, color), ("depth", before_depth, depth),
                                         ("stencil", before_stencil, stencil)) if a != b]
        node = triangle = None
        if picture.ids is not None:
            number, prim = (int(v) for v in picture.ids[py, px])
            if 0 < number <= len(x.node_names):
                node, triangle = x.node_names[number - 1], prim
        out.append({"pass": picture.number, "name": picture.name, "description": picture.description,
                    "color_before": before_color, "color": color, "depth_before": before_depth, "depth": depth,
                    "stencil_before": before_stencil, "stencil": stencil, "wrote": wrote,
                    "node": node, "triangle": triangle})
        before_color, before_depth, before_stencil = color, depth, stencil
    return out
