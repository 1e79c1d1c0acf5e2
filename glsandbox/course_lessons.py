"""Where the course's own lessons are: the package ``glsandbox.lessons``, found in a checkout too.

The course's lessons are the package ``glsandbox.lessons``, under glsandbox's
own name, so that a user's ``lessons/`` folder neither hides them nor is
hidden by them. The wheel installs the repository's top-level ``lessons/``
folder as ``glsandbox/lessons/``; a checkout keeps it at the top, where
:class:`CourseLessonsFinder` finds it. ``import glsandbox`` installs the
finder (this module imports nothing heavy), so ``python -m
glsandbox.lessons.<name>`` runs a lesson in a checkout as in a wheel.
"""

from __future__ import annotations

import os
import sys

__all__ = ["COURSE_PACKAGE", "BUILTIN_LESSONS", "CourseLessonsFinder"]

COURSE_PACKAGE = "glsandbox.lessons"
_PACKAGE_DIR = os.path.dirname(os.path.realpath(__file__))
# The lessons' folder: inside the package (a wheel) or beside it (a checkout). Plain strings:
# this module is imported with glsandbox, before a class's zygote starts (pathlib waits).
_LESSONS_DIR = next((folder for folder in (os.path.join(_PACKAGE_DIR, "lessons"),
                                           os.path.join(os.path.dirname(_PACKAGE_DIR), "lessons"))
                     if os.path.isfile(os.path.join(folder, "__init__.py"))), os.path.join(_PACKAGE_DIR, "lessons"))


def __getattr__(name: str) -> object:
    """``BUILTIN_LESSONS``: the lessons' folder as a :class:`~pathlib.Path`, made on first use."""
    if name == "BUILTIN_LESSONS":
        from pathlib import Path

        return Path(_LESSONS_DIR)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class CourseLessonsFinder:
    """A ``sys.meta_path`` finder for ``glsandbox.lessons`` in a checkout: the folder is at the
    repository's top, not inside the package. Asked last, so an installed wheel's
    ``glsandbox/lessons/`` is found the ordinary way first."""

    def find_spec(self, fullname: str, path: object = None,
                  target: object = None) -> importlib.machinery.ModuleSpec | None:  # noqa: F821 - not imported
        init = os.path.join(_LESSONS_DIR, "__init__.py")
        if fullname != COURSE_PACKAGE or not os.path.isfile(init):
            return None
        import importlib.util

        return importlib.util.spec_from_file_location(fullname, init, submodule_search_locations=[_LESSONS_DIR])


if not any(type(finder).__name__ == CourseLessonsFinder.__name__ for finder in sys.meta_path):
    sys.meta_path.append(CourseLessonsFinder())
