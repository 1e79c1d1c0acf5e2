"""Exercises: the student writes the course's own functions; glsandbox checks them.

Each exercise (one module under :mod:`glsandbox.exercises.catalogue`) is a
function of the course (``intersect_sphere``, ``reflect``, ...) with the
notes' worked examples as visible cases, generated hard cases kept hidden
until the teacher runs them, a probe picture of where the student's answers
differ from the reference's over a dense field of inputs, and named
mistakes that turn a failing pattern into a sentence.

- :mod:`~glsandbox.exercises.definition`: the data (Exercise, Case, Mistake, Probe);
- :mod:`~glsandbox.exercises.catalogue`: the registry (:func:`get`, :func:`all_exercises`);
- :mod:`~glsandbox.exercises.isolation`: the student's function in a confined process
  (:mod:`~glsandbox.exercises.student_process`, the script that process runs);
- :mod:`~glsandbox.exercises.check`: the cases judged (:mod:`~glsandbox.exercises.compare`), the
  mistakes matched (written with :mod:`~glsandbox.exercises.plain`), a plain record;
- :mod:`~glsandbox.exercises.fields`: the probe pictures' fields of inputs;
  :mod:`~glsandbox.exercises.dxmath`: the course's DirectXMath matrices made from the engine's;
- :mod:`~glsandbox.exercises.states`: the state exercises (a lesson's Direct3D 11 state tables);
- :mod:`~glsandbox.exercises.probe`, :mod:`~glsandbox.exercises.lesson_view`: the pictures;
- :mod:`~glsandbox.exercises.report`, :mod:`~glsandbox.exercises.starter`: what people read;
- :mod:`~glsandbox.exercises.commands`: ``glsandbox exercise list | start | check``.

In a notebook, :func:`exercise` checks a function of the kernel's own
(``glsandbox.exercise("ray_sphere", my_function)``) and shows the report.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from glsandbox.exercises.catalogue import all_exercises, get

__all__ = ["ExerciseReport", "all_exercises", "exercise", "get"]


class ExerciseReport:
    """A check's result that Jupyter shows as a table with its pictures (``_repr_html_``)."""

    def __init__(self, result: Any) -> None:
        self.result = result

    def _repr_html_(self) -> str:
        from glsandbox.exercises.report import html

        return html(self.result, hidden_shown=False)

    def __repr__(self) -> str:
        from glsandbox.exercises.report import text

        return text(self.result, hidden_shown=False)

    @property
    def passed(self) -> bool:
        """Every visible case passes."""
        return bool(self.result.visible_passed)


def exercise(name: str, function: Callable[..., Any], *, lesson: bool = True) -> ExerciseReport:
    """Check ``function`` against the exercise ``name``: the visible cases, the probe picture
    and (for the ray tracer's functions) the lesson rendered with it. The function runs
    here, in the notebook's own kernel; the hidden cases are not run."""
    from glsandbox.exercises.check import check_function

    return ExerciseReport(check_function(get(name), function, hidden=False, lesson=lesson))
