"""The GLSL engine's record layouts: offsets by name, record counts and the defines the shader gets."""

from __future__ import annotations

import pytest

from glsandbox.raytrace.gpu_records import NODE, TRI, RecordLayout, layout_defines

LAYOUT = RecordLayout("X", (("a", 1, ""), ("b", 3, ""), ("c", 2, "")))


def test_a_fields_offset_is_the_rows_before_it() -> None:
    assert [LAYOUT[name] for name in "abc"] == [0, 1, 4] and LAYOUT.records == 6
    with pytest.raises(KeyError):
        LAYOUT["d"]
    assert LAYOUT.defines() == (("X_A", "0"), ("X_B", "1"), ("X_C", "4"), ("X_RECORDS", "6"))


def test_the_node_and_triangle_layouts_as_the_engine_packs_them() -> None:
    assert (NODE["inverse"], NODE["normal"], NODE.records) == (6, 9, 13)  # two 3-row matrices
    assert (TRI["normal"], TRI["color"], TRI.records) == (3, 6, 9)
    names = [name for name, _ in layout_defines()]
    assert len(names) == len(set(names)) and "NODE_RECORDS" in names and "TRI_RECORDS" in names

