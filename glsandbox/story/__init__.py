"""Why does this pixel look like that: a pixel's story, step by step.

:func:`explain` (also ``glsandbox.explain``, ``glsandbox explain LESSON --pixel X,Y`` and
F2 in the window) tells one pixel's story and returns a :class:`Story`: its text, its raw
record (``--json``), and in a notebook an HTML view. A ray-traced pixel is traced through
the numpy engine (numbered steps in the course's names); a rasterised one is told pass
by pass from the frame's X-ray. The modules: ``ray_pixel`` (the ray record and its recorder,
on the numpy engine's probe seam), ``text`` (the ray story's rendering), ``xray`` (each
pass's colour, depth and stencil), ``raster`` (a rasterised pixel's story), ``fragment``
(what the shader saw there), ``divergence`` (a student's function traced beside the
reference), ``seams`` (an exercise's function plugged into the engine's step), ``coverage``
(the top-left rule on the CPU).
"""

from __future__ import annotations

import html
import json
from collections.abc import Callable
from typing import Any

from glsandbox.errors import SandboxError
from glsandbox.frame import FrameRenderer
from glsandbox.scene import Scene
from glsandbox.story.ray_pixel import explain_ray_pixel, locate_pixel
from glsandbox.story.text import render_story

__all__ = ["Story", "explain", "parse_pixel", "pixel_story"]


class Story:
    """One pixel's story: :attr:`text` (what the terminal prints), :attr:`record` (the raw
    record: a ray-traced pixel's :class:`~glsandbox.story.ray_pixel.PixelTrace` or a rasterised
    one's :class:`~glsandbox.story.raster.RasterTrace`), :meth:`to_json`. Jupyter shows it
    as a block of text with a swatch of the colour (``_repr_html_``)."""

    def __init__(self, record: Any, text: str) -> None:
        self.record = record
        self.text = text

    @property
    def rgba8(self) -> list[int]:
        """The pixel's colour in 8-bit levels."""
        return list(self.record.rgba8)

    def to_dict(self) -> dict[str, Any]:
        return self.record.to_dict()

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1, ensure_ascii=False)

    def __str__(self) -> str:
        return self.text

    def __repr__(self) -> str:
        return self.text

    def _repr_html_(self) -> str:
        r = self.record
        swatch = "rgb({}, {}, {})".format(*r.rgba8[:3])
        return (f'<div><span style="display:inline-block;width:1em;height:1em;background:{swatch};'
                f'border:1px solid #888;vertical-align:middle"></span> <b>{html.escape(r.title)}</b>, '
                f'pixel {r.pixel[0]},{r.pixel[1]}<pre style="white-space:pre-wrap">{html.escape(self.text)}</pre></div>')


def pixel_story(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], title: str = "",
                renderer: Callable[[], FrameRenderer] | None = None) -> Story:
    """The story of frame pixel ``pixel`` (row 0 at the top) of ``scene`` at ``size``: traced
    when its viewport is ray-traced, else pass by pass on the renderer ``renderer()`` gives
    (asked for only then: a ray-traced pixel needs no GL)."""
    index, _, _ = locate_pixel(scene, size, pixel)
    if scene.viewports[index].renderer != "raster":
        record = explain_ray_pixel(scene, size, pixel, title)
        return Story(record, render_story(record))
    if renderer is None:
        raise SandboxError(f"--pixel {pixel[0]},{pixel[1]}: a rasterised pixel needs a GL context")
    from glsandbox.story.raster import explain_raster_pixel, render_raster_story

    raster = explain_raster_pixel(renderer(), scene, size, pixel, title)
    return Story(raster, render_raster_story(raster))


def parse_pixel(text: str) -> tuple[int, int]:
    """``X,Y`` (row 0 at the top) -> ``(X, Y)``, refusing anything else with the value named."""
    parts = str(text).replace(" ", "").split(",")
    try:
        x, y = (int(p) for p in parts)
    except ValueError:
        raise SandboxError(f"--pixel {text!r}: expected two whole numbers X,Y (y from the top)") from None
    return x, y


def explain(lesson_or_scene: Any, pixel: tuple[int, int] | str, size: tuple[int, int] | None = None,
            exercise: tuple[str, Callable[..., Any]] | None = None, **params: Any) -> Story:
    """The story of one pixel of a lesson (a name, class or instance, with ``params`` as
    ``glsandbox.show`` takes them) or a :class:`Scene`, framed at ``size`` (default
    640x480): ``glsandbox.explain("ray_spheres", (320, 240))``. A rasterised pixel is drawn
    on the notebook helpers' shared headless renderer. ``exercise=(NAME, function)`` traces the
    pixel with your function (called here, in your own kernel) beside the reference, as
    ``glsandbox explain --exercise`` does (:mod:`glsandbox.story.divergence`)."""
    from glsandbox.frame import DEFAULT_SIZE

    if isinstance(pixel, str):
        pixel = parse_pixel(pixel)
    from glsandbox.app.notebook import scene_of, shared_renderer

    scene, title = scene_of(lesson_or_scene, "explain", **params)
    frame = tuple(size) if size is not None else DEFAULT_SIZE
    if exercise is not None:
        from glsandbox.exercises.catalogue import get
        from glsandbox.story.divergence import Direct, explain_with_function, render_exercise_story

        name, function = exercise
        if not callable(function):
            raise SandboxError(f"explain: exercise=(NAME, function) takes a function, got {type(function).__name__}")
        told = explain_with_function(scene, (int(frame[0]), int(frame[1])), (int(pixel[0]), int(pixel[1])),
                                     get(name), Direct(function), title)
        return Story(told, render_exercise_story(told))

    return pixel_story(scene, (int(frame[0]), int(frame[1])), (int(pixel[0]), int(pixel[1])), title, shared_renderer)
