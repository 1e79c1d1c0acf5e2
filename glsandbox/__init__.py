"""glsandbox: a graphics course as runnable, tested ModernGL lessons.

This package's namespace is the public face: everything a lesson or a user
script needs to describe a scene and run it. A Scene is plain data; the
rasterizer plans and draws it (:func:`glsandbox.plan.plan`, :mod:`glsandbox.gl`),
and the ray tracer (:mod:`glsandbox.raytrace`) traces the same Scene::

    import glsandbox
    from glsandbox import Lesson, Node, Scene, geometry, register

    @register
    class OneCube(Lesson):
        name = "one_cube"
        def build(self) -> Scene:
            return Scene(self.name, nodes=(Node("cube", geometry.cube()),))

    if __name__ == "__main__":
        raise SystemExit(glsandbox.run(OneCube))   # a window, or --headless --out cube.png

A model file is one call: ``Node("bunny", glsandbox.load_mesh("bunny.obj", fit=True))``;
:func:`load_model` gives its texture and colour too (:mod:`glsandbox.mesh.load`),
and :mod:`glsandbox.mesh.generate` makes models without a file.

The layers below (the table in docs/how-it-works.md) import downwards only;
:func:`run` is the one door up to the command line, opened when called.
"""

from __future__ import annotations

import importlib

from glsandbox import course_lessons  # noqa: F401 - the course's lessons found in a checkout (python -m glsandbox.lessons.X)
from glsandbox.version import __version__

TYPE_CHECKING = False  # (typing's own would import typing: 15 ms of a cold start)
if TYPE_CHECKING:  # the names, for type checkers and editors; at run time each is imported on first use
    from glsandbox import geometry, transforms
    from glsandbox.errors import SandboxError
    from glsandbox.geometry import Mesh
    from glsandbox.lesson import Lesson, Param, register
    from glsandbox.overlay import Overlay, WorldLine, WorldLines, WorldMark, text_image
    from glsandbox.scene import (COURSE_BLUE, DEPTH_MODES, LIT_SHADINGS, NORMAL_MODES, TEXTURE_FILTERS, TEXTURE_WRAPS,
                                 Camera, Light, Material, Motion, Node, Scene, ShadowMap, Texture, Viewport)

__all__ = [
    "COURSE_BLUE", "DEPTH_MODES", "LIT_SHADINGS", "NORMAL_MODES", "TEXTURE_FILTERS", "TEXTURE_WRAPS",
    "Camera", "Lesson", "Light", "Material", "Mesh", "Mirror", "Model", "Motion", "Node", "Overlay", "Param", "PlanarShadow",
    "SandboxError", "Scene", "ShadowMap", "Texture", "Viewport", "WorldLine", "WorldLines", "WorldMark",
    "__version__", "camera", "check_texture_source", "exercise", "explain", "fit_mesh", "geometry", "load_mesh", "load_model", "meshgen", "register", "run",
    "show", "text_image", "transforms", "view", "widget",
]


# Every name is imported on first use (PEP 562): ``import glsandbox`` costs nothing, so the
# command line can start what a long command starts early (the grading zygote,
# :mod:`glsandbox.launch`) before numpy and moderngl are imported, and a cold start skips the
# modules it never uses (model files, the model generators, the window's camera controls).
_SCENE_NAMES = ("COURSE_BLUE", "DEPTH_MODES", "LIT_SHADINGS", "NORMAL_MODES", "TEXTURE_FILTERS", "TEXTURE_WRAPS",
                "Camera", "Light", "Material", "Motion", "Node", "Scene", "ShadowMap", "Texture", "Viewport")
_LAZY = {
    "geometry": ("glsandbox.geometry", None),
    "transforms": ("glsandbox.transforms", None),
    "SandboxError": ("glsandbox.errors", "SandboxError"),
    "Mesh": ("glsandbox.geometry", "Mesh"),
    "Lesson": ("glsandbox.lesson", "Lesson"),
    "Param": ("glsandbox.lesson", "Param"),
    "register": ("glsandbox.lesson", "register"),
    **{name: ("glsandbox.overlay", name) for name in ("Overlay", "WorldLine", "WorldLines", "WorldMark", "text_image")},
    **{name: ("glsandbox.scene", name) for name in _SCENE_NAMES},
    "camera": ("glsandbox.camera", None),
    "exercise": ("glsandbox.exercises", "exercise"),
    "Mirror": ("glsandbox.planar", "Mirror"),
    "PlanarShadow": ("glsandbox.planar", "PlanarShadow"),
    "meshgen": ("glsandbox.mesh.generate", None),
    "check_texture_source": ("glsandbox.images", "check_texture_source"),
    "Model": ("glsandbox.mesh.load", "Model"),
    "fit_mesh": ("glsandbox.mesh.load", "fit_mesh"),
    "load_mesh": ("glsandbox.mesh.load", "load_mesh"),
    "load_model": ("glsandbox.mesh.load", "load_model"),
}


def __getattr__(name: str) -> object:
    try:
        module_name, attribute = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    module = importlib.import_module(module_name)
    value = module if attribute is None else getattr(module, attribute)
    globals()[name] = value  # later look-ups skip this hook
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


def run(lesson_cls: type[Lesson], argv: list[str] | None = None) -> int:
    """Run a lesson class from the command line: a window, or ``--headless --out FILE.png``.

    ``argv`` defaults to ``sys.argv[1:]``; the return value is the exit
    status (0, or 2 with one ``error:`` line for a mistake). The command
    line (:mod:`glsandbox.cli`) is imported only now.
    """
    from glsandbox.cli import lesson_main

    return lesson_main(lesson_cls, argv)


def show(lesson_or_scene: object, *args: object, **params: object) -> object:
    """A lesson (name, class or instance, with ``--set``-style ``params``) or a Scene rendered
    headless as a picture that Jupyter shows inline (:mod:`glsandbox.app.notebook`, imported when called)."""
    from glsandbox.app.notebook import show as _show

    return _show(lesson_or_scene, *args, **params)


def explain(lesson_or_scene: object, *args: object, **params: object) -> object:
    """One pixel's story: ``glsandbox.explain("ray_spheres", (320, 240))`` traces that pixel of the
    lesson (or a Scene) step by step (:func:`glsandbox.story.explain`); Jupyter shows the story."""
    from glsandbox.story import explain as _explain

    return _explain(lesson_or_scene, *args, **params)


def widget(lesson: object, *args: object, **params: object) -> object:
    """The lesson's parameters as ipywidgets (the ``notebook`` extra) over its picture, re-rendered on change."""
    from glsandbox.app.notebook import widget as _widget

    return _widget(lesson, *args, **params)


def view(lesson: object, *args: object, **params: object) -> object:
    """A live view of the lesson in Jupyter (the ``notebook`` extra): drag to orbit, wheel to zoom,
    a play button and a time slider (:func:`glsandbox.app.notebook.view`)."""
    from glsandbox.app.notebook import view as _view

    return _view(lesson, *args, **params)
