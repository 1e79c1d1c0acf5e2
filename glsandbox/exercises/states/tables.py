"""A student's state tables read as data, and their Direct3D 11 names mapped to the plan's GL states.

Course section "The stencil Test: MarkMirrorDSS, DrawReflectionDSS". The
tutorials fill Direct3D 11 descriptions (``D3D11_DEPTH_STENCIL_DESC``,
``D3D11_RASTERIZER_DESC``, ``D3D11_BLEND_DESC``); glsandbox's plan holds
the same state the way OpenGL sets it. The mapping:

==============================================  ==============================================
Direct3D 11                                     the plan / OpenGL
==============================================  ==============================================
``DepthEnable``                                 ``Pass.depth_test`` (``glEnable(GL_DEPTH_TEST)``)
``DepthWriteMask`` ``..._ALL`` / ``..._ZERO``   ``Pass.depth_write`` (``glDepthMask(1 / 0)``)
``StencilEnable`` False                         no stencil state (``glDisable(GL_STENCIL_TEST)``)
``StencilFunc`` ``D3D11_COMPARISON_ALWAYS``     ``StencilState.test`` ``always`` (``GL_ALWAYS``)
``..._EQUAL``, ``..._NOT_EQUAL``, ``..._NEVER``   ``equal``, ``not_equal``, ``never``
``StencilRef`` (``OMSetDepthStencilState``)     ``ref`` (``glStencilFunc``'s reference)
``StencilReadMask``                             ``mask`` (``glStencilFunc``'s mask)
``StencilWriteMask``                            ``write_mask`` (``glStencilMask``)
``StencilPassOp`` ``D3D11_STENCIL_OP_KEEP``     ``on_pass`` ``keep`` (``glStencilOp``'s third)
``..._REPLACE``, ``..._INCR_SAT``/``..._INCR``,  ``replace``, ``incr`` (``GL_INCR``: saturating),
``..._INVERT``, ``..._ZERO``                    ``invert``, ``zero``
``CullMode`` ``D3D11_CULL_BACK``                the draws' own back-face culling
``D3D11_CULL_NONE`` / ``D3D11_CULL_FRONT``      no culling / the front-face rule flipped again
``FrontCounterClockwise`` False (the default)   the normal passes' rule (glsandbox's ``GL_CCW``)
``FrontCounterClockwise`` True                  flipped: ``Pass.front_face`` ``cw``
``BlendEnable`` False                           ``Pass.blend`` (``one``, ``zero``): replace
``SrcBlend``/``DestBlend`` ``D3D11_BLEND_SRC_   ``Pass.blend`` (``src_alpha``,
ALPHA``/``D3D11_BLEND_INV_SRC_ALPHA``           ``one_minus_src_alpha``), and so on
``shadowOffsetY``                               ``PlanarShadow.lift``
==============================================  ==============================================

The stencil-fail and depth-fail operations are ``KEEP`` in every table of
the tutorials (and in the plan), so the tables have no field for them.
A Direct3D front face is read against the normal passes: the course's
``FrontCounterClockwise = true`` for the reflection says "the other winding
than usual", which is what glsandbox's ``front_face="cw"`` says in GL.

The student's file is data, not code: it is parsed (:mod:`ast`) and each
assignment's value read with :func:`ast.literal_eval`; any other statement,
name or value is refused with one ``error:`` line naming the file and line.
Nothing of the file is ever run, so it needs no isolated process (unlike
the function exercises, :mod:`glsandbox.exercises.isolation`).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from glsandbox.errors import SandboxError

__all__ = ["DSS_FIELDS", "TABLES", "DepthStencil", "Rasterizer", "Blend", "StateTables", "load_tables", "parse_tables"]

COMPARISONS = {"D3D11_COMPARISON_ALWAYS": "always", "D3D11_COMPARISON_EQUAL": "equal",
               "D3D11_COMPARISON_NOT_EQUAL": "not_equal", "D3D11_COMPARISON_NEVER": "never"}
STENCIL_OPS = {"D3D11_STENCIL_OP_KEEP": "keep", "D3D11_STENCIL_OP_REPLACE": "replace",
               "D3D11_STENCIL_OP_INCR_SAT": "incr", "D3D11_STENCIL_OP_INCR": "incr",
               "D3D11_STENCIL_OP_INVERT": "invert", "D3D11_STENCIL_OP_ZERO": "zero"}
DEPTH_WRITE = {"D3D11_DEPTH_WRITE_MASK_ALL": True, "D3D11_DEPTH_WRITE_MASK_ZERO": False}
CULL_MODES = {"D3D11_CULL_BACK": "back", "D3D11_CULL_FRONT": "front", "D3D11_CULL_NONE": "none"}
BLENDS = {"D3D11_BLEND_ZERO": "zero", "D3D11_BLEND_ONE": "one", "D3D11_BLEND_SRC_ALPHA": "src_alpha",
          "D3D11_BLEND_INV_SRC_ALPHA": "one_minus_src_alpha", "D3D11_BLEND_DEST_ALPHA": "dst_alpha",
          "D3D11_BLEND_INV_DEST_ALPHA": "one_minus_dst_alpha", "D3D11_BLEND_SRC_COLOR": "src_color",
          "D3D11_BLEND_INV_SRC_COLOR": "one_minus_src_color", "D3D11_BLEND_DEST_COLOR": "dst_color",
          "D3D11_BLEND_INV_DEST_COLOR": "one_minus_dst_color"}

#: A depth-stencil table's fields: each one's allowed names (a dict), or its Python type.
DSS_FIELDS: dict[str, Any] = {"DepthEnable": bool, "DepthWriteMask": DEPTH_WRITE, "StencilEnable": bool,
                              "StencilReadMask": int, "StencilWriteMask": int, "StencilFunc": COMPARISONS,
                              "StencilPassOp": STENCIL_OPS, "StencilRef": int}
RASTERIZER_FIELDS: dict[str, Any] = {"CullMode": CULL_MODES, "FrontCounterClockwise": bool}
BLEND_FIELDS: dict[str, Any] = {"BlendEnable": bool, "SrcBlend": BLENDS, "DestBlend": BLENDS}
#: The tables a file must assign, with their fields (None: a number).
TABLES: dict[str, dict[str, Any] | None] = {
    "MARK_MIRROR_DSS": DSS_FIELDS, "DRAW_REFLECTION_DSS": DSS_FIELDS, "REFLECTED_RASTERIZER": RASTERIZER_FIELDS,
    "SHADOW_BLEND": BLEND_FIELDS, "SHADOW_DSS": DSS_FIELDS, "SHADOW_LIFT": None}


@dataclass(frozen=True)
class DepthStencil:
    """A ``D3D11_DEPTH_STENCIL_DESC`` (and its reference) in the plan's words."""

    depth_test: bool
    depth_write: bool
    stencil: bool
    read_mask: int
    write_mask: int
    test: str
    on_pass: str
    ref: int


@dataclass(frozen=True)
class Rasterizer:
    """The reflected pass's ``D3D11_RASTERIZER_DESC``: ``cull`` back, front or none; ``ccw_front``."""

    cull: str
    ccw_front: bool


@dataclass(frozen=True)
class Blend:
    """The shadow's ``D3D11_BLEND_DESC`` render target 0: (source, destination) factor names."""

    enabled: bool
    source: str
    destination: str


@dataclass(frozen=True)
class StateTables:
    """The six tables of the mirror-and-shadow exercise."""

    mark_mirror: DepthStencil
    draw_reflection: DepthStencil
    reflected_rasterizer: Rasterizer
    shadow_blend: Blend
    shadow: DepthStencil
    shadow_lift: float


def _field(where: str, table: str, key: str, kind: Any, value: Any) -> Any:
    if value is Ellipsis:
        raise SandboxError(f"{where}: {table}[{key!r}] is left blank (...): fill it in")
    if isinstance(kind, dict):
        if value not in kind:
            raise SandboxError(f"{where}: {table}[{key!r}] = {value!r} is not one of {', '.join(kind)}")
        return kind[value]
    if kind is bool:
        if not isinstance(value, bool):
            raise SandboxError(f"{where}: {table}[{key!r}] = {value!r}: write True or False")
        return value
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 0xFF:
        raise SandboxError(f"{where}: {table}[{key!r}] = {value!r}: a whole number 0..255 (0xFF)")
    return value


def _table(where: str, name: str, fields: dict[str, Any], value: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise SandboxError(f"{where}: {name} must be a dict of {', '.join(fields)}, got {type(value).__name__}")
    unknown = [k for k in value if k not in fields]
    if unknown:
        raise SandboxError(f"{where}: {name} has no field {unknown[0]!r}; its fields are {', '.join(fields)}")
    missing = [k for k in fields if k not in value]
    if missing:
        raise SandboxError(f"{where}: {name} lacks {missing[0]!r} (its fields: {', '.join(fields)})")
    return {k: _field(where, name, k, kind, value[k]) for k, kind in fields.items()}


def _dss(d: dict[str, Any]) -> DepthStencil:
    return DepthStencil(d["DepthEnable"], d["DepthWriteMask"], d["StencilEnable"], d["StencilReadMask"],
                        d["StencilWriteMask"], d["StencilFunc"], d["StencilPassOp"], d["StencilRef"])


def parse_tables(source: str, filename: str) -> StateTables:
    """The tables assigned in ``source``; a :class:`SandboxError` naming ``filename`` and the
    line for anything else (a statement other than ``NAME = literal``, an unknown name or
    field, a blank ``...`` left, a value of the wrong kind, a table missing)."""
    try:
        module = ast.parse(source, filename=filename)
    except SyntaxError as exc:
        raise SandboxError(f"{filename}:{exc.lineno}: not Python: {exc.msg}") from None
    values: dict[str, tuple[int, Any]] = {}
    for i, node in enumerate(module.body):
        where = f"{filename}:{node.lineno}"
        if i == 0 and isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) \
                and isinstance(node.value.value, str):
            continue  # the docstring
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)):
            raise SandboxError(f"{where}: only assignments NAME = {{...}} of the tables belong in this file "
                               f"({', '.join(TABLES)}); nothing here is run")
        name = node.targets[0].id
        if name not in TABLES:
            raise SandboxError(f"{where}: {name} is not one of the tables ({', '.join(TABLES)})")
        try:
            value = ast.literal_eval(node.value)
        except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
            raise SandboxError(f"{where}: {name}'s value must be a literal (numbers, True/False, strings in "
                               f"quotes, dicts): nothing here is run") from None
        values[name] = (node.lineno, value)
    missing = [name for name in TABLES if name not in values]
    if missing:
        raise SandboxError(f"{filename}:1: {missing[0]} is not assigned (the tables: {', '.join(TABLES)})")
    read: dict[str, Any] = {}
    for name, fields in TABLES.items():
        line, value = values[name]
        where = f"{filename}:{line}"
        if fields is None:
            if value is Ellipsis:
                raise SandboxError(f"{where}: {name} is left blank (...): fill it in")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not abs(value) < 1.0:
                raise SandboxError(f"{where}: {name} = {value!r}: a number of world units, smaller than 1")
            read[name] = float(value)
        else:
            read[name] = _table(where, name, fields, value)
    r, b = read["REFLECTED_RASTERIZER"], read["SHADOW_BLEND"]
    return StateTables(_dss(read["MARK_MIRROR_DSS"]), _dss(read["DRAW_REFLECTION_DSS"]),
                       Rasterizer(r["CullMode"], r["FrontCounterClockwise"]),
                       Blend(b["BlendEnable"], b["SrcBlend"], b["DestBlend"]), _dss(read["SHADOW_DSS"]),
                       read["SHADOW_LIFT"])


def load_tables(path: Path) -> StateTables:
    """:func:`parse_tables` of the file at ``path`` (one ``error:`` line when it cannot be read)."""
    from glsandbox.files import read_user_file

    data = read_user_file(path, "state tables", "a Python file of the tables")
    try:
        source = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SandboxError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    return parse_tables(source, str(path))
