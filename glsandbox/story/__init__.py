"""Why does this pixel look like that: a pixel's story, step by step.

:func:`explain` (also ``glsandbox.explain`` and ``glsandbox explain LESSON --pixel X,Y``)
traces one pixel of a ray-traced viewport through the numpy engine and returns a
:class:`Story`: its text (numbered steps in the course's names, :mod:`.text`), its
raw record (:class:`~glsandbox.story.ray.PixelTrace`, ``--json``), and in a
notebook an HTML view. The modules: ``ray`` (the record and its recorder, on the
numpy engine's probe seam), ``text`` (the story's rendering).
"""

from __future__ import annotations

import html
import json
from typing import Any

from glsandbox.errors import SandboxError
from glsandbox.story.ray import PixelTrace, explain_ray_pixel
from glsandbox.story.text import render_story
from glsandbox.scene import Scene

__all__ = ["Story", "explain", "parse_pixel"]


class Story:
    """One pixel's story: :attr:`text` (what the terminal prints), :attr:`record` (the raw
    :class:`~glsandbox.story.ray.PixelTrace`), :meth:`to_json`. Jupyter shows it as a
    block of text (``_repr_html_``)."""

    def __init__(self, record: PixelTrace) -> None:
        self.record = record
        self.text = render_story(record)

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


def parse_pixel(text: str) -> tuple[int, int]:
    """``X,Y`` (row 0 at the top) -> ``(X, Y)``, refusing anything else with the value named."""
    parts = str(text).replace(" ", "").split(",")
    try:
        x, y = (int(p) for p in parts)
    except ValueError:
        raise SandboxError(f"--pixel {text!r}: expected two whole numbers X,Y (y from the top)") from None
    return x, y


def explain(lesson_or_scene: Any, pixel: tuple[int, int] | str, size: tuple[int, int] | None = None,
            **params: Any) -> Story:
    """The story of one pixel of a lesson (a name, class or instance, with ``params`` as
    ``glsandbox.show`` takes them) or a :class:`Scene`, framed at ``size`` (default
    640x480): ``glsandbox.explain("ray_spheres", (320, 240))``."""
    from glsandbox.frame import DEFAULT_SIZE

    if isinstance(pixel, str):
        pixel = parse_pixel(pixel)
    if isinstance(lesson_or_scene, Scene):
        if params:
            raise SandboxError(f"explain: a Scene takes no parameters (got {', '.join(params)})")
        scene, title = lesson_or_scene, lesson_or_scene.name
    else:
        from glsandbox.notebook import make_lesson

        lesson = make_lesson(lesson_or_scene, **params)
        scene, title = lesson.scene(), lesson.name
    frame = tuple(size) if size is not None else DEFAULT_SIZE
    return Story(explain_ray_pixel(scene, (int(frame[0]), int(frame[1])), (int(pixel[0]), int(pixel[1])), title))
