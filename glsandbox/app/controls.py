"""The live controls' model: what the window's panel and the notebook helpers show and change.

Free of imgui and GL, so it is tested on its own. :mod:`glsandbox.app.panel` draws
it with Dear ImGui in the window; :mod:`glsandbox.app.notebook` with ipywidgets.

- :func:`control_for`: the widget that fits a parameter (choice -> combo,
  bool -> checkbox, number -> slider with a range, order -> the six orders,
  other text -> a text field);
- :func:`uniform_controls`: the widgets of a scene's own shader uniforms
  (:func:`shader_uniforms`), typed from their values;
- :func:`to_text`: a value back to the ``--set`` text its parameter parses,
  and :func:`set_line`, the command-line tail that renders a window's state
  headless (``glsandbox render LESSON <line>``);
- :class:`Clock`: the window's time (pause, scrub, step);
- :class:`LiveCompare` and :func:`compare_scene`: the window split into
  tiles, through :mod:`glsandbox.measure.compare`'s variants and stitching.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from glsandbox.camera import CameraInput
from glsandbox.errors import NUMBER_LIMIT
from glsandbox.lesson import UNIFORM_PREFIX, Lesson, Param, parse_uniform_text, uniform_param
from glsandbox.measure import compare
from glsandbox.overlay import Overlay, text_image
from glsandbox.scene import Scene, check_uniform_value
from glsandbox.transforms import ORDERS, parse_order

#: MSAA sample counts offered by the panel (0: off).
SAMPLE_CHOICES = (0, 2, 4, 8)
#: The parameters the panel shows in their own sections (time, renderer) or not at all (camera: the camera section).
SECTION_PARAMS = ("time", "renderer", "effects", "camera")


@dataclass(frozen=True)
class Control:
    """One widget: ``kind`` is combo, checkbox, slider_int, slider_float or text; for a shader's
    uniform also color (a colour picker) or drag_floats (2 to 4 numbers)."""

    param: Param
    kind: str
    options: tuple[str, ...] = ()
    low: float = 0.0
    high: float = 1.0


def number_range(param: Param, value: float) -> tuple[float, float]:
    """A slider's range: the parameter's own bounds where it has them, else
    four times the default's size either way (at least ±1, ±10 for integers),
    always wide enough for the current value (keys may have moved it)."""
    span = max(4.0 * abs(float(param.default)), 10.0 if param.kind is int else 1.0)
    low = -span if param.minimum is None else float(param.minimum)
    high = span if param.maximum is None else float(param.maximum)
    low, high = min(low, float(value)), max(high, float(value))
    return max(low, -NUMBER_LIMIT), min(high, NUMBER_LIMIT)


def control_for(param: Param, value: Any) -> Control:
    """The widget that fits ``param`` (see the module doc)."""
    if param.convert is parse_order:
        return Control(param, "combo", ORDERS)
    if param.choices is not None:
        return Control(param, "combo", tuple(param.choices))
    if param.kind is bool:
        return Control(param, "checkbox")
    if param.kind in (int, float):
        low, high = number_range(param, value)
        return Control(param, "slider_int" if param.kind is int else "slider_float", (), low, high)
    return Control(param, "text")


def lesson_controls(lesson: Lesson) -> list[Control]:
    """The controls of a lesson's own parameters and the renderer, in declaration order."""
    shown = [p for p in lesson.all_params() if p.name not in SECTION_PARAMS or p.name in ("renderer", "effects")]
    return [control_for(p, lesson.values[p.name]) for p in shown]


def shader_uniforms(scene: Scene) -> dict[str, Any]:
    """The uniforms of the scene's own shaders, by name, with the value the frame gives them:
    a ``--set u.NAME`` override, else the first node's own (``[nodes.uniforms]`` in a scene file)."""
    found: dict[str, Any] = {}
    for node in scene.nodes:
        for name, value in node.uniforms.items():
            found.setdefault(name, value)
    found.update((name, value) for name, value in scene.uniform_overrides.items() if name in found)
    return found


#: What a uniform's name holds when its widget is a colour picker (3 or 4 numbers, each 0..1).
COLOR_WORDS = ("color", "colour")


def uniform_controls(uniforms: dict[str, Any]) -> list[Control]:
    """The widgets of a scene's shader uniforms (:func:`shader_uniforms`), typed from their values:
    on/off -> checkbox; a number -> float slider (range as :func:`number_range`); 3 or 4 numbers
    named ``*color*`` -> colour picker (``color``); other 2 to 4 numbers -> drag-floats
    (``drag_floats``). Each is the parameter ``u.NAME`` (``--set u.NAME=...``), its default the
    scene's value; a change goes into the lesson's values, which the next frame draws."""
    controls = []
    for name, value in uniforms.items():
        param = Param(f"{UNIFORM_PREFIX}{name}", value, f"the shader's uniform {name}", convert=parse_uniform_text)
        if isinstance(value, bool):
            controls.append(Control(param, "checkbox"))
        elif isinstance(value, tuple):
            colour = len(value) in (3, 4) and any(word in name.lower() for word in COLOR_WORDS)
            controls.append(Control(param, "color" if colour else "drag_floats", (), 0.0, 1.0))
        else:
            low, high = number_range(param, value)
            controls.append(Control(param, "slider_float", (), low, high))
    return controls


def uniform_value(control: Control, new: Any) -> Any:
    """What a uniform's widget gave (a bool, a float, a list of floats) as the value the scene
    keeps (:func:`~glsandbox.scene.check_uniform_value`): a colour's numbers within 0..1."""
    if control.kind == "checkbox":
        return bool(new)
    if control.kind in ("color", "drag_floats"):
        numbers = [float(v) for v in new]
        if control.kind == "color":
            numbers = [min(max(v, 0.0), 1.0) for v in numbers]
        return check_uniform_value(tuple(numbers), control.param.name)
    return check_uniform_value(float(new), control.param.name)


def to_text(param: Param, value: Any) -> str:
    """The ``--set`` text that ``param.parse`` turns back into ``value``.

    Floats use Python's repr, the shortest text that parses to the same
    float, so the headless render gets the window's numbers bit for bit."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, tuple):  # the camera's numbers
        return ",".join(repr(float(v)) for v in value)
    return str(value)


def camera_numbers(camera_input: CameraInput) -> tuple[float, ...] | None:
    """The moved camera as ``--set camera=`` numbers (eye, target, fov, near, far), or None if never moved."""
    if camera_input.camera is None:
        return None
    cam = camera_input.camera.camera()
    return (*cam.eye, *cam.target, cam.fov_y, cam.near, cam.far)


def set_line(lesson: Lesson, size: tuple[int, int], samples: int = 0,
             camera: tuple[float, ...] | None = None) -> str:
    """The arguments after ``glsandbox render LESSON`` that draw this state:
    size, samples, and ``--set`` for every value that is not the lesson's default."""
    parts = ["--size", f"{size[0]}x{size[1]}"]
    if samples:
        parts += ["--samples", str(samples)]
    defaults = type(lesson)().values
    values = {**lesson.values, **({"camera": camera} if camera is not None else {})}
    for param in lesson.all_params():
        value = values.get(param.name)
        if value != defaults.get(param.name) and not (param.name == "camera" and not value):
            parts += ["--set", f"{param.name}={to_text(param, value)}"]
    for key, value in values.items():  # the shader's uniforms set in the panel: u.NAME
        if key.startswith(UNIFORM_PREFIX):
            parts += ["--set", f"{key}={to_text(uniform_param(key), value)}"]
    return " ".join(shlex.quote(p) for p in parts)


class Clock:
    """The window's time: runs with the wall clock, or paused; scrubbing and
    stepping set it (and a step pauses, so the frame stays to look at)."""

    def __init__(self, start: float, wall: float) -> None:
        self.base, self.wall, self.paused = float(start), float(wall), False

    def time(self, wall: float) -> float:
        return self.base if self.paused else self.base + (float(wall) - self.wall)

    def set(self, time: float, wall: float) -> None:
        self.base, self.wall = max(0.0, float(time)), float(wall)

    def pause(self, paused: bool, wall: float) -> None:
        self.set(self.time(wall), wall)
        self.paused = paused

    def step(self, seconds: float, wall: float) -> None:
        self.set(self.time(wall) + seconds, wall)
        self.paused = True


@dataclass
class LiveCompare:
    """The panel's live compare: one parameter, two or more value texts, optionally the difference view."""

    param: str = ""
    texts: list[str] = field(default_factory=list)
    difference: bool = False
    enabled: bool = False

    def active(self) -> bool:
        return self.enabled and bool(self.param) and len(self.texts) >= 2

    def variants(self, lesson: Lesson) -> tuple[list[compare.Variant], int]:
        """The tiles for the lesson's current values, built by ``glsandbox compare``'s own
        :func:`~glsandbox.measure.compare.build_variants` (every value parsed by its parameter)."""
        params = {p.name: p for p in lesson.all_params()}
        defaults = type(lesson)().values
        settings = [f"{name}={to_text(params[name], value)}" for name, value in lesson.values.items()
                    if name != self.param and value != defaults.get(name)]
        return compare.build_variants(type(lesson), [f"{self.param}={','.join(self.texts)}"], settings)


@dataclass
class Session:
    """What the window's loop and its panel share: the lesson (its values are the
    parameters), the clock, MSAA, the camera, live compare, and what the last
    frame drew (its plan, and the ``--set`` line that renders it headless)."""

    lesson: Lesson
    clock: Clock
    samples: int
    camera: CameraInput
    live: LiveCompare = field(default_factory=LiveCompare)
    compare_error: str = ""
    #: The last shader reload's error (R or a saved shader file); the last good program draws meanwhile.
    shader_error: str = ""
    #: The lesson file's error (a mistake saved in it); the last good lesson draws meanwhile.
    lesson_error: str = ""
    #: What the last frame drew: the lesson at its time, the frame size, MSAA, the camera and the plan.
    drawn: tuple[Lesson, tuple[int, int], int, tuple[float, ...] | None, Any] | None = None
    #: The uniforms of the last frame's own shaders (:func:`shader_uniforms`): the panel's sliders.
    uniforms: dict[str, Any] = field(default_factory=dict)

    def record(self, size: tuple[int, int], plan: Any, scene: Scene | None = None) -> None:
        """Note the frame just drawn (cheap: the texts below are made only when shown) and,
        given the lesson's ``scene`` it drew, the uniforms of its own shaders."""
        self.drawn = (self.lesson.at(self.lesson.time), size, self.samples, camera_numbers(self.camera), plan)
        if scene is not None:
            self.uniforms = shader_uniforms(scene)

    def drawn_line(self) -> str:
        """The ``--set`` line that renders the last frame headless (see :func:`set_line`)."""
        if self.drawn is None:
            return ""
        lesson, size, samples, camera, _ = self.drawn
        return set_line(lesson, size, samples, camera)

    def plan_text(self) -> str:
        """The last frame's plan, as ``glsandbox plan`` prints it."""
        return "" if self.drawn is None else self.drawn[4].describe()


def frame_image_scene(image: np.ndarray, name: str = "live-compare") -> Scene:
    """A scene that only shows ``image`` (H, W, 4) texel for pixel over the whole frame."""
    opaque = image.copy()
    opaque[..., 3] = 255
    return Scene(name, overlays=(Overlay(name, opaque, None, (0, 0), scalable=False),))


def compare_scene(variants: list[compare.Variant], columns: int, size: tuple[int, int], renderer: Any,
                  difference: bool = False) -> Scene:
    """The live compare frame as a scene: the tiles composed into one frame when
    they can share it, else stitched from each rendered alone (``glsandbox compare``'s
    rule); or the difference view of the first two variants at the full size."""
    if difference:
        a, b = (renderer.render_scene(replace(v.scene, overlays=()), size).image for v in variants[:2])
        image = compare.difference_image(a, b)
        label = text_image([f"difference x{compare.DIFFERENCE_GAIN}: {variants[0].label} vs {variants[1].label}"],
                           color=compare.LABEL_COLOR)
        scene = frame_image_scene(image)
        return replace(scene, overlays=(*scene.overlays, Overlay("difference-label", label, None, (4, -4))))
    if compare.composable(variants) is None:
        return compare.compose(variants, columns, size)
    return frame_image_scene(compare.stitch(variants, columns, size, renderer))


def parse_value(param: Param, text: str) -> Any:
    """A text field's value through the parameter's own parser (errors name the value)."""
    return param.parse(text, "panel")


__all__ = ["SAMPLE_CHOICES", "Clock", "Control", "LiveCompare", "Session", "camera_numbers", "compare_scene", "control_for",
           "frame_image_scene", "lesson_controls", "number_range", "parse_value", "set_line", "shader_uniforms", "to_text",
           "uniform_controls", "uniform_value"]
