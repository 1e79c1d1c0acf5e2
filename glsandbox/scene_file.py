"""Scene files: a :class:`~glsandbox.scene.Scene` read from TOML, with line-numbered errors.

The format is the README's "Scene files" section: top-level ``name``,
``clear_color``, ``depth_test`` and ``depth_mode``, a ``[camera]`` table,
``[[nodes]]``, ``[[lights]]`` and ``[[viewports]]`` arrays, and the optional
``[mirror]`` and ``[shadow]`` tables that tie the planar effects to nodes by
name. Every value is checked here; a mistake is one :class:`SandboxError`
naming the file, the line and the key (``scene.toml:7: nodes[0].mesh: ...``).
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.geometry import builtin_mesh
from glsandbox.meshfile import CREASE_ANGLE, NORMALS as MESH_NORMALS, Model, is_model_path, load_model
from glsandbox.planar import Mirror, PlanarShadow
from glsandbox.scene import (BUILTIN_TEXTURES, COURSE_BLUE, DEPTH_MODES, SHADINGS, Camera, Color, Light, Material,
                             Node, Scene, Texture, Viewport)

#: Lighting coefficients a scene file may set on a node (see :class:`~glsandbox.scene.Material`).
_MATERIAL_NUMBERS = ("ambient", "diffuse", "specular", "shininess")

#: Keys only a node whose mesh is a model file takes (:mod:`glsandbox.meshfile`).
_MODEL_FILE_KEYS = ("fit", "mesh_normals", "crease_angle")


class _Locator:
    """Finds the line of a key in a TOML text, for error messages.

    tomllib gives no positions for values, so this walks the text once,
    tracking the current ``[table]`` / ``[[array]]`` header.
    """

    _header = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")
    _key = re.compile(r"^\s*([A-Za-z0-9_\-]+)\s*=")

    def __init__(self, text: str) -> None:
        self.lines: dict[tuple[str, int, str], int] = {}
        self.tables: dict[tuple[str, int], int] = {}
        counts: dict[str, int] = {}
        table, index = "", 0
        for number, line in enumerate(text.splitlines(), start=1):
            if m := self._header.match(line):
                table = m.group(2)
                if m.group(1) == "[[":
                    index = counts.get(table, 0)
                    counts[table] = index + 1
                else:
                    index = 0
                self.tables[(table, index)] = number
            elif m := self._key.match(line):
                self.lines.setdefault((table, index, m.group(1)), number)

    def line(self, table: str, index: int, key: str | None) -> int | None:
        if key is not None and (table, index, key) in self.lines:
            return self.lines[(table, index, key)]
        return self.tables.get((table, index))


class _SceneReader:
    """Reads one scene file; every error names the file and line."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.where = _Locator(text)

    def fail(self, table: str, index: int, key: str | None, message: str) -> SandboxError:
        line = self.where.line(table, index, key)
        at = f"{self.path}:{line}" if line else str(self.path)
        name = f"{table}[{index}]" if table in ("nodes", "lights", "viewports") else table
        label = ".".join(p for p in (name, key) if p)
        return SandboxError(f"{at}: {label}: {message}" if label else f"{at}: {message}")

    def check_keys(self, data: dict[str, Any], allowed: set[str], table: str, index: int = 0) -> None:
        for key in data:
            if key not in allowed:
                raise self.fail(table, index, key, f"unknown key; expected one of {', '.join(sorted(allowed))}")

    def numbers(self, data: dict[str, Any], key: str, count: tuple[int, ...], table: str,
                index: int = 0, default: Any = None) -> tuple[float, ...] | None:
        if key not in data:
            return default
        value = data[key]
        ok = isinstance(value, list) and len(value) in count and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
        if not ok:
            want = " or ".join(str(c) for c in count)
            raise self.fail(table, index, key, f"expected a list of {want} finite numbers, got {value!r}")
        return tuple(float(v) for v in value)

    def flag(self, data: dict[str, Any], key: str, table: str, index: int = 0, default: bool = True) -> bool:
        value = data.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(table, index, key, f"expected true or false, got {value!r}")
        return value

    def names(self, data: dict[str, Any], key: str, table: str, known: set[str]) -> tuple[str, ...]:
        """A list of node names, each one a node of the file."""
        value = data.get(key)
        if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
            raise self.fail(table, 0, key, f"expected a list of node names, got {value!r}")
        for name in value:
            if name not in known:
                raise self.fail(table, 0, key, f"no node is named {name!r} (nodes: {', '.join(sorted(known))})")
        return tuple(value)

    def node_name(self, data: dict[str, Any], key: str, table: str, known: set[str]) -> str:
        value = data.get(key)
        if not isinstance(value, str):
            raise self.fail(table, 0, key if key in data else None, f"needs {key} = \"<node name>\"")
        return self.names({key: [value]}, key, table, known)[0]

    def number(self, data: dict[str, Any], key: str, table: str, index: int = 0,
               default: float | None = None) -> float | None:
        if key not in data:
            return default
        value = data[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.fail(table, index, key, f"expected a finite number, got {value!r}")
        return float(value)

    def color(self, data: dict[str, Any], key: str, table: str, index: int = 0,
              default: Color | None = None) -> Color | None:
        rgba = self.numbers(data, key, (3, 4), table, index)
        if rgba is None:
            return default
        if any(not 0.0 <= c <= 1.0 for c in rgba):
            raise self.fail(table, index, key, f"colour channels must lie in 0..1, got {list(rgba)}")
        return (*rgba, 1.0) if len(rgba) == 3 else rgba  # type: ignore[return-value]

    def camera(self, data: dict[str, Any]) -> Camera:
        self.check_keys(data, {"eye", "target", "up", "fov_y", "near", "far"}, "camera")
        base = Camera()
        cam = Camera(
            eye=self.numbers(data, "eye", (3,), "camera", default=base.eye),  # type: ignore[arg-type]
            target=self.numbers(data, "target", (3,), "camera", default=base.target),  # type: ignore[arg-type]
            up=self.numbers(data, "up", (3,), "camera", default=base.up),  # type: ignore[arg-type]
            fov_y=self.number(data, "fov_y", "camera", default=base.fov_y),  # type: ignore[arg-type]
            near=self.number(data, "near", "camera", default=base.near),  # type: ignore[arg-type]
            far=self.number(data, "far", "camera", default=base.far),  # type: ignore[arg-type]
        )
        try:  # build both matrices once so a degenerate camera is reported here
            cam.view()
            cam.projection(1.0)
        except SandboxError as exc:
            raise self.fail("camera", 0, None, str(exc)) from None
        return cam

    def node(self, data: dict[str, Any], i: int) -> Node:
        allowed = {"name", "mesh", "order", "scale", "translate", "rotate", "color", "shading",
                   "cull_back_faces", "viewports", *_MATERIAL_NUMBERS, "normals", "texture", "filter", "wrap",
                   *_MODEL_FILE_KEYS}
        self.check_keys(data, allowed, "nodes", i)
        mesh_name = data.get("mesh")
        if not isinstance(mesh_name, str):
            raise self.fail("nodes", i, "mesh" if "mesh" in data else None, "every node needs mesh = \"<name>\"")
        loaded = self.model_file(data, i, mesh_name)
        try:
            mesh = loaded.mesh if loaded is not None else builtin_mesh(mesh_name)
        except SandboxError as exc:
            raise self.fail("nodes", i, "mesh", str(exc)) from None
        order = data.get("order", "STR")
        try:
            order = transforms.parse_order(order) if isinstance(order, str) else transforms.parse_order(repr(order))
        except SandboxError as exc:
            raise self.fail("nodes", i, "order", str(exc)) from None
        s = self.numbers(data, "scale", (3,), "nodes", i, default=(1.0, 1.0, 1.0))
        t = self.numbers(data, "translate", (3,), "nodes", i, default=(0.0, 0.0, 0.0))
        r = self.numbers(data, "rotate", (3,), "nodes", i, default=(0.0, 0.0, 0.0))
        assert s is not None and t is not None and r is not None
        rx, ry, rz = (math.radians(a) for a in r)
        rotation = transforms.rotate_z(rz) @ transforms.rotate_y(ry) @ transforms.rotate_x(rx)
        model = transforms.compose(order, S=transforms.scale(*s), T=transforms.translate(*t), R=rotation)
        shading = data.get("shading", "vertex_color" if mesh.colors is not None else "solid")
        if shading not in SHADINGS:
            raise self.fail("nodes", i, "shading", f"unknown shading {shading!r}; use one of {', '.join(SHADINGS)}")
        if shading == "vertex_color" and mesh.colors is None:
            raise self.fail("nodes", i, "shading", f"mesh {mesh_name!r} has no vertex colours")
        cull = self.flag(data, "cull_back_faces", "nodes", i)
        views = data.get("viewports")
        if views is not None and not (isinstance(views, list) and all(isinstance(v, int) for v in views)):
            raise self.fail("nodes", i, "viewports", f"expected a list of viewport indices, got {views!r}")
        return Node(
            name=str(data.get("name", f"node{i}")),
            mesh=mesh,
            model=model,
            material=self.material(data, i, shading) if loaded is None else self.model_material(data, i, shading,
                                                                                                 loaded),
            cull_back_faces=cull,
            viewports=tuple(views) if views is not None else None,
        )

    def model_file(self, data: dict[str, Any], i: int, mesh_name: str) -> Model | None:
        """A node's model file (``mesh = "path/to/model.obj"``, relative to the scene file),
        loaded with its ``fit``, ``mesh_normals`` and ``crease_angle``; None for a built-in mesh."""
        if not is_model_path(mesh_name):
            for key in _MODEL_FILE_KEYS:
                if key in data:
                    raise self.fail("nodes", i, key, f"only for a mesh loaded from a file; {mesh_name!r} is built in")
            return None
        fit = self.flag(data, "fit", "nodes", i, default=False)
        normals = data.get("mesh_normals", "auto")
        if normals not in MESH_NORMALS:
            raise self.fail("nodes", i, "mesh_normals", f"unknown mesh normals {normals!r}; "
                                                        f"use one of {', '.join(MESH_NORMALS)}")
        crease = self.number(data, "crease_angle", "nodes", i, default=CREASE_ANGLE)
        assert crease is not None
        if not 0.0 <= crease <= 180.0:
            raise self.fail("nodes", i, "crease_angle", f"expected degrees in 0..180, got {crease:g}")
        path = Path(mesh_name)
        if not path.is_absolute():
            path = self.path.parent / path  # relative to the scene file, not the shell
        try:
            return load_model(path, fit=fit, normals=normals, crease_angle=crease)
        except SandboxError as exc:
            key = "mesh_normals" if "normals = " in str(exc) else "mesh"
            raise self.fail("nodes", i, key, str(exc)) from None

    def model_material(self, data: dict[str, Any], i: int, shading: str, model: Model) -> Material:
        """:meth:`material` for a model file's node: the file's base colour texture and
        colour unless the node gives its own (``filter`` and ``wrap`` apply to the file's texture)."""
        own = model.texture is None or "texture" in data
        material = self.material(data if own else {k: v for k, v in data.items() if k not in ("filter", "wrap")},
                                 i, shading)
        if not own:
            try:
                texture = replace(model.texture, filter=str(data.get("filter", "mip_linear")),  # type: ignore[arg-type]
                                  wrap=str(data.get("wrap", "repeat")))
            except SandboxError as exc:
                raise self.fail("nodes", i, "filter" if "filter" in str(exc) else "wrap", str(exc)) from None
            material = replace(material, texture=texture)
        if model.color is not None and "color" not in data:
            material = replace(material, color=model.color)
        if material.texture is not None and model.mesh.uvs is None:
            raise self.fail("nodes", i, "texture", f"{model.path.name} has no texture coordinates to map it with")
        return material

    def material(self, data: dict[str, Any], i: int, shading: str) -> Material:
        """A node's material: colour, shading, the lighting coefficients, a texture."""
        numbers = {}
        for key in _MATERIAL_NUMBERS:
            value = self.number(data, key, "nodes", i)
            if value is not None:
                numbers[key] = value
        texture = None
        if "texture" in data:
            source = data["texture"]
            if not isinstance(source, str):
                raise self.fail("nodes", i, "texture", f"expected an image name or file path, got {source!r}")
            if source not in BUILTIN_TEXTURES and not Path(source).is_absolute():
                source = str(self.path.parent / source)  # relative to the scene file, not the shell
            try:
                texture = Texture(source, filter=str(data.get("filter", "mip_linear")),
                                  wrap=str(data.get("wrap", "repeat")))
            except SandboxError as exc:
                bad = "filter" if "filter" in str(exc) else "wrap" if "wrap" in str(exc) else "texture"
                raise self.fail("nodes", i, bad, str(exc)) from None
        elif "filter" in data or "wrap" in data:
            raise self.fail("nodes", i, "filter" if "filter" in data else "wrap", "needs texture = \"<image>\"")
        try:
            return Material(color=self.color(data, "color", "nodes", i, default=(1.0, 1.0, 1.0, 1.0)),  # type: ignore[arg-type]
                            shading=shading, normals=str(data.get("normals", "correct")), texture=texture,
                            **numbers)
        except SandboxError as exc:
            key = next((k for k in (*_MATERIAL_NUMBERS, "normals") if k in data and k in str(exc)), None)
            raise self.fail("nodes", i, key, str(exc)) from None

    def viewport(self, data: dict[str, Any], i: int) -> Viewport:
        self.check_keys(data, {"rect", "clear_color", "label"}, "viewports", i)
        rect = self.numbers(data, "rect", (4,), "viewports", i, default=(0.0, 0.0, 1.0, 1.0))
        assert rect is not None
        x, y, w, h = rect
        if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > 1 + 1e-9 or y + h > 1 + 1e-9:
            raise self.fail("viewports", i, "rect", f"rect {list(rect)} must lie inside 0..1 with positive size")
        return Viewport(rect=rect, clear_color=self.color(data, "clear_color", "viewports", i),  # type: ignore[arg-type]
                        label=str(data.get("label", "")))

    def light(self, data: dict[str, Any], i: int) -> Light:
        self.check_keys(data, {"position", "color"}, "lights", i)
        pos = self.numbers(data, "position", (3,), "lights", i)
        if pos is None:
            raise self.fail("lights", i, None, "every light needs position = [x, y, z]")
        col = self.numbers(data, "color", (3,), "lights", i, default=(1.0, 1.0, 1.0))
        return Light(position=pos, color=col)  # type: ignore[arg-type]

    def mirror(self, data: dict[str, Any], known: set[str]) -> Mirror:
        """``[mirror]``: the glass node, its plane (a, b, c, d with ax + by + cz + d = 0), what it reflects."""
        self.check_keys(data, {"node", "plane", "reflected", "stencil"}, "mirror")
        node = self.node_name(data, "node", "mirror", known)
        plane = self.numbers(data, "plane", (4,), "mirror")
        if plane is None:
            raise self.fail("mirror", 0, None, "needs plane = [a, b, c, d] (the glass's plane ax + by + cz + d = 0)")
        reflected = self.names(data, "reflected", "mirror", known)
        try:
            return Mirror(node, plane, reflected, stencil=self.flag(data, "stencil", "mirror"))  # type: ignore[arg-type]
        except SandboxError as exc:
            raise self.fail("mirror", 0, "reflected" if "reflect" in str(exc) else "plane", str(exc)) from None

    def shadow(self, data: dict[str, Any], known: set[str]) -> PlanarShadow:
        """``[shadow]``: casters flattened onto the receiver's plane along the light."""
        self.check_keys(data, {"receiver", "plane", "light", "casters", "lift", "polygon_offset", "stencil", "color"},
                        "shadow")
        receiver = self.node_name(data, "receiver", "shadow", known)
        plane = self.numbers(data, "plane", (4,), "shadow")
        light = self.numbers(data, "light", (4,), "shadow")
        for key, value, what in (("plane", plane, "[a, b, c, d]"), ("light", light, "[x, y, z, 1] (point) or "
                                                                               "[x, y, z, 0] (directional)")):
            if value is None:
                raise self.fail("shadow", 0, None, f"needs {key} = {what}")
        casters = self.names(data, "casters", "shadow", known)
        try:
            shadow = PlanarShadow(receiver, plane, light, casters,  # type: ignore[arg-type]
                                  lift=self.number(data, "lift", "shadow", default=0.005),  # type: ignore[arg-type]
                                  polygon_offset=self.flag(data, "polygon_offset", "shadow"),
                                  stencil=self.flag(data, "stencil", "shadow"),
                                  color=self.numbers(data, "color", (4,), "shadow",  # type: ignore[arg-type]
                                                     default=(0.0, 0.0, 0.0, 0.5)))
        except SandboxError as exc:
            key = next((k for k in ("lift", "color", "light", "plane") if k in str(exc)), None)
            raise self.fail("shadow", 0, key, str(exc)) from None
        try:  # a light in the plane or parallel to it has no shadow matrix
            transforms.shadow_matrix(shadow.plane, shadow.light)
        except SandboxError as exc:
            raise self.fail("shadow", 0, "light", str(exc)) from None
        return shadow

    def scene(self, data: dict[str, Any]) -> Scene:
        self.check_keys(data, {"name", "clear_color", "camera", "nodes", "lights", "viewports", "depth_test",
                               "depth_mode", "mirror", "shadow"}, "")
        tables = {"camera": dict, "nodes": list, "lights": list, "viewports": list, "mirror": dict, "shadow": dict}
        for key, kind in tables.items():
            if key in data and not isinstance(data[key], kind):
                shape = f"[{key}]" if kind is dict else f"[[{key}]]"
                raise self.fail("", 0, key, f"expected a {shape} table")
        viewports = tuple(self.viewport(v, i) for i, v in enumerate(data.get("viewports", []))) or (Viewport(),)
        nodes = tuple(self.node(n, i) for i, n in enumerate(data.get("nodes", [])))
        for i, n in enumerate(nodes):
            for v in n.viewports or ():
                if not 0 <= v < len(viewports):
                    raise self.fail("nodes", i, "viewports", f"viewport {v} does not exist ({len(viewports)} defined)")
        depth = self.flag(data, "depth_test", "")
        depth_mode = data.get("depth_mode", "standard")
        if depth_mode not in DEPTH_MODES:
            raise self.fail("", 0, "depth_mode", f"unknown depth mode {depth_mode!r}; use one of {', '.join(DEPTH_MODES)}")
        known = {n.name for n in nodes}
        if len(known) < len(nodes) and ("mirror" in data or "shadow" in data):
            raise self.fail("", 0, None, "node names must differ when a mirror or shadow names them")
        return Scene(
            name=str(data.get("name", self.path.stem)),
            nodes=nodes,
            camera=self.camera(data.get("camera", {})),
            lights=tuple(self.light(v, i) for i, v in enumerate(data.get("lights", []))),
            clear_color=self.color(data, "clear_color", "", default=COURSE_BLUE),  # type: ignore[arg-type]
            viewports=viewports,
            depth_test=depth,
            mirror=self.mirror(data["mirror"], known) if "mirror" in data else None,
            shadow=self.shadow(data["shadow"], known) if "shadow" in data else None,
            depth_mode=depth_mode,
        )


def load_scene(path: str | Path) -> Scene:
    """Read and validate a TOML scene file.

    Errors raise :class:`SandboxError` naming the file and the line, e.g.
    ``scene.toml:7: nodes[0].mesh: unknown mesh 'cbe'; ...``.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SandboxError(f"{p}: scene file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SandboxError(f"{p}: cannot read scene file ({exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        # tomllib ends its message with "(at line L, column C)".
        m = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        where = f"{p}:{m.group(1)}" if m else str(p)
        reason = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc)) or "malformed TOML"
        raise SandboxError(f"{where}: malformed TOML: {reason}") from None
    return _SceneReader(p, text).scene(data)
