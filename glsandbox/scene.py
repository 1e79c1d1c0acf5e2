"""The Scene: plain data that both renderers read. No GL here.

A lesson builds a :class:`Scene` in Python; a TOML file can describe one too
(:func:`glsandbox.scene_file.load_scene`). Coordinates are OpenGL's (right-handed, camera looking
down -z); see :mod:`glsandbox.transforms` for the course's DirectX form.
"""

from __future__ import annotations

import math
import os
import re
import weakref
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from glsandbox import transforms
from glsandbox.errors import NUMBER_LIMIT, SandboxError, check_number, check_numbers, plain
from glsandbox.geometry import Mesh
from glsandbox.overlay import Overlay

if TYPE_CHECKING:  # imported where a scene has a planar effect: a plain render skips it (a cold start)
    from glsandbox.planar import Mirror, PlanarShadow

Color = tuple[float, float, float, float]

#: The course's clear colour, ``{0.0f, 0.125f, 0.6f, 1.0f}`` ("DirectX 11").
COURSE_BLUE: Color = (0.0, 0.125, 0.6, 1.0)

#: Shadings lit by the scene's lights (``shaders/phong.glsl``, course section
#: "Lighting"): per-pixel Phong, per-vertex (Gouraud) and Blinn-Phong.
LIT_SHADINGS = ("phong", "gouraud", "blinn_phong")

#: How a node's surface gets its colour (each is a shader variant).
SHADINGS = ("solid", "vertex_color", *LIT_SHADINGS)

#: How lit shaders turn normals into world space: "correct" uses the normal
#: matrix (inverse transpose), "naive" the course's ``mul(Input.Norm, world)``.
NORMAL_MODES = ("correct", "naive")

#: Texture filters (course section "Texture Mapping", ``g_pSamplerLinear``):
#: min/mag ``NEAREST``; ``LINEAR``; bilinear in the nearest mip level;
#: trilinear (bilinear in the two nearest levels, blended); trilinear with
#: 16x anisotropy.
TEXTURE_FILTERS = ("nearest", "linear", "mip_nearest", "mip_linear", "anisotropic")

#: What happens to uv outside 0..1: ``REPEAT``, ``MIRRORED_REPEAT``, ``CLAMP_TO_EDGE``.
TEXTURE_WRAPS = ("repeat", "mirrored", "clamp")

#: Who renders a viewport: the rasterizer, the GLSL ray tracer, the numpy (float64) ray tracer.
RENDERERS = ("raster", "ray", "ray_numpy")

#: How much the plan turns on (:attr:`Scene.plan_mode`; every lesson's
#: ``--set effects=...``): only what the scene needs, or everything that does
#: not change the picture.
PLAN_MODES = ("needed", "all")

#: How depth is stored and compared. ``standard``: OpenGL's -1..1 clip depth
#: into a 24-bit integer buffer, test LESS. ``reverse_z``: a 32-bit float
#: buffer, ``glClipControl`` 0..1, near at 1 and far at 0, test GREATER (see
#: :func:`glsandbox.transforms.reverse_z`).
DEPTH_MODES = ("standard", "reverse_z")


#: How a material's alpha is used (glTF ``alphaMode``): ignored (the surface is opaque); a
#: cut-out, where an alpha below ``alpha_cutoff`` leaves no fragment; or blended over what lies
#: behind (drawn after the opaque nodes, farthest first, without depth writes).
ALPHA_MODES = ("opaque", "mask", "blend")

#: Images the project draws itself (:mod:`glsandbox.images`); any other
#: texture source is an image file path.
BUILTIN_TEXTURES = ("checker", "labels", "mip_levels")


# --- the checks values pass on their way in ------------------------------------
# Lessons and scene files build the same dataclasses, so their numbers are
# checked here, once, in __post_init__ (glsandbox.errors.check_numbers): finite,
# within +-NUMBER_LIMIT, colours within 0..1, so that neither renderer meets a
# NaN or an overflow it would turn into a silent miss.

#: The least a lit node's model may scale any direction by: its normal matrix,
#: the inverse, then stays within +-NUMBER_LIMIT (a flatter node has no
#: normals a renderer can use; the ray tracer traces such a node's triangles
#: with their face normals).
MIN_SCALE = 1.0 / NUMBER_LIMIT


def _set(obj: object, name: str, value: object) -> None:
    object.__setattr__(obj, name, value)  # a frozen dataclass normalizing its own field


@dataclass(frozen=True)
class Camera:
    """A perspective camera. Defaults are the course's: eye (0,3,-10) in
    DirectX, i.e. (0,3,10) in OpenGL, looking at the origin, up (0,1,0),
    45° vertical field of view, near 0.01, far 100."""

    eye: tuple[float, float, float] = (0.0, 3.0, 10.0)
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y: float = 45.0
    near: float = 0.01
    far: float = 100.0

    def __post_init__(self) -> None:
        for name in ("eye", "target", "up"):
            _set(self, name, check_numbers(getattr(self, name), f"camera {name}"))
        _set(self, "fov_y", check_number(self.fov_y, "camera fov_y"))
        if not 0.0 < self.fov_y < 180.0:
            raise SandboxError(f"camera fov_y must lie strictly between 0 and 180 degrees, got {plain(self.fov_y)}")
        _set(self, "near", check_number(self.near, "camera near"))
        _set(self, "far", check_number(self.far, "camera far"))
        if not 0.0 < self.near < self.far:
            raise SandboxError(f"camera near and far need 0 < near < far, got near={plain(self.near)}, "
                               f"far={plain(self.far)}")
        self.view()  # eye on the target, or up along the view: refused with the reason

    def view(self) -> np.ndarray:
        return transforms.look_at(self.eye, self.target, self.up)

    def projection(self, aspect: float) -> np.ndarray:
        return transforms.perspective(self.fov_y, aspect, self.near, self.far)


#: Shadow-map sizes a light may ask for (texels per side).
SHADOW_MAP_SIZES = (64, 128, 256, 512, 1024, 2048, 4096)
#: The widest percentage-closer filter (texels per side of the kernel).
MAX_PCF = 7


@dataclass(frozen=True)
class ShadowMap:
    """A light's shadow map (:mod:`glsandbox.shadowmap`): the depth of the
    nearest caster seen from the light, ``size`` x ``size`` texels, which a
    lit receiver compares its own distance with.

    ``bias`` and ``slope_bias`` (per unit of ``tan`` of the angle between the
    surface normal and the light) move the receiver's point towards the light
    before the comparison, in *texels*: the map's texel width where the point
    is (``2·tan(fov/2)·d / size`` at distance ``d`` from the light, the
    frustum's own fov, :func:`glsandbox.shadowmap.light_frame`), so the same
    settings hold for a scene of any size anywhere: too little and a surface
    shadows itself in stripes (acne), too much and shadows come loose from
    their casters (peter-panning). ``pcf`` is the width in texels of the
    percentage-closer filter (1: one comparison, hard aliased edges; 3: a 3x3
    grid of comparisons averaged). ``fov`` is the light frustum's field of view
    in degrees at most: a point light gets one perspective frustum looking from
    it at the centre of the shadow casters, fitted to them and the receivers,
    not a cube map (what lies outside the frustum is lit).
    """

    size: int = 1024
    bias: float = 2.5
    slope_bias: float = 2.5
    pcf: int = 3
    fov: float = 90.0

    def __post_init__(self) -> None:
        if isinstance(self.size, bool) or self.size not in SHADOW_MAP_SIZES:
            raise SandboxError(f"shadow map size must be one of {', '.join(map(str, SHADOW_MAP_SIZES))}, "
                               f"got {plain(self.size)}")
        for name in ("bias", "slope_bias"):
            _set(self, name, check_number(getattr(self, name), f"shadow map {name}", low=0.0))
        if isinstance(self.pcf, bool) or self.pcf not in range(1, MAX_PCF + 1, 2):
            raise SandboxError(f"shadow map pcf must be an odd width from 1 to {MAX_PCF} texels, got {plain(self.pcf)}")
        _set(self, "fov", check_number(self.fov, "shadow map fov"))
        if not 1.0 <= self.fov <= 150.0:
            raise SandboxError(f"shadow map fov must lie in 1..150 degrees, got {plain(self.fov)}")


@dataclass(frozen=True)
class Light:
    """A point light; with ``shadow`` it casts a shadow map (:class:`ShadowMap`)."""

    position: tuple[float, float, float]
    #: Its colour (intensity per channel, >= 0; above 1 is a brighter light).
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    shadow: ShadowMap | None = None

    def __post_init__(self) -> None:
        _set(self, "position", check_numbers(self.position, "light position"))
        _set(self, "color", check_numbers(self.color, "light colour", low=0.0))
        if self.shadow is not None and not isinstance(self.shadow, ShadowMap):
            raise SandboxError(f"a light's shadow must be a ShadowMap, got {plain(self.shadow)}")


#: Digests of in-memory texture images by array identity (the arrays are read-only), so that
#: a Texture made again from the same image (``dataclasses.replace`` of its sampler, a scene
#: file read every frame) does not hash its pixels again.
_IMAGE_DIGESTS: dict[int, tuple[weakref.ref[np.ndarray], str]] = {}


def _image_digest(image: np.ndarray) -> str:
    key = id(image)
    entry = _IMAGE_DIGESTS.get(key)
    if entry is not None and entry[0]() is image:
        return entry[1]
    shape = np.asarray(image.shape, dtype=np.int64).tobytes()
    import hashlib  # only image textures are hashed (loads OpenSSL): lessons without one skip it

    digest = hashlib.blake2b(shape + image.tobytes(), digest_size=12).hexdigest()
    _IMAGE_DIGESTS[key] = (weakref.ref(image, lambda _: _IMAGE_DIGESTS.pop(key, None)), digest)
    return digest


@dataclass(frozen=True)
class Texture:
    """An image on a surface and the sampler that reads it.

    ``source`` is a built-in image name (:data:`BUILTIN_TEXTURES`) or an image
    file path; ``filter`` and ``wrap`` are the sampler state, data like the
    rest of the scene, so one lesson can be rendered with each of them.

    ``image``, when given, is the picture itself, in memory: an ``(H, W, 4)``
    uint8 RGBA array, row 0 at the top (a model file's base colour texture,
    :mod:`glsandbox.mesh.load`). ``source`` then only names it (in plans and
    errors); textures are told apart by ``digest``, a hash of the pixels,
    made once here (the array is made read-only).
    """

    source: str = "checker"
    filter: str = "mip_linear"
    wrap: str = "repeat"
    image: np.ndarray | None = field(default=None, compare=False, repr=False)
    digest: str = field(init=False, default="", repr=False)

    def __post_init__(self) -> None:
        if self.image is not None:
            image = np.ascontiguousarray(self.image)
            if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 4 or 0 in image.shape:
                raise SandboxError(f"texture {self.source!r}: expected a non-empty (H, W, 4) uint8 image, "
                                   f"got {image.dtype} {image.shape}")
            image.setflags(write=False)
            object.__setattr__(self, "image", image)
            object.__setattr__(self, "digest", _image_digest(image))
        if self.filter not in TEXTURE_FILTERS:
            raise SandboxError(f"unknown texture filter {self.filter!r}; use one of {', '.join(TEXTURE_FILTERS)}")
        if self.wrap not in TEXTURE_WRAPS:
            raise SandboxError(f"unknown texture wrap {self.wrap!r}; use one of {', '.join(TEXTURE_WRAPS)}")
        if not str(self.source).strip():
            raise SandboxError("texture source is empty: give a built-in image name or an image file path")

    @property
    def is_file(self) -> bool:
        """Whether ``source`` names an image file (not a built-in image, nor one in memory)."""
        return self.image is None and self.source not in BUILTIN_TEXTURES

    def describe(self) -> str:
        return f"{self.source} ({self.filter}, {self.wrap})"


@dataclass(frozen=True)
class Material:
    """How a surface is coloured: a flat colour, the mesh's vertex colours, or lit.

    Lit shadings use the course's per-light formula (section "Lighting")
    ``min(ambient*mesh + diffuse*D + specular*S, 1)`` summed over the lights,
    with ambient 0.1, diffuse 0.4, specular 0.3 and exponent 32 by default; a
    coefficient of 0 switches its term off (the course's experiments).
    ``texture`` replaces the flat colour's rgb by the sampled image times it.
    """

    color: Color = (1.0, 1.0, 1.0, 1.0)
    shading: str = "solid"
    ambient: float = 0.1
    diffuse: float = 0.4
    specular: float = 0.3
    shininess: float = 32.0
    normals: str = "correct"
    texture: Texture | None = None
    #: Share of the colour that a mirror-like surface takes from the reflected
    #: ray (course section "Yansıma vektörü"): ``(1-r)·local + r·reflected``.
    #: Only the ray tracer follows reflection rays; the rasterizer ignores it.
    reflectivity: float = 0.0
    #: Lit shadings multiply the mesh colour by the mesh's vertex colours (a PLY's
    #: ``red green blue``), as ``vertex_color`` shading does unlit.
    vertex_colors: bool = False
    #: :data:`ALPHA_MODES`; alpha is the colour's times the texture's.
    alpha_mode: str = "opaque"
    alpha_cutoff: float = 0.5
    #: Both faces are drawn and lit, a back face with its normal reversed (glTF
    #: ``doubleSided``): the node's back-face culling is off whatever it says.
    double_sided: bool = False

    def __post_init__(self) -> None:
        _set(self, "color", check_numbers(self.color, "material colour", (4,), low=0.0, high=1.0))
        if self.alpha_mode not in ALPHA_MODES:
            raise SandboxError(f"unknown alpha mode {self.alpha_mode!r}; use one of {', '.join(ALPHA_MODES)}")
        if not (isinstance(self.alpha_cutoff, (int, float)) and math.isfinite(self.alpha_cutoff)
                and 0.0 <= self.alpha_cutoff <= 1.0):
            raise SandboxError(f"material alpha cutoff must lie in 0..1, got {plain(self.alpha_cutoff)}")
        if not (isinstance(self.reflectivity, (int, float)) and math.isfinite(self.reflectivity)
                and 0.0 <= self.reflectivity <= 1.0):
            raise SandboxError(f"material reflectivity must lie in 0..1, got {plain(self.reflectivity)}")
        if self.shading not in SHADINGS:
            raise SandboxError(f"unknown shading {self.shading!r}; use one of {', '.join(SHADINGS)}")
        if self.normals not in NORMAL_MODES:
            raise SandboxError(f"unknown normals {self.normals!r}; use one of {', '.join(NORMAL_MODES)}")
        for name in ("ambient", "diffuse", "specular", "shininess"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and 0.0 <= value <= NUMBER_LIMIT):
                raise SandboxError(f"material {name} must be a finite number in 0..{NUMBER_LIMIT:g}, "
                                   f"got {plain(value)}")

    @property
    def lit(self) -> bool:
        """Whether the surface is shaded by the scene's lights."""
        return self.shading in LIT_SHADINGS


# --- a node's own shader (docs/your-own.md, "Your own shader") -----------------------------

#: What the rasterizer gives a node's own shader (``Node.shader``), as
#: ``(name, GLSL type, space, what)``: the vertex attributes, then the
#: uniforms. The same ones the built-in shaders read (``shaders/basic.glsl``,
#: ``shaders/phong.glsl``); ``common/transform.glsl`` declares the matrices,
#: ``common/lighting.glsl`` the colour, eye, lights and coefficients. The
#: program is compiled with ``NUM_LIGHTS`` (the scene's light count) and, for
#: a textured material, ``TEXTURED`` defined. An attribute the mesh lacks is
#: an error (normals excepted: a mesh without them gets face normals).
#: "World" is camera-relative: the world translated so that the eye is at 0
#: (formed in float64, so a scene far from the origin keeps its precision;
#: docs/numerics.md). Directions and distances are the world's.
SHADER_INPUTS: tuple[tuple[str, str, str, str], ...] = (
    ("in_position", "in vec3", "model", "vertex position"),
    ("in_normal", "in vec3", "model", "vertex normal (face normals if the mesh has none)"),
    ("in_uv", "in vec2", "texture", "texture coordinates (the mesh must have them)"),
    ("in_color", "in vec3", "-", "vertex colour (the mesh must have them)"),
    ("m_model", "uniform mat4", "model -> world", "the node's model matrix (world relative to the eye)"),
    ("m_view", "uniform mat4", "world -> view", "the camera's view matrix (a rotation: the eye is at 0)"),
    ("m_proj", "uniform mat4", "view -> clip", "the projection"),
    ("m_normal", "uniform mat3", "model -> world", "normal matrix, inverse transpose of m_model's 3x3"),
    ("u_color", "uniform vec4", "-", "material colour (rgba, 0..1)"),
    ("u_eye", "uniform vec3", "world", "camera position (0: world is relative to the eye)"),
    ("u_light_pos", "uniform vec3[NUM_LIGHTS]", "world", "light positions, relative to the eye (if NUM_LIGHTS > 0)"),
    ("u_light_color", "uniform vec3[NUM_LIGHTS]", "-", "light colours"),
    ("u_ambient", "uniform float", "-", "material coefficient (0.1)"),
    ("u_diffuse", "uniform float", "-", "material coefficient (0.4)"),
    ("u_specular", "uniform float", "-", "material coefficient (0.3)"),
    ("u_shininess", "uniform float", "-", "specular exponent (32)"),
    ("u_texture", "uniform sampler2D", "texture", "the material's texture on unit 0 (with TEXTURED)"),
    ("u_alpha_cutoff", "uniform float", "-", "material alpha cutoff (0.5; alpha_mode \"mask\" discards below it)"),
)

#: The names the renderer sets; a node's own uniforms may not use them.
STANDARD_SHADER_NAMES = frozenset(name for name, *_ in SHADER_INPUTS)

_GLSL_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

#: A uniform value: a number (float, int or uint uniforms), a bool, or 2 to 4 numbers (vecN, ivecN, uvecN).
UniformValue = float | bool | tuple[float, ...]


def check_uniform_name(name: object, what: str) -> str:
    """A GLSL identifier that is not one of the renderer's own (:data:`STANDARD_SHADER_NAMES`)."""
    if not isinstance(name, str) or not _GLSL_NAME.fullmatch(name) or name.startswith("gl_"):
        raise SandboxError(f"{what}: not a GLSL uniform name (letters, digits and _, not gl_...)")
    if name in STANDARD_SHADER_NAMES:
        raise SandboxError(f"{what}: set by the renderer (the manual's table of shader inputs, docs/your-own.md), not by a scene")
    return name


def check_uniform_value(value: object, what: str) -> UniformValue:
    """A uniform value as the scene keeps it: a bool, a float, or a tuple of 2 to 4 floats,
    each number finite and within +-NUMBER_LIMIT (:func:`~glsandbox.errors.check_numbers`)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        return check_number(value, what)
    return check_numbers(value, what, (2, 3, 4))


def check_uniforms(values: object, what: str) -> Mapping[str, UniformValue]:
    """``{name: value}`` checked name by name, as a read-only mapping; ``what`` names
    each in errors, with ``{name}`` replaced by the uniform's name."""
    if not isinstance(values, Mapping):
        raise SandboxError(f"{what.format(name='').rstrip(' .')} must be a table of name = value, "
                           f"got {plain(values)}")
    checked = {}
    for name, value in values.items():
        label = what.format(name=name if isinstance(name, str) else plain(name))
        checked[check_uniform_name(name, label)] = check_uniform_value(value, label)
    return MappingProxyType(checked)


_NO_UNIFORMS: Mapping[str, UniformValue] = MappingProxyType({})


def check_node_model(name: str, model: object) -> np.ndarray:
    """A node's model matrix as an array, or a :class:`SandboxError` naming the node: 4x4
    numbers, each finite and within +-NUMBER_LIMIT."""
    matrix = np.asarray(model)
    if matrix.shape != (4, 4) or matrix.dtype.kind not in "biuf":
        raise SandboxError(f"node {name!r}: model matrix must be 4x4 numbers, got {plain(model)}")
    if matrix.dtype.kind == "f":  # the common case, checked every frame a node moves: sixteen Python floats
        entries = matrix.ravel().tolist()
        total = sum(entries)  # NaN or infinite where an entry is: then the general test below speaks
        if total - total == 0.0 and -NUMBER_LIMIT <= min(entries) and max(entries) <= NUMBER_LIMIT:
            return matrix
    in_bounds = bool(np.abs(matrix).max() <= NUMBER_LIMIT)  # False for NaN (max propagates it) and inf too
    if not in_bounds and not np.all(np.isfinite(matrix)):
        raise SandboxError(f"node {name!r}: model matrix has a non-finite entry: {plain(matrix)}")
    if not in_bounds:
        raise SandboxError(f"node {name!r}: model matrix entry {plain(np.max(np.abs(matrix)))} is beyond "
                           f"+-{NUMBER_LIMIT:g} (scale and position within +-{NUMBER_LIMIT:g})")
    return matrix


def check_moved_model(name: str, model: object, lit: bool) -> None:
    """:func:`check_node_model` and, for a ``lit`` node, :func:`check_lit_model` of a moved node's
    model (:func:`moved_scene`, every frame): a float 4x4 is read into Python floats once for
    both; anything else, or a matrix failing either, gets their own checks and messages."""
    matrix = np.asarray(model)
    if matrix.shape == (4, 4) and matrix.dtype.kind == "f":
        entries = matrix.ravel().tolist()
        total = sum(entries)  # NaN or infinite where an entry is
        if (total - total == 0.0 and -NUMBER_LIMIT <= min(entries) and max(entries) <= NUMBER_LIMIT
                and (not lit or transforms.least_scale_bound(*entries[0:3], *entries[4:7], *entries[8:11])
                     >= MIN_SCALE)):
            return
    matrix = check_node_model(name, model)
    if lit:
        check_lit_model(name, matrix)


def check_lit_model(name: str, model: object) -> None:
    """A lit node's model must keep every direction at least :data:`MIN_SCALE` long: its normal
    matrix (the inverse transpose) then exists and stays within +-NUMBER_LIMIT."""
    if transforms.scales_at_least(model, MIN_SCALE):
        return
    smallest = transforms.smallest_scale(model)
    if smallest < MIN_SCALE:
        what = ("is singular (a scale of 0?)" if smallest == 0.0 else
                f"shrinks one direction to {smallest:.3g}, below {MIN_SCALE:g}")
        raise SandboxError(f"node {name!r}: model matrix {what}, so a lit node has no usable normals; "
                           f"scale every axis by at least {MIN_SCALE:g}, or use an unlit shading")


@dataclass(frozen=True, eq=False)
class Node:
    """A mesh placed in the world with a model matrix and a material.

    ``cull_back_faces`` is the rasterizer state (on by default, as in the
    course; off for a double-sided material); ``viewports`` limits the node to some viewports (None: all).

    ``shader`` names a GLSL file of the user's (a path, relative to the
    working folder or absolute, kept absolute; a scene file's is relative to
    the scene file) that the rasterizer draws the node with instead of a built-in
    program: one file, both stages, inputs as :data:`SHADER_INPUTS` lists.
    ``uniforms`` sets the shader's own uniforms (``{"u_bands": 3.0}``):
    numbers, bools, or 2 to 4 numbers. The ray tracer cannot run GLSL: it
    traces such a node with its ``material``.
    """

    name: str
    mesh: Mesh
    model: np.ndarray = field(default_factory=lambda: np.eye(4))
    material: Material = Material()
    cull_back_faces: bool = True
    viewports: tuple[int, ...] | None = None
    shader: str | os.PathLike[str] | None = None
    uniforms: Mapping[str, Any] = field(default_factory=lambda: _NO_UNIFORMS)
    #: Shadow maps: whether the node is drawn into them (casts), and whether a
    #: lit node looks them up (receives). The planar shadow names its own.
    casts_shadow: bool = True
    receives_shadow: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise SandboxError(f"a node's name must be text, got {plain(self.name)}")
        if not isinstance(self.mesh, Mesh):
            hint = f" (a built-in mesh by name: glsandbox.geometry.builtin_mesh({self.mesh!r}))" \
                if isinstance(self.mesh, str) else ""
            raise SandboxError(f"node {self.name!r}: mesh must be a Mesh{hint}, got {plain(self.mesh)}")
        if not isinstance(self.material, Material):
            raise SandboxError(f"node {self.name!r}: material must be a Material, got {plain(self.material)}")
        if self.material.double_sided:
            _set(self, "cull_back_faces", False)  # both faces are the surface
        if self.shader is not None:
            if not isinstance(self.shader, (str, os.PathLike)) or not str(self.shader).strip():
                raise SandboxError(f"node {self.name!r}: shader must be a GLSL file path, got {plain(self.shader)}")
            # Absolute now: the working folder at the node's making is the one meant, and
            # programs are cached by path, so two folders' "toon.glsl" stay apart.
            _set(self, "shader", Path(os.path.abspath(self.shader)))
        if self.uniforms or type(self.uniforms) is not MappingProxyType:
            _set(self, "uniforms", check_uniforms(self.uniforms, f"node {self.name!r}: uniform {{name}}"))
            if self.uniforms and self.shader is None:
                raise SandboxError(f"node {self.name!r}: uniforms need a shader of the node's own (shader = ...)")
        check_node_model(self.name, self.model)
        # What the material reads from the mesh (the renderers would fail later, naming no node).
        # Normals are not among them: a lit mesh without normals is shaded flat by both
        # renderers (glsandbox.geometry.with_face_normals).
        for needed, data, attribute in (("a texture", self.material.texture is not None, "uvs"),
                                        ("vertex_color shading", self.material.shading == "vertex_color", "colors"),
                                        ("vertex_colors = true", self.material.vertex_colors, "colors")):
            if data and getattr(self.mesh, attribute, None) is None:
                raise SandboxError(f"node {self.name!r}: mesh {self.mesh.name!r} has no {attribute[:-1]} data, "
                                   f"which {needed} needs")
        if self.material.lit:
            check_lit_model(self.name, self.model)

    def shown_in(self, viewport: int) -> bool:
        """Whether the node is drawn in viewport ``viewport`` (by index)."""
        return self.viewports is None or viewport in self.viewports


@dataclass(frozen=True)
class Viewport:
    """A rectangle of the frame, in fractions of its size from the bottom left.

    Several viewports make the course's split screen. Each may clear to its
    own colour and look through its own camera (None: the scene's).
    """

    rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0)
    clear_color: Color | None = None
    camera: Camera | None = None
    label: str = ""
    #: Who draws the viewport's 3D content: ``"raster"`` (the executor),
    #: ``"ray"`` (the GLSL ray tracer) or ``"ray_numpy"`` (the float64 ray
    #: tracer); see :func:`glsandbox.frame.trace_viewports`.
    renderer: str = "raster"

    def __post_init__(self) -> None:
        if self.renderer not in RENDERERS:
            raise SandboxError(f"unknown renderer {self.renderer!r}; use one of {', '.join(RENDERERS)}")
        rect = check_numbers(self.rect, "viewport rect", (4,), low=0.0, high=1.0)
        x, y, w, h = rect
        if w <= 0.0 or h <= 0.0 or x + w > 1.0 + 1e-9 or y + h > 1.0 + 1e-9:
            raise SandboxError(f"viewport rect {plain(rect)} must lie inside 0..1 with positive size")
        _set(self, "rect", rect)
        if self.clear_color is not None:
            _set(self, "clear_color", check_numbers(self.clear_color, "viewport clear colour", (4,), 0.0, 1.0))
        if self.camera is not None and not isinstance(self.camera, Camera):
            raise SandboxError(f"viewport camera must be a Camera, got {plain(self.camera)}")

    def pixels(self, width: int, height: int) -> tuple[int, int, int, int]:
        """(x, y, w, h) in pixels; edges are rounded so tiles meet without gaps."""
        x0, y0 = round(self.rect[0] * width), round(self.rect[1] * height)
        x1 = round((self.rect[0] + self.rect[2]) * width)
        y1 = round((self.rect[1] + self.rect[3]) * height)
        return x0, y0, x1 - x0, y1 - y0


@dataclass(frozen=True, eq=False)
class Scene:
    """Everything a frame shows. Renderers never change it."""

    name: str
    nodes: tuple[Node, ...] = ()
    camera: Camera = Camera()
    lights: tuple[Light, ...] = ()
    clear_color: Color = COURSE_BLUE
    viewports: tuple[Viewport, ...] = (Viewport(),)
    samples: int = 0
    depth_test: bool = True
    #: Labels and figures drawn over the frame (:mod:`glsandbox.overlay`).
    overlays: tuple[Overlay, ...] = ()
    #: A planar mirror drawn through the stencil buffer (:mod:`glsandbox.planar`).
    mirror: Mirror | None = None
    #: A planar shadow projected onto a receiver (:mod:`glsandbox.planar`).
    planar_shadow: PlanarShadow | None = None
    #: How depth is stored and compared (:data:`DEPTH_MODES`).
    depth_mode: str = "standard"
    #: ``"needed"``: the plan lists only what the scene calls for; ``"all"``:
    #: every buffer and pass state forced on (the everything-on baseline that
    #: ``glsandbox bench`` measures on-demand planning against). See :data:`PLAN_MODES`.
    plan_mode: str = "needed"
    #: Uniform values for every node's own shader that declares them
    #: (``--set u.NAME=value``; they win over the nodes' ``uniforms``).
    uniform_overrides: Mapping[str, Any] = field(default_factory=lambda: _NO_UNIFORMS)

    def __post_init__(self) -> None:
        # Lists are welcome from Python (Scene("s", nodes=[...])); stored as tuples, so a
        # Scene stays immutable and the renderers can compare its parts by identity.
        for field_name in ("nodes", "lights", "viewports", "overlays"):
            if isinstance(getattr(self, field_name), list):
                _set(self, field_name, tuple(getattr(self, field_name)))
        self._check_parts()
        if self.uniform_overrides or type(self.uniform_overrides) is not MappingProxyType:
            _set(self, "uniform_overrides", check_uniforms(self.uniform_overrides, "--set u.{name}"))
        _set(self, "clear_color", check_numbers(self.clear_color, "scene clear colour", (4,), 0.0, 1.0))
        if self.depth_mode not in DEPTH_MODES:
            raise SandboxError(f"unknown depth mode {self.depth_mode!r}; use one of {', '.join(DEPTH_MODES)}")
        if self.plan_mode not in PLAN_MODES:
            raise SandboxError(f"unknown plan mode {self.plan_mode!r}; use one of {', '.join(PLAN_MODES)}")

    def _check_parts(self) -> None:
        """Each field holds what it names (``nodes=(1, 2)`` would fail deep in a renderer, naming nothing)."""
        if not isinstance(self.name, str):
            raise SandboxError(f"a scene's name must be text, got {plain(self.name)}")
        for field_name, kind in (("nodes", Node), ("lights", Light), ("viewports", Viewport), ("overlays", Overlay)):
            items = getattr(self, field_name)
            if not isinstance(items, tuple):
                lone = " (one alone needs a comma: (x,))" if isinstance(items, kind) else ""
                raise SandboxError(f"scene {self.name!r}: {field_name} must be a tuple or list of {kind.__name__}"
                                   f"{lone}, got {plain(items)}")
            for i, item in enumerate(items):
                if not isinstance(item, kind):
                    raise SandboxError(f"scene {self.name!r}: {field_name}[{i}] must be a {kind.__name__}, "
                                       f"got {plain(item)}")
        checks: tuple[tuple[str, type], ...] = (("camera", Camera),)
        if self.mirror is not None or self.planar_shadow is not None:
            from glsandbox.planar import Mirror, PlanarShadow

            checks += (("mirror", Mirror), ("planar_shadow", PlanarShadow))
        for field_name, kind in checks:
            value = getattr(self, field_name)
            if not isinstance(value, kind) and (value is not None or field_name == "camera"):
                raise SandboxError(f"scene {self.name!r}: {field_name} must be a {kind.__name__}, got {plain(value)}")
        if isinstance(self.samples, bool) or not isinstance(self.samples, (int, np.integer)) or self.samples < 0:
            raise SandboxError(f"scene {self.name!r}: samples must be a whole number >= 0, got {plain(self.samples)}")


# --- frames that pay only for what moves ------------------------------


@dataclass(frozen=True)
class Motion:
    """What ``time`` moves in a lesson's scene (:meth:`glsandbox.Lesson.motion`): new model
    matrices of nodes, by node name, new positions of lights, by index, and a new camera
    (the window's camera keys). Everything else
    of the scene stays as it was built, so a frame whose only change is time keeps its
    Scene, the Scene's checks and its plan (:func:`moved_scene`)."""

    models: Mapping[str, Any] = field(default_factory=dict)
    lights: Mapping[int, tuple[float, float, float]] = field(default_factory=dict)
    #: A camera replacing the scene's (the window's camera keys, :meth:`glsandbox.camera.CameraInput.apply`).
    camera: Camera | None = None
    #: New vertex positions of nodes' meshes, by node name: the same number of vertices, every
    #: other array and the indices as built (transform_order's trail). The renderer writes
    #: them into the mesh's own vertex buffer instead of uploading a new mesh.
    positions: Mapping[str, Any] = field(default_factory=dict)
    #: New images of overlays, by overlay name (a panel whose numbers change); the renderer
    #: writes them into the overlay's texture.
    overlays: Mapping[str, Any] = field(default_factory=dict)


def _copy_with(obj: Any, **changes: Any) -> Any:
    """A frozen dataclass ``obj`` with ``changes``, without running its ``__post_init__`` again:
    the caller has checked the changed fields (the others were checked when ``obj`` was made)."""
    new = object.__new__(type(obj))
    new.__dict__.update({**obj.__dict__, **changes})
    return new


def moved_mesh(mesh: Mesh, positions: Any) -> Mesh:
    """``mesh`` with new vertex positions (as many as it has, finite), the rest its own; it
    remembers the mesh it was moved from (:func:`mesh_origin`), so that the renderer writes
    the positions into that mesh's vertex buffer, not a new one each frame."""
    array = np.asarray(positions)
    if array.shape != mesh.positions.shape or array.dtype.kind not in "iuf":
        raise SandboxError(f"mesh {mesh.name!r}: moved positions must be a {mesh.positions.shape} array of "
                           f"numbers like the mesh's, got shape {array.shape} of {array.dtype}")
    if not np.isfinite(array).all():
        row = int(np.argwhere(~np.isfinite(array))[0][0])
        raise SandboxError(f"mesh {mesh.name!r}: moved positions[{row}] is not finite: {plain(array[row])}")
    if array is positions and array.flags.writeable:
        array = array.copy()  # the mesh keeps its own, read-only as every mesh's arrays
    array.flags.writeable = False
    origin = mesh_origin(mesh) or mesh
    # analytic: the exact shape the built triangles tessellate; moved ones tessellate none.
    return _copy_with(mesh, positions=array, analytic=None, _moved_from=origin)


def mesh_origin(mesh: Mesh) -> Mesh | None:
    """The mesh ``mesh`` was moved from by :func:`moved_mesh` (None: it was made as it is)."""
    return mesh.__dict__.get("_moved_from")


def moved_scene(scene: Scene, motion: Motion) -> Scene:
    """``scene`` with ``motion`` applied: the moved nodes and lights are new objects, each new
    value checked as the dataclasses check it (a model matrix of 4x4 bounded numbers, at
    least :data:`MIN_SCALE` in every direction for a lit node; a light position of three
    bounded numbers); every other part is the same object as in ``scene``. The result
    remembers ``scene`` (:func:`scene_origin`): the renderers keep what they derived from
    it (the plan, per-draw uniform bytes) while only positions change."""
    origin = scene.__dict__.get("_moved_from") or scene  # (scene_origin, inline: this runs every frame)
    nodes, lights, overlays = scene.nodes, scene.lights, scene.overlays
    models, positions = motion.models, motion.positions
    if models or positions:
        moved = list(nodes)
        for i in _touched_nodes(scene, origin, models, positions):
            node = nodes[i]
            model, points = models.get(node.name), positions.get(node.name)
            if points is None:  # (the common case: a node turning)
                if model is None:  # (a name given None: nothing moves)
                    continue
                check_moved_model(node.name, model, node.material.lit)
                moved[i] = _copy_with(node, model=model)
                continue
            changes: dict[str, Any] = {}
            if model is not None:
                check_moved_model(node.name, model, node.material.lit)
                changes["model"] = model
            changes["mesh"] = moved_mesh(node.mesh, points)
            moved[i] = _copy_with(node, **changes)
        nodes = tuple(moved)
    if motion.overlays:
        images = dict(motion.overlays)
        unknown = set(images) - {overlay.name for overlay in overlays}
        if unknown:
            raise SandboxError(f"scene {scene.name!r}: the motion changes overlay "
                               f"{', '.join(map(repr, sorted(unknown)))}, which is not an overlay of the scene")
        overlays = tuple(Overlay(o.name, images[o.name], o.viewport, o.position, o.scalable) if o.name in images else o
                         for o in overlays)
    if motion.lights:
        lights = _moved_lights(scene, motion.lights)
    camera = scene.camera
    if motion.camera is not None:
        if not isinstance(motion.camera, Camera):
            raise SandboxError(f"scene {scene.name!r}: the motion's camera must be a Camera, got {plain(motion.camera)}")
        camera = motion.camera
    return _copy_with(scene, nodes=nodes, lights=lights, camera=camera, overlays=overlays, _moved_from=origin)


def _touched_nodes(scene: Scene, origin: Scene, models: Mapping[str, Any],
                   positions: Mapping[str, Any]) -> list[int]:
    """The indices into ``scene.nodes`` of the nodes ``models`` and ``positions`` name, in scene
    order (the first bad one is then named), or the error naming what is not a node. Only the
    moved nodes are visited, not every node."""
    # Where each name's nodes are (the same in every scene moved from ``origin``: a moved
    # scene's nodes are its origin's, some replaced by moved copies, in the same order).
    where = origin.__dict__.get("_node_indices")
    if where is None:
        where = {}
        for i, node in enumerate(origin.nodes):
            where[node.name] = (*where.get(node.name, ()), i)
        origin.__dict__["_node_indices"] = where
    if not where.keys() >= models.keys() or (positions and not where.keys() >= positions.keys()):
        unknown = (set(models) | set(positions)) - where.keys()
        raise SandboxError(f"scene {scene.name!r}: the motion moves {', '.join(map(repr, sorted(unknown)))}, "
                           f"which is not a node of the scene")
    touched: list[int] = []
    for name in models:
        touched += where[name]
    for name in positions:
        if name not in models:
            touched += where[name]
    touched.sort()
    return touched


def _moved_lights(scene: Scene, moves: Mapping[int, Any]) -> tuple[Light, ...]:
    """``scene``'s lights with ``moves`` (new positions by index) applied, each checked."""
    lights = list(scene.lights)
    for index, position in moves.items():
        if not (isinstance(index, int) and 0 <= index < len(lights)):
            raise SandboxError(f"scene {scene.name!r}: the motion moves light {plain(index)}, and the scene "
                               f"has {len(lights)}")
        lights[index] = _copy_with(lights[index], position=check_numbers(position, "light position"))
    return tuple(lights)


def motion_parts(scene: Scene, motion: Motion) -> tuple[dict[str, Any], tuple[Light, ...]]:
    """What a motion of model matrices and light positions alone (no ``positions``,
    ``overlays`` or ``camera``) moves in ``scene``, checked exactly as :func:`moved_scene`
    checks it (the same errors, in the same order), without making the moved scene: the
    moved models by node name (a name given None left out) and the lights. The headless
    frames hand these to the executor (:meth:`glsandbox.frame.FrameRenderer.render_motion`);
    ``moved_scene(scene, motion)`` has exactly these models and lights."""
    origin = scene.__dict__.get("_moved_from") or scene
    nodes, models = scene.nodes, motion.models
    moved: dict[str, Any] = {}
    if models:
        for i in _touched_nodes(scene, origin, models, {}):
            node = nodes[i]
            model = models[node.name]
            if model is not None:  # (a name given None: nothing moves)
                check_moved_model(node.name, model, node.material.lit)
                moved[node.name] = model
    lights = _moved_lights(scene, motion.lights) if motion.lights else scene.lights
    return moved, lights


def scene_origin(scene: Scene) -> Scene | None:
    """The scene ``scene`` was moved from by :func:`moved_scene` (None: it was built as it is).
    A scene made from it any other way (``dataclasses.replace``) has none."""
    return scene.__dict__.get("_moved_from")
