"""The ``mirror_states`` exercise's room (glsandbox/exercises/states/mirror.py): drawn with the
reference tables it leaks nowhere, each known mistake gives its own leak map and hint, and the
tables become the plan's pass states."""

from __future__ import annotations

import itertools

import numpy as np

from glsandbox.exercises.states.mirror import (CLASSES, MISTAKES, REFERENCE_SOURCE, apply_tables, check_tables,
                                               reference_tables)
from glsandbox.exercises.states.tables import parse_tables
from glsandbox.passes.plan_parts import StencilState
from glsandbox.plan import MARK_MIRROR_STENCIL, plan


def test_the_reference_tables_give_an_empty_leak_map(gl) -> None:
    result = check_tables(gl, reference_tables())
    assert result.passed and result.hints == []
    assert all(count == 0 for count in result.leaks.counts().values())


def test_each_known_mistake_gives_its_own_leak_map_and_its_hint(gl) -> None:
    maps = {}
    for mistake in MISTAKES:
        result = check_tables(gl, mistake.change(reference_tables()))
        assert not result.passed, mistake.name
        assert result.leaks.counts()[CLASSES[mistake.shows_as][0]] > 100, (mistake.name, result.leaks.counts())
        assert result.hints and result.hints[0].startswith(f"{mistake.name}: "), (mistake.name, result.hints)
        maps[mistake.name] = result.leaks.classes
    for (a, ma), (b, mb) in itertools.combinations(maps.items(), 2):
        assert not np.array_equal(ma, mb), (a, b)


def test_the_tables_become_the_plans_states() -> None:
    from glsandbox.exercises.states.mirror import _scene

    passes = {step.kind: step for step in plan(_scene(None)).passes}
    assert passes["mark_mirror"].depth_write is None and passes["reflection"].front_face is None  # the defaults
    tables = reference_tables()
    mark = apply_tables(passes["mark_mirror"], tables)
    assert mark.stencil == StencilState("always", 1, mask=0xFF, write_mask=0xFF, on_pass="replace")
    assert mark.stencil.describe() == MARK_MIRROR_STENCIL.describe() and mark.depth_write is False
    reflection = apply_tables(passes["reflection"], tables)
    assert reflection.stencil == StencilState("equal", 1, mask=0xFF, write_mask=0xFF) and reflection.front_face == "cw"
    shadow = apply_tables(passes["planar_shadow"], tables)
    assert shadow.stencil.on_pass == "incr" and shadow.blend == ("src_alpha", "one_minus_src_alpha")
    unflipped = parse_tables(REFERENCE_SOURCE.replace('"FrontCounterClockwise": True', '"FrontCounterClockwise": False'),
                             "f.py")
    assert apply_tables(passes["reflection"], unflipped).front_face == "ccw"
