"""The GLSL engine's record layouts: which ``vec4`` of a node's or a triangle's record holds what.

:mod:`glsandbox.raytrace.gpu` packs a :class:`~glsandbox.raytrace.world.World`
into flat arrays of ``vec4`` records (a uniform block or RGBA32F textures),
``NODE.records`` per node and ``TRI.records`` per triangle. The layouts are
written once, here; the packing indexes them by name (``NODE["inverse"]``) and
``shaders/raytrace.glsl`` gets them as ``#define``s (:func:`layout_defines`:
``NODE_INVERSE 6``, ``NODE_RECORDS 13``...), so the shader reads
``node_rec(k, NODE_INVERSE + 1)`` and never a bare number. A new field is one
line in a layout; the node kind's code (``NODE_BOX_MIN``'s ``w``) comes from
:class:`~glsandbox.raytrace.world.NodeKind` (``KIND_<NAME>`` defines).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["NODE", "TRI", "RecordLayout", "layout_defines"]


@dataclass(frozen=True)
class RecordLayout:
    """Named runs of ``vec4`` records, in order: ``(name, rows, what the four floats hold)``."""

    prefix: str
    fields: tuple[tuple[str, int, str], ...]

    def __getitem__(self, name: str) -> int:
        """The first record of field ``name``."""
        offset = 0
        for field, rows, _ in self.fields:
            if field == name:
                return offset
            offset += rows
        raise KeyError(name)

    @property
    def records(self) -> int:
        """``vec4`` records per element."""
        return sum(rows for _, rows, _ in self.fields)

    def defines(self) -> tuple[tuple[str, str], ...]:
        """``PREFIX_FIELD first`` per field and ``PREFIX_RECORDS records``."""
        found = tuple((f"{self.prefix}_{name.upper()}", str(self[name])) for name, _, _ in self.fields)
        return (*found, (f"{self.prefix}_RECORDS", str(self.records)))


#: A node (positions relative to the upload's anchor, see ``gpu.world_anchor``).
NODE = RecordLayout("NODE", (
    ("box_min", 1, "world box min xyz (padded), NodeKind code"),
    ("box_max", 1, "world box max xyz (padded), one-sided 0/1"),
    ("range", 1, "first triangle, triangle count, scene order (ties), 0"),
    ("color", 1, "material rgb, shading mode (world.MODES)"),
    ("phong", 1, "ka, kd, ks, shininess"),
    ("extra", 1, "reflectivity, texture slot (-1 none), lamp bits, 0"),
    ("inverse", 3, "rows of the inverse model matrix: world to the node's own space"),
    ("normal", 3, "rows of the normal matrix: own-space normal to world"),
    ("look", 1, "alpha, alpha mode, cutoff, flags (1 vertex colours tint a lit colour, 2 two-sided)"),
))
#: A triangle (world positions relative to the anchor; normals, colours, uv per corner).
TRI = RecordLayout("TRI", (
    ("v0", 1, "corner 0 xyz, 0"),
    ("v1", 1, "corner 1 xyz, 0"),
    ("v2", 1, "corner 2 xyz, 0"),
    ("normal", 3, "normal of corner i xyz, one of the six uv floats (uv0.x, uv0.y, uv1.x)"),
    ("color", 3, "colour of corner i rgb, one of the six uv floats (uv1.y, uv2.x, uv2.y)"),
))


def layout_defines() -> tuple[tuple[str, str], ...]:
    """Both layouts as shader defines."""
    return NODE.defines() + TRI.defines()
