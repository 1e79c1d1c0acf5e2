"""The probe picture: the student's function and the reference over a dense field of inputs.

Each pixel of a square picture is one input (a ray of a grid, a normal of a
hemisphere, ...; the exercise's :class:`~glsandbox.exercises.base.Probe` says
which). The pixel's colour says how the two answers compare:

========================  ==========================================================
colour                    meaning
========================  ==========================================================
dark                      both say "nothing" (``None``, ``False``)
grey (shaded)             both give the same answer (the shade shows the value)
red                       the student's function answers, the reference says nothing
blue                      the reference answers, the student's function says nothing
amber                     both answer, with different values
magenta                   the student's function raised, or gave NaN or the wrong type
========================  ==========================================================

A correct function draws only dark and grey; each named mistake draws its
own pattern of colours (the tests check that no two are alike).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from glsandbox.exercises import runner
from glsandbox.exercises.base import Exercise
from glsandbox.exercises.compare import WrongType, matches, normalize

__all__ = ["CLASSES", "COLOURS", "ProbeResult", "classify", "probe_picture", "reference_values"]

#: The classes of a probe pixel, in the order of :data:`COLOURS`.
CLASSES = ("both none", "agree", "student only", "reference only", "value differs", "broken")
COLOURS = np.array([(24, 24, 32), (0, 0, 0), (230, 60, 60), (60, 120, 240), (250, 190, 40), (200, 60, 200)],
                   dtype=np.uint8)
#: Values on the probe compare to this relative and absolute tolerance.
PROBE_REL, PROBE_ABS = 1e-6, 1e-9


@dataclass
class ProbeResult:
    """The probe's picture, the share of each class, and the inputs and answers behind it."""

    what: str
    image: np.ndarray | None
    classes: np.ndarray | None
    inputs: list[tuple[Any, ...]]
    student: list[Any]
    error: str = ""

    def counts(self) -> dict[str, int]:
        if self.classes is None:
            return {}
        found = np.bincount(self.classes.ravel(), minlength=len(CLASSES))
        return {name: int(n) for name, n in zip(CLASSES, found, strict=True)}

    @property
    def agrees(self) -> bool:
        """Every pixel dark or grey."""
        counts = self.counts()
        return bool(counts) and sum(counts[c] for c in CLASSES[2:]) == 0

    def figures(self) -> dict[str, Any]:
        return {"what": self.what, "counts": self.counts(), "error": self.error}

    def summary(self) -> str:
        """``65,536 inputs: 97.1% agree, 2.9% reference only``."""
        if self.classes is None:
            return f"no probe picture: {self.error}"
        counts, total = self.counts(), self.classes.size
        shown = [("agree", counts["both none"] + counts["agree"])]
        shown += [(name, counts[name]) for name in CLASSES[2:] if counts[name]]
        text = ", ".join(f"{100.0 * n / total:.1f}% {name}" for name, n in shown)
        return f"{total:,} inputs ({self.what}): {text}"

    def wrong_sample(self, stride: int) -> list[tuple[tuple[Any, ...], Any]]:
        """(inputs, answer) of a sample of the wrong pixels: evidence for matching a mistake."""
        if self.classes is None:
            return []
        n = self.classes.shape[0]
        out = []
        for y in range(0, n, stride):
            for x in range(0, n, stride):
                if self.classes[y, x] in (2, 3, 4):
                    out.append((self.inputs[y * n + x], self.student[y * n + x]))
        return out


def reference_values(exercise: Exercise, inputs: list[tuple[Any, ...]]) -> list[Any]:
    """The reference's answers on the field, as plain data (vectorized where the exercise can)."""
    if exercise.probe.reference_many is not None:
        return [runner._encode(v) for v in exercise.probe.reference_many(inputs)]
    return [runner._encode(exercise.reference(*args)) for args in inputs]


def _present(value: Any) -> bool:
    return value is not None and value is not False


def classify(exercise: Exercise, reference: list[Any], student: list[Any], errors: dict[int, str]) -> np.ndarray:
    """Each input's class (an index into :data:`CLASSES`)."""
    out = np.empty(len(reference), dtype=np.uint8)
    for i, (r, s) in enumerate(zip(reference, student, strict=True)):
        if i in errors:
            out[i] = 5
            continue
        try:
            s = normalize(s, exercise.returns)
            r = normalize(r, exercise.returns)
        except WrongType:
            out[i] = 5
            continue
        if _present(r) != _present(s):
            out[i] = 2 if _present(s) else 3
        elif not _present(r):
            out[i] = 0
        else:
            out[i] = 1 if matches(s, r, PROBE_REL, PROBE_ABS) else 4
    return out


def _draw(exercise: Exercise, classes: np.ndarray, reference: list[Any], n: int) -> np.ndarray:
    colours = COLOURS[classes].reshape(n, n, 3).copy()
    shade = exercise.probe.shade or (lambda value: 0.75)
    agree = np.flatnonzero(classes == 1)
    grey = np.array([80 + 160 * min(1.0, max(0.0, float(shade(normalize(reference[i], exercise.returns)))))
                     for i in agree], dtype=np.float64)
    flat = colours.reshape(-1, 3)
    flat[agree] = np.round(grey)[:, None].astype(np.uint8)
    rgba = np.empty((n, n, 4), dtype=np.uint8)
    rgba[..., :3] = colours
    rgba[..., 3] = 255
    return rgba


def probe_picture(exercise: Exercise, caller: Any, n: int = 256) -> ProbeResult:
    """The probe of ``caller``'s function (``Isolated`` or ``InProcess``) against the reference."""
    inputs = exercise.probe.inputs(n)
    batch = caller.batch(inputs)
    if not isinstance(batch, tuple):
        return ProbeResult(exercise.probe.what, None, None, inputs, [], batch.error)
    student, errors = batch
    reference = reference_values(exercise, inputs)
    classes = classify(exercise, reference, student, errors)
    return ProbeResult(exercise.probe.what, _draw(exercise, classes, reference, n), classes.reshape(n, n), inputs,
                       student)
