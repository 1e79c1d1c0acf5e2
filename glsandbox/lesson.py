"""Lessons: a base class with typed parameters, and the registry.

A lesson turns its parameter values (always including ``time``) into a
:class:`~glsandbox.scene.Scene`. Rendering, windows and the CLI are elsewhere
(:mod:`glsandbox.frame`, :mod:`glsandbox.app.window`, :mod:`glsandbox.cli`); a lesson is only data and maths,
so it renders the same moment exactly, headless or in a window.
"""

from __future__ import annotations

import importlib
import inspect
import itertools
import math
import pkgutil
import sys
import types
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar, NoReturn

from glsandbox.course_lessons import BUILTIN_LESSONS, COURSE_PACKAGE
from glsandbox.errors import NUMBER_LIMIT, SandboxError, plain
from glsandbox.files import read_user_file
from glsandbox.scene import RENDERERS
from glsandbox.scene import (PLAN_MODES, Camera, Motion, Scene, check_uniform_name, check_uniform_value,
                             moved_scene)

#: The module name prefix of lesson files loaded from outside the package.
_FILE_MODULE = "_glsandbox_lesson_"

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

    def __post_init__(self) -> None:
        # A lesson's own mistakes, refused where the lesson is defined (the loader adds file and line).
        if not isinstance(self.name, str) or not self.name or any(c.isspace() or c == "=" for c in self.name):
            raise SandboxError(f"Param name must be a word (no spaces or =), got {plain(self.name)}")
        if self.choices is not None:
            if isinstance(self.choices, str) or not isinstance(self.choices, (tuple, list)) \
                    or not all(isinstance(c, str) for c in self.choices) or not self.choices:
                raise SandboxError(f"Param {self.name!r}: choices must be a tuple of texts, got {plain(self.choices)}")
            object.__setattr__(self, "choices", tuple(self.choices))  # a frozen dataclass keeping its own tuple
            if self.default not in self.choices:
                raise SandboxError(f"Param {self.name!r}: default {plain(self.default)} is not one of its choices "
                                   f"({', '.join(self.choices)})")
        if isinstance(self.default, (int, float)) and not isinstance(self.default, bool):
            low = -math.inf if self.minimum is None else self.minimum
            high = math.inf if self.maximum is None else self.maximum
            if not low <= self.default <= high:
                raise SandboxError(f"Param {self.name!r}: default {plain(self.default)} is outside its range "
                                   f"{plain(self.minimum)}..{plain(self.maximum)}")

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


#: ``--set u.NAME=value``: a uniform of the scene's own shaders (docs/your-own.md, "Your own shader").
UNIFORM_PREFIX = "u."


def uniform_param(key: str, flag: str = "--set") -> Param:
    """The parameter behind ``u.NAME``: its text is a number, on/off (true/false), or 2 to 4
    numbers separated by commas or spaces (``1,0.5,0`` or ``[1, 0.5, 0]``)."""
    check_uniform_name(key[len(UNIFORM_PREFIX):], f"{flag} {key}")
    return Param(key, None, "a uniform of the scene's own shaders", convert=parse_uniform_text)


def parse_uniform_text(text: str) -> Any:
    """``--set u.NAME`` text -> a bool, a float or a tuple of floats, checked as scene values are."""
    lowered = text.strip().lower()
    if lowered in ("true", "on", "false", "off"):
        return lowered in ("true", "on")
    parts = lowered.strip("[]() ").replace(",", " ").split()
    try:
        numbers = [float(part) for part in parts]
    except ValueError:
        numbers = []
    if not numbers:
        raise SandboxError("expected a number, on/off, or 2 to 4 numbers (1,0.5,0)")
    return check_uniform_value(numbers[0] if len(numbers) == 1 else tuple(numbers), "value")


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

#: Every lesson has ``overlay``: off drops the text, figures and helper lines drawn on
#: the picture (a lesson's own, such as a trail, too), leaving the 3D picture alone.
OVERLAY = Param("overlay", True, "the text, figures and helper lines drawn on the picture "
                "(off: the 3D picture alone, to compare pixel for pixel)")


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
    #: The comparisons the lesson is about, as (caption, ``--vary`` text): the
    #: tour's course page shows each as a grid of labelled tiles, the picture
    #: ``glsandbox compare NAME --vary TEXT`` writes (e.g. the mirror's
    #: ``("stencil against leak", "mirror=stencil,no_stencil")``).
    contrasts: ClassVar[tuple[tuple[str, str], ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        check_lesson_class(cls)

    def __init__(self, **values: Any) -> None:
        known = {p.name: p for p in self.all_params()}
        self.values: dict[str, Any] = {p.name: self.defaults.get(p.name, p.default) for p in known.values()}
        for key, value in values.items():
            if key.startswith(UNIFORM_PREFIX):
                uniform_param(key)  # checks the name; the value is checked with the scene
            elif key not in known:
                raise SandboxError(unknown_param_message(self, key))
            self.values[key] = value

    @classmethod
    def all_params(cls) -> tuple[Param, ...]:
        return (*SHARED_PARAMS, *cls.params)

    @classmethod
    def setting(cls, item: str, flag: str = "--set", expected: str = "key=value") -> tuple[Param, str]:
        """Split ``key=text`` (a ``--set`` or ``--vary`` argument) into the parameter and its text."""
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise SandboxError(f"{flag} {item!r}: expected {expected}")
        known = {p.name: p for p in cls.all_params()}
        if key.startswith(UNIFORM_PREFIX):
            return uniform_param(key, flag), text.strip()
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
        moment = object.__new__(type(self))  # copy.copy's result, without its __reduce_ex__ round trip
        moment.__dict__.update(self.__dict__)
        moment.values = {**self.values, "time": time}
        return moment

    def scene(self) -> Scene:
        """The Scene for the current values (``renderer`` marks its viewports).

        A lesson whose :meth:`motion` says what ``time`` moves builds its scene once per
        set of its other values (at most :data:`SCENES_KEPT` kept per lesson class) and per
        frame only moves that (:func:`glsandbox.scene.moved_scene`): no dataclass is
        made or checked again but the moved ones, and the renderers keep their plan."""
        parts = self.moving()
        if parts is None:
            return self._scene_as_built()
        return moved_scene(*parts)

    def moving(self) -> tuple[Scene, Motion] | None:
        """The scene :meth:`scene` moves and the motion it moves it by (None: a lesson without
        :meth:`motion`, built every frame): :meth:`scene` is ``moved_scene(*lesson.moving())``.
        The scene is the kept one (built once per set of the other values) unless a value
        cannot be a key; a headless frame hands the motion to the renderer without making the
        moved scene (:meth:`glsandbox.frame.FrameRenderer.render_motion`)."""
        motion = self.motion()
        if motion is None:
            return None
        if motion.overlays and not self.values.get("overlay", True):
            motion = replace(motion, overlays={})  # overlay=off: the scene has none to change
        cls = type(self)
        last = cls.__dict__.get("_scene_last")  # (values, their types, scene) of the class's last frame
        if last is not None:  # the same values as the last frame's (the common case): no key hashed
            rest = {**self.values}
            rest.pop("time", None)
            # The types first (equal ones are no array: the last values were a key); a value holding
            # an array (whose == is no answer) goes on to the key, which refuses it.
            try:
                if last[1] == tuple(map(type, rest.values())) and last[0] == tuple(rest.items()):
                    return last[2], motion
            except (TypeError, ValueError):
                pass
        key = self._still_key()
        if key is None:  # a value that cannot be a key (an array given from Python): built every frame
            return self._scene_as_built(), motion
        kept = cls.__dict__.get("_scenes_kept")  # the class's own (not a parent's): it goes with the class
        if kept is None:
            kept = {}
            cls._scenes_kept = kept
        scene = kept.pop(key, None)
        if scene is None:
            scene = self._scene_as_built()
            if len(kept) >= SCENES_KEPT:
                del kept[next(iter(kept))]  # the least recently used
        kept[key] = scene  # the most recent last
        cls._scene_last = (*key, scene)
        return scene, motion

    def _still_key(self) -> tuple | None:
        """Every value but ``time``, with its type (1, 1.0 and True stay apart), or None when one cannot be hashed.

        In the values' own order, unsorted (C calls only: this runs every frame): a lesson's values
        keep the order its parameters gave them (:meth:`at` and the window's keys keep it), and
        the same values in another order only build the scene once more."""
        rest = {**self.values}
        rest.pop("time", None)
        key = (tuple(rest.items()), tuple(map(type, rest.values())))
        try:
            hash(key)
        except TypeError:
            return None
        return key

    def motion(self) -> Motion | None:
        """What ``time`` moves in :meth:`build`'s scene, at :attr:`time`: the model matrices of
        the nodes that move (by name) and the positions of the lights that move (by index).

        None (the default): the scene is built again every frame. A lesson that returns a
        :class:`~glsandbox.scene.Motion` promises that :meth:`build` depends on its
        :attr:`values` alone, and that its scene at any time is the one built at another
        time with this motion applied (a static lesson returns an empty ``Motion()``);
        its frames then pay only for what moves. ``tests/core/test_frame_cache.py``
        checks every built-in lesson's promise, pixel for pixel, at several times."""
        return None

    def _scene_as_built(self) -> Scene:
        """:meth:`build`'s scene with the shared parameters applied (renderer, camera, effects, ``u.*``)."""
        scene = built_scene(self)
        renderer = self.values.get("renderer", "raster")
        if renderer != "raster":  # traced by glsandbox.frame.trace_viewports
            scene = replace(scene, viewports=tuple(replace(vp, renderer=renderer) for vp in scene.viewports))
        camera = self.values.get("camera")
        if camera:  # --set camera=...: the lens stays the lesson's where not given
            scene = replace(scene, camera=camera_from_numbers(scene.camera, camera))
        if scene.overlays and not self.values.get("overlay", True):
            scene = replace(scene, overlays=())
        plan_mode = self.values.get("effects", "needed")  # effects=all: the bench's everything-on plan
        scene = scene if scene.plan_mode == plan_mode else replace(scene, plan_mode=plan_mode)
        uniforms = {k[len(UNIFORM_PREFIX):]: v for k, v in self.values.items() if k.startswith(UNIFORM_PREFIX)}
        if uniforms and not any(node.shader is not None for node in scene.nodes):
            raise SandboxError(f"--set {UNIFORM_PREFIX}{next(iter(uniforms))}: no node of {self.name} has a shader "
                               "of its own (shader = \"file.glsl\") to take it")
        return replace(scene, uniform_overrides={**scene.uniform_overrides, **uniforms}) if uniforms else scene

    def build(self) -> Scene:
        raise NotImplementedError

    def on_key(self, key: str) -> bool:
        """Window key hook (glfw key name, e.g. ``"1"``); return True when handled."""
        return False


#: Scenes kept per lesson class for :meth:`Lesson.scene` (one per set of values but ``time``):
#: a window's live compare shows several variants of one lesson at once.
SCENES_KEPT = 16

#: The parameters every lesson has; a lesson's own may not reuse their names.
SHARED_PARAMS = (TIME, RENDERER, EFFECTS_PARAM, CAMERA, OVERLAY)


def check_lesson_class(cls: type[Lesson]) -> None:
    """Refuse a lesson class's own mistakes when it is defined: ``params`` not a tuple of
    :class:`Param`, two parameters with one name (or one of :data:`SHARED_PARAMS`'s), a
    ``defaults`` entry that names no parameter or is not among its choices. The message
    names the class; a lesson file's loader adds the file and line of the class."""
    def refuse(what: str) -> NoReturn:
        raise SandboxError(f"{_definition_site(cls)}class {cls.__name__}: {what}")

    params = cls.__dict__.get("params", cls.params)
    if isinstance(params, list):
        params = tuple(params)
        cls.params = params
    if not isinstance(params, tuple) or not all(isinstance(p, Param) for p in params):
        bad = next((p for p in params if not isinstance(p, Param)), params) if isinstance(params, tuple) else params
        refuse(f"params must be a tuple of Param(...), got {plain(bad)}{'' if bad is params else ' in it'}")
    shared = {p.name for p in SHARED_PARAMS}
    seen = set(shared)
    for param in params:
        if param.name in seen:
            reason = "every lesson has it already" if param.name in shared else "two parameters have that name"
            refuse(f"parameter {param.name!r} defined again ({reason})")
        seen.add(param.name)
    if not isinstance(cls.defaults, dict):
        refuse(f"defaults must be a dict of name: value, got {plain(cls.defaults)}")
    known = {p.name: p for p in (*SHARED_PARAMS, *params)}
    for key, value in cls.defaults.items():
        if key not in known:
            refuse(f"defaults names {plain(key)}, which is no parameter (parameters: {', '.join(known)})")
        choices = known[key].choices
        if choices is not None and value not in choices:
            refuse(f"defaults {key}={plain(value)} is not one of {', '.join(choices)}")


def _definition_site(cls: type) -> str:
    """``file:line: `` of a class statement running now, for a class outside a lesson file
    (whose loader names the file and line itself); empty when not found."""
    if cls.__module__.startswith(_FILE_MODULE):
        return ""
    filename = getattr(sys.modules.get(cls.__module__), "__file__", None)
    frame = sys._getframe(1)
    while frame is not None and frame.f_code.co_filename != filename:
        frame = frame.f_back
    return f"{filename}:{frame.f_lineno}: " if frame is not None else ""


def built_scene(lesson: Lesson) -> Scene:
    """``lesson.build()``, checked to be a Scene. A :class:`SandboxError` raised in a lesson
    file's ``build()`` (a Scene, Node or Mesh refusing a value) gets the file and line
    it came from in front. (Any other exception is the lesson's own code: its traceback
    is shown, see docs/your-own.md, "The rule for a lesson file".)"""
    try:
        scene = lesson.build()
    except SystemExit as exc:  # sys.exit() in build(): no picture, and never a quiet exit 0
        source = lesson_source(type(lesson))
        line = _user_line(exc, str(source)) if source is not None else 0
        where = f"{source}:{line}: " if source is not None else ""
        raise SandboxError(f"{where}{type(lesson).__name__}.build() exited (SystemExit {exc.code}) "
                           "before its picture") from None
    except SandboxError as exc:
        source = lesson_source(type(lesson))
        line = _user_line(exc, str(source)) if source is not None else 0
        if line and not str(exc).startswith(str(source)):
            raise SandboxError(f"{source}:{line}: {exc}") from None
        raise
    if not isinstance(scene, Scene):
        code = getattr(type(lesson).build, "__code__", None)
        where = f"{code.co_filename}:{code.co_firstlineno}: " if code is not None else ""
        hint = " (a forgotten return?)" if scene is None else f" (type {type(scene).__name__})"
        raise SandboxError(f"{where}{type(lesson).__name__}.build() returned {plain(scene)}{hint}; "
                           "it must return a glsandbox.Scene")
    return scene


def unknown_param_message(lesson: type[Lesson] | Lesson, key: str, flag: str = "--set") -> str:
    names = [p.name for p in lesson.all_params()]
    import difflib  # only a misspelt name needs it

    close = difflib.get_close_matches(key, names, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"{flag} {key}: {lesson.name} has no parameter {key!r}{hint} (parameters: {', '.join(names)})"


class SceneFileLesson(Lesson):
    """A TOML scene file used as a lesson: static, only ``time``."""

    course_section = "scene file"
    path: ClassVar[Path]

    def build(self) -> Scene:
        from glsandbox.scene_file import load_scene  # TOML and its checks: only where a scene file is used

        return load_scene(self.path)

    def motion(self) -> Motion:
        """Nothing moves: the file is read and its scene built once per set of values, and its
        frames keep their plan (a saved file is read again by a new lesson class,
        :func:`reload_lesson`)."""
        return Motion()


def scene_file_lesson(path: Path) -> type[Lesson]:
    """A lesson class for one scene file; the file is validated now."""
    from glsandbox.scene_file import load_scene

    load_scene(path)  # fail early, with file and line
    # A class name must be text Python can encode: a file name with any bytes is made safe here.
    stem = "".join(c if c.isalnum() and c.isascii() else "_" for c in path.stem)
    return type(f"SceneFile_{stem}", (SceneFileLesson,),
                {"name": path.stem, "title": f"scene file {path}", "path": path})


# --- the registry -----------------------------------------------------------

_REGISTRY: dict[str, type[Lesson]] = {}


def register(cls: type[Lesson]) -> type[Lesson]:
    """Class decorator: make a lesson known to ``glsandbox list`` and the tour."""
    if not cls.name:
        raise ValueError(f"{cls.__qualname__} has no name")
    _REGISTRY[cls.name] = cls
    return cls


def builtin_lessons() -> types.ModuleType:
    """The course's lessons package, ``glsandbox.lessons`` (from :data:`BUILTIN_LESSONS`).

    Not ``lessons`` on ``sys.path``: a student's own ``lessons/`` folder in the
    working directory (first on the path under ``python -m`` and in Jupyter)
    would shadow the course's, and the course's would shadow the student's.
    """
    try:
        return importlib.import_module(COURSE_PACKAGE)
    except ModuleNotFoundError as exc:
        if exc.name != COURSE_PACKAGE:
            raise
        raise SandboxError(f"the course's lessons are missing from {BUILTIN_LESSONS}; reinstall glsandbox") from None


def all_lessons() -> list[type[Lesson]]:
    """Every lesson in the built-in ``lessons`` package, in course order."""
    for module in pkgutil.iter_modules(builtin_lessons().__path__):
        if not module.name.startswith("_"):
            importlib.import_module(f"{COURSE_PACKAGE}.{module.name}")
    return sorted(_REGISTRY.values(), key=lambda c: (c.order, c.name))


#: The file kinds a lesson can come from, besides a built-in lesson's name.
LESSON_SUFFIXES = (".py", ".toml")


def find_lesson(name_or_path: str) -> type[Lesson]:
    """A lesson by name, a scene ``.toml`` file or a lesson ``.py`` file; suggest the closest name.

    A built-in lesson lives in the module of its name (``glsandbox.lessons.<name>``),
    so that module alone is imported; other names look through every lesson.
    """
    path = Path(name_or_path)
    if name_or_path.endswith(".py"):
        return lesson_file_lesson(path)
    if name_or_path.endswith(".toml"):
        return scene_file_lesson(path)
    if path.is_file() or path.is_dir():
        raise SandboxError(f"{path}: expected a lesson name, a lesson .py file or a scene .toml file")
    if name_or_path.isidentifier() and not name_or_path.startswith("_"):
        builtin_lessons()
        try:
            importlib.import_module(f"{COURSE_PACKAGE}.{name_or_path}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{COURSE_PACKAGE}.{name_or_path}":
                raise
        if name_or_path in _REGISTRY:
            return _REGISTRY[name_or_path]
    lessons_by_name = {cls.name: cls for cls in all_lessons()}
    if name_or_path in lessons_by_name:
        return lessons_by_name[name_or_path]
    import difflib  # only a misspelt name needs it

    close = difflib.get_close_matches(name_or_path, list(lessons_by_name), n=1, cutoff=0.4)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    raise SandboxError(f"unknown lesson {name_or_path!r}{hint} (see glsandbox list)")


# --- lesson files outside the package -----------------------------------------

_loaded_files = itertools.count()


def lesson_file_lesson(path: Path) -> type[Lesson]:
    """The Lesson subclass a ``.py`` file outside the package defines.

    The rule: the file's own Lesson subclasses (defined in it, not imported)
    are the candidates; exactly one is the lesson, or, with several, the one
    the file names in ``LESSON = TheClass``. A class without a ``name`` takes
    the file's stem. The file is imported under a fresh module name each
    time (``_glsandbox_lesson_<n>_<stem>``), with its folder on ``sys.path``
    while it imports (a helper module beside it is found); ``@register`` in
    it does not reach the built-in registry (``glsandbox list`` and the tour
    stay the course's). Every failure is one :class:`SandboxError` naming
    the file: missing, unreadable, a syntax error (with its line), an
    exception while importing, no lesson, several lessons.
    """
    source = read_user_file(path, "lesson file", "a .py file").decode("utf-8", errors="replace")
    try:
        code = compile(source, str(path), "exec")
    except SyntaxError as exc:
        raise SandboxError(f"{path}:{exc.lineno or 0}: syntax error: {exc.msg}") from None
    stem = "".join(c if c.isalnum() else "_" for c in path.stem)
    module = types.ModuleType(f"{_FILE_MODULE}{next(_loaded_files)}_{stem}")
    module.__file__ = str(path)
    registry_before = dict(_REGISTRY)
    folder = str(path.resolve().parent)
    sys.modules[module.__name__] = module  # dataclasses and pickling look a class's module up here
    sys.path.insert(0, folder)
    try:
        exec(code, module.__dict__)
    except SystemExit as exc:
        raise SandboxError(f"{path}: exited while importing (SystemExit {exc.code}); "
                           "keep glsandbox.run(...) under if __name__ == \"__main__\"") from None
    except SandboxError as exc:  # a glsandbox call of the file's, or its lesson class refused where defined
        raise SandboxError(f"{path}:{_user_line(exc, str(path))}: {exc}") from None
    except Exception as exc:
        raise SandboxError(f"{path}:{_user_line(exc, str(path))}: {type(exc).__name__} while importing: "
                           f"{_cut(str(exc))}") from None
    finally:
        sys.path.remove(folder)
        # A user's @register must neither join nor shadow the built-in lessons;
        # a built-in module the file imported (to subclass a lesson) keeps its entry.
        for key, cls in list(_REGISTRY.items()):
            if cls.__module__ == module.__name__:
                if key in registry_before:
                    _REGISTRY[key] = registry_before[key]
                else:
                    del _REGISTRY[key]
    return _the_lesson_in(module, path)


def _cut(text: str, limit: int = 200) -> str:
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _user_line(exc: BaseException, filename: str) -> int:
    """The line of ``filename`` deepest in the traceback (0 when the file is not in it)."""
    line = 0
    tb = exc.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == filename:
            line = tb.tb_lineno
        tb = tb.tb_next
    return line


def _the_lesson_in(module: types.ModuleType, path: Path) -> type[Lesson]:
    """The one lesson a loaded lesson file defines (see :func:`lesson_file_lesson`)."""
    chosen = module.__dict__.get("LESSON")
    if chosen is not None and not (isinstance(chosen, type) and issubclass(chosen, Lesson)):
        raise SandboxError(f"{path}: LESSON must be a Lesson subclass, got {plain(chosen)}")
    if chosen is None:
        own = [value for value in module.__dict__.values()
               if isinstance(value, type) and issubclass(value, Lesson) and value.__module__ == module.__name__]
        if not own:
            raise SandboxError(f"{path}: defines no Lesson subclass (class MyLesson(glsandbox.Lesson) "
                               "with a build() method)")
        if len(own) > 1:
            names = ", ".join(cls.__name__ for cls in own)
            raise SandboxError(f"{path}: defines {len(own)} Lesson subclasses ({names}); "
                               "say which one with LESSON = TheClass")
        chosen = own[0]
    if not chosen.name:
        chosen.name = path.stem
    if not chosen.title:
        chosen.title = f"lesson file {path}"
    if not chosen.course_section:
        chosen.course_section = "lesson file"
    return chosen


def lesson_files(folder: Path, entry: str | None = None) -> list[tuple[str, Path]]:
    """The lesson files in ``folder``, as (name, path), sorted by name: the rule
    of ``glsandbox tour --lessons DIR`` and ``glsandbox check DIR``.

    Each ``.py`` and ``.toml`` file directly in the folder is one lesson,
    named by its stem (by its file name when a ``.py`` and a ``.toml`` share
    a stem). Each subfolder is one lesson too, named by the subfolder, its
    lesson file chosen by :func:`entry_point` (a student's folder, with its
    helper modules, textures, models and shaders beside). A subfolder whose
    lesson cannot be told is listed with the folder itself as its path, and
    loading it (:func:`submission_lesson`) reports why. A file or subfolder
    that is a symbolic link is listed as the link, which loading refuses.
    Hidden and ``_``-prefixed names are skipped.
    """
    if not folder.is_dir():
        raise SandboxError(f"{folder}: not a folder")
    files, subfolders, links = [], [], []
    for entry_path in sorted(folder.iterdir()):
        if entry_path.name.startswith((".", "_")):
            continue
        if entry_path.is_symlink():
            if entry_path.is_dir() or entry_path.suffix in LESSON_SUFFIXES:
                links.append(entry_path)
        elif entry_path.is_dir():
            subfolders.append(entry_path)
        elif entry_path.suffix in LESSON_SUFFIXES and entry_path.is_file():
            files.append(entry_path)
    stems = [f.stem for f in [*files, *(p for p in links if not p.is_dir())]]
    found = [(f.stem if stems.count(f.stem) == 1 else f.name, f) for f in files]
    found += [(p.name if p.is_dir() or stems.count(p.stem) > 1 else p.stem, p) for p in links]
    found += [(sub.name, entry_point(sub, entry)) for sub in subfolders]
    return sorted(found)


def _imported_names(path: Path) -> set[str]:
    """The top-level module names ``path`` imports (read, never run); none when it does not parse."""
    import ast

    try:
        if path.stat().st_size > 1 << 20:
            return set()
        tree = ast.parse(path.read_bytes())
    except (OSError, SyntaxError, ValueError, RecursionError, MemoryError):
        return set()
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.module and node.level <= 1:
                names.add(node.module.split(".")[0])
            elif node.level == 1:  # from . import helpers
                names.update(alias.name for alias in node.names)
    return names


def _defines_a_class_with_bases(path: Path) -> bool:
    import ast

    try:
        tree = ast.parse(path.read_bytes()) if path.stat().st_size <= 1 << 20 else None
    except (OSError, SyntaxError, ValueError, RecursionError, MemoryError):
        return False
    return tree is not None and any(isinstance(n, ast.ClassDef) and n.bases for n in tree.body)


def entry_point(folder: Path, entry: str | None = None) -> Path:
    """A student's folder's lesson file: ``entry`` (the rubric's, e.g. ``spin.py``) when given; else
    its one ``.py`` file, or of several the one no other imports (the rest are its helper modules),
    or of those the one defining a class; else its one ``.toml``. ``folder`` itself when none can
    be told (:func:`submission_lesson` says why)."""
    if entry is not None:
        chosen = folder / entry
        return chosen if chosen.is_file() and not chosen.is_symlink() else folder
    for suffix in LESSON_SUFFIXES:
        inside = sorted(p for p in folder.iterdir() if p.suffix == suffix and p.is_file() and not p.is_symlink()
                        and not p.name.startswith((".", "_")))
        if len(inside) == 1:
            return inside[0]
        if len(inside) > 1 and suffix == ".py":
            imported = set().union(*(_imported_names(p) for p in inside))
            candidates = [p for p in inside if p.stem not in imported]
            if len(candidates) > 1:
                candidates = [p for p in candidates if _defines_a_class_with_bases(p)]
            return candidates[0] if len(candidates) == 1 else folder
        if inside:
            return folder
    return folder


def submission_lesson(path: Path, entry: str | None = None) -> type[Lesson]:
    """:func:`find_lesson` for an entry of :func:`lesson_files`, a subfolder's problem named."""
    if path.is_symlink():
        raise SandboxError(f"{path}: is a link (a submission is its own files, not a link to others')")
    if path.is_dir():
        kinds = " or ".join(LESSON_SUFFIXES)
        if entry is not None:
            raise SandboxError(f"{path}: no {entry} in this folder (the rubric's entry point)")
        count = {s: sum(1 for p in path.iterdir() if p.suffix == s) for s in LESSON_SUFFIXES}
        if not any(count.values()):
            raise SandboxError(f"{path}: no {kinds} lesson file in this folder")
        several = next(s for s in LESSON_SUFFIXES if count[s] > 1)
        if several == ".py":
            raise SandboxError(f"{path}: {count[several]} .py files in this folder and none stands out as the "
                               "lesson (the one no other imports); name it with entry = \"FILE.py\" in the rubric")
        raise SandboxError(f"{path}: {count[several]} {several} files in this folder; expected one")
    return find_lesson(str(path))


# --- reading a lesson's file again (the window's reload on save) --------------


def lesson_description(cls: type[Lesson]) -> str:
    """What the lesson shows, in its author's words: the docstring of the module that
    defines it (a lesson file's own), else of the class; "" for a scene file or none."""
    if issubclass(cls, SceneFileLesson):
        return ""
    module = sys.modules.get(cls.__module__)
    doc = (module.__doc__ if module is not None else None) or cls.__dict__.get("__doc__") or ""
    return inspect.cleandoc(doc) if isinstance(doc, str) else ""


def lesson_source(cls: type[Lesson]) -> Path | None:
    """The file a lesson came from: its ``.py`` lesson file or ``.toml`` scene file (None: built in)."""
    if issubclass(cls, SceneFileLesson):
        return cls.path
    module = sys.modules.get(cls.__module__)
    if cls.__module__.startswith(_FILE_MODULE) and module is not None and module.__file__:
        return Path(module.__file__)
    return None


def reload_lesson(lesson: Lesson) -> Lesson:
    """``lesson``'s file read again: the class it defines now, with the values the window
    had (those its parameters still accept; else the new defaults at the same time), its
    scene built once, so a mistake is a :class:`SandboxError` here (one line naming the
    file and line) and the window keeps the lesson it has."""
    path = lesson_source(type(lesson))
    if path is None:
        raise SandboxError(f"lesson {lesson.name!r} is built in: there is no file of its own to read again")
    cls = find_lesson(str(path))
    names = {p.name for p in cls.all_params()}
    kept = {k: v for k, v in lesson.values.items() if k in names or k.startswith(UNIFORM_PREFIX)}
    try:
        try:
            fresh = cls(**kept)
            fresh.scene()
        except SandboxError:
            fresh = cls(time=lesson.time)
            fresh.scene()
    except SandboxError:
        raise
    except Exception as exc:  # the user's own code
        raise user_code_error(exc) from None
    return fresh


def user_code_error(exc: BaseException) -> SandboxError:
    """An exception raised by a lesson's own code as one line, with the deepest line outside glsandbox."""
    library = tuple(str(Path(p).resolve()) for p in {sys.prefix, sys.base_prefix, sys.exec_prefix})
    ours = str(Path(__file__).resolve().parent)  # the glsandbox package
    where = ""
    tb = exc.__traceback__
    while tb is not None:
        filename = tb.tb_frame.f_code.co_filename
        if not filename.startswith(("<", ours, *library)):
            where = f" at {filename}:{tb.tb_lineno}"
        tb = tb.tb_next
    text = str(exc)
    text = text if len(text) <= 200 else text[:197] + "..."
    return SandboxError(f"{type(exc).__name__}{where}: {text}")
