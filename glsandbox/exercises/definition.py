"""What an exercise is: its function, its cases, its probe picture and its named mistakes.

Everything here is plain data. An :class:`Exercise` is written once per
course function (one module each under :mod:`glsandbox.exercises.catalogue`)
and read by the checker (:mod:`glsandbox.exercises.check`), the starter
(:mod:`glsandbox.exercises.starter`), the reports and the docs.

Values are plain Python, as a student writes them: a number, ``None`` for
"no hit", a ``bool``, a 3-vector (any sequence of three numbers, numpy arrays
included) or a 4x4 matrix (nested sequences). :data:`RESULT_KINDS` names what
each exercise's function returns; :mod:`glsandbox.exercises.compare` judges a
value against the expected one with the tolerance its case states.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ["RESULT_KINDS", "Case", "Exercise", "LessonView", "Mistake", "Probe"]

#: What an exercise's function may return:
#: ``t`` a distance ``t > 0`` or ``None``; ``number`` a float; ``bool``; ``vec3`` three numbers;
#: ``vec3_or_none`` three numbers or ``None``; ``matrix4`` a 4x4 matrix; ``indices`` an index
#: buffer (whole numbers >= 0, three per triangle).
RESULT_KINDS = ("t", "number", "bool", "vec3", "vec3_or_none", "matrix4", "indices")


@dataclass(frozen=True)
class Case:
    """One call of the student's function and the answer it must give.

    ``rel`` and ``abs`` are the case's tolerance: a number ``g`` matches ``e``
    when ``|g - e| <= abs + rel·|e|`` (for vectors and matrices, component by
    component, with ``|e|`` the largest component). ``also`` lists other
    answers accepted: where the reference itself is within its error bound
    of a decision (a ray exactly on an edge, a tangent ray), either side is
    right, and ``margin`` says why. ``group`` is ``"visible"`` (the notes'
    worked examples, shown) or a hidden group's name (graded only when the
    teacher runs the hidden cases). An ``expected`` with an ``accepts(value)``
    method judges the answer itself (an index buffer is right in more than
    one triangulation).
    """

    name: str
    args: tuple[Any, ...]
    expected: Any
    rel: float = 1e-9
    abs: float = 1e-9
    also: tuple[Any, ...] = ()
    margin: str = ""
    group: str = "visible"

    @property
    def hidden(self) -> bool:
        return self.group != "visible"


@dataclass(frozen=True)
class Mistake:
    """A known wrong version of the function and the one sentence that names it.

    ``function`` has the exercise's signature. The checker runs it on the
    same cases as the student's; when the student's failures match it, the
    feedback is ``hint``.
    """

    name: str
    hint: str
    function: Callable[..., Any]


@dataclass(frozen=True)
class Probe:
    """The function over a dense field of inputs, one per pixel of a square picture.

    ``inputs(n)`` gives the ``n·n`` argument tuples, row by row from the top;
    ``reference_many(inputs)``, when given, computes the reference's values for
    all of them at once (vectorized: the picture must not cost seconds);
    ``shade(value)`` maps an answer to a brightness in ``[0, 1]`` for the
    pixels where both agree (``None`` and ``False`` are the dark background).
    ``what`` says in words what the field is. ``resolution``, when given, is
    the field's side for a function too slow to ask 65,536 times (each of
    its inputs then covers a square of pixels of the picture).

    ``draw``, when given, makes a picture of another kind: ``inputs(n)`` are
    then a few argument tuples, and ``draw(reference, student, errors, n)``
    returns each of the ``n x n`` pixels' class (an index into
    :data:`glsandbox.exercises.probe.CLASSES`) and a shade in ``[0, 1]``,
    drawn from all the answers at once (a matrix's picture is the unit cube's
    image under it, not one pixel per input). Each input is then one piece
    of evidence for naming a mistake: ``draw`` returns, third, each input's
    class (1 agree, 4 differ, 5 broken).
    """

    what: str
    inputs: Callable[[int], list[tuple[Any, ...]]]
    reference_many: Callable[[list[tuple[Any, ...]]], list[Any]] | None = None
    shade: Callable[[Any], float] | None = None
    resolution: int | None = None
    draw: Callable[[list[Any], list[Any], dict[int, str], int], tuple[Any, Any, Any]] | None = None


@dataclass(frozen=True)
class LessonView:
    """How the student's function renders a scene through the numpy engine.

    ``scene()`` builds the scene; ``kind`` is the shape kind whose hit test the
    student's function replaces (``"sphere"`` or ``"triangles"``); ``size`` is
    the picture's size.
    """

    what: str
    scene: Callable[[], Any]
    kind: str
    size: tuple[int, int] = (160, 90)


@dataclass(frozen=True)
class Exercise:
    """One course function to write.

    ``function`` is the name the student's file must define and ``params``
    its parameters; ``doc`` is the docstring a student reads (the course
    section and its Turkish term, the formula as the notes write it, the
    worked example); ``example`` is the worked example as a line of Python
    for the starter. ``reference`` is the engine's own function wrapped to
    the plain signature (never a copy of it). ``visible`` are the notes'
    worked examples; ``hidden()`` generates the hard cases (deterministic: the
    same cases every call). ``convention`` says, for matrix exercises, which
    convention is accepted (the course's DirectX row vectors or OpenGL's
    column vectors).
    """

    name: str
    function: str
    params: tuple[str, ...]
    section: str
    term: str
    summary: str
    doc: str
    example: str
    returns: str
    reference: Callable[..., Any]
    visible: tuple[Case, ...]
    hidden: Callable[[], list[Case]]
    probe: Probe
    mistakes: tuple[Mistake, ...]
    convention: str = ""
    lesson: LessonView | None = None
    order: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.returns not in RESULT_KINDS:
            raise ValueError(f"exercise {self.name}: returns {self.returns!r} is not one of {RESULT_KINDS}")
        if len(self.mistakes) < 3:
            raise ValueError(f"exercise {self.name}: at least three named mistakes, got {len(self.mistakes)}")

    @property
    def signature(self) -> str:
        """``intersect_sphere(origin, direction, center, radius)``."""
        return f"{self.function}({', '.join(self.params)})"

    def cases(self, hidden: bool = False) -> list[Case]:
        """The visible cases, then (with ``hidden``) the generated hard cases."""
        return [*self.visible, *(self.hidden() if hidden else ())]


def vec(values: Sequence[float]) -> tuple[float, ...]:
    """A plain tuple of floats (what expected vectors are written as)."""
    return tuple(float(v) for v in values)
