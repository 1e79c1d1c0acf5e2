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
from glsandbox.scene import Light, Material, Node, Scene, mesh_origin

try:  # hashlib.blake2b is this very type; importing hashlib loads OpenSSL too (~4 ms of every start, issue 24)
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


@functools.lru_cache(maxsize=1024)
def _model_matrix_bytes(model: bytes) -> bytes:
    """``m_model``'s uniform bytes (float32, column-major) for a float64 model matrix given as bytes."""
    return transforms.gl_bytes(np.frombuffer(model).reshape(4, 4))


@functools.lru_cache(maxsize=1024)
def _normal_matrix_bytes(model: bytes) -> bytes:
    """The normal matrix's uniform bytes for a float64 model matrix given as
    bytes: models that do not move (walls, floors) skip the inverse each frame."""
    return transforms.gl_bytes(transforms.normal_matrix(np.frombuffer(model).reshape(4, 4)))


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
    uniforms: dict[str, moderngl.Uniform] = field(default_factory=dict)
    written: dict[str, bytes] = field(default_factory=dict)
    # Per material drawn with it (by id, the object kept to check): its constant uniform bytes.
    constants: dict[int, tuple[Material, tuple[tuple[str, bytes], ...]]] = field(default_factory=dict)


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
        # Pass cameras by the camera, the viewport's pixels and the depth mode (see _frame_camera).
        self._cameras: dict[tuple[int, tuple[int, int, int, int], str], tuple[object, PassCamera]] = {}
        self._overlays: OverlayDrawer | None = None  # made on the first overlay pass
        self._textures = TextureCache(host)
        self._lights: tuple[Light, ...] = ()  # the lights of the frame being drawn (draw_node's default)
        self._lights_cache: tuple[tuple[Light, ...], bytes, bytes] | None = None
        # The uniform bytes last written into each program (by program key): see _uniform_writer.
        self._written: dict[str, dict[str, bytes]] = {}
        self._culling: tuple[bool, str] | None = None  # what _set_culling set last (None: not known)
        self._bound_texture: object | None = None  # the material texture on unit 0 in this frame
        self._clear_depth = 1.0  # 0 with reverse-Z (glsandbox.gl.depth)
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
        self._programs = fresh
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
               frame_plan: Plan | None = None) -> Plan:
        """Draw one frame of ``scene`` into ``framebuffer`` (``size`` pixels)."""
        if any(vp.renderer != "raster" for vp in scene.viewports):
            raise ValueError("the executor draws raster viewports only: trace the others first "
                             "(glsandbox.frame.trace_viewports)")
        frame_plan = frame_plan or make_plan(scene)
        self._frame += 1
        for variant in frame_plan.programs:
            self.program(variant)
        self._overrides = scene.uniform_overrides
        users = [self._user[v.key] for v in frame_plan.programs if v.user]
        for name in scene.uniform_overrides if users else ():
            if not any(name in user.declared for user in users):
                raise SandboxError(f"--set u.{name}: no shader of the scene declares uniform {name} "
                                   f"({', '.join(sorted(str(user.path) for user in users))})")
        frame = FrameState(scene, {node.name: node for node in scene.nodes}, framebuffer, size)
        self._lights = scene.lights
        self._clear_depth = gl_depth.clear_depth_value(scene)
        framebuffer.use()
        self._culling = None  # not known: the first draw sets it
        gl_depth.begin_depth_mode(self.ctx, self.raw, scene)
        try:
            for step in frame_plan.passes:
                runner = PASS_RUNNERS.get(step.kind)
                if runner is None:
                    raise SandboxError(f"pass kind {step.kind!r} has no runner (gl.executor.PASS_RUNNERS)")
                # Every pass starts from the same state (gl.passes.restore_state), whatever the last
                # one set or raised. A clear pass sets nothing, and a draw pass only culling (blended
                # draws put blending and depth writes back themselves): those put back only that.
                restored = False
                try:
                    runner(self, frame, step, self._frame_camera(frame, step))
                    restored = step.kind in _STATE_KEEPING
                    changed = _PASS_CHANGES.get(step.kind)
                    if changed is not None:  # a planar pass: only what it changes is put back
                        gl_passes.restore_state(self.ctx, self.raw, changed)
                        restored = True
                finally:
                    if restored:
                        self._set_culling(False, "ccw")
                    else:
                        gl_passes.restore_state(self.ctx, self.raw)
                        self._culling = (False, "ccw")  # what restore_state leaves
        finally:
            # Also when a pass raised (a texture file that cannot be read, say): a sampler
            # object left on unit 0 overrides the state of every texture later bound there,
            # and a mipmapped filter makes the gpu ray engine's data textures incomplete
            # (texelFetch then reads zeros) on a context the next user shares.
            gl_depth.end_depth_mode(self.ctx, self.raw, scene)
            self._unbind_texture()
            self._set_depth(False)  # the depth test a pass switched on, also when it raised
        framebuffer.viewport = (0, 0, *size)
        self.ctx.disable(moderngl.CULL_FACE)
        self._release_stale_meshes()
        return frame_plan

    @staticmethod
    def pass_camera(view: np.ndarray, proj: np.ndarray) -> PassCamera:
        """A pass's camera from its matrices (for runners that look through their own, a light's)."""
        return PassCamera(view, proj)

    def _frame_camera(self, frame: FrameState, step: Pass) -> PassCamera | None:
        """A frame pass with ``camera="viewport"``: its viewport set, its depth test
        switched, and its camera (the viewport's or the scene's). Other passes set
        their own target up (:data:`PASS_RUNNERS`)."""
        if step.target != "frame" or step.camera != "viewport":
            return None
        scene = frame.scene
        viewport = scene.viewports[step.viewport]
        rect = viewport.pixels(*frame.size)
        camera = viewport.camera or scene.camera
        aspect = rect[2] / rect[3] if rect[3] else 1.0
        frame.framebuffer.viewport = rect
        self._set_depth(step.depth_test)
        # A camera that does not change (a Camera is immutable) keeps its matrices and their bytes.
        key = (id(camera), rect, scene.depth_mode)
        kept = self._cameras.get(key)
        if kept is None or kept[0] is not camera:
            if len(self._cameras) >= 64:
                self._cameras.clear()
            kept = self._cameras[key] = (camera, PassCamera(camera.view(), gl_depth.projection_for(
                scene, camera.projection(aspect))))
        return kept[1]

    def _clear(self, frame: FrameState, step: Pass, camera: PassCamera | None) -> None:
        framebuffer = frame.framebuffer
        rect = frame.scene.viewports[step.viewport].pixels(*frame.size)
        r, g, b, _ = step.clear_color or (0.0, 0.0, 0.0, 0.0)
        # Frames are opaque whatever the clear colour's alpha (glsandbox.gl.target).
        clear_opaque(framebuffer, (r, g, b), self._clear_depth, rect)
        if step.clear_stencil:  # moderngl's clear leaves the stencil alone
            self.raw.clear_stencil(rect)

    def _set_culling(self, cull: bool, front_face: str) -> None:
        """Back-face culling on or off, with the winding rule of front faces, set only where it
        differs from what the executor set last in this pass (GL keeps it; draws of one
        pass mostly share it). Only the executor changes culling within a pass."""
        state = (cull, front_face)
        if state == self._culling:
            return
        if cull:
            self.ctx.enable(moderngl.CULL_FACE)
            self.ctx.cull_face = "back"
        else:
            self.ctx.disable(moderngl.CULL_FACE)
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

    def _uniforms(self, program_key: str) -> dict[str, moderngl.Uniform]:
        """A program's uniforms by name (its other members are attributes)."""
        program = self._programs[program_key][1]
        return {name: member for name in self._members(program_key)
                if isinstance(member := program[name], moderngl.Uniform)}

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
        user = self._user.get(draw.program)
        own: dict[str, object] = {}
        if user is not None:  # a node's own shader: checked before anything is made or drawn with it
            own = self._check_user_draw(user, self._programs[draw.program][1], self._members(draw.program), node)
            self._user_nodes.setdefault(draw.program, {})[node.name] = node
        setup = self._draw_setup(draw.program, node.mesh)
        self._mesh_last_frame[setup.mesh_key] = self._frame
        model = node.model if model is None else model
        material = node.material if material is None else material
        if (draw.cull_back_faces, front_face) != self._culling:
            self._set_culling(draw.cull_back_faces, front_face)
        model_bytes, normal_bytes = self._model_bytes(model, setup.normal)
        # What this draw writes: the matrices, then (lit) the eye and the lights, then the
        # material's constants (made once per material and program, _material_constants).
        values = [("m_model", model_bytes), ("m_view", camera.view_bytes), ("m_proj", camera.proj_bytes)]
        if normal_bytes is not None:
            values.append(("m_normal", normal_bytes))
        lit = material.lit or user is not None  # a node's own shader may light itself whatever the shading
        if lit:
            values.append(("u_eye", camera.eye_bytes))
            frame_lights = self._lights if lights is None else lights
            if frame_lights:  # with none, the shader's arrays do not exist (NUM_LIGHTS 0)
                light_pos, light_color = self._light_bytes(frame_lights)
                values += (("u_light_pos", light_pos), ("u_light_color", light_color))
        constants = setup.constants.get(id(material))
        if constants is None or constants[0] is not material:
            if len(setup.constants) >= 64:  # materials made anew each frame (a planar shadow's): start again
                setup.constants.clear()
            constants = setup.constants[id(material)] = (material, self._material_constants(material, lit))
        written, uniforms = setup.written, setup.uniforms
        for name, data in (*values, *constants[1]):
            # A program keeps its uniform values between draws and frames: bytes equal to the
            # last written (the view while the camera stands, lights, materials) are not sent.
            if written.get(name) != data:
                written[name] = data
                uniform = uniforms.get(name)
                if uniform is not None:  # a term the compiler removed has no uniform
                    uniform.write(data)
        if own:
            program = setup.program
            for name, value in own.items():
                program[name].value = value
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
                               self._uniforms(program_key), self._written.setdefault(program_key, {}))
            self._setups[moved_key] = setup
            return setup
        vao, gpu = self._vao(drawn, program_key)
        if len(self._setups) >= self.SETUPS_KEPT:  # new meshes every frame (a trail): start again
            self._setups.clear()
        setup = _DrawSetup(mesh, program, members, self._uniform_writer(program_key, program, members), _mesh_key(drawn), vao, gpu,
                           "m_normal" in members, self._uniforms(program_key), self._written.setdefault(program_key, {}))
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
        content = np.asarray(model, dtype=np.float64).tobytes()
        return _model_matrix_bytes(content), _normal_matrix_bytes(content) if normal else None

    def _uniform_writer(self, program_key: str, program: moderngl.Program,
                        members: Collection[str]) -> Callable[[str, bytes], None]:
        """``write(name, data)`` for one program: the bytes go to GL only where the program has the
        uniform (a term the compiler removed has none) and they differ from what was written last.
        A program keeps its uniform values between draws and frames, so what does not change (the
        view while the camera stands, lights, materials, a wall's model) is written once."""
        written = self._written.setdefault(program_key, {})
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
        """``u_light_pos`` and ``u_light_color`` bytes of ``lights``, made once per frame (and once
        per pass that reflects them): every lit draw of the frame writes the same ones."""
        cached = self._lights_cache
        if cached is None or cached[0] is not lights:
            cached = self._lights_cache = (lights, np.array([l.position for l in lights], dtype="f4").tobytes(),
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
        for draw in step.draws:
            self.draw_node(frame.nodes[draw.node], draw, camera)

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
        self._cameras.clear()
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


#: Pass kinds whose runners leave GL state as :func:`glsandbox.gl.passes.restore_state` sets it,
#: but for culling (:meth:`Executor._set_culling`): a clear, a draw pass (its blended draws
#: put blending and depth writes back) and an overlay pass (:meth:`OverlayDrawer.draw` puts
#: blending and the scissor back, and switches off only the depth test, which every pass
#: sets for itself, and culling, which restore_state leaves off).
_STATE_KEEPING = frozenset({"clear", "draw", "overlay"})
#: The planar passes (:mod:`glsandbox.gl.planar`) and the groups of
#: :func:`~glsandbox.gl.passes.restore_state` each changes (culling besides, through
#: :meth:`Executor._set_culling`): after one, only those are put back.
_PASS_CHANGES = {"mark_mirror": frozenset({"stencil", "masks"}), "reflection": frozenset({"stencil"}),
                 "mirror_surface": frozenset({"blend"}),
                 "planar_shadow": frozenset({"stencil", "masks", "blend", "offset"})}

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
