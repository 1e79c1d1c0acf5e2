"""The lesson rendered with the student's function: theirs, the reference's, and the difference.

For the ray tracer's exercises the numpy engine renders a course scene twice:
once as it is, and once with the student's function as its hit test for one
kind of node (the engine's ``hit_tests`` seam,
:func:`glsandbox.raytrace.numpy_engine.render_viewport`). The engine runs
here; every call of the student's function goes, in batches, to their
isolated process (or, in a notebook, to their own function): the rays in,
the ``t`` values back.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.exercises.compare import WrongType, normalize
from glsandbox.exercises.definition import Exercise

__all__ = ["LessonResult", "lesson_reference", "render_lesson", "sphere_scene", "triangle_scene"]

#: Pixels whose largest channel differs by more than this count as different.
THRESHOLD = 2


@dataclass
class LessonResult:
    """The three pictures side by side (yours | the reference's | the difference) and figures."""

    what: str
    image: np.ndarray | None
    differing: int = 0
    pixels: int = 0
    calls: int = 0
    error: str = ""

    def summary(self) -> str:
        if self.image is None:
            return f"no lesson picture: {self.error}"
        share = 100.0 * self.differing / max(self.pixels, 1)
        extra = f"; {self.error}" if self.error else ""
        return (f"{self.what}: yours | the reference's | the difference; {self.differing:,} of {self.pixels:,} "
                f"pixels differ ({share:.1f}%), {self.calls:,} calls of your function{extra}")


def sphere_scene() -> Any:
    """The ``ray_spheres`` lesson's scene (three spheres, the notes' #4 among them)."""
    from glsandbox.lesson import find_lesson

    return dataclasses.replace(find_lesson("ray_spheres")().build(), overlays=())


def triangle_scene() -> Any:
    """The ``indexed_cube`` lesson's scene: the notes' 8-vertex, 36-index cube."""
    from glsandbox.lesson import find_lesson

    return dataclasses.replace(find_lesson("indexed_cube")().build(), overlays=())


class _Calls:
    """The student's function as the engine's batched hit test, counting calls and failures."""

    def __init__(self, exercise: Exercise, caller: Any) -> None:
        self.exercise, self.caller = exercise, caller
        self.calls, self.failed, self.error = 0, 0, ""

    def values(self, inputs: list[tuple]) -> list[float]:
        """``t`` of each input (``inf`` for None, a failure or the wrong type)."""
        if not inputs or self.error:
            return [math.inf] * len(inputs)
        self.calls += len(inputs)
        batch = self.caller.batch(inputs)
        if not isinstance(batch, tuple):
            self.error = f"your function stopped answering ({batch.error})"
            return [math.inf] * len(inputs)
        answers, errors = batch
        out = []
        for i, value in enumerate(answers):
            try:
                t = None if i in errors else normalize(value, self.exercise.returns)
            except WrongType:
                t = None
            if i in errors:
                self.failed += 1
            out.append(math.inf if t is None or not t > 0 else float(t))
        return out

    def sphere(self, o: NDArray[np.float64], d: NDArray[np.float64]) -> NDArray[np.float64]:
        """Rays in the unit sphere's own space: ``intersect_sphere(O, d/|d|, (0,0,0), 1) / |d|``."""
        lengths = np.linalg.norm(d, axis=1)
        unit = d / lengths[:, None]
        inputs = [(tuple(a), tuple(b), (0.0, 0.0, 0.0), 1.0) for a, b in zip(o.tolist(), unit.tolist(), strict=True)]
        return np.asarray(self.values(inputs)) / lengths

    def triangles(self, o: NDArray[np.float64], d: NDArray[np.float64], v0: NDArray[np.float64],
                  v1: NDArray[np.float64], v2: NDArray[np.float64], one_sided: bool
                  ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        """Every ray against every triangle of a node; the nearest, and which."""
        n, m = d.shape[0], v0.shape[0]
        tris = [(tuple(a), tuple(b), tuple(c)) for a, b, c in zip(v0.tolist(), v1.tolist(), v2.tolist(), strict=True)]
        rays = list(zip(map(tuple, o.tolist()), map(tuple, d.tolist()), strict=True))
        t = np.asarray(self.values([(*ray, *tri) for ray in rays for tri in tris])).reshape(n, m)
        if one_sided:  # back-face culling is the engine's, not the exercise's: N·Rd > 0 is dropped
            normals = np.cross(v1 - v0, v2 - v0)
            t = np.where(d @ normals.T > 0.0, np.inf, t)
        j = np.argmin(t, axis=1) if m else np.zeros(n, dtype=np.intp)
        best = t[np.arange(n), j] if m else np.full(n, np.inf)
        return best, np.where(np.isfinite(best), j, -1)


def _difference(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, int]:
    delta = np.abs(a[..., :3].astype(np.int16) - b[..., :3].astype(np.int16)).max(axis=2)
    bad = delta > THRESHOLD
    picture = np.zeros_like(a)
    picture[..., 3] = 255
    picture[..., 0] = np.where(bad, 255, np.minimum(delta * 40, 255)).astype(np.uint8)
    picture[..., 1] = np.where(bad, 64, 0)
    return picture, int(bad.sum())


def lesson_reference(exercise: Exercise) -> tuple[Any, np.ndarray]:
    """The lesson's scene and the engine's own picture of it: what :func:`render_lesson` compares
    the student's picture with, made on its own so that it can be made while the student's
    process is busy (the probe's calls)."""
    from glsandbox.raytrace.numpy_engine import render_viewport

    view = exercise.lesson
    assert view is not None
    scene = view.scene()
    # Secondary rays leave the surface by the course's simple offset: the engine's own
    # (the hit point's rounding-error bound) is tight for its stable tests, too tight for a
    # correct geometric one, which would then see its own surface and draw acne.
    return scene, render_viewport(scene, view.size, offset="simple")


def render_lesson(exercise: Exercise, caller: Any, prepared: tuple[Any, np.ndarray] | None = None) -> LessonResult:
    """Render ``exercise.lesson`` with ``caller``'s function and with the engine's own
    (``prepared``: :func:`lesson_reference`'s scene and picture, made already)."""
    from glsandbox.raytrace.numpy_engine import render_viewport

    view = exercise.lesson
    assert view is not None
    scene, reference = prepared if prepared is not None else lesson_reference(exercise)
    calls = _Calls(exercise, caller)
    test = calls.sphere if view.kind == "sphere" else calls.triangles
    yours = render_viewport(scene, view.size, offset="simple", hit_tests={view.kind: test})
    difference, differing = _difference(yours, reference)
    gap = np.full((view.size[1], 4, 4), 255, dtype=np.uint8)
    image = np.concatenate([yours, gap, reference, gap, difference], axis=1)
    note = calls.error or (f"your function failed {calls.failed:,} times" if calls.failed else "")
    return LessonResult(view.what, image, differing, view.size[0] * view.size[1], calls.calls, note)
