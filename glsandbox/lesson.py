"""Lessons: a base class with typed parameters, and the registry.

A lesson turns its parameter values (always including ``time``) into a
:class:`~glsandbox.scene.Scene`. Rendering, windows and the CLI are elsewhere
(:mod:`glsandbox.frame`, :mod:`glsandbox.window`, :mod:`glsandbox.cli`); a lesson is only data and maths,
so it renders the same moment exactly, headless or in a window.
"""

from __future__ import annotations

import copy
import difflib
import importlib
import math
import pkgutil
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

from glsandbox.errors import NUMBER_LIMIT, SandboxError
from glsandbox.scene import RENDERERS
from glsandbox.scene import PLAN_MODES, Camera, Scene
from glsandbox.scene_file import load_scene

# NUMBER_LIMIT (glsandbox.errors) is the largest magnitude a number parameter
# takes unless it says otherwise: the same bound the scene's dataclasses keep.


@dataclass(frozen=True)
class Param:
    """A lesson parameter, settable with ``--set name=value``."""

    name: str
    default: Any
    help: str
    choices: tuple[str, ...] | None = None
    minimum: float | None = None
    maximum: float | None = None
    #: A parser of its own for text values (e.g. :func:`glsandbox.transforms.parse_order`);
    #: its :class:`SandboxError` is reported with the parameter and value.
    convert: Callable[[str], Any] | None = None

    @property
    def kind(self) -> type:
        return type(self.default)

    def parse(self, text: str, flag: str = "--set") -> Any:
        """Turn ``--set`` text into a value, or raise naming the value (and ``flag``)."""
        where = f"{flag} {self.name}={text}"
        if self.convert is not None:
            try:
                return self.convert(text)
            except SandboxError as exc:
                raise SandboxError(f"{where}: {exc}") from None
        if self.choices is not None:
            if text not in self.choices:
                raise SandboxError(f"{where}: expected one of {', '.join(self.choices)}")
            return text
        if self.kind is bool:
            lowered = text.strip().lower()
            if lowered in ("1", "true", "on", "yes"):
                return True
            if lowered in ("0", "false", "off", "no"):
                return False
            raise SandboxError(f"{where}: expected on or off")
        if self.kind in (int, float):
            try:
                value = self.kind(text)
            except ValueError:
                noun = "an integer" if self.kind is int else "a number"
                raise SandboxError(f"{where}: expected {noun}") from None
            if not math.isfinite(value):
                raise SandboxError(f"{where}: expected a finite number")
            # Values enter the maths here: bounded, so products (time x speed, a
            # camera distance, a far plane) stay finite and meaningful.
            low = -NUMBER_LIMIT if self.minimum is None else self.minimum
            high = NUMBER_LIMIT if self.maximum is None else self.maximum
            if value < low:
                raise SandboxError(f"{where}: must be at least {low:g}")
            if value > high:
                raise SandboxError(f"{where}: must be at most {high:g}")
            return value
        return text

    def describe(self) -> str:
        options = f" ({'|'.join(self.choices)})" if self.choices else ""
        default = ("on" if self.default else "off") if self.kind is bool else self.default
        return f"{self.name}={default}{options}: {self.help}"


#: Every lesson has ``time``: the moment to render, in seconds.
TIME = Param("time", 0.0, "the moment to render, in seconds (animated lessons move with it)", minimum=0.0)

#: Every lesson has ``effects``: ``needed`` plans only what the scene calls for,
#: ``all`` forces every buffer and pass on (same picture; the bench's baseline).
EFFECTS_PARAM = Param("effects", "needed", "plan only the effects the scene needs, or force all on "
                      "(same picture, for the bench)", choices=PLAN_MODES)

#: Every lesson has ``renderer``: the rasterizer, or the ray tracer on the same
#: Scene (``ray``: the GLSL engine, ``ray_numpy``: the float64 reference), so
#: ``glsandbox compare LESSON --vary renderer=raster,ray`` shows both.
RENDERER = Param("renderer", "raster", "who draws the 3D content: the rasterizer or the ray tracer "
                 "(the same Scene)", choices=RENDERERS)


def parse_camera(text: str) -> tuple[float, ...] | None:
    """``--set camera=ex,ey,ez,tx,ty,tz[,fov,near,far]``: a camera replacing the lesson's (up is +y).

    Empty text keeps the lesson's own camera. The window's "copy --set line"
    writes all nine numbers with Python's shortest exact repr, so the headless
    render sees the same floats the window's camera had.
    """
    if not str(text).strip():
        return None
    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) not in (6, 9):
        raise SandboxError("expected eye x,y,z, target x,y,z and optionally fov,near,far (6 or 9 numbers)")
    try:
        numbers = [float(p) for p in parts]
    except ValueError:
        raise SandboxError("expected numbers separated by commas") from None
    camera_from_numbers(Camera(), tuple(numbers))  # refuses non-finite values, eye on target, near >= far
    return tuple(numbers)


def camera_from_numbers(base: Camera, numbers: tuple[float, ...]) -> Camera:
    """``base`` with eye and target (and fov, near, far when nine numbers) from ``numbers``; up is +y."""
    lens = dict(zip(("fov_y", "near", "far"), numbers[6:]))
    return replace(base, eye=tuple(numbers[:3]), target=tuple(numbers[3:6]), up=(0.0, 1.0, 0.0), **lens)


#: Every lesson has ``camera``: empty keeps its own; the window's "copy --set line"
#: fills it with the interactive camera so a window state renders headless exactly.
CAMERA = Param("camera", "", "replace the lesson's camera: eye x,y,z, target x,y,z[, fov, near, far] "
               "(empty: the lesson's own)", convert=parse_camera)


class Lesson:
    """Base class. Subclasses set the class attributes and implement :meth:`build`."""

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    course_section: ClassVar[str] = ""
    #: Position in ``glsandbox list`` and the tour.
    order: ClassVar[int] = 100
    #: Whether the picture changes with ``time`` (the window advances it).
    animated: ClassVar[bool] = False
    params: ClassVar[tuple[Param, ...]] = ()
    #: Defaults of the shared parameters this lesson changes (the ray-tracing
    #: lessons set ``{"renderer": "ray"}``).
    defaults: ClassVar[dict[str, Any]] = {}

    def __init__(self, **values: Any) -> None:
        known = {p.name: p for p in self.all_params()}
        self.values: dict[str, Any] = {p.name: self.defaults.get(p.name, p.default) for p in known.values()}
        for key, value in values.items():
            if key not in known:
                raise SandboxError(unknown_param_message(self, key))
            self.values[key] = value

    @classmethod
    def all_params(cls) -> tuple[Param, ...]:
        return (TIME, RENDERER, EFFECTS_PARAM, CAMERA, *cls.params)

    @classmethod
    def setting(cls, item: str, flag: str = "--set", expected: str = "key=value") -> tuple[Param, str]:
        """Split ``key=text`` (a ``--set`` or ``--vary`` argument) into the parameter and its text."""
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise SandboxError(f"{flag} {item!r}: expected {expected}")
        known = {p.name: p for p in cls.all_params()}
        if key not in known:
            raise SandboxError(unknown_param_message(cls, key, flag))
        return known[key], text.strip()

    @classmethod
    def from_settings(cls, settings: Iterable[str]) -> Lesson:
        """Build from ``key=value`` strings (the CLI's ``--set``)."""
        values: dict[str, Any] = {}
        for item in settings:
            param, text = cls.setting(item)
            values[param.name] = param.parse(text)
        return cls(**values)

    @property
    def time(self) -> float:
        return float(self.values["time"])

    def at(self, time: float) -> Lesson:
        """The same lesson at another moment (a copy; this one is unchanged).

        The values were checked when this lesson was made, so the copy skips
        that: the window and the benchmarks call this every frame."""
        moment = copy.copy(self)
        moment.values = {**self.values, "time": time}
        return moment

    def scene(self) -> Scene:
        """The Scene for the current values (``renderer`` marks its viewports)."""
        scene = self.build()
        renderer = self.values.get("renderer", "raster")
        if renderer != "raster":  # traced by glsandbox.frame.trace_viewports
            scene = replace(scene, viewports=tuple(replace(vp, renderer=renderer) for vp in scene.viewports))
        camera = self.values.get("camera")
        if camera:  # --set camera=...: the lens stays the lesson's where not given
            scene = replace(scene, camera=camera_from_numbers(scene.camera, camera))
        plan_mode = self.values.get("effects", "needed")  # effects=all: the bench's everything-on plan
        return scene if scene.plan_mode == plan_mode else replace(scene, plan_mode=plan_mode)

    def build(self) -> Scene:
        raise NotImplementedError

    def on_key(self, key: str) -> bool:
        """Window key hook (glfw key name, e.g. ``"1"``); return True when handled."""
        return False


def unknown_param_message(lesson: type[Lesson] | Lesson, key: str, flag: str = "--set") -> str:
    names = [p.name for p in lesson.all_params()]
    close = difflib.get_close_matches(key, names, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"{flag} {key}: {lesson.name} has no parameter {key!r}{hint} (parameters: {', '.join(names)})"


class SceneFileLesson(Lesson):
    """A TOML scene file used as a lesson: static, only ``time``."""

    course_section = "scene file"
    path: ClassVar[Path]

    def build(self) -> Scene:
        return load_scene(self.path)


def scene_file_lesson(path: Path) -> type[Lesson]:
    """A lesson class for one scene file; the file is validated now."""
    load_scene(path)  # fail early, with file and line
    return type(f"SceneFile_{path.stem}", (SceneFileLesson,),
                {"name": path.stem, "title": f"scene file {path}", "path": path})


# --- the registry -----------------------------------------------------------

_REGISTRY: dict[str, type[Lesson]] = {}


def register(cls: type[Lesson]) -> type[Lesson]:
    """Class decorator: make a lesson known to ``glsandbox list`` and the tour."""
    if not cls.name:
        raise ValueError(f"{cls.__qualname__} has no name")
    _REGISTRY[cls.name] = cls
    return cls


def all_lessons() -> list[type[Lesson]]:
    """Every lesson in the ``lessons`` package, in course order."""
    import lessons

    for module in pkgutil.iter_modules(lessons.__path__):
        if not module.name.startswith("_"):
            importlib.import_module(f"lessons.{module.name}")
    return sorted(_REGISTRY.values(), key=lambda c: (c.order, c.name))


def find_lesson(name_or_path: str) -> type[Lesson]:
    """A lesson by name, or a scene ``.toml`` file; suggest the closest name.

    A built-in lesson lives in the module of its name (``lessons/<name>.py``),
    so that module alone is imported; other names look through every lesson.
    """
    path = Path(name_or_path)
    if name_or_path.endswith(".toml") or path.is_file():
        return scene_file_lesson(path)
    if name_or_path.isidentifier() and not name_or_path.startswith("_"):
        try:
            importlib.import_module(f"lessons.{name_or_path}")
        except ModuleNotFoundError as exc:
            if exc.name != f"lessons.{name_or_path}":
                raise
        if name_or_path in _REGISTRY:
            return _REGISTRY[name_or_path]
    lessons_by_name = {cls.name: cls for cls in all_lessons()}
    if name_or_path in lessons_by_name:
        return lessons_by_name[name_or_path]
    close = difflib.get_close_matches(name_or_path, list(lessons_by_name), n=1, cutoff=0.4)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise SandboxError(f"unknown lesson {name_or_path!r}{hint} (see glsandbox list)")
