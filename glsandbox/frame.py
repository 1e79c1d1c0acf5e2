"""One frame from a Scene: the rasterizer and the ray tracer composed.

Every frame, headless or in a window, goes through :class:`FrameRenderer`:

1. viewports the lesson asked to ray-trace (``renderer=ray`` or
   ``ray_numpy``) are traced first (:func:`trace_viewports`); each becomes a
   plain viewport showing its traced image, so overlays and split screens
   keep working. A frame with only raster viewports never enters
   :mod:`glsandbox.raytrace`;
2. :func:`glsandbox.plan.plan` lists the passes the scene needs;
3. the raster executor draws them into an offscreen target with exactly the
   depth, stencil and MSAA the plan lists.

The plan a frame returns (and ``glsandbox plan`` prints) is the whole frame's:
a ``trace`` pass per ray-traced viewport first, saying who traces it and how,
then the raster passes, and as notes what the ray tracer ignores of the scene.

:class:`HeadlessRenderer` opens a context of its own and reads frames back;
the window (:mod:`glsandbox.app.window`) copies the target onto the screen.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.gl.context import GLHost, open_context
from glsandbox.gl.executor import Executor
from glsandbox.gl.passes import all_moved
from glsandbox.gl.target import OffscreenTarget
from glsandbox.lesson import Lesson
from glsandbox.overlay import Overlay
from glsandbox.plan import TRACE_OPTIONS, Buffers, Pass, Plan, motion_decisions, plan, traced_image_name, traced_scene
from glsandbox.scene import Motion, Scene, motion_parts, moved_scene

__all__ = ["DEFAULT_SIZE", "Frame", "FrameRenderer", "HeadlessRenderer", "InteractiveResolution",
           "LazyRenderer", "single_viewport", "trace_viewports", "with_samples"]

#: The frame size when none is given (``--size``).
DEFAULT_SIZE = (640, 480)


@dataclass
class Frame:
    """One rendered frame: the pixels, the plan that made them, and its cost."""

    image: np.ndarray  # (H, W, 4) uint8, top row first, alpha 255 (glsandbox.gl.target)
    plan: Plan
    seconds: float


def with_samples(scene: Scene, samples: int) -> Scene:
    """The scene with the requested MSAA sample count (0 or 1: none; else a power of two)."""
    if samples < 0 or (samples > 1 and samples & (samples - 1)):
        raise SandboxError(f"--samples {samples}: MSAA takes 0 (off) or a power of two (2, 4, 8, ...)")
    return replace(scene, samples=samples) if samples != scene.samples else scene


# --- the raster-versus-ray hook ----------------------------------------------


def single_viewport(scene: Scene, index: int) -> Scene:
    """Viewport ``index`` of ``scene`` as a scene of its own, filling the frame: its nodes
    (those shown in it), no overlays. What a ray-traced viewport is traced as."""
    vp = scene.viewports[index]
    return replace(scene, viewports=(replace(vp, rect=(0.0, 0.0, 1.0, 1.0)),),
                   nodes=tuple(replace(n, viewports=None) for n in scene.nodes if n.shown_in(index)), overlays=())


def trace_viewports(scene: Scene, size: tuple[int, int], ctx: object | None = None,
                    resolution: float = 1.0) -> Scene:
    """The hook that lets every lesson render with either renderer.

    Viewports whose ``renderer`` is ``"ray"`` (GLSL engine on ``ctx``) or
    ``"ray_numpy"`` are traced now; each becomes a plain viewport with no
    nodes that shows its traced image as its first overlay (drawn texel for
    pixel, so the rasterizer's own overlays still land on top). A scene with
    only raster viewports comes back unchanged, without importing the ray
    tracer. The result is an ordinary Scene for the raster executor.
    ``resolution`` < 1 traces that fraction of the pixels in each direction
    and enlarges the image (nearest pixel): the interactive window's coarse
    frames while the camera moves.
    """
    for vp in scene.viewports:
        if vp.renderer != "raster":
            break
    else:  # only raster viewports (a loop, not a set: this runs every frame)
        return scene
    ray = {i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"}
    from glsandbox.raytrace.render import render  # only frames that trace pay for the import

    width, height = size
    images = {}
    for i in sorted(ray):
        vp = scene.viewports[i]
        w, h = vp.pixels(width, height)[2:]
        if w <= 0 or h <= 0:
            continue
        single = single_viewport(scene, i)
        engine = "gpu" if vp.renderer == "ray" and ctx is not None else "numpy"
        if resolution < 1.0:
            small = (max(1, math.ceil(w * resolution)), max(1, math.ceil(h * resolution)))
            image = render(single, small, engine, ctx=ctx, **TRACE_OPTIONS)
            rows = np.minimum((np.arange(h) * small[1]) // h, small[1] - 1)
            cols = np.minimum((np.arange(w) * small[0]) // w, small[0] - 1)
            image = np.ascontiguousarray(image[rows][:, cols])
        else:
            image = render(single, (w, h), engine, ctx=ctx, **TRACE_OPTIONS)
        images[i] = Overlay(traced_image_name(i), image, viewport=i, position=(0, 0), scalable=False)
    return traced_scene(scene, images)


class InteractiveResolution:
    """The interactive ray tracer's rule: coarse while the camera moves, full when still.

    :meth:`resolution` is called once per window frame with the scene about
    to be drawn; while its camera or a node's model matrix differs from the last frame's (or did
    within ``settle`` seconds) it answers ``moving`` (a quarter of the
    pixels each way by default: 16 times fewer rays), then 1.
    """

    def __init__(self, moving: float = 0.25, settle: float = 0.3) -> None:
        self.moving = moving
        self.settle = settle
        self._last: object | None = None
        self._moved_at = -math.inf

    def resolution(self, scene: Scene, now: float | None = None) -> float:
        now = time.perf_counter() if now is None else now
        # The picture moves when a camera does or a node does (the model lesson's turning
        # model): a big model is then traced coarse, and the window keeps answering.
        cameras = (tuple(vp.camera or scene.camera for vp in scene.viewports),
                   tuple(np.asarray(node.model).tobytes() for node in scene.nodes))
        if self._last is not None and cameras != self._last:
            self._moved_at = now
        self._last = cameras
        return self.moving if now - self._moved_at < self.settle else 1.0


# --- renderers ---------------------------------------------------------------


class FrameRenderer:
    """Draws scenes into offscreen targets on one context, reusing programs and targets.

    Every frame goes into a target made for its plan, so a frame has the
    buffers its plan lists whether it ends up read back (headless) or copied
    onto a window, whose own framebuffer has fixed ones (24-bit integer
    depth, no float depth for reverse-Z).
    """

    #: Targets kept for reuse; a window being resized makes one per size.
    KEEP_TARGETS = 8
    #: Plans kept for frames moved from one scene (:meth:`plan`): a live compare's variants.
    KEEP_PLANS = 16

    def __init__(self, host: GLHost, primitive_ids: bool = False) -> None:
        self.host = host
        #: Targets and programs with the X-ray's primitive ids (:mod:`glsandbox.story.xray`).
        self.primitive_ids = primitive_ids
        self.executor = Executor(host, primitive_ids)
        self._targets: dict[tuple[tuple[int, int], Buffers], OffscreenTarget] = {}
        self._plans: dict[int, tuple[Scene, tuple, Plan]] = {}  # by id of the scene frames were moved from
        # Whether a plan's frames may be drawn from a motion handed over (render_motion), by id of the plan.
        self._moves: dict[int, tuple[Plan, bool]] = {}
        self._unmoved: dict[int, Scene] = {}  # scenes whose frames render_motion leaves to the caller
        self._noted: set[str] = set()  # user-shader notes already printed: once per run, not per frame
        self._noted_plan: Plan | None = None  # the plan render_motion printed the notes of last
        self._last_target: tuple[tuple[int, int], Buffers, OffscreenTarget] | None = None  # what target() gave last

    def target(self, size: tuple[int, int], buffers: Buffers) -> OffscreenTarget:
        last = self._last_target
        if last is not None and last[0] == size and last[1] is buffers:  # a kept plan's frames: no hashing
            return last[2]
        key = (size, buffers)
        target = self._targets.get(key)
        if target is None:
            if len(self._targets) >= self.KEEP_TARGETS:  # drop the oldest
                self._targets.pop(next(iter(self._targets))).release()
            target = self._targets[key] = OffscreenTarget(self.host, size, buffers, self.primitive_ids)
        self._last_target = (size, buffers, target)
        return target

    def draw(self, scene: Scene, size: tuple[int, int], ray_resolution: float = 1.0,
             after_pass: Callable[[int, Pass], None] | None = None) -> tuple[Plan, OffscreenTarget]:
        """Draw one frame; returns its plan (with a ``trace`` pass per ray-traced viewport)
        and the target holding it. ``ray_resolution`` < 1 traces ray-traced viewports
        coarser (the window while moving); ``after_pass`` is handed to the executor (called
        after each raster pass: the X-ray). What a ray-traced viewport ignores of the
        scene, and what a model file holds that is not drawn, is one ``warning:`` line
        each on stderr, once per run."""
        self.host.make_current()
        traced = scene
        for vp in scene.viewports:  # (trace_viewports's own test, inline: a raster frame makes no call)
            if vp.renderer != "raster":
                traced = trace_viewports(scene, size, self.host.ctx, ray_resolution)
                break
        raster_plan = self.plan(traced)
        target = self.target(size, raster_plan.buffers)
        self.executor.render(traced, target.framebuffer, size, raster_plan, after_pass=after_pass)
        # The whole frame's plan: the same raster passes after the trace passes, with the
        # notes and warnings of the scene as given (a traced viewport's nodes are an image now).
        frame_plan = raster_plan if traced is scene else plan(scene)
        self._note(frame_plan)
        return frame_plan, target

    def _note(self, frame_plan: Plan) -> None:
        """The plan's notes and warnings, one ``warning:`` line each, once per run (after a frame that worked)."""
        for note in (*frame_plan.notes, *frame_plan.warnings):
            if note not in self._noted:
                self._noted.add(note)
                print(f"warning: {note}", file=sys.stderr, flush=True)

    def plan(self, scene: Scene) -> Plan:
        """:func:`~glsandbox.plan.plan` of ``scene``, kept while only time moves it.

        A scene moved from another (:func:`glsandbox.scene.moved_scene`: a lesson's
        :meth:`~glsandbox.lesson.Lesson.motion`) reuses the plan of the last frame moved from
        the same scene when their :func:`~glsandbox.plan.motion_decisions` agree: the plan
        is then the same (blended order and planar shadow casters are its only parts that
        depend on positions). Any other scene is planned afresh."""
        origin = scene.__dict__.get("_moved_from")  # (scene_origin, inline: every frame)
        if origin is None:
            return plan(scene)
        decisions = motion_decisions(scene)
        kept = self._plans.get(id(origin))
        if kept is not None and kept[0] is origin and kept[1] == decisions:
            return kept[2]
        fresh = plan(scene)
        if len(self._plans) >= self.KEEP_PLANS and id(origin) not in self._plans:
            self._plans.pop(next(iter(self._plans)))
        self._plans[id(origin)] = (origin, decisions, fresh)
        return fresh

    def render_motion(self, scene: Scene, motion: Motion, size: tuple[int, int]) -> Frame | None:
        """The frame of ``moved_scene(scene, motion)``, read back, drawn without making that scene
        (a frame whose only change is time pays for what moves): the motion's model
        matrices and lights are checked as :func:`~glsandbox.scene.moved_scene` checks them
        (:func:`~glsandbox.scene.motion_parts`), the plan is the one kept for frames moved from
        ``scene`` while its :func:`~glsandbox.plan.motion_decisions` agree, and the executor
        writes the moved uniforms into its prepared steps. None, with nothing drawn, where this
        does not apply: a motion that moves meshes, overlays or the camera, a ray-traced
        viewport, a plan with a pass that reads the scene's nodes where they are
        (:attr:`glsandbox.gl.passes.Runner.moved`: known from the scene's first frame on); the
        caller then draws the moved scene."""
        if motion.positions or motion.overlays or motion.camera is not None:
            return None
        for vp in scene.viewports:
            if vp.renderer != "raster":
                return None
        if self._unmoved.get(id(scene)) is scene:  # its plan has such a pass: known since its first frame
            return None
        start = time.perf_counter()
        models, lights = motion_parts(scene, motion)
        parts = scene.__dict__.get("_decision_parts")  # (motion_decisions keeps them on the scene)
        if parts is not None and not any(parts) and scene.planar_shadow is None:
            decisions: tuple = ()  # nothing blended, reflected blended or casting a planar shadow: no decision moves
        else:
            decisions = motion_decisions(scene, models)
        kept = self._plans.get(id(scene))
        if kept is not None and kept[0] is scene and kept[1] == decisions:
            frame_plan = kept[2]
        else:  # a new plan: made from the moved scene, and kept as that scene's frames keep it
            frame_plan = self.plan(moved_scene(scene, motion))
        moves = self._moves.get(id(frame_plan))
        if moves is None or moves[0] is not frame_plan:
            if len(self._moves) >= self.KEEP_PLANS:
                self._moves.clear()
            moves = self._moves[id(frame_plan)] = (frame_plan, all_moved(frame_plan.passes))
        if not moves[1]:
            if len(self._unmoved) >= self.KEEP_PLANS:
                self._unmoved.clear()
            self._unmoved[id(scene)] = scene
            return None
        self.host.make_current()
        target = self.target(size, frame_plan.buffers)
        self.executor.render(scene, target.framebuffer, size, frame_plan, (models, lights))
        if frame_plan is not self._noted_plan:  # (a plan's notes are printed by its first frame)
            self._note(frame_plan)
            self._noted_plan = frame_plan
        image = target.read()
        return Frame(image, frame_plan, time.perf_counter() - start)

    def render_scene(self, scene: Scene, size: tuple[int, int]) -> Frame:
        """Draw one frame and read it back (headless, and the window's live compare tiles)."""
        start = time.perf_counter()
        frame_plan, target = self.draw(scene, size)
        image = target.read()
        return Frame(image, frame_plan, time.perf_counter() - start)

    def forget(self) -> None:
        """Start afresh on the same context, keeping only the compiled built-in programs
        (:meth:`~glsandbox.gl.executor.Executor.hand_over_programs`): every target, mesh, texture,
        plan and cache keyed by an object's ``id`` is released, and the notes already printed
        are printed again. A renderer kept for many graded submissions calls it before each, so
        that nothing drawn for one (an ``id`` reused by another's object) reaches the next."""
        programs = self.executor.hand_over_programs()
        FrameRenderer.close(self)  # (a HeadlessRenderer's close would release the context too)
        FrameRenderer.__init__(self, self.host, self.primitive_ids)
        self.executor.adopt(programs)

    def close(self) -> None:
        self.host.make_current()  # deletes must reach this context's objects
        for target in self._targets.values():
            target.release()
        self._targets.clear()
        self._last_target = None
        self.executor.release()


class HeadlessRenderer(FrameRenderer):
    """Renders lessons offscreen on a context of its own and reads the frames back."""

    def __init__(self, backend: str | None = None) -> None:
        super().__init__(open_context(backend))

    def render(self, lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0) -> Frame:
        """One frame of ``lesson``. A lesson moved only by time (:meth:`~glsandbox.lesson.Lesson.motion`)
        hands its motion to :meth:`render_motion` where it applies: the same pixels and plan as
        its moved scene's, without that scene being made."""
        parts = lesson.moving() if type(lesson).scene is Lesson.scene else None  # (a lesson's own scene(): asked)
        if parts is not None:
            if samples == parts[0].samples:
                frame = self.render_motion(*parts, size)
                if frame is not None:
                    return frame
            scene = moved_scene(*parts)
        else:
            scene = lesson.scene()
        if samples != scene.samples:  # (equal: the scene's own, checked when it was made)
            scene = with_samples(scene, samples)
        return self.render_scene(scene, size)

    def close(self) -> None:
        super().close()
        self.host.release()

    def __enter__(self) -> HeadlessRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class LazyRenderer:
    """A :class:`HeadlessRenderer` opened on first use and shared until :meth:`close`.

    The measuring tools (``glsandbox bench``, ``glsandbox tradeoffs``) hold
    one: a run whose cases all skip never opens a context.
    """

    def __init__(self, backend: str | None = None, renderer: HeadlessRenderer | None = None) -> None:
        self.backend = backend
        self._renderer = renderer  # given: an open renderer to share (it is closed by its owner)
        self._owned = renderer is None

    @property
    def opened(self) -> bool:
        """Whether a renderer is open (given, or opened by a use)."""
        return self._renderer is not None

    @property
    def renderer(self) -> HeadlessRenderer:
        if self._renderer is None:
            self._renderer = HeadlessRenderer(self.backend)
        return self._renderer

    def close(self) -> None:
        if self._renderer is not None and self._owned:
            self._renderer.close()
        self._renderer = None
