"""The raster executor: runs a Plan on a ModernGL context.

It compiles the plan's program variants once, uploads each mesh once (cached
by name and content), and walks the passes in order. It does what the plan
says and nothing more; choosing passes is :func:`glsandbox.plan.plan`'s job.
"""

from __future__ import annotations

import functools
import struct
import weakref
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import moderngl
import numpy as np

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh, with_face_normals
from glsandbox.gl import depth as gl_depth, passes as gl_passes, planar as gl_planar, shadowmap as gl_shadowmap
from glsandbox.gl.context import GLHost
from glsandbox.gl.overlay import OverlayDrawer
from glsandbox.gl.shaders import compile_with_sources, declared_uniforms, source_files
from glsandbox.gl.target import clear_opaque
from glsandbox.gl.textures import TextureCache
from glsandbox.gl.passes import FrameState, PassRunner
from glsandbox.plan import SHADOW_MAP_UNIT, Draw, Pass, Plan, ProgramVariant, plan as make_plan
from glsandbox.scene import Camera, Light, Material, Node, Scene, mesh_origin

try:  # hashlib.blake2b is this very type; importing hashlib loads OpenSSL too (~4 ms of every start)
    from _blake2 import blake2b
except ImportError:  # a Python built without its own BLAKE2
    from hashlib import blake2b

_MODES = {"triangles": moderngl.TRIANGLES, "triangle_strip": moderngl.TRIANGLE_STRIP,
          "lines": moderngl.LINES, "line_strip": moderngl.LINE_STRIP}
# Mesh arrays and the attribute names the shaders use for them.
_ATTRIBUTES = (("positions", "in_position", 3), ("normals", "in_normal", 3),
               ("uvs", "in_uv", 2), ("colors", "in_color", 3))


_MESH_KEYS: weakref.WeakKeyDictionary[Mesh, tuple[str, str]] = weakref.WeakKeyDictionary()


def _gpu_arrays(mesh: Mesh) -> dict[str, np.ndarray]:
    """What the GPU gets of ``mesh``: each vertex array as contiguous float32 (by attribute name),
    the indices as uint32 (``"indices"``)."""
    arrays = {attr: np.ascontiguousarray(getattr(mesh, field), dtype="f4")
              for field, attr, _ in _ATTRIBUTES if getattr(mesh, field) is not None}
    if mesh.indices is not None:
        arrays["indices"] = np.ascontiguousarray(mesh.indices, dtype="u4")
    return arrays


def _mesh_key(mesh: Mesh, arrays: dict[str, np.ndarray] | None = None) -> tuple[str, str]:
    """Name and a digest of what the GPU gets (``arrays``, :func:`_gpu_arrays`): meshes that upload
    the same bytes share GPU buffers. Meshes are immutable, so the digest is made once per mesh
    object."""
    key = _MESH_KEYS.get(mesh)
    if key is None:
        digest = blake2b(digest_size=12)
        for name, array in (arrays if arrays is not None else _gpu_arrays(mesh)).items():
            digest.update(name.encode())
            digest.update(array)  # the array's memory as it is: no copy
        digest.update(mesh.mode.encode())
        key = _MESH_KEYS[mesh] = (mesh.name, digest.hexdigest())
    return key


#: The GPU key of each mesh moved by a lesson's Motion (``Motion.positions``): its own buffers,
#: shared with no mesh of equal content, since the positions are written into them every frame.
_MOVED_KEYS: weakref.WeakKeyDictionary[Mesh, tuple[str, str]] = weakref.WeakKeyDictionary()


def _moved_key(origin: Mesh) -> tuple[str, str]:
    key = _MOVED_KEYS.get(origin)
    if key is None:
        key = _MOVED_KEYS[origin] = (origin.name, f"moved-{len(_MOVED_KEYS)}-{id(origin):x}")
    return key


class PassCamera:
    """A pass's view and projection, with what the draws need from them made
    once per pass instead of once per draw: the uniform bytes, and the eye
    (only lit draws ask for it)."""

    __slots__ = ("view", "proj", "view_bytes", "proj_bytes", "_eye_bytes")

    def __init__(self, view: np.ndarray, proj: np.ndarray) -> None:
        self.view, self.proj = view, proj
        self.view_bytes, self.proj_bytes = transforms.gl_bytes(view), transforms.gl_bytes(proj)
        self._eye_bytes: bytes | None = None

    @property
    def eye_bytes(self) -> bytes:
        """``u_eye``'s uniform bytes: a camera that does not move inverts its view once per run."""
        if self._eye_bytes is None:
            self._eye_bytes = _eye_bytes(np.asarray(self.view, dtype=np.float64).tobytes())
        return self._eye_bytes


#: Uniform bytes of material colours: a lesson rebuilding its scene each frame
#: makes new Materials with the same few colours.
_COLOR_BYTES: dict[tuple[float, ...], bytes] = {}


def _color_bytes(color: tuple[float, ...]) -> bytes:
    data = _COLOR_BYTES.get(color)
    if data is None:
        data = _COLOR_BYTES[color] = np.asarray(color, dtype="f4").tobytes()
    return data


def _float_bytes(value: float) -> bytes:
    return struct.pack("f", value)


#: ``u_texture``'s value: the material texture is on unit 0.
_UNIT_0 = struct.pack("i", 0)


def _material_bytes(material: Material) -> tuple[tuple[str, bytes], ...]:
    """The coefficients of the course's ``0.1*mesh + 0.4*diffuse + 0.3*specular`` and the
    exponent (32) as uniform bytes; a zero coefficient switches its term off."""
    return _coefficient_bytes(material.ambient, material.diffuse, material.specular, material.shininess)


@functools.lru_cache(maxsize=256)
def _coefficient_bytes(ambient: float, diffuse: float, specular: float,
                       shininess: float) -> tuple[tuple[str, bytes], ...]:
    """:func:`_material_bytes` made once per set of coefficients (a scene has a few)."""
    return (("u_ambient", _float_bytes(ambient)), ("u_diffuse", _float_bytes(diffuse)),
            ("u_specular", _float_bytes(specular)), ("u_shininess", _float_bytes(shininess)))


@functools.lru_cache(maxsize=64)
def _eye_bytes(view: bytes) -> bytes:
    """The eye position's uniform bytes for a float64 view matrix given as bytes."""
    return eye_position(np.frombuffer(view).reshape(4, 4)).astype("f4").tobytes()


#: Entries each of :data:`_MODEL_BYTES` and :data:`_NORMAL_BYTES` keeps; past it, it starts
#: again (a moving node adds one per frame).
_MATRICES_KEPT = 1024


class _MatrixBytes(dict):
    """Uniform bytes by the C-order bytes of a float64 4x4 model matrix, each made on its first
    lookup (``cache[content]``: a plain subscript, no method call, for a matrix seen before)
    by ``convert`` of the matrix read back from ``content``."""

    def __init__(self, convert: Callable[[np.ndarray], bytes]) -> None:
        super().__init__()
        self.convert = convert

    def __missing__(self, content: bytes) -> bytes:
        if len(self) >= _MATRICES_KEPT:
            self.clear()
        data = self[content] = self.convert(np.frombuffer(content).reshape(4, 4))
        return data


#: ``m_model``'s and ``m_normal``'s uniform bytes by the float64 model matrix's bytes (see
#: :meth:`Executor.draw_node`): a node that does not move converts its matrix, and inverts it,
#: once; an array changed in place between frames has other bytes, so it is converted again.
_MODEL_BYTES = _MatrixBytes(transforms.gl_bytes)
_NORMAL_BYTES = _MatrixBytes(lambda matrix: transforms.gl_bytes(transforms.normal_matrix(matrix)))


class _Written(dict):
    """The uniform bytes last written into one program, by uniform name (and the ``#`` keys
    below); a name never written gives None (``written[name]``: a subscript, not a ``get`` call)."""

    def __missing__(self, name: str) -> None:
        return None


@dataclass(frozen=True)
class UserProgram:
    """What the executor knows of a node's own shader program besides the program itself."""

    path: Path  # the user's file
    files: frozenset[Path]  # it and every file it includes (watched by the window)
    declared: frozenset[str]  # the uniform names its text declares


#: GL types of the uniforms a scene may set (``Node.uniforms``, ``--set u.NAME``):
#: GLSL name, component kind, component count.
_SETTABLE_UNIFORMS = {
    0x1406: ("float", "float", 1), 0x8B50: ("vec2", "float", 2), 0x8B51: ("vec3", "float", 3),
    0x8B52: ("vec4", "float", 4), 0x1404: ("int", "int", 1), 0x8B53: ("ivec2", "int", 2),
    0x8B54: ("ivec3", "int", 3), 0x8B55: ("ivec4", "int", 4), 0x1405: ("uint", "uint", 1),
    0x8DC6: ("uvec2", "uint", 2), 0x8DC7: ("uvec3", "uint", 3), 0x8DC8: ("uvec4", "uint", 4),
    0x8B56: ("bool", "bool", 1),
}
#: Other GL types, named in errors.
_OTHER_TYPES = {0x8B5A: "mat2", 0x8B5B: "mat3", 0x8B5C: "mat4", 0x8B5E: "sampler2D", 0x8B60: "samplerCube",
                0x8B57: "bvec2", 0x8B58: "bvec3", 0x8B59: "bvec4"}
#: The attributes the executor feeds, with the GLSL type of what their buffers hold.
_ATTRIBUTE_GLSL = {attr: f"vec{width}" for _, attr, width in _ATTRIBUTES}
#: GL's float, vec2, vec3, vec4: the types a buffer of floats can feed.
_FLOAT_VECTORS = (0x1406, 0x8B50, 0x8B51, 0x8B52)


def user_uniform_value(user: UserProgram, uniform: moderngl.Uniform, name: str, value: object,
                       given_by: str) -> object:
    """``value`` as ``uniform`` takes it, or a :class:`SandboxError` naming the user's file:
    a number for float, int and uint (whole numbers for the last two), a bool for bool,
    N numbers for vecN, ivecN and uvecN; arrays, matrices and samplers are not set this way."""
    settable = _SETTABLE_UNIFORMS.get(uniform.gl_type)
    glsl = settable[0] if settable else _OTHER_TYPES.get(uniform.gl_type, f"GL type 0x{uniform.gl_type:04X}")
    if uniform.array_length > 1:
        glsl += f"[{uniform.array_length}]"
    if settable is None or uniform.array_length > 1:
        raise SandboxError(f"{user.path}: uniform {name} is a {glsl}; {given_by} may set float, int, uint, bool, "
                           "vecN, ivecN and uvecN uniforms only")
    _, kind, count = settable
    items = value if isinstance(value, tuple) else (value,)
    fits = len(items) == count and all(isinstance(v, bool) == (kind == "bool") for v in items)
    if fits and kind in ("int", "uint"):
        fits = all(float(v).is_integer() and (kind == "int" or v >= 0) for v in items)
    if not fits:
        shown = ("true" if value else "false") if isinstance(value, bool) else \
            ", ".join(f"{v:g}" for v in items) if len(items) > 1 else f"{items[0]:g}"
        raise SandboxError(f"{user.path}: uniform {name} is a {glsl}, but {given_by} gives it {shown}")
    if kind in ("int", "uint"):
        items = tuple(int(v) for v in items)
    return items if count > 1 else items[0]


@dataclass
class _GpuMesh:
    """A mesh's GPU buffers (shared by meshes that upload the same bytes), draw mode and element count."""

    buffers: dict[str, moderngl.Buffer]
    index: moderngl.Buffer | None
    mode: int
    count: int
    positions: np.ndarray | None = None  # a moved mesh's: the positions its buffer holds now


@dataclass
class _DrawSetup:
    """What :meth:`Executor.draw_node` needs for one mesh drawn with one program (see ``_draw_setup``)."""

    source: Mesh  # the node's mesh (the key's object)
    program: moderngl.Program
    members: frozenset[str]
    write: Callable[[str, bytes], None]
    mesh_key: tuple[str, str]  # of the mesh as drawn
    vao: moderngl.VertexArray
    gpu: _GpuMesh
    normal: bool  # the program reads m_normal
    # The program's uniforms by name, and the bytes last written into each (the program's
    # entry of Executor._written): draw_node's loop writes only what changed.
    uniforms: dict[str, moderngl.Uniform] = field(default_factory=dict)  # a _Uniforms
    written: dict[str, bytes] = field(default_factory=dict)


#: A key of a program's ``written`` dict that names no uniform: the constants tuple of the
#: prepared draw that wrote its material's uniforms last (see :meth:`Executor.draw_node`).
_CONSTANTS = "#constants"
#: The PassCamera whose view and projection a program holds (its ``written`` dict's key, like
#: :data:`_CONSTANTS`): draws through the same camera skip comparing them.
_CAMERA = "#camera"
#: The PassCamera whose eye position a program holds (lit draws only write it).
_EYE = "#eye"
#: A model matrix of this dtype is converted and compared as it is.
_FLOAT64 = np.dtype(np.float64)


def _constants_change(written: dict[str, bytes], last: tuple | None,
                      constants: tuple[tuple[str, bytes], ...]) -> tuple[tuple[str, bytes], ...]:
    """What a draw writes of its material's ``constants`` into a program that holds ``last``'s (the
    constants a draw wrote last; None: not known, so the program's ``written`` bytes are compared):
    the entries whose bytes differ (walls of one program that differ only in colour: ``u_color``)."""
    held = written if last is None else dict(last)
    return tuple((name, data) for name, data in constants if held.get(name) != data)


class _NoUniform:
    """What :class:`_Uniforms` gives for a name the program lacks (a term the compiler removed)."""

    @staticmethod
    def write(data: bytes) -> None:
        pass


class _Uniforms(dict):
    """A program's uniforms by name; a name it lacks gives :class:`_NoUniform` (nothing written)."""

    def __missing__(self, name: str) -> type[_NoUniform]:
        return _NoUniform


class _Steps(dict):
    """The prepared draws by key (:attr:`Executor._steps`); a key not there gives None (a subscript per draw)."""

    def __missing__(self, key: tuple[int, str]) -> None:
        return None


class _DrawStep:
    """One draw of a kept plan prepared once (the flat draw list): what
    :meth:`Executor.draw_node` found for ``draw`` drawn with ``material`` and ``front_face``
    (its set-up, culling, whether lit, its material's constant uniform bytes). A frame whose
    only change is time finds it by the Draw (plans are kept while only time moves) and
    writes only the model matrix and what moved; any other draw prepares a step anew."""

    __slots__ = ("draw", "material", "front_face", "mesh", "origin", "setup", "user", "culling", "lit",
                 "constants", "change", "lights")

    def __init__(self, draw: Draw, material: Material, front_face: str, mesh: Mesh, origin: Mesh | None,
                 setup: _DrawSetup, user: UserProgram | None, lit: bool,
                 constants: tuple[tuple[str, bytes], ...]) -> None:
        self.draw, self.material, self.front_face = draw, material, front_face
        self.mesh = mesh  # the node's mesh drawn last
        self.origin = origin  # a moved mesh's origin: another moved copy of it keeps the step
        self.setup, self.user, self.lit, self.constants = setup, user, lit, constants
        self.culling = (draw.cull_back_faces, front_face)
        # The constants a program held before this draw last time, and the entries it wrote then (a
        # kept plan draws in the same order every frame: the same ones again).
        self.change: tuple[tuple | None, tuple[tuple[str, bytes], ...]] = (None, ())
        # The lights this draw was lit by last, and their uniform bytes.
        self.lights: tuple[tuple[Light, ...] | None, bytes, bytes] = (None, b"", b"")


class Executor:
    """Runs plans on one context, keeping programs and meshes between frames."""

    #: Uploaded meshes kept between frames. A lesson that makes a new mesh
    #: every frame (transform_order's trail) would otherwise fill GPU memory
    #: in a long-running window: past this many, the least recently drawn
    #: are released (never one the current frame draws).
    MESH_LIMIT = 256
    #: Draw set-ups kept (:meth:`_draw_setup`), all dropped at once past this many (a lesson
    #: making a new mesh every frame).
    SETUPS_KEPT = 1024

    def __init__(self, host: GLHost) -> None:
        self.host = host
        self.ctx = host.ctx
        self.raw = host.raw  # the GL calls moderngl lacks (stencil, write masks, clip control)
        self._programs: dict[str, tuple[ProgramVariant, moderngl.Program]] = {}
        # Nodes' own shaders: what each program read and declares, and the nodes drawn with it lately
        # (by name), so that a reload checks the new program against them before replacing the old one.
        self._user: dict[str, UserProgram] = {}
        self._user_nodes: dict[str, dict[str, Node]] = {}
        self._overrides: Mapping[str, object] = {}  # the frame's --set u.NAME values
        self._member_names: dict[str, frozenset[str]] = {}
        self._meshes: dict[tuple[str, str], _GpuMesh] = {}
        self._mesh_last_frame: dict[tuple[str, str], int] = {}
        self._frame = 0
        self._vaos: dict[tuple[tuple[str, str], str], moderngl.VertexArray] = {}
        # What a draw of one mesh with one program needs, found once (see _draw_setup), by
        # (program key, id of the mesh); emptied whenever a VAO or a program is released.
        self._setups: dict[tuple[str, int], _DrawSetup] = {}
        # The prepared draws of the plans drawn lately (see _DrawStep), by (id of the Draw, front
        # face); emptied with the set-ups whenever a VAO or a program is released.
        self._steps: dict[tuple[int, str], _DrawStep] = _Steps()
        # Pass cameras by the camera, the viewport's pixels and the depth mode (see _viewport_camera).
        self._cameras: dict[tuple[int, tuple[int, int, int, int], str], tuple[object, PassCamera]] = {}
        # What the frames of each plan drawn lately share (see _prepare_frame), by id of the plan.
        self._prepared_frames: dict[int, _PreparedFrame] = {}
        self._overlays: OverlayDrawer | None = None  # made on the first overlay pass
        self._textures = TextureCache(host)
        self._lights: tuple[Light, ...] = ()  # the lights of the frame being drawn (draw_node's default)
        # u_light_pos and u_light_color bytes by id of the lights tuple (the tuple kept to check): see _light_bytes.
        self._lights_cache: dict[int, tuple[tuple[Light, ...], bytes, bytes]] = {}
        # The uniform bytes last written into each program (by program key): see _uniform_writer.
        self._written: dict[str, _Written] = {}
        self._culling: tuple[bool, str] | None = None  # what _set_culling set last (None: not known)
        self._bound_texture: object | None = None  # the material texture on unit 0 in this frame
        self._clear_depth = 1.0  # 0 with reverse-Z (glsandbox.gl.depth)
        self._pass_rect: tuple[int, int, int, int] | None = None  # the pass's viewport in pixels (see render)
        self.shadow_maps = gl_shadowmap.ShadowMaps(self.ctx)  # the lights' depth textures

    # --- resources ----------------------------------------------------------

    def program(self, variant: ProgramVariant) -> moderngl.Program:
        entry = self._programs.get(variant.key)
        if entry is None:
            program, user = self._compile(variant)
            entry = (variant, program)
            self._programs[variant.key] = entry
            if user is not None:
                self._user[variant.key] = user
        return entry[1]

    def _compile(self, variant: ProgramVariant) -> tuple[moderngl.Program, UserProgram | None]:
        program, sources = compile_with_sources(self.ctx, variant)
        if not variant.user:
            return program, None
        return program, UserProgram(Path(variant.shader), source_files(sources), declared_uniforms(sources))

    def reload_shaders(self) -> None:
        """Recompile every program from disk. All or nothing: if one fails, or a
        node's own shader no longer fits the nodes drawn with it lately (a uniform
        or attribute), the old programs stay and the :class:`SandboxError` propagates."""
        fresh: dict[str, tuple[ProgramVariant, moderngl.Program]] = {}
        users: dict[str, UserProgram] = {}
        try:
            for key, (variant, _) in self._programs.items():
                program, user = self._compile(variant)
                fresh[key] = (variant, program)
                if user is not None:
                    users[key] = user
                    for node in self._user_nodes.get(key, {}).values():
                        self._check_user_draw(user, program, frozenset(program), node)
        except SandboxError:
            for _, program in fresh.values():
                program.release()
            raise
        for _, old in self._programs.values():
            old.release()
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        self._setups.clear()
        self._steps.clear()
        self._programs = fresh
        self._prepared_frames.clear()
        self._user = users
        self._member_names.clear()
        self._written.clear()  # new programs hold no values yet

    def shader_files(self) -> frozenset[Path]:
        """The files the nodes' own shader programs were built from (with their includes)."""
        return frozenset(path for user in self._user.values() for path in user.files)

    def _check_user_draw(self, user: UserProgram, program: moderngl.Program, members: Collection[str],
                       node: Node) -> dict[str, object]:
        """The values to write into a node's own shader program, each checked against the program.

        Also checks the attributes against the node's mesh. The node's ``uniforms``
        must be declared by the shader (a typo is an error); one declared but
        unused has no uniform in the program, and is skipped as GL would. A
        ``--set u.NAME`` value applies where the shader declares NAME.
        """
        for name in members:
            member = program[name]
            if not isinstance(member, moderngl.Attribute):
                continue
            if name not in _ATTRIBUTE_GLSL:
                raise SandboxError(f"{user.path}: attribute {name} is none the renderer gives "
                                   f"({', '.join(_ATTRIBUTE_GLSL)})")
            glsl = _ATTRIBUTE_GLSL[name]
            # GL converts the buffer's floats to any float vector (missing y, z are 0, w is 1:
            # 'in vec4 in_position' works); integer or matrix attributes it cannot feed.
            if member.gl_type not in _FLOAT_VECTORS:
                raise SandboxError(f"{user.path}: attribute {name} must be a float vector: 'in {glsl} {name}'")
            array = {"in_uv": "uvs", "in_color": "colors"}.get(name)
            if array and getattr(node.mesh, array) is None:
                what = "texture coordinates (uvs)" if array == "uvs" else "vertex colours"
                raise SandboxError(f"{user.path}: in {glsl} {name} needs {what}, which node {node.name!r}'s "
                                   f"mesh {node.mesh.name!r} does not have")
        values = {}
        for name, value in node.uniforms.items():
            if name not in user.declared:
                raise SandboxError(f"{user.path}: node {node.name!r} sets uniform {name}, which the shader does not "
                                   f"declare (it declares: {', '.join(sorted(user.declared)) or 'none'})")
            if name in members:
                values[name] = user_uniform_value(user, program[name], name, value, f"node {node.name!r}")
        for name, value in self._overrides.items():
            if name in members and name in user.declared:
                values[name] = user_uniform_value(user, program[name], name, value, f"--set u.{name}")
        return values

    def _gpu_mesh(self, mesh: Mesh) -> tuple[tuple[str, str], _GpuMesh]:
        origin = mesh_origin(mesh)
        if origin is not None:
            return self._moved_gpu_mesh(mesh, origin)
        arrays = None if mesh in _MESH_KEYS else _gpu_arrays(mesh)  # made once for the digest and the upload
        key = _mesh_key(mesh, arrays)
        gpu = self._meshes.get(key)
        if gpu is None:
            gpu = self._meshes[key] = self._upload(mesh, arrays or _gpu_arrays(mesh))
        self._mesh_last_frame[key] = self._frame
        return key, gpu

    def _upload(self, mesh: Mesh, arrays: dict[str, np.ndarray], moving: bool = False) -> _GpuMesh:
        """GPU buffers of ``arrays`` (:func:`_gpu_arrays` of ``mesh``); ``moving``: the positions
        are rewritten each frame (a dynamic buffer, and the mesh's positions remembered)."""
        index_array = arrays.pop("indices", None)
        buffers = {attr: self.ctx.buffer(array, dynamic=moving and attr == "in_position")
                   for attr, array in arrays.items()}
        index = None if index_array is None else self.ctx.buffer(index_array)
        return _GpuMesh(buffers, index, _MODES[mesh.mode], mesh.element_count, mesh.positions if moving else None)

    def _moved_gpu_mesh(self, mesh: Mesh, origin: Mesh) -> tuple[tuple[str, str], _GpuMesh]:
        """A moved mesh (:func:`glsandbox.scene.moved_mesh`): the buffers of the mesh it was moved
        from, its own, with ``mesh``'s positions written into the position buffer where they
        are not the ones it holds (once per frame however many passes draw it)."""
        key = _moved_key(origin)
        gpu = self._meshes.get(key)
        if gpu is None:
            gpu = self._meshes[key] = self._upload(mesh, _gpu_arrays(mesh), moving=True)
        elif gpu.positions is not mesh.positions:
            gpu.buffers["in_position"].write(np.ascontiguousarray(mesh.positions, dtype="f4"))
            gpu.positions = mesh.positions
        self._mesh_last_frame[key] = self._frame
        return key, gpu

    @property
    def mesh_count(self) -> int:
        """How many meshes are uploaded now."""
        return len(self._meshes)

    def _release_stale_meshes(self) -> None:
        """Keep at most :attr:`MESH_LIMIT` meshes, dropping the least recently drawn."""
        excess = len(self._meshes) - self.MESH_LIMIT
        if excess <= 0:
            return
        stale = sorted((frame, key) for key, frame in self._mesh_last_frame.items() if frame < self._frame)
        for _, key in stale[:excess]:
            gpu = self._meshes.pop(key)
            del self._mesh_last_frame[key]
            for vao_key in [k for k in self._vaos if k[0] == key]:
                self._vaos.pop(vao_key).release()
            self._setups.clear()
            self._steps.clear()
            for buffer in gpu.buffers.values():
                buffer.release()
            if gpu.index is not None:
                gpu.index.release()

    def _vao(self, mesh: Mesh, program_key: str) -> tuple[moderngl.VertexArray, _GpuMesh]:
        key, gpu = self._gpu_mesh(mesh)
        vao = self._vaos.get((key, program_key))
        if vao is None:
            program = self._programs[program_key][1]
            content = []
            for _, attr, width in _ATTRIBUTES:
                if attr in program:
                    if attr not in gpu.buffers:
                        raise SandboxError(f"mesh {mesh.name!r} has no {attr[3:]} data, which {program_key} needs")
                    content.append((gpu.buffers[attr], f"{width}f", attr))
            vao = self.ctx.vertex_array(program, content, index_buffer=gpu.index)
            self._vaos[(key, program_key)] = vao
        return vao, gpu

    # --- frames -------------------------------------------------------------

    def render(self, scene: Scene, framebuffer: moderngl.Framebuffer, size: tuple[int, int],
               frame_plan: Plan | None = None,
               moved: tuple[Mapping[str, np.ndarray], tuple[Light, ...]] | None = None) -> Plan:
        """Draw one frame of ``scene`` into ``framebuffer`` (``size`` pixels).

        ``moved``: (model matrices by node name, lights), checked (:func:`glsandbox.scene.motion_parts`):
        the frame of ``scene`` moved there, drawn without the moved scene being made (a headless
        frame moved only by time, :meth:`glsandbox.frame.FrameRenderer.render_motion`; ``frame_plan``
        is then the moved scene's). Only a plan whose passes all draw at :class:`FrameState`'s
        models and lights takes it (:data:`MOVED_PASSES`)."""
        frame_plan = frame_plan or make_plan(scene)
        prepared = self._prepared_frames.get(id(frame_plan))
        if (prepared is None or prepared.plan is not frame_plan or prepared.viewports is not scene.viewports
                or prepared.size != size or prepared.overrides is not scene.uniform_overrides
                or prepared.depth_mode != scene.depth_mode or prepared.programs is not self._programs
                or (moved is not None and prepared.scene is not scene)):
            prepared = self._prepare_frame(scene, frame_plan, size)
        self._frame += 1
        self._overrides = scene.uniform_overrides
        if moved is None:
            frame = FrameState(scene, {node.name: node for node in scene.nodes}, framebuffer, size, _NO_MODELS,
                               scene.lights)
        else:
            if not prepared.moves:
                raise ValueError(f"a moved frame of scene {scene.name!r} has a pass that reads where the scene's "
                                 "nodes are: draw the moved scene (glsandbox.scene.moved_scene)")
            frame = FrameState(scene, prepared.nodes, framebuffer, size, *moved)
        self._lights = frame.lights
        self._clear_depth = prepared.clear_depth
        framebuffer.use()
        self._culling = None  # not known: the first draw sets it
        ctx, raw = self.ctx, self.raw
        if prepared.reverse_z:
            gl_depth.begin_depth_mode(ctx, raw, scene)
        # The state groups of gl.passes.restore_state that a pass left changed. Every pass starts
        # from that state but for the groups it sets wholly itself before drawing (a stencil pass
        # its stencil, a blended pass its blending): only the others are put back before it runs,
        # and after the last pass whatever is left. Culling is the executor's own (_set_culling,
        # per draw); a pass of a kind not listed in _PASS_STATE changes anything: all is put back.
        changed: frozenset[str] = frozenset()
        try:
            for runner, step, viewport, rect, sets, changes in prepared.passes:
                if changed:
                    pending = changed - sets
                    if pending:
                        gl_passes.restore_state(ctx, raw, pending)
                        changed = changed & sets
                camera, self._pass_rect = None, rect
                if viewport is not None:  # a frame pass through a viewport: its rectangle, depth test and camera
                    framebuffer.viewport = rect
                    self._set_depth(step.depth_test)
                    camera = self._viewport_camera(viewport.camera or scene.camera, rect, scene)
                if changes is None:  # a runner of unknown habits: it starts and ends in the default state
                    self._set_culling(False, "ccw")  # (every other group is put back above)
                    runner(self, frame, step, camera)
                    gl_passes.restore_state(ctx, raw)
                    self._culling = _NO_CULLING
                    continue
                runner(self, frame, step, camera)
                if changes:
                    changed = changed | changes
                if step.kind == "overlay" and self._culling is not None:  # OverlayDrawer switches culling off
                    self._culling = (False, self._culling[1])
        except BaseException:
            # Whatever the pass that raised left set is put back, as after any pass.
            gl_passes.restore_state(ctx, raw)
            self._culling = _NO_CULLING
            raise
        finally:
            # Also when a pass raised (a texture file that cannot be read, say): a sampler
            # object left on unit 0 overrides the state of every texture later bound there,
            # and a mipmapped filter makes the gpu ray engine's data textures incomplete
            # (texelFetch then reads zeros) on a context the next user shares.
            if prepared.reverse_z:
                gl_depth.end_depth_mode(ctx, raw, scene)
            if self._bound_texture is not None:
                self._unbind_texture()
            ctx.disable(moderngl.DEPTH_TEST)  # the depth test a pass switched on, also when it raised
        if changed:
            gl_passes.restore_state(ctx, raw, changed)
        if self._culling != _NO_CULLING:
            self._set_culling(False, "ccw")
        framebuffer.viewport = (0, 0, *size)
        if len(self._meshes) > self.MESH_LIMIT:
            self._release_stale_meshes()
        return frame_plan

    def _prepare_frame(self, scene: Scene, frame_plan: Plan, size: tuple[int, int]) -> _PreparedFrame:
        """What every frame of ``frame_plan`` at ``size`` shares, found once: each pass's
        runner, viewport rectangle and state habits, the programs compiled, the scene's checks
        (raster viewports only, ``--set u.NAME`` values some shader declares). Kept while the
        plan, the scene's viewports and overrides, the size and the programs stay the same objects."""
        if any(vp.renderer != "raster" for vp in scene.viewports):
            raise ValueError("the executor draws raster viewports only: trace the others first "
                             "(glsandbox.frame.trace_viewports)")
        for variant in frame_plan.programs:
            self.program(variant)
        users = [self._user[v.key] for v in frame_plan.programs if v.user]
        for name in scene.uniform_overrides if users else ():
            if not any(name in user.declared for user in users):
                raise SandboxError(f"--set u.{name}: no shader of the scene declares uniform {name} "
                                   f"({', '.join(sorted(str(user.path) for user in users))})")
        passes = []
        for step in frame_plan.passes:
            runner = PASS_RUNNERS.get(step.kind)
            if runner is None:
                raise SandboxError(f"pass kind {step.kind!r} has no runner (gl.executor.PASS_RUNNERS)")
            viewport = None
            rect = scene.viewports[step.viewport].pixels(*size) if 0 <= step.viewport < len(scene.viewports) else None
            if step.target == "frame" and step.camera == "viewport":
                viewport = scene.viewports[step.viewport]
            habits = _PASS_STATE.get(step.kind)
            sets, changes = habits(step) if habits is not None else (frozenset(), None)
            passes.append((runner, step, viewport, rect, sets, changes))
        prepared = _PreparedFrame(frame_plan, scene.viewports, size, scene.uniform_overrides, self._programs,
                                  scene.depth_mode, gl_depth.clear_depth_value(scene), scene.depth_mode == "reverse_z",
                                  tuple(passes), scene, {node.name: node for node in scene.nodes},
                                  all(step.kind in MOVED_PASSES for step in frame_plan.passes))
        if len(self._prepared_frames) >= 16:  # a live compare draws a few plans by turns; more: start again
            self._prepared_frames.clear()
        self._prepared_frames[id(frame_plan)] = prepared
        return prepared

    @staticmethod
    def pass_camera(view: np.ndarray, proj: np.ndarray) -> PassCamera:
        """A pass's camera from its matrices (for runners that look through their own, a light's)."""
        return PassCamera(view, proj)

    def _viewport_camera(self, camera: Camera, rect: tuple[int, int, int, int], scene: Scene) -> PassCamera:
        """The pass camera of ``camera`` seen in ``rect``. A camera that does not change (a Camera
        is immutable) keeps its matrices and their bytes."""
        key = (id(camera), rect, scene.depth_mode)
        kept = self._cameras.get(key)
        if kept is None or kept[0] is not camera:
            if len(self._cameras) >= 64:
                self._cameras.clear()
            aspect = rect[2] / rect[3] if rect[3] else 1.0
            kept = self._cameras[key] = (camera, PassCamera(camera.view(), gl_depth.projection_for(
                scene, camera.projection(aspect))))
        return kept[1]

    def _clear(self, frame: FrameState, step: Pass, camera: PassCamera | None) -> None:
        framebuffer = frame.framebuffer
        rect = self._pass_rect or frame.scene.viewports[step.viewport].pixels(*frame.size)
        r, g, b, _ = step.clear_color or (0.0, 0.0, 0.0, 0.0)
        # Frames are opaque whatever the clear colour's alpha (glsandbox.gl.target).
        clear_opaque(framebuffer, (r, g, b), self._clear_depth, rect)
        if step.clear_stencil:  # moderngl's clear leaves the stencil alone
            self.raw.clear_stencil(rect)

    def _set_culling(self, cull: bool, front_face: str) -> None:
        """Back-face culling on or off, with the winding rule of front faces, set only where it
        differs from what the executor set last in this frame (GL keeps it; draws mostly share it),
        each part (on or off, the front face) only where it differs. Only the executor changes
        culling within a frame (the overlay pass switches it off; :meth:`render` notes that)."""
        state = (cull, front_face)
        known = self._culling
        if state == known:
            return
        if known is None or known[0] != cull:
            if cull:
                self.ctx.enable(moderngl.CULL_FACE)
                self.ctx.cull_face = "back"
            else:
                self.ctx.disable(moderngl.CULL_FACE)
        if known is None or known[1] != front_face:
            self.ctx.front_face = front_face
        self._culling = state

    def _set_depth(self, on: bool) -> None:
        if on:
            self.ctx.enable(moderngl.DEPTH_TEST)
        else:
            self.ctx.disable(moderngl.DEPTH_TEST)

    def _members(self, program_key: str) -> frozenset[str]:
        """A program's uniform and attribute names. moderngl's Program has no
        ``__contains__``, so ``name in program`` walks all its members each
        time; the set is built once per program."""
        names = self._member_names.get(program_key)
        if names is None:
            names = self._member_names[program_key] = frozenset(self._programs[program_key][1])
        return names

    def _uniforms(self, program_key: str) -> _Uniforms:
        """A program's uniforms by name (its other members are attributes)."""
        program = self._programs[program_key][1]
        return _Uniforms({name: member for name in self._members(program_key)
                          if isinstance(member := program[name], moderngl.Uniform)})

    def draw_node(self, node: Node, draw: Draw, camera: PassCamera, *, model: np.ndarray | None = None,
                  front_face: str = "ccw", lights: tuple[Light, ...] | None = None,
                  material: Material | None = None) -> None:
        """Draw one node of the frame being rendered with ``draw``'s program,
        culling as ``draw`` says, seen through ``camera`` (the pass's).

        The planar passes (:mod:`glsandbox.gl.planar`) override what they
        change: ``model`` replaces the node's model matrix, ``front_face`` the
        winding rule of front faces, ``lights`` the frame's lights and
        ``material`` the node's (a mirror's reflection: ``R @ model``,
        ``"cw"``, the reflected lights; a planar shadow: the flattening
        matrix and one flat colour).
        """
        if material is None:
            material = node.material
        key = (id(draw), front_face)
        step = self._steps[key]
        if step is None or step.draw is not draw or step.material is not material:
            step = self._draw_step(key, node, draw, material, front_face)
        elif step.mesh is not node.mesh:
            mesh = node.mesh
            if step.origin is not None and mesh_origin(mesh) is step.origin:
                self._moved_gpu_mesh(mesh, step.origin)  # this frame's positions into its buffer
                step.mesh = mesh
            else:
                step = self._draw_step(key, node, draw, material, front_face)
        setup = step.setup
        own: dict[str, object] = {}
        if step.user is not None:  # a node's own shader: checked before anything is drawn with it
            own = self._check_user_draw(step.user, setup.program, setup.members, node)
            self._user_nodes.setdefault(draw.program, {})[node.name] = node
        self._mesh_last_frame[setup.mesh_key] = self._frame
        if step.culling != self._culling:
            self._set_culling(draw.cull_back_faces, front_face)
        # What this draw writes, each only where its bytes differ from the program's last
        # (a program keeps its uniform values between draws and frames): the matrices, then
        # (lit) the eye and the lights, then the material's constants. A uniform the compiler
        # removed (a term switched off) is remembered as written and writes nothing (_Uniforms).
        written, uniforms = setup.written, setup.uniforms
        matrix = node.model if model is None else model
        if type(matrix) is not np.ndarray or matrix.dtype != _FLOAT64:
            matrix = np.asarray(matrix, dtype=np.float64)
        content = matrix.tobytes()
        data = _MODEL_BYTES[content]
        if written["m_model"] != data:
            written["m_model"] = data
            uniforms["m_model"].write(data)
        if written[_CAMERA] is not camera:  # (a pass's draws share its camera)
            if camera.view_bytes != written["m_view"]:
                written["m_view"] = camera.view_bytes
                uniforms["m_view"].write(camera.view_bytes)
            if camera.proj_bytes != written["m_proj"]:
                written["m_proj"] = camera.proj_bytes
                uniforms["m_proj"].write(camera.proj_bytes)
            written[_CAMERA] = camera
        if setup.normal:
            data = _NORMAL_BYTES[content]
            if written["m_normal"] != data:
                written["m_normal"] = data
                uniforms["m_normal"].write(data)
        if step.lit:
            if written[_EYE] is not camera:
                data = camera.eye_bytes
                if written["u_eye"] != data:
                    written["u_eye"] = data
                    uniforms["u_eye"].write(data)
                written[_EYE] = camera
            frame_lights = self._lights if lights is None else lights
            if frame_lights:  # with none, the shader's arrays do not exist (NUM_LIGHTS 0)
                if step.lights[0] is not frame_lights:  # (lights that do not move: the same tuple every frame)
                    step.lights = (frame_lights, *self._light_bytes(frame_lights))
                _, light_pos, light_color = step.lights
                if written["u_light_pos"] != light_pos:
                    written["u_light_pos"] = light_pos
                    uniforms["u_light_pos"].write(light_pos)
                if written["u_light_color"] != light_color:
                    written["u_light_color"] = light_color
                    uniforms["u_light_color"].write(light_color)
        constants = step.constants
        last = written[_CONSTANTS]
        if last is not constants:  # another material's were written since: only the bytes that differ
            change = step.change
            if change[0] is not last or last is None:
                change = (last, _constants_change(written, last, constants))
                step.change = change
            for name, data in change[1]:
                written[name] = data
                uniforms[name].write(data)
            written[_CONSTANTS] = constants
        if own:
            program = setup.program
            for name, value in own.items():
                program[name].value = value
            written.pop(_CONSTANTS, None)  # a node's own values may have replaced a constant
        texture = material.texture
        if texture is not None and self._bound_texture is not texture:  # unit 0; consecutive draws bind once
            self._textures.bind(texture, 0)
            self._bound_texture = texture
        if draw.shadow_map is not None:  # unit 1: the light's shadow map (a depth texture, compared)
            for name, data in self.shadow_maps.use(draw.shadow_map, SHADOW_MAP_UNIT):
                setup.write(name, data)
        vao, gpu = setup.vao, setup.gpu
        if draw.blend:  # over what is drawn already; hidden by it where nearer, but not hiding
            self.ctx.enable(moderngl.BLEND)
            self.ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
            self.raw.glDepthMask(0)
        vao.render(gpu.mode, vertices=gpu.count)
        if draw.blend:
            self.raw.glDepthMask(1)
            self.ctx.disable(moderngl.BLEND)
            self.ctx.blend_func = moderngl.DEFAULT_BLENDING

    def _draw_step(self, key: tuple[int, str], node: Node, draw: Draw, material: Material,
                   front_face: str) -> _DrawStep:
        """Prepare ``draw`` of ``node`` with ``material`` and ``front_face`` (see :class:`_DrawStep`)
        and keep it under ``key`` until the set-ups are dropped (a program reloaded, a mesh released)."""
        user = self._user.get(draw.program)
        if user is not None:  # a node's own shader: checked before anything is made or drawn with it
            self._check_user_draw(user, self._programs[draw.program][1], self._members(draw.program), node)
        mesh = node.mesh
        setup = self._draw_setup(draw.program, mesh)
        lit = material.lit or user is not None  # a node's own shader may light itself whatever the shading
        origin = setup.source if setup.source is not mesh else None  # a moved mesh's set-up is its origin's
        if len(self._steps) >= self.SETUPS_KEPT:  # new draws every frame (plans not kept): start again
            self._steps.clear()
        step = self._steps[key] = _DrawStep(draw, material, front_face, mesh, origin, setup, user, lit,
                                            self._material_constants(material, lit))
        return step

    def _draw_setup(self, program_key: str, mesh: Mesh) -> _DrawSetup:
        """What every draw of ``mesh`` with the program ``program_key`` needs, found once: the
        program, its member names, its uniform writer, the mesh as drawn (face normals for a
        lit program and a mesh without normals: what the ray tracer does with such a mesh,
        :func:`~glsandbox.geometry.with_face_normals`), its buffers and VAO."""
        setup = self._setups.get((program_key, id(mesh)))
        if setup is not None and setup.source is mesh:
            return setup
        program = self._programs[program_key][1]
        members = self._members(program_key)
        drawn = with_face_normals(mesh) if mesh.normals is None and "in_normal" in members else mesh
        origin = mesh_origin(mesh)
        if origin is not None and drawn is mesh:  # (face normals made for a moved mesh: a mesh of its own)
            # A moved mesh: the setup of the mesh it was moved from, this frame's positions in its buffer.
            moved_key = (program_key + "#moved", id(origin))  # apart from a setup of ``origin`` itself
            setup = self._setups.get(moved_key)
            if setup is not None and setup.source is origin:
                self._moved_gpu_mesh(mesh, origin)
                return setup
            vao, gpu = self._vao(mesh, program_key)
            setup = _DrawSetup(origin, program, members, self._uniform_writer(program_key, program, members),
                               _moved_key(origin), vao, gpu, "m_normal" in members,
                               self._uniforms(program_key), self._written.setdefault(program_key, _Written()))
            self._setups[moved_key] = setup
            return setup
        vao, gpu = self._vao(drawn, program_key)
        if len(self._setups) >= self.SETUPS_KEPT:  # new meshes every frame (a trail): start again
            self._setups.clear()
        setup = _DrawSetup(mesh, program, members, self._uniform_writer(program_key, program, members), _mesh_key(drawn), vao, gpu,
                           "m_normal" in members, self._uniforms(program_key), self._written.setdefault(program_key, _Written()))
        self._setups[(program_key, id(mesh))] = setup
        return setup

    @staticmethod
    def _material_constants(material: Material, lit: bool) -> tuple[tuple[str, bytes], ...]:
        """The uniform bytes a draw of ``material`` writes that no position changes: its colour,
        (lit) the coefficients of the course's formula, the alpha cutoff, the texture's unit."""
        constants = [("u_color", _color_bytes(material.color))]
        if lit:
            constants += _material_bytes(material)
        constants.append(("u_alpha_cutoff", _float_bytes(material.alpha_cutoff)))
        if material.texture is not None:
            constants.append(("u_texture", _UNIT_0))
        return tuple(constants)

    @staticmethod
    def _model_bytes(model: np.ndarray, normal: bool) -> tuple[bytes, bytes | None]:
        """``m_model``'s uniform bytes and, with ``normal``, ``m_normal``'s (the inverse transpose,
        :func:`~glsandbox.transforms.normal_matrix`), looked up by the matrix's content: a node
        that does not move converts its matrix once, not every frame, and an array changed in
        place between frames is converted again (no stale matrix)."""
        matrix = np.asarray(model, dtype=np.float64)
        content = matrix.tobytes()
        return _MODEL_BYTES[content], _NORMAL_BYTES[content] if normal else None

    def _uniform_writer(self, program_key: str, program: moderngl.Program,
                        members: Collection[str]) -> Callable[[str, bytes], None]:
        """``write(name, data)`` for one program: the bytes go to GL only where the program has the
        uniform (a term the compiler removed has none) and they differ from what was written last.
        A program keeps its uniform values between draws and frames, so what does not change (the
        view while the camera stands, lights, materials, a wall's model) is written once."""
        written = self._written.setdefault(program_key, _Written())
        uniforms: dict[str, moderngl.Uniform] = {}

        def write(name: str, data: bytes) -> None:
            if written.get(name) != data and name in members:
                uniform = uniforms.get(name)
                if uniform is None:
                    uniform = uniforms[name] = program[name]
                uniform.write(data)
                written[name] = data

        return write

    def _light_bytes(self, lights: tuple[Light, ...]) -> tuple[bytes, bytes]:
        """``u_light_pos`` and ``u_light_color`` bytes of ``lights``, made once per lights tuple: every
        lit draw of a frame writes the same ones, and lights that do not move (the scene's, and
        the mirror's reflected ones) keep them from frame to frame."""
        cached = self._lights_cache.get(id(lights))
        if cached is None or cached[0] is not lights:
            if len(self._lights_cache) >= 8:  # lights that move make a tuple a frame
                self._lights_cache.clear()
            cached = self._lights_cache[id(lights)] = (
                lights, np.array([l.position for l in lights], dtype="f4").tobytes(),
                np.array([l.color for l in lights], dtype="f4").tobytes())
        return cached[1], cached[2]

    def _unbind_texture(self) -> None:
        """Leave texture unit 0 without the frame's sampler object (the overlays and the next user
        of the context see plain texture state); once per frame, not per draw."""
        if self._bound_texture is not None:
            self._textures.unbind(0)
            self._bound_texture = None

    def _traced_before(self, frame: FrameState, step: Pass, camera: PassCamera | None) -> None:
        """A ``trace`` pass is run before the executor, by :func:`glsandbox.frame.trace_viewports`
        (its picture is an overlay by then); :meth:`render` refuses a scene that still has one."""
        raise ValueError(f"trace viewport {step.viewport}: trace it first (glsandbox.frame.trace_viewports)")

    def _draw(self, frame: FrameState, step: Pass, camera: PassCamera | None) -> None:
        """A ``draw`` pass: each node with its program, through the viewport's camera."""
        assert camera is not None
        nodes, models = frame.nodes, frame.models
        for draw in step.draws:
            self.draw_node(nodes[draw.node], draw, camera, model=models.get(draw.node))

    def _draw_overlays(self, frame: FrameState, step: Pass, camera: PassCamera | None) -> None:
        """An ``overlay`` pass: labels and figures, blended over the frame (:mod:`glsandbox.gl.overlay`)."""
        self._unbind_texture()
        if self._overlays is None:
            self._overlays = OverlayDrawer(self.ctx)
        self._overlays.draw(frame.scene, step, frame.framebuffer, frame.size,
                            self._programs[step.draws[0].program][1])

    def release(self) -> None:
        if self._overlays is not None:
            self._overlays.release()
            self._overlays = None
        for vao in self._vaos.values():
            vao.release()
        for gpu in self._meshes.values():
            for buf in gpu.buffers.values():
                buf.release()
            if gpu.index is not None:
                gpu.index.release()
        for _, program in self._programs.values():
            program.release()
        self._textures.release()
        self.shadow_maps.release()
        self._vaos.clear()
        self._setups.clear()
        self._steps.clear()
        self._cameras.clear()
        self._prepared_frames.clear()
        self._meshes.clear()
        self._mesh_last_frame.clear()
        self._programs.clear()
        self._member_names.clear()
        self._written.clear()
        self._user.clear()
        self._user_nodes.clear()


# --- lighting uniforms (course section "Lighting") --------------------------


def eye_position(view: np.ndarray) -> np.ndarray:
    """The camera position in world space: the view matrix maps it to the
    origin, so it is the translation column of the inverse view matrix (the
    course's ``vEyePos``)."""
    return np.linalg.inv(np.asarray(view, dtype=np.float64))[:3, 3]


_NO_SETS: frozenset[str] = frozenset()


def _stencil_set(step: Pass) -> frozenset[str]:
    """A planar pass with a stencil state sets all of the stencil group (gl.planar.set_stencil)."""
    return frozenset({"stencil"}) if step.stencil is not None else _NO_SETS


#: How each pass kind treats the state groups of :func:`glsandbox.gl.passes.restore_state`
#: (culling aside: the executor sets it per draw, :meth:`Executor._set_culling`), from its pass:
#: (the groups it sets wholly itself before it draws, so what the pass before left there need
#: not be put back first; the groups it leaves changed). A clear sets nothing; a draw pass
#: changes nothing (its blended draws put blending and depth writes back); an overlay pass puts
#: blending and the scissor back itself; a shadow-map pass binds the frame's framebuffer again,
#: which sets its write masks. The planar passes (:mod:`glsandbox.gl.planar`): marking the mirror
#: sets the stencil and both write masks, the reflection the stencil (with one), the glass its
#: blending, the shadow the stencil (with one) and its blending, and leaves depth writes off
#: and the polygon offset set. A kind not listed here is put back wholly before and after it.
_PASS_STATE: dict[str, Callable[[Pass], tuple[frozenset[str], frozenset[str]]]] = {
    "clear": lambda step: (_NO_SETS, _NO_SETS),
    "draw": lambda step: (_NO_SETS, _NO_SETS),
    "overlay": lambda step: (_NO_SETS, _NO_SETS),
    "shadow_map": lambda step: (_NO_SETS, _NO_SETS),
    "mark_mirror": lambda step: (_stencil_set(step) | {"masks"}, frozenset({"stencil", "masks"})),
    "reflection": lambda step: (_stencil_set(step), _stencil_set(step)),
    "mirror_surface": lambda step: (frozenset({"blend"}), frozenset({"blend"})),
    "planar_shadow": lambda step: (_stencil_set(step) | {"blend"}, frozenset({"stencil", "masks", "blend", "offset"})),
}
#: The pass kinds whose runners draw each node at :class:`FrameState`'s ``models`` and light with
#: its ``lights`` (a shadow-map pass fits its light's frustum to the scene's nodes: not one).
MOVED_PASSES = frozenset({"clear", "draw", "overlay", "mark_mirror", "reflection", "mirror_surface",
                          "planar_shadow"})
#: A frame's models where nothing is moved by a motion handed over (see :class:`FrameState`).
_NO_MODELS: Mapping[str, np.ndarray] = MappingProxyType({})
#: What restore_state leaves of culling (off, counter-clockwise fronts).
_NO_CULLING = (False, "ccw")


@dataclass(frozen=True)
class _PreparedFrame:
    """What the frames of one plan share (:meth:`Executor._prepare_frame`): per pass, its runner,
    the pass, its viewport and rectangle (a frame pass through a viewport; else None), and the
    state groups it sets and changes (:data:`_PASS_STATE`)."""

    plan: Plan
    viewports: tuple
    size: tuple[int, int]
    overrides: Mapping[str, object]
    programs: dict
    depth_mode: str
    clear_depth: float
    reverse_z: bool  # the frame's depth mode is begun and ended (glsandbox.gl.depth)
    passes: tuple[tuple[PassRunner, Pass, object, tuple[int, int, int, int] | None, frozenset[str],
                        frozenset[str] | None], ...]
    # The scene it was prepared for and its nodes by name: a moved frame's (see render's ``moved``),
    # whose scene is the one every frame of the plan is moved from.
    scene: Scene
    nodes: dict
    moves: bool  # every pass is of MOVED_PASSES: frames of the plan may be drawn ``moved``


#: One runner per pass kind (:data:`glsandbox.plan.PASS_KINDS`); a new kind adds
#: its entry here and its describer in :data:`glsandbox.plan.PASS_DESCRIBERS`.
#: A runner gets the executor, the frame, the pass, and the pass's camera when it
#: draws into the frame through a viewport's (None otherwise: it sets up its own).
PASS_RUNNERS: dict[str, PassRunner] = {
    "trace": Executor._traced_before,
    "shadow_map": gl_shadowmap.run_shadow_map_pass,
    "clear": Executor._clear,
    "draw": Executor._draw,
    "mark_mirror": gl_planar.mark_mirror,
    "reflection": gl_planar.reflection,
    "mirror_surface": gl_planar.mirror_surface,
    "planar_shadow": gl_planar.planar_shadow,
    "overlay": Executor._draw_overlays,
}
