"""What a frame's plan is made of: program variants, draws, stencil states and passes.

Pure data, no GL: the planners of :mod:`glsandbox.passes` make these, the
executor (:mod:`glsandbox.gl.executor`) runs them, ``glsandbox plan`` prints them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from glsandbox.errors import SandboxError

#: The texture unit a receiver's shadow map is bound to (unit 0 is the material's texture).
SHADOW_MAP_UNIT = 1


@dataclass(frozen=True, order=True)
class ProgramVariant:
    """A shader file compiled with a set of ``#define`` lines.

    ``shader`` is a built-in program's name (``phong``: ``shaders/phong.glsl``),
    or with ``user`` the path of a node's own GLSL file (:attr:`Node.shader`).
    """

    shader: str
    defines: tuple[tuple[str, str], ...] = ()
    user: bool = False
    #: ``shader[DEFINE,NAME=value]``: names the compiled program in plans and caches.
    key: str = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        flags = ",".join(name if value == "" else f"{name}={value}" for name, value in self.defines)
        object.__setattr__(self, "key", f"{self.shader}[{flags}]" if self.defines else self.shader)




@dataclass(frozen=True)
class Draw:
    """One node drawn with one program variant (in a ``trace`` pass: traced, shaded as ``program`` says)."""

    node: str
    program: str  # a ProgramVariant key; in a trace pass, the shading the ray tracer gives the node
    cull_back_faces: bool
    texture: str | None = None  # what texture unit 0 holds, only for textured nodes
    #: Alpha blending on and depth writes off (a material's ``alpha_mode = "blend"``).
    blend: bool = False
    #: The light whose shadow map texture unit 1 holds (:data:`SHADOW_MAP_UNIT`), for receivers.
    shadow_map: int | None = None

    def describe(self) -> str:
        return (f"{self.node} with {self.program}" + ("" if self.cull_back_faces else " (no culling)")
                + (" (blended, no depth writes)" if self.blend else "")
                + (f" + texture unit 0: {self.texture}" if self.texture else "")
                + (f" + texture unit {SHADOW_MAP_UNIT}: shadow map {self.shadow_map}"
                   if self.shadow_map is not None else ""))


#: Stencil comparisons a pass may use (``glStencilFunc``).
STENCIL_TESTS = ("always", "equal", "not_equal", "never")
#: What a fragment that passes the stencil and depth tests does to the
#: written bits (``glStencilOp``'s third operation).
STENCIL_OPS = ("keep", "replace", "invert", "incr", "zero")


@dataclass(frozen=True)
class StencilState:
    """The stencil state of one pass: Direct3D's depth-stencil state (the
    course's ``MarkMirrorDSS``, ``DrawReflectionDSS``), which OpenGL sets
    with ``glStencilFunc``, ``glStencilMask`` and ``glStencilOp``.

    A fragment passes when ``stencil & mask`` compares by ``test`` with
    ``ref & mask`` (``always``: every fragment passes). Where it passes both
    the stencil and the depth test, ``on_pass`` updates the bits of
    ``write_mask``: ``keep`` leaves them, ``replace`` writes ``ref``'s,
    ``invert`` flips them. A fragment that fails either test leaves the
    stencil as it was.
    """

    test: str
    ref: int
    mask: int = 0xFF  # the compare mask
    write_mask: int = 0x00
    on_pass: str = "keep"

    def __post_init__(self) -> None:
        if self.test not in STENCIL_TESTS:
            raise SandboxError(f"unknown stencil test {self.test!r}; use one of {', '.join(STENCIL_TESTS)}")
        if self.on_pass not in STENCIL_OPS:
            raise SandboxError(f"unknown stencil operation {self.on_pass!r}; use one of {', '.join(STENCIL_OPS)}")
        for name in ("ref", "mask", "write_mask"):
            if not 0 <= getattr(self, name) <= 0xFF:
                raise SandboxError(f"stencil {name} must lie in 0..255 (an 8-bit buffer), got {getattr(self, name)!r}")

    def describe(self) -> str:
        """``always, replace 1``; ``equal 1, keep``; ``equal 0 on bit 2, set it``."""
        test = self.test
        if self.test != "always":
            test += f" {self.ref}" + ("" if self.mask in (0xFF, self.ref) else f" on bit {self.mask}")
        if self.on_pass == "replace":
            update = f"replace {self.ref & self.write_mask}"
        elif self.on_pass == "invert":
            # Under "equal" with those bits 0 in ref, a flip can only set them.
            clear_before = (self.test == "equal" and self.write_mask != 0
                            and self.write_mask & self.mask == self.write_mask and self.ref & self.write_mask == 0)
            update = "set it" if clear_before else f"invert bits {self.write_mask}"
        elif self.on_pass in ("incr", "zero"):
            update = f"{self.on_pass} bits {self.write_mask}"
        else:
            update = "keep"
        return f"{test}, {update}"


@dataclass(frozen=True)
class Pass:
    """One step of the frame, restricted to one viewport.

    ``kind`` is one of :data:`glsandbox.passes.PASS_KINDS`: each has its
    module here (``glsandbox/passes/<kind>.py``: its planner and describer)
    and its runner (``glsandbox/gl/passes/<kind>.py``). ``target`` is what the pass
    draws into: ``"frame"``, or a named offscreen (``"shadow map 0"``: light
    0's depth texture). ``camera`` is what it looks through: ``"viewport"``
    (the viewport's camera, or the scene's), ``"light N"`` (light N's shadow
    camera, :func:`glsandbox.shadowmap.light_camera`), or None for passes
    that draw no 3D content (clears, overlays).
    """

    kind: str
    viewport: int  # -1: the whole target
    clear_color: tuple[float, float, float, float] | None = None
    clear_depth: bool = False
    clear_stencil: bool = False
    draws: tuple[Draw, ...] = ()
    depth_test: bool = False

    #: The planar passes (:mod:`glsandbox.passes.planar_effects`): the stencil state
    #: (None: no stencil test); any pass: what else it does differently, as text.
    stencil: StencilState | None = None
    detail: str = ""
    target: str = "frame"
    camera: str | None = "viewport"
    #: The planar passes' rasterizer and blend state where a state table gives them
    #: (:mod:`glsandbox.exercises.states`); None: the pass kind's own (no depth writes
    #: for ``mark_mirror`` and ``planar_shadow``, clockwise front faces for ``reflection``,
    #: source-alpha blending for ``planar_shadow``). ``blend`` is (source, destination)
    #: factor names of :data:`glsandbox.gl.planar_state.BLEND_FACTORS`.
    depth_write: bool | None = None
    front_face: str | None = None
    blend: tuple[str, str] | None = None

    def describe(self) -> str:
        from glsandbox.passes import describer  # the registry, which finds each kind's module by its name

        return describer(self.kind)(self)


def describe_draws(step: Pass) -> str:
    """Each draw as :meth:`Draw.describe` says it, or ``nothing``."""
    return "; ".join(d.describe() for d in step.draws) or "nothing"

