"""The exercises, one module each, in the course's order.

A module defines ``EXERCISE``, an :class:`~glsandbox.exercises.definition.Exercise`.
To add one: write the module (``ray_sphere.py`` is the template: the
reference wrapped from the engine, the notes' worked examples as visible
cases, a generator of hard cases, the probe, at least three named mistakes),
add its name to :data:`MODULES`, and its tests follow from
``tests/exercises/`` (every exercise is checked by the same tests).
"""

from __future__ import annotations

import importlib

from glsandbox.errors import SandboxError
from glsandbox.exercises.definition import Exercise

__all__ = ["MODULES", "all_exercises", "get", "markdown_table"]

#: Every exercise's module, in the order of the course's sections.
MODULES: tuple[str, ...] = (
    "image_plane",
    "triangle_normal",
    "ray_plane",
    "ray_triangle",
    "ray_sphere",
    "reflect",
    "phong",
    "shadow",
    "backface",
    "aabb",
    "camera_turn",
    "cube_indices",
    "world_matrix",
    "look_at",
    "perspective",
    "normal_matrix",
    "reflect_matrix",
    "shadow_matrix",
)

_LOADED: dict[str, Exercise] = {}


def all_exercises() -> list[Exercise]:
    """Every exercise, in the course's order."""
    return [get(name) for name in MODULES]


def get(name: str) -> Exercise:
    """The exercise ``name``; a :class:`SandboxError` naming the known ones when there is none."""
    if name not in MODULES:
        known = ", ".join(MODULES)
        raise SandboxError(f"no exercise {name!r}; the exercises are: {known} (glsandbox exercise list)")
    if name not in _LOADED:
        _LOADED[name] = importlib.import_module(f"glsandbox.exercises.catalogue.{name}").EXERCISE
    return _LOADED[name]


def markdown_table() -> str:
    """The catalogue as a Markdown table (the docs' and the README's, kept true by a test)."""
    rows = ["| exercise | function | course section | cases (visible + hidden) | named mistakes |",
            "|---|---|---|---|---|"]
    for e in all_exercises():
        mistakes = ", ".join(f"`{m.name}`" for m in e.mistakes)
        rows.append(f"| `{e.name}` | `{e.signature}` | {e.section} | {len(e.visible)} + {len(e.hidden())} | "
                    f"{mistakes} |")
    return "\n".join(rows)
