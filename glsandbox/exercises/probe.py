"""The probe picture: the student's function and the reference over a dense field of inputs.

Each pixel of a square picture is one input (a ray of a grid, a normal of a
hemisphere, ...; the exercise's :class:`~glsandbox.exercises.definition.Probe` says
which). The pixel's colour says how the two answers compare:

========================  ==========================================================
colour                    meaning
========================  ==========================================================
dark                      both say "nothing" (``None``, ``False``)
grey (shaded)             both give the same answer (the shade shows the value)
amber (shaded)            both answer, with different values (shaded by the student's)
red                       the student's function answers, the reference says nothing
blue                      the reference answers, the student's function says nothing
magenta                   the student's function raised, or gave NaN or the wrong type
========================  ==========================================================

A correct function draws only dark and grey; each named mistake draws its
own pattern of colours (the tests check that no two are alike).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from glsandbox.exercises import student_process
from glsandbox.exercises.compare import WrongType, matches, normalize
from glsandbox.exercises.definition import Exercise

__all__ = ["CLASSES", "COLOURS", "ProbeResult", "classify", "picture", "probe_field", "probe_picture",
           "reference_values", "start_probe"]

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
    reference: list[Any] = field(default_factory=list)
    error: str = ""
    #: For a drawn probe (``Probe.draw``): each input's own class, the evidence of :meth:`sample`.
    input_classes: np.ndarray | None = None

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
        if self.input_classes is not None:
            return f"{len(self.inputs)} inputs drawn over {total:,} pixels ({self.what}): {text}"
        return f"{total:,} inputs ({self.what}): {text}"

    def sample(self, stride: int) -> list[tuple[tuple[Any, ...], Any, Any, bool]]:
        """(inputs, the student's answer, the reference's, whether the student's is wrong) of
        every ``stride``-th input each way, but none the student's function raised on: the
        evidence for matching a named mistake."""
        if self.classes is None:
            return []
        if self.input_classes is not None:
            return [(args, s, r, bool(c >= 2)) for args, s, r, c in
                    zip(self.inputs, self.student, self.reference, self.input_classes, strict=True) if c != 5]
        n = self.classes.shape[0]
        out = []
        for y in range(0, n, stride):
            for x in range(0, n, stride):
                i = y * n + x
                if self.classes[y, x] != 5:
                    out.append((self.inputs[i], self.student[i], self.reference[i], self.classes[y, x] >= 2))
        return out


def reference_values(exercise: Exercise, inputs: list[tuple[Any, ...]]) -> list[Any]:
    """The reference's answers on the field, as plain data (vectorized where the exercise can)."""
    if exercise.probe.reference_many is not None:
        values = exercise.probe.reference_many(inputs)
        if set(map(type, values)) <= _PLAIN:  # already what encoding gives (a field of distances)
            return list(values)
        return [student_process._encode(v) for v in values]
    return [student_process._encode(exercise.reference(*args)) for args in inputs]


#: The types an answer has as plain data already (:func:`student_process._encode` leaves them alone).
_PLAIN = {float, int, bool, type(None)}


def _present(value: Any) -> bool:
    return value is not None and value is not False


def _as_t(values: list[Any]) -> np.ndarray | None:
    """Answers that are all numbers or None as floats (NaN for None); None when any is not."""
    if not all(v is None or ((type(v) is float or type(v) is int) and v == v) for v in values):
        return None  # another type, or a NaN: judged one by one
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


def _classify_t(exercise: Exercise, reference: list[Any], student: list[Any],
                errors: dict[int, str]) -> np.ndarray | None:
    """:func:`classify` for distances (``t`` or None) in whole arrays; None when an answer is
    of another type (then each is judged one by one)."""
    if exercise.returns != "t":
        return None
    r, s = _as_t(reference), _as_t(student)
    if r is None or s is None:
        return None
    has_r, has_s = ~np.isnan(r), ~np.isnan(s)
    same = np.abs(np.where(has_r & has_s, s - r, 0.0)) <= PROBE_ABS + PROBE_REL * np.abs(np.where(has_r, r, 0.0))
    out = np.where(has_r & has_s, np.where(same, 1, 4), np.where(has_s, 2, np.where(has_r, 3, 0))).astype(np.uint8)
    if errors:
        out[list(errors)] = 5
    return out


def classify(exercise: Exercise, reference: list[Any], student: list[Any], errors: dict[int, str]) -> np.ndarray:
    """Each input's class (an index into :data:`CLASSES`)."""
    fast = _classify_t(exercise, reference, student, errors)
    if fast is not None:
        return fast
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


def _brightness(exercise: Exercise, value: Any) -> float:
    shade = exercise.probe.shade
    if shade is None:
        return 0.75
    try:
        level = float(shade(normalize(value, exercise.returns)))
    except (WrongType, TypeError, ValueError, ZeroDivisionError):
        return 0.75
    return min(1.0, max(0.0, level)) if level == level else 0.75


def _levels(exercise: Exercise, values: list[Any]) -> np.ndarray:
    """:func:`_brightness` of each value; for distances (``t``, every one a number) the shade
    is taken of them all at once, as one array."""
    shade = exercise.probe.shade
    t = _as_t(values) if exercise.returns == "t" and shade is not None and values else None
    if t is not None and not np.isnan(t).any():
        try:
            with np.errstate(all="ignore"):
                level = np.asarray(shade(t), dtype=np.float64)
        except (TypeError, ValueError, ZeroDivisionError):
            level = None
        if level is not None and level.shape == t.shape:
            return np.where(np.isnan(level), 0.75, np.clip(level, 0.0, 1.0))
    return np.array([_brightness(exercise, v) for v in values], dtype=np.float64)


def _draw(exercise: Exercise, classes: np.ndarray, reference: list[Any], student: list[Any], n: int) -> np.ndarray:
    """The picture: each class's colour; where both agree, grey shaded by the value; where the
    values differ, amber shaded by the student's value (so two wrong versions that differ
    everywhere still draw different pictures)."""
    flat = COLOURS[classes].astype(np.float64)
    agree, differ = np.flatnonzero(classes == 1), np.flatnonzero(classes == 4)
    flat[agree] = (80.0 + 160.0 * _levels(exercise, [reference[i] for i in agree]))[:, None]
    flat[differ] = COLOURS[4] * (0.45 + 0.55 * _levels(exercise, [student[i] for i in differ]))[:, None]
    rgba = np.full((n * n, 4), 255, dtype=np.uint8)
    rgba[:, :3] = np.round(flat).astype(np.uint8)
    return rgba.reshape(n, n, 4)


def _shaded(classes: np.ndarray, shade: np.ndarray) -> np.ndarray:
    """A drawn probe's picture: each class's colour, agreeing pixels grey and differing ones
    amber, both shaded by ``shade``."""
    flat = COLOURS[classes].astype(np.float64)
    level = np.clip(np.nan_to_num(shade, nan=0.75), 0.0, 1.0)[..., None]
    flat = np.where((classes == 1)[..., None], 80.0 + 160.0 * level, flat)
    flat = np.where((classes == 4)[..., None], COLOURS[4] * (0.45 + 0.55 * level), flat)
    rgba = np.full((*classes.shape, 4), 255, dtype=np.uint8)
    rgba[..., :3] = np.round(flat).astype(np.uint8)
    return rgba


def probe_picture(exercise: Exercise, caller: Any, n: int = 256) -> ProbeResult:
    """The probe of ``caller``'s function (``Isolated`` or ``InProcess``) against the reference,
    drawn ``n x n`` (from a coarser field where the exercise's probe has a ``resolution``)."""
    return start_probe(exercise, caller, n)()


def probe_field(exercise: Exercise, n: int = 256) -> list[tuple[Any, ...]]:
    """The inputs of the probe drawn ``n x n``: one a pixel, or a coarser field's
    (``resolution``), or a drawn probe's few."""
    m = n if exercise.probe.draw is not None else min(n, exercise.probe.resolution or n)
    return exercise.probe.inputs(m)


def start_probe(exercise: Exercise, caller: Any, n: int = 256,
                inputs: list[tuple[Any, ...]] | None = None) -> Callable[[], ProbeResult]:
    """:func:`probe_picture` in two halves: the field (``inputs``: :func:`probe_field`'s, made
    already) is sent to ``caller`` now; the returned function computes the reference's values
    (while the student's process is still answering) and then draws the picture. What the
    grader does in between overlaps the student's calls."""
    draw = exercise.probe.draw
    m = n if draw is not None else min(n, exercise.probe.resolution or n)
    inputs = probe_field(exercise, n) if inputs is None else inputs
    begin = getattr(caller, "begin_batch", None)
    if begin is not None:
        answers = begin(inputs)
    else:  # a caller with batch alone
        batch = caller.batch(inputs)
        answers = lambda: batch  # noqa: E731

    def finish() -> ProbeResult:
        reference = reference_values(exercise, inputs)
        batch = answers()
        if not isinstance(batch, tuple):
            return ProbeResult(exercise.probe.what, None, None, inputs, [], error=batch.error)
        student, errors = batch
        if draw is not None:
            classes, shade, own = draw(reference, student, errors, n)
            classes = np.asarray(classes, dtype=np.uint8)
            return ProbeResult(exercise.probe.what, _shaded(classes, np.asarray(shade, dtype=np.float64)), classes,
                               inputs, student, reference, input_classes=np.asarray(own, dtype=np.uint8))
        classes, image = picture(exercise, reference, student, errors, m)
        if m < n:
            image = np.repeat(np.repeat(image, -(-n // m), axis=0), -(-n // m), axis=1)[:n, :n]
        return ProbeResult(exercise.probe.what, image, classes, inputs, student, reference)

    return finish


def picture(exercise: Exercise, reference: list[Any], student: list[Any], errors: dict[int, str],
            n: int) -> tuple[np.ndarray, np.ndarray]:
    """The classes (``n x n``) and the RGBA picture of ``student``'s answers against ``reference``'s."""
    if exercise.probe.draw is not None:
        drawn, shade, _ = exercise.probe.draw(reference, student, errors, n)
        return drawn, _shaded(np.asarray(drawn, dtype=np.uint8), np.asarray(shade, dtype=np.float64))
    classes = classify(exercise, reference, student, errors)
    return classes.reshape(n, n), _draw(exercise, classes, reference, student, n)
