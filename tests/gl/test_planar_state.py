"""GL state for the planar passes (glsandbox/gl/planar_state.py): a pass's stencil state set as the
course's depth-stencil objects say (``MarkMirrorDSS``, ``DrawReflectionDSS``), the lights seen in
the mirror, and no import back to the executor (course section "The stencil Test")."""

from __future__ import annotations

import numpy as np

from glsandbox import transforms
from glsandbox.gl import rawgl
from glsandbox.gl.planar_state import reflected_lights, set_stencil
from glsandbox.passes.planar_effects import MARK_MIRROR_STENCIL, PLANAR_SHADOW_STENCIL, REFLECTION_STENCIL
from glsandbox.scene import Light


class RecordingGL:
    """Stands in for :class:`glsandbox.gl.rawgl.RawGL`: each call by name with its arguments."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def __getattr__(self, name: str):
        return lambda *args: self.calls.append((name, *args))


def stencil_calls(state) -> list[tuple]:
    raw = RecordingGL()
    set_stencil(raw, state)
    return raw.calls


def test_the_mirror_is_marked_always_replacing_its_bit() -> None:
    assert stencil_calls(MARK_MIRROR_STENCIL) == [
        ("glEnable", rawgl.GL_STENCIL_TEST), ("glStencilMask", 1), ("glStencilFunc", rawgl.GL_ALWAYS, 1, 0xFF),
        ("glStencilOp", rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_REPLACE)]


def test_the_reflection_reads_the_mirror_bit_and_writes_nothing() -> None:
    assert stencil_calls(REFLECTION_STENCIL)[1:] == [
        ("glStencilMask", 0), ("glStencilFunc", rawgl.GL_EQUAL, 1, 1),
        ("glStencilOp", rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_KEEP)]


def test_the_planar_shadow_flips_its_own_bit_where_it_is_clear() -> None:
    bit = PLANAR_SHADOW_STENCIL.mask
    assert bit != 1  # its own bit, apart from the mirror's: one buffer serves both
    assert stencil_calls(PLANAR_SHADOW_STENCIL)[1:] == [
        ("glStencilMask", bit), ("glStencilFunc", rawgl.GL_EQUAL, 0, bit),
        ("glStencilOp", rawgl.GL_KEEP, rawgl.GL_KEEP, rawgl.GL_INVERT)]


def test_the_lights_seen_in_the_mirror_are_reflected_and_keep_their_colour() -> None:
    lights = (Light((1.0, 2.0, 3.0), (1.0, 0.5, 0.25)), Light((0.0, 0.0, -4.0)))
    mirrored = reflected_lights(lights, transforms.reflection_matrix((0.0, 0.0, 1.0, 0.0)))  # the plane z = 0
    assert np.allclose([l.position for l in mirrored], [(1.0, 2.0, -3.0), (0.0, 0.0, 4.0)])
    assert [l.color for l in mirrored] == [l.color for l in lights]


def test_gl_planar_does_not_import_the_executor():
    # The executor imports the planar passes; they reach it only through the
    # NodeDrawer protocol, so no import (not even for typing) goes back.
    import ast
    from pathlib import Path

    import glsandbox.gl.planar_state

    tree = ast.parse(Path(glsandbox.gl.planar_state.__file__).read_text(encoding="utf-8"))
    imported = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    imported |= {f"{node.module}.{alias.name}" if node.module else alias.name
                 for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) for alias in node.names}
    imported |= {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
    assert not any("executor" in name for name in imported), sorted(imported)
