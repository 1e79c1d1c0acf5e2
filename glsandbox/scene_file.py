"""Scene files: a :class:`~glsandbox.scene.Scene` read from TOML, with line-numbered errors.

The format is docs/commands.md's "Scene files" section: top-level ``name``,
``clear_color``, ``depth_test`` and ``depth_mode``, a ``[camera]`` table,
``[[nodes]]``, ``[[lights]]`` and ``[[viewports]]`` arrays, and the optional
``[mirror]`` and ``[shadow]`` tables that tie the planar effects to nodes by
name (``[shadow]`` is the planar shadow, kept under its old name; a light's
shadow map is its ``shadow_map = {size = 1024, ...}``, and a node opts out of
it with ``casts_shadow``/``receives_shadow = false``). Every value is checked here; a mistake is one :class:`SandboxError`
naming the file, the line and the key (``scene.toml:7: nodes[0].mesh: ...``),
once: a value of the wrong type (a number where a table, list or text is
expected), a number that is not finite or lies beyond
:data:`~glsandbox.errors.NUMBER_LIMIT`, and what the scene's dataclasses
refuse (:mod:`glsandbox.scene`) are all reported that way.

The ``[shadow]`` light must be one of the scene's ``[[lights]]`` (a point
light at its position, or a directional light pointing at it from the
origin, the mirror lesson's far light): the raster shadow is cast along it
and the shading and the ray tracer use the lights, so a light of its own
would make the two disagree. With exactly one light, ``light`` may be left
out: the shadow is cast from that light.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from glsandbox import transforms
from glsandbox.errors import NUMBER_LIMIT, SandboxError, plain
from glsandbox.files import check_inside_sandbox, read_user_file, written_path
from glsandbox.geometry import Mesh, builtin_mesh
from glsandbox.images import load_image
from glsandbox.mesh.load import CREASE_ANGLE, NORMALS as MESH_NORMALS, Model, ModelPart, is_model_path, load_model
from glsandbox.planar import Mirror, PlanarShadow
from glsandbox.scene import (BUILTIN_TEXTURES, COURSE_BLUE, DEPTH_MODES, SHADINGS, Camera, Color, Light, Material,
                             Node, Scene, ShadowMap, Texture, Viewport, check_uniforms)

#: Lighting coefficients a scene file may set on a node (see :class:`~glsandbox.scene.Material`).
_MATERIAL_NUMBERS = ("ambient", "diffuse", "specular", "shininess")
#: A material's alpha and sides (glsandbox.scene.Material; a model file's parts bring their own).
_MATERIAL_LOOKS = ("alpha_mode", "alpha_cutoff", "double_sided", "vertex_colors")

#: Keys only a node whose mesh is a model file takes (:mod:`glsandbox.mesh.load`).
_MODEL_FILE_KEYS = ("fit", "mesh_normals", "crease_angle", "up")
#: A model file's up axis (``up = "z"`` stands a Z-up scan upright: z becomes y).
_UP_AXES = ("y", "z")


class _Locator:
    """Finds the line of a key in a TOML text, for error messages.

    tomllib gives no positions for values, so this walks the text once,
    tracking the current ``[table]`` / ``[[array]]`` header.
    """

    _header = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")
    # ``key =`` or a dotted ``key.sub =`` (its first part is the key of this table).
    _key = re.compile(r"^\s*([A-Za-z0-9_\-]+)\s*(?:\.\s*[A-Za-z0-9_\-]+\s*)*=")

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
                else:  # [nodes.uniforms] is a table of the last [[nodes]] element
                    index = max(counts.get(table.rpartition(".")[0], 0) - 1, 0)
                self.tables[(table, index)] = number
            elif m := self._key.match(line):
                self.lines.setdefault((table, index, m.group(1)), number)

    def line(self, table: str, index: int, key: str | None) -> int | None:
        """The line of ``key`` in ``table`` (element ``index`` of an array of
        tables), else of the table's header, else of ``table = ...`` written
        as a key of the top level (an inline table or array, a dotted key)."""
        if key is not None and (table, index, key) in self.lines:
            return self.lines[(table, index, key)]
        if (table, index) in self.tables:
            return self.tables[(table, index)]
        return self.lines.get(("", 0, table)) if table else None


def _guess_key(message: str, keys: tuple[str, ...]) -> str | None:
    """The key a dataclass's message is about (it names the field), if any."""
    return next((k for k in keys if k in message), None)


class _SceneReader:
    """Reads one scene file; every error names the file and line."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.where = _Locator(text)

    def table(self, value: Any, table: str, index: int = 0) -> dict[str, Any]:
        """``value``, which must be a table (``[table]``, an element of ``[[table]]``, or ``{...}``)."""
        if not isinstance(value, dict):
            shape = f"[[{table}]]" if table in ("nodes", "lights", "viewports") else f"[{table}]"
            raise self.fail(table, index, None, f"expected a table ({shape} or {{ ... }}), got {plain(value)}")
        return value

    def text(self, data: dict[str, Any], key: str, table: str, index: int = 0, default: str = "") -> str:
        value = data.get(key, default)
        if not isinstance(value, str):
            raise self.fail(table, index, key, f"expected text (a quoted string), got {plain(value)}")
        return value

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
            raise self.fail(table, index, key, f"expected a list of {want} finite numbers, got {plain(value)}")
        if any(abs(v) > NUMBER_LIMIT for v in value):
            raise self.fail(table, index, key, f"numbers must lie within +-{NUMBER_LIMIT:g}, got {plain(value)}")
        return tuple(float(v) for v in value)

    def flag(self, data: dict[str, Any], key: str, table: str, index: int = 0, default: bool = True) -> bool:
        value = data.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(table, index, key, f"expected true or false, got {plain(value)}")
        return value

    def names(self, data: dict[str, Any], key: str, table: str, known: set[str]) -> tuple[str, ...]:
        """A list of node names, each one a node of the file."""
        value = data.get(key)
        if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
            raise self.fail(table, 0, key, f"expected a list of node names, got {plain(value)}")
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
            raise self.fail(table, index, key, f"expected a finite number, got {plain(value)}")
        if abs(value) > NUMBER_LIMIT:
            raise self.fail(table, index, key, f"must lie within +-{NUMBER_LIMIT:g}, got {plain(value)}")
        return float(value)

    def color(self, data: dict[str, Any], key: str, table: str, index: int = 0,
              default: Color | None = None) -> Color | None:
        rgba = self.numbers(data, key, (3, 4), table, index)
        if rgba is None:
            return default
        if any(not 0.0 <= c <= 1.0 for c in rgba):
            raise self.fail(table, index, key, f"colour channels must lie in 0..1, got {plain(list(rgba))}")
        return (*rgba, 1.0) if len(rgba) == 3 else rgba  # type: ignore[return-value]

    def camera(self, data: Any) -> Camera:
        data = self.table(data, "camera")
        self.check_keys(data, {"eye", "target", "up", "fov_y", "near", "far"}, "camera")
        base = Camera()
        values = dict(
            eye=self.numbers(data, "eye", (3,), "camera", default=base.eye),
            target=self.numbers(data, "target", (3,), "camera", default=base.target),
            up=self.numbers(data, "up", (3,), "camera", default=base.up),
            fov_y=self.number(data, "fov_y", "camera", default=base.fov_y),
            near=self.number(data, "near", "camera", default=base.near),
            far=self.number(data, "far", "camera", default=base.far),
        )
        try:  # Camera checks the lens and builds the view once: a degenerate camera is reported here
            return Camera(**values)  # type: ignore[arg-type]
        except SandboxError as exc:
            key = _guess_key(str(exc).split(":")[0], ("fov_y", "near", "far"))
            raise self.fail("camera", 0, key, str(exc)) from None

    def node(self, data: Any, i: int) -> tuple[Node, ...]:
        """The node of ``[[nodes]]`` table ``i``; a model file with several materials gives one
        node per material, named ``name/material``, unless the table sets its own colour or texture."""
        data = self.table(data, "nodes", i)
        allowed = {"name", "mesh", "order", "scale", "translate", "rotate", "color", "shading",
                   "cull_back_faces", "viewports", *_MATERIAL_NUMBERS, *_MATERIAL_LOOKS, "normals", "texture",
                   "filter", "wrap",
                   *_MODEL_FILE_KEYS, "shader", "uniforms", "casts_shadow", "receives_shadow"}
        self.check_keys(data, allowed, "nodes", i)
        mesh_name = data.get("mesh")
        if not isinstance(mesh_name, str):
            raise self.fail("nodes", i, "mesh" if "mesh" in data else None, "every node needs mesh = \"<name>\"")
        loaded = self.model_file(data, i, mesh_name)
        try:
            # A model file's first part (its only one, mostly): the parts are drawn, never joined.
            mesh = loaded.parts[0].mesh if loaded is not None else builtin_mesh(mesh_name)
        except SandboxError as exc:
            raise self.fail("nodes", i, "mesh", str(exc)) from None
        coloured = mesh.colors is not None if loaded is None else all(p.mesh.colors is not None for p in loaded.parts)
        order = self.text(data, "order", "nodes", i, default="STR")
        try:
            order = transforms.parse_order(order)
        except SandboxError as exc:
            raise self.fail("nodes", i, "order", str(exc)) from None
        s = self.numbers(data, "scale", (3,), "nodes", i, default=(1.0, 1.0, 1.0))
        t = self.numbers(data, "translate", (3,), "nodes", i, default=(0.0, 0.0, 0.0))
        r = self.numbers(data, "rotate", (3,), "nodes", i, default=(0.0, 0.0, 0.0))
        assert s is not None and t is not None and r is not None
        rx, ry, rz = (math.radians(a) for a in r)
        rotation = transforms.rotate_z(rz) @ transforms.rotate_y(ry) @ transforms.rotate_x(rx)
        model = transforms.compose(order, S=transforms.scale(*s), T=transforms.translate(*t), R=rotation)
        if loaded is not None and data.get("up", "y") == "z":
            model = model @ transforms.rotate_x(-math.pi / 2)  # the file's z becomes y, before the node's own transform
        shading = self.text(data, "shading", "nodes", i, default="vertex_color" if coloured else "solid")
        if shading not in SHADINGS:
            raise self.fail("nodes", i, "shading", f"unknown shading {shading!r}; use one of {', '.join(SHADINGS)}")
        if shading == "vertex_color" and not coloured:
            raise self.fail("nodes", i, "shading", f"mesh {mesh_name!r} has no vertex colours")
        cull = self.flag(data, "cull_back_faces", "nodes", i)
        views = data.get("viewports")
        if views is not None and not (isinstance(views, list) and all(isinstance(v, int) and not isinstance(v, bool)
                                                                      for v in views)):
            raise self.fail("nodes", i, "viewports", f"expected a list of viewport indices, got {plain(views)}")
        name = self.text(data, "name", "nodes", i, default=f"node{i}")
        if loaded is None:
            looks = [(name, mesh, self.material(data, i, shading))]
        elif len(loaded.parts) == 1 or "color" in data or "texture" in data:  # one look: one node, all parts
            looks = [(name, loaded.mesh, self.model_material(data, i, shading, loaded.parts[0], loaded.mesh))]
        else:
            looks = [(f"{name}/{part.name}", part.mesh, self.model_material(data, i, shading, part, part.mesh))
                     for part in loaded.parts]
        shader, uniforms = self.shader(data, i)
        try:
            return tuple(Node(name=label, mesh=part_mesh, model=model, material=material, cull_back_faces=cull,
                              viewports=tuple(views) if views is not None else None, shader=shader,
                              uniforms=uniforms,
                              casts_shadow=self.flag(data, "casts_shadow", "nodes", i),
                              receives_shadow=self.flag(data, "receives_shadow", "nodes", i))
                         for label, part_mesh, material in looks)
        except SandboxError as exc:  # the mesh lacks what the material reads, or the model is out of bounds
            message = str(exc)
            if "which a texture needs" in message:
                key: str | None = "texture"
            elif "shading needs" in message:
                key = "shading"
            elif "vertex_colors = true needs" in message:
                key = "vertex_colors"
            else:
                key = next((k for k in ("scale", "translate") if k in data), None)
            raise self.fail("nodes", i, key, message) from None

    def written(self, text: str, table: str, i: int, key: str) -> Path:
        """A file path written in the scene file, as this system names it (:func:`written_path`:
        ``/`` or ``\\`` between folders, relative to the scene file); a Windows drive
        path elsewhere is an error at the key's line."""
        try:
            return written_path(text, self.path.parent)
        except SandboxError as exc:
            raise self.fail(table, i, key, str(exc)) from None

    def shader(self, data: dict[str, Any], i: int) -> tuple[Path | None, dict[str, Any]]:
        """A node's own GLSL file (``shader = "toon.glsl"``, relative to the scene file) and
        its ``[nodes.uniforms]``: numbers, true/false, or lists of 2 to 4 numbers."""
        uniforms = data.get("uniforms", {})

        def fail_uniforms(message: str) -> SandboxError:  # at the [nodes.uniforms] header, if written so
            line = self.where.tables.get(("nodes.uniforms", i))
            return SandboxError(f"{self.path}:{line}: nodes[{i}].uniforms: {message}") if line \
                else self.fail("nodes", i, "uniforms", message)

        if "shader" not in data:
            if "uniforms" in data:
                raise fail_uniforms("needs shader = \"<file.glsl>\" (uniforms are the shader's)")
            return None, {}
        text = self.text(data, "shader", "nodes", i)
        if not text.strip():
            raise self.fail("nodes", i, "shader", "expected a GLSL file path, got an empty text")
        path = self.written(text, "nodes", i, "shader")  # relative to the scene file, not the shell
        try:
            check_inside_sandbox(path, "shader file")  # while grading: the submission's own files only
        except SandboxError as exc:
            raise self.fail("nodes", i, "shader", str(exc)) from None
        if not path.exists():
            raise self.fail("nodes", i, "shader", f"shader file {path} not found")
        if not isinstance(uniforms, dict):
            raise fail_uniforms(f"expected a table ([nodes.uniforms] or {{ ... }}), got {plain(uniforms)}")
        checked = {}
        for name, value in uniforms.items():
            line = self.where.line("nodes.uniforms", i, name) or self.where.line("nodes", i, "uniforms")
            at = f"{self.path}:{line}" if line else str(self.path)
            try:
                checked.update(check_uniforms({name: value}, "{name}"))
            except SandboxError as exc:
                raise SandboxError(f"{at}: nodes[{i}].uniforms.{exc}") from None
        return path, checked

    def model_file(self, data: dict[str, Any], i: int, mesh_name: str) -> Model | None:
        """A node's model file (``mesh = "path/to/model.obj"``, relative to the scene file),
        loaded with its ``fit``, ``mesh_normals`` and ``crease_angle``; None for a built-in mesh."""
        if not is_model_path(mesh_name):
            for key in _MODEL_FILE_KEYS:
                if key in data:
                    raise self.fail("nodes", i, key, f"only for a mesh loaded from a file; {mesh_name!r} is built in")
            return None
        fit = self.flag(data, "fit", "nodes", i, default=False)
        if data.get("up", "y") not in _UP_AXES:
            raise self.fail("nodes", i, "up", f"unknown up axis {plain(data['up'])}; use one of {', '.join(_UP_AXES)}")
        normals = data.get("mesh_normals", "auto")
        if normals not in MESH_NORMALS:
            raise self.fail("nodes", i, "mesh_normals", f"unknown mesh normals {normals!r}; "
                                                        f"use one of {', '.join(MESH_NORMALS)}")
        crease = self.number(data, "crease_angle", "nodes", i, default=CREASE_ANGLE)
        assert crease is not None
        if not 0.0 <= crease <= 180.0:
            raise self.fail("nodes", i, "crease_angle", f"expected degrees in 0..180, got {crease:g}")
        path = self.written(mesh_name, "nodes", i, "mesh")  # relative to the scene file, not the shell
        try:
            return load_model(path, fit=fit, normals=normals, crease_angle=crease)
        except SandboxError as exc:
            key = "mesh_normals" if "normals = " in str(exc) else "mesh"
            raise self.fail("nodes", i, key, str(exc)) from None

    def model_material(self, data: dict[str, Any], i: int, shading: str, model: ModelPart, mesh: Mesh) -> Material:
        """:meth:`material` for a model file's part drawn as ``mesh``: the file's base colour
        texture and colour unless the node gives its own (``filter`` and ``wrap`` apply to the
        file's texture), its alpha mode and sidedness (``cull_back_faces``, when given, wins),
        and its vertex colours tinting a lit shading."""
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
        if material.texture is not None and mesh.uvs is None:
            raise self.fail("nodes", i, "texture", f"{mesh.name} has no texture coordinates to map it with")
        # The file's alpha and sides, unless the node says (cull_back_faces = true makes it one-sided).
        sided = model.double_sided if "cull_back_faces" not in data else not data["cull_back_faces"]
        file_look = dict(alpha_mode=model.alpha_mode, alpha_cutoff=model.alpha_cutoff, double_sided=sided,
                         vertex_colors=mesh.colors is not None and material.lit)
        return replace(material, **{k: v for k, v in file_look.items() if k not in data})

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
                raise self.fail("nodes", i, "texture", f"expected an image name or file path, got {plain(source)}")
            if source not in BUILTIN_TEXTURES:
                source = str(self.written(source, "nodes", i, "texture"))  # relative to the scene file
            filter_name = self.text(data, "filter", "nodes", i, default="mip_linear")
            wrap = self.text(data, "wrap", "nodes", i, default="repeat")
            try:
                texture = Texture(source, filter=filter_name, wrap=wrap)
            except SandboxError as exc:
                bad = "filter" if "filter" in str(exc) else "wrap" if "wrap" in str(exc) else "texture"
                raise self.fail("nodes", i, bad, str(exc)) from None
            if texture.is_file:
                try:  # loaded now, so a missing or broken image is an error at this line, not in a frame
                    check_image_file(Path(texture.source))
                except SandboxError as exc:
                    raise self.fail("nodes", i, "texture", str(exc)) from None
        elif "filter" in data or "wrap" in data:
            raise self.fail("nodes", i, "filter" if "filter" in data else "wrap", "needs texture = \"<image>\"")
        color = self.color(data, "color", "nodes", i, default=(1.0, 1.0, 1.0, 1.0))
        normals = self.text(data, "normals", "nodes", i, default="correct")
        looks = dict(alpha_mode=self.text(data, "alpha_mode", "nodes", i, default="opaque"),
                     alpha_cutoff=self.number(data, "alpha_cutoff", "nodes", i, default=0.5),
                     double_sided=self.flag(data, "double_sided", "nodes", i, default=False),
                     vertex_colors=self.flag(data, "vertex_colors", "nodes", i, default=False))
        try:
            return Material(color=color, shading=shading, normals=normals, texture=texture,  # type: ignore[arg-type]
                            **numbers, **looks)
        except SandboxError as exc:
            words = str(exc).replace(" ", "_")
            key = next((k for k in (*_MATERIAL_NUMBERS, "normals", *_MATERIAL_LOOKS) if k in data and k in words),
                       None)
            raise self.fail("nodes", i, key, str(exc)) from None

    def viewport(self, data: Any, i: int) -> Viewport:
        data = self.table(data, "viewports", i)
        self.check_keys(data, {"rect", "clear_color", "label"}, "viewports", i)
        rect = self.numbers(data, "rect", (4,), "viewports", i, default=(0.0, 0.0, 1.0, 1.0))
        assert rect is not None
        x, y, w, h = rect
        if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > 1 + 1e-9 or y + h > 1 + 1e-9:
            raise self.fail("viewports", i, "rect", f"rect {plain(list(rect))} must lie inside 0..1 with positive size")
        return Viewport(rect=rect, clear_color=self.color(data, "clear_color", "viewports", i),  # type: ignore[arg-type]
                        label=self.text(data, "label", "viewports", i))

    def light(self, data: Any, i: int) -> Light:
        data = self.table(data, "lights", i)
        self.check_keys(data, {"position", "color", "shadow_map"}, "lights", i)
        pos = self.numbers(data, "position", (3,), "lights", i)
        if pos is None:
            raise self.fail("lights", i, None, "every light needs position = [x, y, z]")
        col = self.numbers(data, "color", (3,), "lights", i, default=(1.0, 1.0, 1.0))
        shadow = self.shadow_map(data["shadow_map"], i) if "shadow_map" in data else None
        try:
            return Light(position=pos, color=col, shadow=shadow)  # type: ignore[arg-type]
        except SandboxError as exc:
            raise self.fail("lights", i, "color" if "colour" in str(exc) else "position", str(exc)) from None

    def shadow_map(self, data: Any, i: int) -> ShadowMap:
        """A light's ``shadow_map = {size, bias, slope_bias, pcf, fov}`` (every key optional)."""
        if not isinstance(data, dict):
            raise self.fail("lights", i, "shadow_map", f"expected a table such as {{size = 1024}}, got {plain(data)}")
        allowed = ("size", "bias", "slope_bias", "pcf", "fov")
        unknown = sorted(set(data) - set(allowed))
        if unknown:
            raise self.fail("lights", i, "shadow_map", f"unknown key {unknown[0]!r}; use {', '.join(allowed)}")
        values = {}
        for key in allowed:
            if key in data:
                value = data[key]
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise self.fail("lights", i, "shadow_map", f"{key} must be a number, got {plain(value)}")
                values[key] = value
        try:
            return ShadowMap(**values)
        except SandboxError as exc:
            raise self.fail("lights", i, "shadow_map", str(exc)) from None

    def mirror(self, data: Any, known: set[str]) -> Mirror:
        """``[mirror]``: the glass node, its plane (a, b, c, d with ax + by + cz + d = 0), what it reflects."""
        data = self.table(data, "mirror")
        self.check_keys(data, {"node", "plane", "reflected", "stencil"}, "mirror")
        node = self.node_name(data, "node", "mirror", known)
        plane = self.numbers(data, "plane", (4,), "mirror")
        if plane is None:
            raise self.fail("mirror", 0, None, "needs plane = [a, b, c, d] (the glass's plane ax + by + cz + d = 0)")
        reflected = self.names(data, "reflected", "mirror", known)
        stencil = self.flag(data, "stencil", "mirror")
        try:
            return Mirror(node, plane, reflected, stencil=stencil)  # type: ignore[arg-type]
        except SandboxError as exc:
            raise self.fail("mirror", 0, "reflected" if "reflect" in str(exc) else "plane", str(exc)) from None

    def planar_shadow(self, data: Any, known: set[str], lights: tuple[Light, ...]) -> PlanarShadow:
        """``[shadow]``: casters flattened onto the receiver's plane along the light (one of ``lights``)."""
        data = self.table(data, "shadow")
        self.check_keys(data, {"receiver", "plane", "light", "casters", "lift", "polygon_offset", "stencil", "color"},
                        "shadow")
        receiver = self.node_name(data, "receiver", "shadow", known)
        plane = self.numbers(data, "plane", (4,), "shadow")
        light = self.numbers(data, "light", (4,), "shadow")
        if plane is None:
            raise self.fail("shadow", 0, None, "needs plane = [a, b, c, d]")
        if light is None:
            if len(lights) != 1:
                raise self.fail("shadow", 0, None, "needs light = [x, y, z, 1] (point) or [x, y, z, 0] (directional), "
                                f"one of the scene's lights (it has {len(lights)}; with one, light may be left out)")
            light = (*lights[0].position, 1.0)
        casters = self.names(data, "casters", "shadow", known)
        options = dict(lift=self.number(data, "lift", "shadow", default=0.005),
                       polygon_offset=self.flag(data, "polygon_offset", "shadow"),
                       stencil=self.flag(data, "stencil", "shadow"),
                       color=self.numbers(data, "color", (4,), "shadow", default=(0.0, 0.0, 0.0, 0.5)))
        try:
            shadow = PlanarShadow(receiver, plane, light, casters, **options)  # type: ignore[arg-type]
        except SandboxError as exc:
            key = next((k for k in ("lift", "colour", "light", "plane") if k in str(exc)), None)
            raise self.fail("shadow", 0, "color" if key == "colour" else key, str(exc)) from None
        try:  # a light in the plane or parallel to it has no shadow matrix
            transforms.shadow_matrix(shadow.plane, shadow.light)
        except SandboxError as exc:
            raise self.fail("shadow", 0, "light", str(exc)) from None
        if not any(_shadow_light_is(shadow.light, li.position) for li in lights):
            kind = "point light at" if shadow.light[3] == 1.0 else "directional light from"
            have = ", ".join(plain(li.position) for li in lights[:4]) + (", ..." if len(lights) > 4 else "")
            raise self.fail("shadow", 0, "light" if "light" in data else None,
                            f"the shadow's {kind} {plain(shadow.light[:3])} is none of the scene's lights "
                            f"({have or 'it has none'}), so the shadow and the shading would disagree: use a light's "
                            "position with w = 1, or with w = 0 a direction pointing at a light from the origin")
        return shadow

    def scene(self, data: dict[str, Any]) -> Scene:
        self.check_keys(data, {"name", "clear_color", "camera", "nodes", "lights", "viewports", "depth_test",
                               "depth_mode", "mirror", "shadow"}, "")
        tables = {"camera": dict, "nodes": list, "lights": list, "viewports": list, "mirror": dict, "shadow": dict}
        for key, kind in tables.items():
            if key in data and not isinstance(data[key], kind):
                shape = f"[{key}]" if kind is dict else f"[[{key}]]"
                raise self.fail("", 0, key, f"expected a {shape} table, got {plain(data[key])}")
        viewports = tuple(self.viewport(v, i) for i, v in enumerate(data.get("viewports", []))) or (Viewport(),)
        # A model file with several materials is one node per material (a table's index i for errors).
        indexed = [(i, node) for i, n in enumerate(data.get("nodes", [])) for node in self.node(n, i)]
        nodes = tuple(node for _, node in indexed)
        for i, n in indexed:
            for v in n.viewports or ():
                if not 0 <= v < len(viewports):
                    raise self.fail("nodes", i, "viewports", f"viewport {v} does not exist ({len(viewports)} defined)")
        depth = self.flag(data, "depth_test", "")
        depth_mode = self.text(data, "depth_mode", "", default="standard")
        if depth_mode not in DEPTH_MODES:
            raise self.fail("", 0, "depth_mode", f"unknown depth mode {depth_mode!r}; use one of {', '.join(DEPTH_MODES)}")
        known = {n.name for n in nodes}
        if len(known) < len(nodes) and ("mirror" in data or "shadow" in data):
            raise self.fail("", 0, None, "node names must differ when a mirror or shadow names them")
        lights = tuple(self.light(v, i) for i, v in enumerate(data.get("lights", [])))
        return Scene(
            name=self.text(data, "name", "", default=self.path.stem),
            nodes=nodes,
            camera=self.camera(data.get("camera", {})),
            lights=lights,
            clear_color=self.color(data, "clear_color", "", default=COURSE_BLUE),  # type: ignore[arg-type]
            viewports=viewports,
            depth_test=depth,
            mirror=self.mirror(data["mirror"], known) if "mirror" in data else None,
            planar_shadow=self.planar_shadow(data["shadow"], known, lights) if "shadow" in data else None,
            depth_mode=depth_mode,
        )


#: Image files that loaded, by (path, size, modification time): a window reads its scene
#: file every frame, and decodes an unchanged texture only the first time.
_IMAGES_LOADED: dict[tuple[str, int, int], None] = {}
_IMAGES_KEPT = 64


def check_image_file(path: Path) -> None:
    """That ``path`` loads as an image (:func:`load_image`), else its one-line :class:`SandboxError`."""
    try:
        stat = path.stat()
        key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
    except OSError:
        key = None  # not there or not readable: load_image says which
    if key is not None and key in _IMAGES_LOADED:
        return
    load_image(path)
    if key is not None:
        if len(_IMAGES_LOADED) >= _IMAGES_KEPT:
            del _IMAGES_LOADED[next(iter(_IMAGES_LOADED))]
        _IMAGES_LOADED[key] = None


def _shadow_light_is(light: tuple[float, ...], position: tuple[float, float, float]) -> bool:
    """Whether the shadow's homogeneous ``light`` is the scene light at ``position``:
    a point light there (w = 1), or a direction pointing at it from the origin (w = 0)."""
    p = np.asarray(position, dtype=np.float64)
    if light[3] == 1.0:
        return bool(np.allclose(light[:3], p, rtol=1e-9, atol=1e-9))
    length = float(np.linalg.norm(p))
    return length > 0.0 and bool(np.allclose(light[:3], p / length, rtol=0.0, atol=1e-9))


def load_scene(path: str | Path) -> Scene:
    """Read and validate a TOML scene file.

    Errors raise :class:`SandboxError` naming the file and the line, e.g.
    ``scene.toml:7: nodes[0].mesh: unknown mesh 'cbe'; ...``.
    """
    p = Path(path)
    raw = read_user_file(p, "scene file", "a scene .toml file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise SandboxError(f"{p}:{line}: not UTF-8 text (byte 0x{raw[exc.start]:02x})") from None
    try:
        data = tomllib.loads(text)
    except RecursionError:  # tomllib recurses once per level of nested arrays and inline tables
        line = _deep_line(text)
        raise SandboxError(f"{p}:{line}: malformed TOML: arrays or tables nested too deeply" if line
                           else f"{p}: malformed TOML: arrays or tables nested too deeply") from None
    except tomllib.TOMLDecodeError as exc:
        # tomllib ends its message with "(at line L, column C)".
        m = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        where = f"{p}:{m.group(1)}" if m else str(p)
        reason = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc)) or "malformed TOML"
        raise SandboxError(f"{where}: malformed TOML: {reason}") from None
    return _SceneReader(p, text).scene(data)


def _deep_line(text: str, depth: int = 100) -> int | None:
    """The line where ``[`` and ``{`` first nest ``depth`` deep (strings and comments skipped roughly)."""
    level, line, quote = 0, 1, ""
    for char in text:
        if char == "\n":
            line += 1
            quote = "" if quote == "#" else quote
        elif quote:
            quote = "" if char == quote and quote != "#" else quote
        elif char in "\"'#":
            quote = char
        elif char in "[{":
            level += 1
            if level >= depth:
                return line
        elif char in "]}":
            level = max(0, level - 1)
    return None
