"""State exercises: the student fills the Direct3D 11 state tables of a lesson; glsandbox
renders the lesson with them and grades the picture.

Unlike the function exercises (:mod:`glsandbox.exercises.catalogue`) the
student's file is data: :mod:`~glsandbox.exercises.states.tables` reads it
with :func:`ast.literal_eval` and never runs it.

- :mod:`~glsandbox.exercises.states.tables`: the file read, the Direct3D names mapped to the plan's;
- :mod:`~glsandbox.exercises.states.mirror`: ``mirror_states``, the stencil mirror and its planar
  shadow, graded by a leak map.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["STATE_EXERCISES", "StateExercise"]


@dataclass(frozen=True)
class StateExercise:
    """One state exercise: its name, course section and what the file holds (``exercise list``'s line)."""

    name: str
    section: str
    holds: str
    #: Its case groups when graded for a class (a rubric's ``points`` keys): one per leak kind.
    groups: tuple[str, ...] = ()


#: The state exercises by name.
STATE_EXERCISES: dict[str, StateExercise] = {
    "mirror_states": StateExercise(
        "mirror_states", "The stencil Test: MarkMirrorDSS, DrawReflectionDSS",
        "MARK_MIRROR_DSS, DRAW_REFLECTION_DSS, REFLECTED_RASTERIZER, SHADOW_BLEND, SHADOW_DSS, SHADOW_LIFT",
        # the leak map's kinds (mirror.CLASSES but "as the reference"), in its order
        ("reflection_outside", "reflection_wrong", "reflection_missing", "shadow_twice", "shadow_missing", "other")),
}
