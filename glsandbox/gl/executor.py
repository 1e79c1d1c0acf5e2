"""The raster executor: runs a Plan on a ModernGL context.

It compiles the plan's program variants once, uploads each mesh once (cached
by name and content), and walks the passes in order. It does what the plan
says and nothing more; choosing passes is :func:`glsandbox.plan.plan`'s job.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping
from pathlib import Path
from types import MappingProxyType

import moderngl
import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.geometry import Mesh, with_face_normals
from glsandbox.gl import depth as gl_depth, passes as gl_passes, shadow_textures
from glsandbox.gl.context import GLHost
from glsandbox.gl.overlay_drawer import OverlayDrawer
from glsandbox.gl.shaders import compile_with_sources, declared_uniforms, source_files
from glsandbox.gl.textures import TextureCache
from glsandbox.gl.passes import FrameState
from glsandbox.gl.gpu_meshes import GpuMeshes, _mesh_key, _moved_key
from glsandbox.gl.uniform_bytes import _CONSTANTS, PassCamera, material_constants, _Uniforms, _Written
from glsandbox.gl.uniform_writes import LightBytes, uniform_writer, write_constants, write_lighting, write_matrices
from glsandbox.gl.draw_steps import _DrawSetup, _DrawStep, _PreparedFrame, _Steps
from glsandbox.gl.prepared_frame import prepare_draw_pass
from glsandbox.gl.user_shaders import UserProgram, check_user_draw
from glsandbox.passes.plan_parts import SHADOW_MAP_UNIT, Draw, Pass, ProgramVariant
from glsandbox.plan import Plan, plan as make_plan
from glsandbox.scene import Camera, Light, Material, Node, Scene, mesh_origin


class Executor(GpuMeshes):
    """Runs plans on one context, keeping programs and meshes between frames."""

    #: Draw set-ups kept (:meth:`_draw_setup`), all dropped at once past this many (a lesson
    #: making a new mesh every frame).
    SETUPS_KEPT = 1024

    def __init__(self, host: GLHost, primitive_ids: bool = False) -> None:
        self.host = host
        self.ctx = host.ctx
        #: The X-ray's primitive-id target (shaders/common/primitive_id.glsl): the built-in programs
        #: compiled with PRIMITIVE_ID, each draw telling them its node's number (``node_ids``).
        self.primitive_ids = primitive_ids
        self.node_ids: dict[str, int] = {}
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
        self._light_bytes = LightBytes()  # u_light_pos and u_light_color bytes, kept while the lights stay
        # The uniform bytes last written into each program (by program key): see uniform_writer.
        self._written: dict[str, _Written] = {}
        self._culling: tuple[bool, str] | None = None  # what _set_culling set last (None: not known)
        self._bound_texture: object | None = None  # the material texture on unit 0 in this frame
        self.clear_depth = 1.0  # 0 with reverse-Z (glsandbox.gl.depth)
        self.pass_rect: tuple[int, int, int, int] | None = None  # the pass's viewport in pixels (see render)
        self.shadow_maps = shadow_textures.ShadowMaps(self.ctx, self.raw)  # the lights' depth textures

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
        if self.primitive_ids and not variant.user:
            variant = ProgramVariant(variant.shader, (*variant.defines, ("PRIMITIVE_ID", "")))
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
                        check_user_draw(self._overrides, user, program, frozenset(program), node)
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

    def hand_over_programs(self) -> dict[str, tuple[ProgramVariant, moderngl.Program]]:
        """Take the built-in programs out of this executor (its :meth:`release` then leaves them),
        for a fresh executor on the same context to :meth:`adopt`. A built-in program is a pure
        function of glsandbox's own shader files and its defines, named by its key, so it holds
        nothing of the scenes drawn with it but uniform values, which a fresh executor writes
        again (it has no record of them); a node's own program stays here, to be released."""
        kept = {key: entry for key, entry in self._programs.items() if not entry[0].user}
        for key in kept:
            del self._programs[key]
        return kept

    def adopt(self, programs: dict[str, tuple[ProgramVariant, moderngl.Program]]) -> None:
        """Use ``programs`` (another executor's :meth:`hand_over_programs`, on this context) as compiled here."""
        self._programs.update(programs)

    def shader_files(self) -> frozenset[Path]:
        """The files the nodes' own shader programs were built from (with their includes)."""
        return frozenset(path for user in self._user.values() for path in user.files)

    # --- frames -------------------------------------------------------------

    def render(self, scene: Scene, framebuffer: moderngl.Framebuffer, size: tuple[int, int],
               frame_plan: Plan | None = None,
               moved: tuple[Mapping[str, np.ndarray], tuple[Light, ...]] | None = None,
               after_pass: Callable[[int, Pass], None] | None = None) -> Plan:
        """Draw one frame of ``scene`` into ``framebuffer`` (``size`` pixels).

        ``after_pass(index, step)`` is called after each pass has drawn (the X-ray of
        :mod:`glsandbox.story.xray` reads the target back there); it must leave GL as it found it.

        ``moved``: (model matrices by node name, lights), checked (:func:`glsandbox.scene.motion_parts`):
        the frame of ``scene`` moved there, drawn without the moved scene being made (a headless
        frame moved only by time, :meth:`glsandbox.frame.FrameRenderer.render_motion`; ``frame_plan``
        is then the moved scene's). Only a plan whose passes all draw at :class:`FrameState`'s
        models and lights takes it (:attr:`glsandbox.gl.passes.Runner.moved`)."""
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
        if self.primitive_ids:
            self.node_ids = {node.name: i + 1 for i, node in enumerate(scene.nodes)}
        self.clear_depth = prepared.clear_depth
        framebuffer.use()
        self._culling = None  # not known: the first draw sets it
        ctx, raw = self.ctx, self.raw
        if prepared.reverse_z:
            gl_depth.begin_depth_mode(ctx, raw, scene)
        # The state groups of gl.passes.restore_state that a pass left changed. Every pass starts
        # from that state but for the groups it sets wholly itself before drawing (a stencil pass
        # its stencil, a blended pass its blending): only the others are put back before it runs,
        # and after the last pass whatever is left. Culling is the executor's own (_set_culling,
        # per draw); a pass of unknown habits (gl.passes.unknown_habits) may change any: all is put back.
        changed: frozenset[str] = frozenset()
        try:
            for index, (runner, step, viewport, rect, sets, changes) in enumerate(prepared.passes):
                if changed:
                    pending = changed - sets
                    if pending:
                        gl_passes.restore_state(ctx, raw, pending)
                        changed = changed & sets
                camera, self.pass_rect = None, rect
                if viewport is not None:  # a frame pass through a viewport: its rectangle, depth test and camera
                    framebuffer.viewport = rect
                    self._set_depth(step.depth_test)
                    camera = self._viewport_camera(viewport.camera or scene.camera, rect, scene)
                if changes is None:  # a runner of unknown habits: it starts and ends in the default state
                    self._set_culling(False, "ccw")  # (every other group is put back above)
                    runner(self, frame, step, camera)
                    gl_passes.restore_state(ctx, raw)
                    self._culling = _NO_CULLING
                    if after_pass is not None:
                        after_pass(index, step)
                    continue
                runner(self, frame, step, camera)
                if changes:
                    changed = changed | changes
                if after_pass is not None:
                    after_pass(index, step)
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
                self.unbind_texture()
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
        nodes = {node.name: node for node in scene.nodes}
        moves = gl_passes.all_moved(frame_plan.passes)
        passes = []
        for step in frame_plan.passes:
            runner = gl_passes.runner(step.kind)
            viewport = None
            rect = scene.viewports[step.viewport].pixels(*size) if 0 <= step.viewport < len(scene.viewports) else None
            if step.target == "frame" and step.camera == "viewport":
                viewport = scene.viewports[step.viewport]
            sets, changes = runner.state(step)
            run = runner.run
            if moves and step.kind == "draw":  # frames moved only by time: its draws found once
                run = prepare_draw_pass(self, step, nodes, runner.run) or run
            passes.append((run, step, viewport, rect, sets, changes))
        prepared = _PreparedFrame(frame_plan, scene.viewports, size, scene.uniform_overrides, self._programs,
                                  scene.depth_mode, gl_depth.clear_depth_value(scene), scene.depth_mode == "reverse_z",
                                  tuple(passes), scene, nodes, moves)
        if len(self._prepared_frames) >= 16:  # a live compare draws a few plans by turns; more: start again
            self._prepared_frames.clear()
        self._prepared_frames[id(frame_plan)] = prepared
        return prepared

    @staticmethod
    def pass_camera(view: np.ndarray, proj: np.ndarray, origin: np.ndarray | None = None) -> PassCamera:
        """A pass's camera from its matrices (for runners that look through their own, a light's),
        its draws' positions relative to ``origin`` (None: the view's eye; see :class:`PassCamera`)."""
        return PassCamera(view, proj, origin)

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
                scene, camera.projection(aspect)), np.asarray(camera.eye, dtype=np.float64)))
        return kept[1]

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

        The planar passes (:mod:`glsandbox.gl.planar_state`) override what they
        change: ``model`` replaces the node's model matrix, ``front_face`` the
        winding rule of front faces, ``lights`` the frame's lights and
        ``material`` the node's (a mirror's reflection: ``R @ model``,
        ``"cw"``, the reflected lights; a planar shadow: the flattening
        matrix and one flat colour).

        What this draw writes, each only where its bytes differ from the program's last
        (a program keeps its uniform values between draws and frames): the matrices, then
        (lit) the eye and the lights, then the material's constants. A uniform the compiler
        removed (a term switched off) is remembered as written and writes nothing (_Uniforms).
        """
        if material is None:
            material = node.material
        step = self._steps[(id(draw), front_face)]  # (_prepared_draw's kept step, inline: every draw)
        if step is None or step.draw is not draw or step.material is not material or step.mesh is not node.mesh:
            step = self._prepared_draw(node, draw, material, front_face)
        setup = step.setup
        own: dict[str, object] = {}
        if step.user is not None:  # a node's own shader: checked before anything is drawn with it
            own = check_user_draw(self._overrides, step.user, setup.program, setup.members, node)
            self._user_nodes.setdefault(draw.program, {})[node.name] = node
        self._mesh_last_frame[setup.mesh_key] = self._frame
        if step.culling != self._culling:
            self._set_culling(draw.cull_back_faces, front_face)
        written, uniforms = setup.written, setup.uniforms
        write_matrices(setup, written, uniforms, node.model if model is None else model, camera)
        if step.lit:
            write_lighting(step, written, uniforms, camera, self._lights if lights is None else lights,
                           self._light_bytes)
        if written[_CONSTANTS] is not step.constants:  # another material's were written since
            write_constants(step, written, uniforms)
        if own:
            program = setup.program
            for name, value in own.items():
                program[name].value = value
            written.pop(_CONSTANTS, None)  # a node's own values may have replaced a constant
        if self.primitive_ids:  # the X-ray's id target: which node this draw is
            uniforms["u_node_id"].write(struct.pack("I", self.node_ids.get(node.name, 0)))
        self._bind_and_render(draw, material, setup, camera)

    def _prepared_draw(self, node: Node, draw: Draw, material: Material, front_face: str) -> _DrawStep:
        """The prepared draw of ``draw`` (:class:`_DrawStep`): the one kept for it while its
        Draw, material and mesh stay (a moved copy of its mesh writes its positions), else a new one."""
        key = (id(draw), front_face)
        step = self._steps[key]
        if step is None or step.draw is not draw or step.material is not material:
            return self._draw_step(key, node, draw, material, front_face)
        if step.mesh is not node.mesh:
            mesh = node.mesh
            if step.origin is not None and mesh_origin(mesh) is step.origin:
                self._moved_gpu_mesh(mesh, step.origin)  # this frame's positions into its buffer
                step.mesh = mesh
            else:
                return self._draw_step(key, node, draw, material, front_face)
        return step

    def _bind_and_render(self, draw: Draw, material: Material, setup: _DrawSetup, camera: PassCamera) -> None:
        """Bind the draw's textures (unit 0: the material's, unit 1: a shadow map) and draw its
        elements; a blended draw over what is drawn already, without depth writes."""
        texture = material.texture
        if texture is not None and self._bound_texture is not texture:  # unit 0; consecutive draws bind once
            self._textures.bind(texture, 0)
            self._bound_texture = texture
        if draw.shadow_map is not None:  # unit 1: the light's shadow map (a depth texture, compared)
            for name, data in self.shadow_maps.use(draw.shadow_map, SHADOW_MAP_UNIT, camera.origin):
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
            check_user_draw(self._overrides, user, self._programs[draw.program][1], self._members(draw.program), node)
        mesh = node.mesh
        setup = self._draw_setup(draw.program, mesh)
        # A node's own shader may light itself whatever the shading; a program without any lighting
        # uniform (a shadow map's depth program drawing a lit node) is given none of them.
        lit = (material.lit or user is not None) and not setup.members.isdisjoint(_LIGHTING_UNIFORMS)
        origin = setup.source if setup.source is not mesh else None  # a moved mesh's set-up is its origin's
        if len(self._steps) >= self.SETUPS_KEPT:  # new draws every frame (plans not kept): start again
            self._steps.clear()
        step = self._steps[key] = _DrawStep(draw, material, front_face, mesh, origin, setup, user, lit,
                                            material_constants(material, lit))
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
        written = self._written.setdefault(program_key, _Written())
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
            setup = _DrawSetup(origin, program, members, uniform_writer(written, program, members),
                               _moved_key(origin), vao, gpu, "m_normal" in members, self._uniforms(program_key), written)
            self._setups[moved_key] = setup
            return setup
        vao, gpu = self._vao(drawn, program_key)
        if len(self._setups) >= self.SETUPS_KEPT:  # new meshes every frame (a trail): start again
            self._setups.clear()
        setup = _DrawSetup(mesh, program, members, uniform_writer(written, program, members), _mesh_key(drawn), vao, gpu,
                           "m_normal" in members, self._uniforms(program_key), written)
        self._setups[(program_key, id(mesh))] = setup
        return setup

    def unbind_texture(self) -> None:
        """Leave texture unit 0 without the frame's sampler object (the overlays and the next user
        of the context see plain texture state); once per frame, not per draw."""
        if self._bound_texture is not None:
            self._textures.unbind(0)
            self._bound_texture = None

    def overlay_drawer(self) -> OverlayDrawer:
        """The drawer of the overlay passes, made on the first."""
        if self._overlays is None:
            self._overlays = OverlayDrawer(self.ctx)
        return self._overlays

    def compiled(self, program_key: str) -> moderngl.Program:
        """The compiled program of a variant of the plan being drawn, by its key."""
        return self._programs[program_key][1]

    def culling_switched_off(self) -> None:
        """A runner switched culling off behind :meth:`_set_culling` (the overlay drawer does)."""
        if self._culling is not None:
            self._culling = (False, self._culling[1])

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



#: A frame's models where nothing is moved by a motion handed over (see :class:`FrameState`).
_NO_MODELS: Mapping[str, np.ndarray] = MappingProxyType({})
#: The uniforms a lit draw writes besides the matrices and colour (write_lighting, the material's
#: coefficients): a program with none of them is drawn as unlit, writing the same into GL.
_LIGHTING_UNIFORMS = frozenset({"u_eye", "u_light_pos", "u_light_color", "u_ambient", "u_diffuse", "u_specular",
                                "u_shininess"})
#: What restore_state leaves of culling (off, counter-clockwise fronts).
_NO_CULLING = (False, "ccw")
