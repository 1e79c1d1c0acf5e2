"""What a draw and a frame need, found once: a mesh's set-up with one program, a prepared
draw of a kept plan (found again by its Draw while only time moves), and what the frames of
one plan share."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import moderngl

from glsandbox.geometry import Mesh
from glsandbox.gl.gpu_meshes import _GpuMesh
from glsandbox.gl.passes import RunPass
from glsandbox.gl.user_shaders import UserProgram
from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.plan import Plan
from glsandbox.scene import Light, Material, Scene

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


class _Steps(dict):
    """The prepared draws by key (:attr:`Executor._steps`); a key not there gives None (a subscript per draw).
    ``made`` counts the times they were all dropped: a prepared pass made before the last
    (:mod:`glsandbox.gl.prepared_frame`) holds draws that may be gone."""

    made = 0

    def __missing__(self, key: tuple[int, str]) -> None:
        return None

    def clear(self) -> None:
        super().clear()
        self.made += 1


class _DrawStep:
    """One draw of a kept plan prepared once: what
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
        # The lights this draw was lit by last, their uniform bytes, and the pass camera they are relative to.
        self.lights: tuple[tuple[Light, ...] | None, bytes, bytes, object] = (None, b"", b"", None)


@dataclass(frozen=True)
class _PreparedFrame:
    """What the frames of one plan share (:meth:`Executor._prepare_frame`): per pass, its runner,
    the pass, its viewport and rectangle (a frame pass through a viewport; else None), and the
    state groups it sets and changes (:attr:`glsandbox.gl.passes.Runner.state`)."""

    plan: Plan
    viewports: tuple
    size: tuple[int, int]
    overrides: Mapping[str, object]
    programs: dict
    depth_mode: str
    clear_depth: float
    reverse_z: bool  # the frame's depth mode is begun and ended (glsandbox.gl.depth)
    passes: tuple[tuple[RunPass, Pass, object, tuple[int, int, int, int] | None, frozenset[str],
                        frozenset[str] | None], ...]
    # The scene it was prepared for and its nodes by name: a moved frame's (see render's ``moved``),
    # whose scene is the one every frame of the plan is moved from.
    scene: Scene
    nodes: dict
    moves: bool  # every pass's runner is moved: frames of the plan may be drawn ``moved``
