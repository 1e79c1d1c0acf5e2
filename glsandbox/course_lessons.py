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

import importlib.util
import sys
from pathlib import Path

__all__ = ["COURSE_PACKAGE", "BUILTIN_LESSONS", "CourseLessonsFinder"]

COURSE_PACKAGE = "glsandbox.lessons"
_PACKAGE_DIR = Path(__file__).resolve().parent
#: The lessons' folder: inside the package (a wheel) or beside it (a checkout).
BUILTIN_LESSONS = next((folder for folder in (_PACKAGE_DIR / "lessons", _PACKAGE_DIR.parent / "lessons")
                        if (folder / "__init__.py").is_file()), _PACKAGE_DIR / "lessons")


class CourseLessonsFinder:
    """A ``sys.meta_path`` finder for ``glsandbox.lessons`` in a checkout: the folder is at the
    repository's top, not inside the package. Asked last, so an installed wheel's
    ``glsandbox/lessons/`` is found the ordinary way first."""

    def find_spec(self, fullname: str, path: object = None,
                  target: object = None) -> importlib.machinery.ModuleSpec | None:
        if fullname != COURSE_PACKAGE or not (BUILTIN_LESSONS / "__init__.py").is_file():
            return None
        return importlib.util.spec_from_file_location(fullname, BUILTIN_LESSONS / "__init__.py",
                                                      submodule_search_locations=[str(BUILTIN_LESSONS)])


if not any(type(finder).__name__ == CourseLessonsFinder.__name__ for finder in sys.meta_path):
    sys.meta_path.append(CourseLessonsFinder())
