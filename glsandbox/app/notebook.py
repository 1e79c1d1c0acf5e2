"""Notebook helpers: ``glsandbox.show`` (an inline picture) and ``glsandbox.widget`` (sliders).

In Jupyter::

    import glsandbox
    glsandbox.show("phong", specular=False)      # a picture, shown inline
    glsandbox.widget("transform_order")           # the parameters as ipywidgets, re-rendering on change
    glsandbox.view("phong")                       # drag to orbit, wheel to zoom, play/slide the time

All render headless on one shared :class:`~glsandbox.frame.HeadlessRenderer`
(EGL, else OSMesa), opened on first use: the pictures are exactly what
``glsandbox render`` writes. :func:`widget` and :func:`view` need the optional
``notebook`` extra (ipywidgets, jupyter_rfb); without it, they raise one
:class:`SandboxError` line. The widgets are the window panel's
(:mod:`glsandbox.app.controls`): a combo becomes a dropdown, a checkbox a
checkbox, a number a slider with the same range.

A widget lives only while its kernel runs: a saved notebook shown on a web
site, or converted by nbconvert, has no kernel to draw it. So the boxes that
:func:`widget` and :func:`view` return put their picture beside the widget in
the cell's output (``image/png``, what the cell showed when it ran): a live
notebook draws the widget, a static viewer shows the picture.
"""

from __future__ import annotations

import base64
import functools
from typing import Any

import numpy as np

from glsandbox.app.controls import Control, lesson_controls, to_text
from glsandbox.errors import SandboxError
from glsandbox.files import png_bytes
from glsandbox.frame import DEFAULT_SIZE, FrameRenderer, LazyRenderer, with_samples
from glsandbox.lesson import Lesson, find_lesson
from glsandbox.scene import Scene

#: The renderer every helper shares (a context opens once per kernel).
_RENDERER = LazyRenderer()
NOTEBOOK_MISSING = ("glsandbox.{helper} needs {module}: install the notebook extra "
                    "(pip install 'glsandbox[notebook]', or uv sync --extra notebook)")


def shared_renderer() -> FrameRenderer:
    """The headless renderer every notebook helper shares (opened on first use)."""
    return _RENDERER.renderer


class Picture:
    """A rendered frame that Jupyter shows inline (``_repr_png_``); ``image`` is (H, W, 4) uint8."""

    def __init__(self, image: np.ndarray, title: str = "") -> None:
        self.image = image
        self.title = title

    def png(self) -> bytes:
        return png_bytes(self.image)

    def _repr_png_(self) -> bytes:
        return self.png()

    def to_pil(self) -> Any:
        from PIL import Image

        return Image.fromarray(self.image)

    def __repr__(self) -> str:
        return f"<glsandbox picture {self.title} {self.image.shape[1]}x{self.image.shape[0]}>"


def make_lesson(lesson: str | type[Lesson] | Lesson, **params: Any) -> Lesson:
    """A lesson from a name, a class or an instance, with ``params`` checked as ``--set`` checks them
    (a value may be given as Python or as its ``--set`` text)."""
    if isinstance(lesson, str):
        lesson = find_lesson(lesson)
    cls = lesson if isinstance(lesson, type) else type(lesson)
    values = dict(lesson.values) if isinstance(lesson, Lesson) else cls().values
    for name, value in params.items():
        param, _ = cls.setting(f"{name}=", "show")  # an unknown name: refused with the lesson's parameters
        values[name] = param.parse(value if isinstance(value, str) else to_text(param, value), "show")
    return cls(**values)


def scene_of(lesson_or_scene: Any, helper: str, **params: Any) -> tuple[Scene, str]:
    """``(scene, title)`` of a lesson (name, class or instance, with ``params``) or of a :class:`Scene`
    (which takes none: ``helper`` names the function refusing them)."""
    if isinstance(lesson_or_scene, Scene):
        if params:
            raise SandboxError(f"{helper}: a Scene takes no parameters (got {', '.join(params)})")
        return lesson_or_scene, lesson_or_scene.name
    lesson = make_lesson(lesson_or_scene, **params)
    return lesson.scene(), lesson.name


def render(lesson_or_scene: Any, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0, **params: Any) -> Picture:
    """Render a lesson (name, class or instance, with ``params``) or a :class:`Scene` headless."""
    scene, title = scene_of(lesson_or_scene, "show", **params)
    frame = _RENDERER.renderer.render_scene(with_samples(scene, samples), tuple(size))
    return Picture(frame.image.copy(), title)


def show(lesson_or_scene: Any, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0, **params: Any) -> Picture:
    """The picture of a lesson (``glsandbox.show("phong", specular=False)``) or a Scene; Jupyter shows it inline."""
    return render(lesson_or_scene, size, samples, **params)


def _ipywidgets(helper: str = "widget") -> Any:
    try:
        import ipywidgets
    except ImportError:
        raise SandboxError(NOTEBOOK_MISSING.format(helper=helper, module="ipywidgets")) from None
    return ipywidgets


@functools.cache
def _picture_box_class(widgets: Any) -> type:
    """``widgets.VBox`` whose output bundle also carries its picture (see the module's docstring)."""

    class PictureBox(widgets.VBox):  # type: ignore[misc, name-defined]
        #: () -> PNG bytes: the picture a static viewer shows
        picture_source: Any = None
        title: str = ""

        def _repr_mimebundle_(self, **kwargs: Any) -> Any:
            data = super()._repr_mimebundle_(**kwargs)
            if isinstance(data, dict) and self.picture_source is not None:
                data["image/png"] = base64.b64encode(self.picture_source()).decode("ascii")
                data["text/plain"] = f"<glsandbox {self.title}>"
            return data

    return PictureBox


def _picture_box(widgets: Any, children: list[Any], title: str, picture_source: Any) -> Any:
    box = _picture_box_class(widgets)(children)
    box.picture_source, box.title = picture_source, title
    return box


def _widget_for(widgets: Any, control: Control, value: Any) -> Any:
    name, tip = control.param.name, control.param.help
    if control.kind == "combo":
        return widgets.Dropdown(options=list(control.options), value=value, description=name, tooltip=tip)
    if control.kind == "checkbox":
        return widgets.Checkbox(value=bool(value), description=name, tooltip=tip)
    if control.kind == "slider_int":
        return widgets.IntSlider(value=int(value), min=int(control.low), max=int(control.high), description=name,
                                 continuous_update=False)
    if control.kind == "slider_float":
        return widgets.FloatSlider(value=float(value), min=control.low, max=control.high,
                                   step=(control.high - control.low) / 200, description=name, continuous_update=False)
    return widgets.Text(value=to_text(control.param, value), description=name, continuous_update=False)


def widget(lesson: str | type[Lesson] | Lesson, size: tuple[int, int] = (480, 360), **params: Any) -> Any:
    """The lesson's parameters as ipywidgets above its picture; a change re-renders.

    Returns an ``ipywidgets.VBox`` with ``.controls`` (parameter name -> widget),
    ``.image`` (the ``ipywidgets.Image``), ``.lesson`` and ``.error`` (a Label
    showing a refused value)."""
    widgets = _ipywidgets()
    current = make_lesson(lesson, **params)
    controls = lesson_controls(current)
    time_param = next(p for p in current.all_params() if p.name == "time")
    time_control = Control(time_param, "slider_float", (), 0.0, max(10.0, current.time))
    made = {c.param.name: _widget_for(widgets, c, current.values[c.param.name]) for c in [time_control, *controls]}
    image = widgets.Image(value=render(current, size).png(), format="png", width=size[0], height=size[1])
    error = widgets.Label(value="")

    def changed(change: dict) -> None:
        owner = change["owner"]
        name = next(n for n, w in made.items() if w is owner)
        value = change["new"]
        try:
            param = next(p for p in current.all_params() if p.name == name)
            parsed = param.parse(value if isinstance(value, str) else to_text(param, value), "widget")
            # Rendered before it is kept: a value that fails (a missing image file) leaves the last picture.
            image.value = render(type(current)(**{**current.values, name: parsed}), size).png()
            current.values[name] = parsed
            error.value = ""
        except SandboxError as exc:
            error.value = f"error: {exc}"

    for w in made.values():
        w.observe(changed, names="value")
    box = _picture_box(widgets, [*made.values(), error, image], f"widget {current.name}", lambda: image.value)
    box.controls, box.image, box.lesson, box.error = made, image, current, error
    return box


def view(lesson: str | type[Lesson] | Lesson, size: tuple[int, int] = (480, 360), **params: Any) -> Any:
    """A live view of the lesson you can orbit: drag to orbit, the wheel to zoom, a double click
    for the lesson's own camera, a play button and a slider for ``time``.

    Returns an ``ipywidgets.VBox`` with ``.canvas`` (a jupyter_rfb widget: its
    ``camera``, ``last_image`` and ``frame_ms``, the render time of each frame),
    ``.time`` (the slider) and ``.play``. Needs the ``notebook`` extra."""
    widgets = _ipywidgets("view")
    try:
        from glsandbox.app.notebook_view import make_view
    except ImportError:
        raise SandboxError(NOTEBOOK_MISSING.format(helper="view", module="jupyter_rfb")) from None
    current = make_lesson(lesson, **params)
    size = (int(size[0]), int(size[1]))
    if min(size) <= 0:
        raise SandboxError(f"view: size must be two positive integers, got {size}")
    parts = make_view(current, lambda: _RENDERER.renderer, size)
    canvas = parts.canvas

    def picture() -> bytes:  # what the view shows now (drawn now if it has not drawn yet)
        return png_bytes(canvas.last_image if canvas.last_image is not None else canvas.draw())

    box = _picture_box(widgets, parts.children, f"view {current.name}", picture)
    box.canvas, box.time, box.play = canvas, parts.time, parts.play
    return box
