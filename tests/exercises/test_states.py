"""The ``mirror_states`` exercise: the tables read as data, the room drawn with them, the leak map."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from support import assert_user_error, run_cli

from glsandbox.errors import SandboxError
from glsandbox.exercises.states.mirror import (CLASSES, MISTAKES, REFERENCE_SOURCE, apply_tables, check_tables,
                                               reference_tables, starter)
from glsandbox.exercises.states.tables import parse_tables
from glsandbox.passes.base import StencilState
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


@pytest.mark.parametrize("change,fragments", [
    (lambda s: s + "\nimport os\n", ("f.py:61:", "only assignments")),
    (lambda s: s + "\nSHADOW_LIFT = __import__('os').getcwd()\n", ("f.py:61:", "literal")),
    (lambda s: s.replace('"D3D11_COMPARISON_EQUAL",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP"',
                         '"GL_EQUAL",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP"'), ("f.py:", "'GL_EQUAL'")),
    (lambda s: s.replace('    "StencilRef": 1,\n}\n\n# CullClockwise', '}\n\n# CullClockwise'), ("lacks 'StencilRef'",)),
    (lambda s: s.replace("MARK_MIRROR_DSS =", "MARK_DSS ="), ("f.py:10:", "MARK_DSS is not one of the tables")),
    (lambda s: s.replace("SHADOW_LIFT = 0.005", "SHADOW_LIFT = True"), ("f.py:59:", "SHADOW_LIFT")),
    (lambda s: s + "\nx = (\n", ("f.py:", "not Python")),
    (lambda s: starter(), ("f.py:10:", "left blank")),
])
def test_a_file_that_is_not_the_tables_is_one_error_naming_the_line(change, fragments) -> None:
    with pytest.raises(SandboxError) as caught:
        parse_tables(change(REFERENCE_SOURCE), "f.py")
    message = str(caught.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message


def test_start_then_check_from_the_command_line(gl, tmp_path: Path) -> None:
    run = run_cli("exercise", "start", "mirror_states", cwd=tmp_path)
    assert run.returncode == 0 and (tmp_path / "mirror_states.py").is_file()
    assert_user_error(run_cli("exercise", "check", "mirror_states", "mirror_states.py", cwd=tmp_path),
                      "mirror_states.py:10:", "left blank")
    assert not (tmp_path / "mirror_states_check").exists()  # nothing half-written
    (tmp_path / "right.py").write_text(REFERENCE_SOURCE, encoding="utf-8")
    run = run_cli("exercise", "check", "mirror_states", "right.py", cwd=tmp_path)
    assert run.returncode == 0 and "PASS" in run.stdout
    assert (tmp_path / "right_check" / "leak_map.png").is_file()
    (tmp_path / "wrong.py").write_text(REFERENCE_SOURCE.replace('"StencilFunc": "D3D11_COMPARISON_EQUAL",\n    '
                                                                '"StencilPassOp": "D3D11_STENCIL_OP_KEEP"',
                                                                '"StencilFunc": "D3D11_COMPARISON_ALWAYS",\n    '
                                                                '"StencilPassOp": "D3D11_STENCIL_OP_KEEP"'),
                                       encoding="utf-8")
    run = run_cli("exercise", "check", "mirror_states", "wrong.py", cwd=tmp_path)
    assert run.returncode == 1 and "hint: stencil_always:" in run.stdout
    assert "reflection outside the mirror" in run.stdout


def test_check_of_a_missing_file_is_one_error_line(tmp_path: Path) -> None:
    assert_user_error(run_cli("exercise", "check", "mirror_states", "nowhere.py", cwd=tmp_path), "nowhere.py")
