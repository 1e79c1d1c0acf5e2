"""The interactive window: the course's render loop on a glfw window.

:class:`Window` clears, draws and swaps each frame, with ESC to quit, F1 for
the panel, F2 for the story of the pixel under the cursor, F12 for a
screenshot, R to reload shaders (and a lesson file), the shared camera keys
(:mod:`glsandbox.camera`), the frame rate in the title, and resizing. Each
frame is drawn exactly as headless draws it
(:class:`glsandbox.frame.FrameRenderer`, into an offscreen target with the
plan's buffers) and its colour copied onto the window, so the window shows the
headless pixels. The live controls (:mod:`glsandbox.app.panel`, the optional
``panel`` extra) are drawn over the copy, never into the frame, and change the
lesson's values, the clock, MSAA and live compare
(:class:`glsandbox.app.controls.Session`).
"""

from __future__ import annotations

import sys
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from glsandbox.camera import CameraInput
from glsandbox.app.controls import Clock, Session, compare_scene
from glsandbox.errors import SandboxError
from glsandbox.app.file_watch import FileWatch
from glsandbox.files import next_numbered, save_png
from glsandbox.frame import DEFAULT_SIZE, FrameRenderer, InteractiveResolution, with_samples
from glsandbox.gl.context import open_context
from glsandbox.lesson import Lesson, lesson_source, user_code_error
from glsandbox.lesson import reload_lesson as reload_lesson_file
from glsandbox.scene import Scene

__all__ = ["FrameRate", "LessonErrors", "Window", "attach_camera_input", "explain_cursor", "run_window",
           "screenshot"]


def run_window(lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0,
               backend: str | None = None, screenshot_dir: Path = Path("screenshots"),
               max_frames: int | None = None, instead: str | None = None) -> None:
    """Open a :class:`Window` on ``lesson`` and run it until ESC, the window closes,
    or ``max_frames`` frames have been drawn."""
    Window(lesson, size, samples, backend, screenshot_dir, instead).run(max_frames)


@dataclass
class LessonErrors:
    """The lesson's three kinds of error, each kept until what it came from succeeds:
    reading its file again (``file``), building a frame (``frame``) and drawing the
    built frame (``draw``: a value only the renderer refuses). The one shown is the
    first set, in that order; a new one is printed once to stderr."""

    kinds: dict[str, str] = field(default_factory=lambda: {"file": "", "frame": "", "draw": ""})

    def report(self, kind: str, error: str) -> str:
        """Set (or, with ``""``, clear) ``kind``'s error; return the error to show."""
        if error and error != self.kinds[kind]:
            print(f"error: {error}", file=sys.stderr, flush=True)
        self.kinds[kind] = error
        return self.shown()

    def shown(self) -> str:
        return next((e for e in self.kinds.values() if e), "")


@dataclass
class FrameRate:
    """Frames per second over windows of at least ``every`` seconds."""

    every: float = 0.5
    start: float = field(default_factory=_time.perf_counter)
    frames: int = 0
    fps: float = 0.0

    def tick(self, now: float) -> bool:
        """Count a frame drawn at ``now``; True when a window closed and ``fps`` is new."""
        self.frames += 1
        if now - self.start < self.every:
            return False
        self.fps = self.frames / (now - self.start)
        self.frames, self.start = 0, now
        return True


class Window:
    """A lesson in a glfw window: its state on the object, the loop in :meth:`run`.

    The hooks, each one method: input (:meth:`on_key`, from the key callback
    between frames), the panel (:meth:`draw_panel`, over the copied frame),
    reload (:meth:`reload_shaders` and :meth:`reload_lesson`, on R or a saved
    file), the screenshot (:meth:`screenshot`, F12, from the next frame's
    target) and the pixel's story (:meth:`explain`, F2, from the next frame's scene).

    Keys: ESC quits; F1 hides or shows the panel; F2 prints the story of the pixel under
    the mouse cursor (``glsandbox explain``); F12 writes
    ``screenshots/<lesson>-<n>.png`` (the next free ``n``; the frame without the
    panel); R reloads the shaders from disk (a broken shader keeps the last good
    program and shows its error in the title and on stderr), as saving a node's
    own shader file does; a lesson from a file (``.py`` or ``.toml``) is read
    again on R and on save, a mistake keeping the last good lesson with its
    error shown the same way; other keys go to the camera, then the lesson.
    ``instead`` is what the errors offer when no window can open (the
    command's headless form, e.g. ``glsandbox render``).
    """

    def __init__(self, lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0,
                 backend: str | None = None, screenshot_dir: Path = Path("screenshots"),
                 instead: str | None = None) -> None:
        import glfw

        from glsandbox.app.panel import open_panel  # imgui only where a window opens (not for headless commands)

        self.glfw = glfw
        self.name = lesson.name
        self.screenshot_dir = screenshot_dir
        instead = instead or f"or render it headless: glsandbox render {lesson.name} --out FILE.png"
        self.host = open_context(backend if backend not in (None, "auto") else "auto", window=True, size=size,
                                 title=f"glsandbox: {lesson.name}", instead=instead)
        if self.host.backend != "window":
            self.host.release()
            raise SandboxError(f"no display for a window: set DISPLAY or run under Xvfb, {instead}")
        self.renderer = FrameRenderer(self.host)
        self.motion = InteractiveResolution()  # ray-traced viewports: coarser while the camera moves
        self.session = Session(lesson, Clock(lesson.time, glfw.get_time()), samples, CameraInput())
        self.errors = LessonErrors()
        self.last_scene: Scene | None = None  # the last scene the lesson built
        self.last_drawn: Scene | None = None  # the last scene the renderer drew
        self.shoot = False  # F12: taken from the next frame's target, before the panel is drawn
        self.explain_next = False  # F2: the pixel under the cursor, in the next frame's scene
        self.pending: list[int] = []
        glfw.set_key_callback(self.host.window, self._on_key_event)
        self.source = lesson_source(type(lesson))  # a lesson .py or scene .toml file: saving it reloads the lesson
        self.lesson_watch = FileWatch(lambda: [self.source] if self.source is not None else [])
        self.camera, self.repeat_keys = attach_camera_input(self.host.window, self.lesson_scene)
        self.session.camera = self.camera
        try:
            self.panel = open_panel(self.host.window)  # chained in front of the callbacks above
        except Exception:
            self.renderer.close()
            self.host.release()
            raise
        self.shader_watch = FileWatch(self.renderer.executor.shader_files)  # nodes' own shader files
        self.rate = FrameRate()

    @property
    def lesson(self) -> Lesson:
        """The lesson now drawn (a reload replaces it)."""
        return self.session.lesson

    def run(self, max_frames: int | None = None) -> None:
        """Draw frames until ESC, the window closes or ``max_frames``; then close."""
        glfw, frames = self.glfw, 0
        try:
            while not glfw.window_should_close(self.host.window):
                glfw.poll_events()
                while self.pending:
                    self.on_key(self.pending.pop(0))
                if self.shader_watch.changed():
                    self.reload_shaders()
                if self.lesson_watch.changed():
                    self.reload_lesson()
                if self.lesson.animated:
                    self.lesson.values["time"] = self.session.clock.time(glfw.get_time())
                width, height = glfw.get_framebuffer_size(self.host.window)
                if width > 0 and height > 0:  # minimised windows have no framebuffer
                    self.draw_frame((width, height))
                frames += 1
                if self.rate.tick(_time.perf_counter()):
                    glfw.set_window_title(self.host.window, self.title())
                if max_frames is not None and frames >= max_frames:
                    break
        finally:
            self.close()

    def close(self) -> None:
        self.panel.close()
        self.renderer.close()
        self.host.release()

    # --- one frame -------------------------------------------------------------------

    def draw_frame(self, size: tuple[int, int]) -> None:
        """Draw the lesson into its target, copy it onto the window, the panel over it, swap."""
        session = self.session
        # The camera keys' camera, once moved, replaces the scene's.
        own = self.lesson_scene()
        scene = self.camera.apply(with_samples(own, session.samples))
        scene = _live_compare(session, self.renderer, size) or scene
        frame_plan, target = self.draw(scene, size)
        if self.shoot:
            self.shoot = False
            self.screenshot(target)
        if self.explain_next:
            self.explain_next = False
            self.explain(scene, size)
            target.framebuffer.use()
        session.record(size, frame_plan, own)  # own: the lesson's scene, whose uniforms the panel shows
        self.host.raw.blit_color(target.resolved().glo, self.host.ctx.screen.glo, size)
        self.host.ctx.screen.use()
        self.draw_panel()
        self.glfw.swap_buffers(self.host.window)

    def draw(self, scene: Scene, size: tuple[int, int]) -> tuple[Any, Any]:
        """Draw ``scene``; when the renderer refuses it after a good frame (a value set in
        the panel that only drawing finds wrong), draw the last good scene, the error on screen."""
        try:
            drawn = self.renderer.draw(scene, size, self.motion.resolution(scene))
        except SandboxError as exc:
            if self.last_drawn is None:
                raise
            self._report("draw", str(exc))
            return self.renderer.draw(self.last_drawn, size, self.motion.resolution(self.last_drawn))
        self.last_drawn = scene
        if self.errors.kinds["draw"]:
            self._report("draw", "")
        return drawn

    def lesson_scene(self) -> Scene:
        """The lesson's scene; while its file (or a value) has a mistake, the last good one,
        the error on screen. A built-in lesson's own exceptions, and a first frame that
        fails, end the window."""
        try:
            scene = self.lesson.scene()
        except Exception as exc:
            if self.last_scene is None or not (isinstance(exc, SandboxError) or self.source is not None):
                raise
            self._report("frame", str(exc if isinstance(exc, SandboxError) else user_code_error(exc)))
            return self.last_scene
        self.last_scene = scene
        if self.errors.kinds["frame"]:
            self._report("frame", "")
        return scene

    def title(self) -> str:
        """``glsandbox: <lesson> | <fps> fps``, then the lesson's and the shaders' errors."""
        suffix = "".join(f" | {what} error: {error}" for what, error in
                         (("lesson", self.session.lesson_error), ("shader", self.session.shader_error)) if error)
        return f"glsandbox: {self.lesson.name} | {self.rate.fps:.0f} fps{suffix}"

    def _report(self, kind: str, error: str) -> None:
        self.session.lesson_error = self.errors.report(kind, error)

    # --- hooks -----------------------------------------------------------------------

    def _on_key_event(self, window: object, key: int, scancode: int, action: int, mods: int) -> None:
        """glfw's key callback: presses (and the camera keys' repeats) wait for the loop."""
        if action == self.glfw.PRESS or (action == self.glfw.REPEAT and key in self.repeat_keys):
            self.pending.append(key)

    def on_key(self, key: int) -> None:
        """The input hook: one pressed key, between frames."""
        glfw = self.glfw
        if key == glfw.KEY_ESCAPE:
            glfw.set_window_should_close(self.host.window, True)
        elif key == glfw.KEY_F1:
            self.panel.toggle()  # without imgui-bundle: one line saying how to install the panel
        elif key == glfw.KEY_F12:
            self.shoot = True
        elif key == glfw.KEY_F2:
            self.explain_next = True
        elif key == glfw.KEY_R:
            self.reload_shaders()
            if self.source is not None:
                self.reload_lesson()
        else:
            name = glfw.get_key_name(key, 0) or {glfw.KEY_TAB: "tab", glfw.KEY_SPACE: "space"}.get(key, "") \
                or _arrow_key_names(glfw).get(key, "")
            if name and not self.camera.key(name, self.lesson_scene()):
                self.lesson.on_key(name)

    def draw_panel(self) -> None:
        """The panel hook: the live controls, drawn on the window over the copied frame."""
        self.panel.draw(self.session)

    def reload_shaders(self) -> None:
        """The shader reload hook (R, or a node's shader file saved): a broken shader keeps
        the last good program, its error in the title, the panel and on stderr."""
        try:
            self.renderer.executor.reload_shaders()
            self.session.shader_error = ""
            print("shaders reloaded", file=sys.stderr, flush=True)
        except SandboxError as exc:
            self.session.shader_error = str(exc)
            print(f"error: {exc}", file=sys.stderr, flush=True)

    def reload_lesson(self) -> None:
        """The lesson reload hook (R, or its file saved): a mistake keeps the last good lesson."""
        try:
            fresh = reload_lesson_file(self.lesson)
        except SandboxError as exc:
            self._report("file", str(exc))
            return
        self.session.lesson = fresh
        self._report("file", "")
        print("lesson reloaded", file=sys.stderr, flush=True)

    def screenshot(self, target: Any) -> Path:
        """The screenshot hook: ``target``'s frame to the next free ``<lesson>-<n>.png``."""
        return screenshot(target.read(), next_numbered(self.screenshot_dir, self.name))

    def explain(self, scene: Scene, size: tuple[int, int]) -> None:
        """The explain hook: the story of the pixel under the cursor in ``scene`` (see :func:`explain_cursor`)."""
        explain_cursor(self.host.window, scene, size, self.renderer, self.lesson.name)


def explain_cursor(window: Any, scene: Scene, size: tuple[int, int], renderer: FrameRenderer, title: str) -> None:
    """F2: print the story of the pixel under the mouse cursor (:func:`glsandbox.story.pixel_story`;
    a rasterised pixel's frame is drawn again with its X-ray on the window's own renderer)."""
    import glfw

    from glsandbox.story import pixel_story

    cx, cy = glfw.get_cursor_pos(window)
    ww, wh = glfw.get_window_size(window)
    # Window coordinates to framebuffer pixels (a HiDPI framebuffer has more of them), row 0 at the top.
    x, y = int(cx * size[0] / max(ww, 1)), int(cy * size[1] / max(wh, 1))
    if not (0 <= x < size[0] and 0 <= y < size[1]):
        print("explain: the cursor is outside the window", file=sys.stderr, flush=True)
        return
    try:
        story = pixel_story(scene, size, (x, y), title, lambda: renderer)
    except SandboxError as exc:
        print(f"error: {exc}", file=sys.stderr, flush=True)
        return
    print(story.text, flush=True)


def screenshot(image: np.ndarray, path: Path) -> Path:
    """Write the frame (never the panel: it is drawn on the window, not the target) to ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    image = np.ascontiguousarray(image)
    image[..., 3] = 255  # what the screen shows: the window is opaque
    save_png(image, path)
    print(f"screenshot: {path}", file=sys.stderr, flush=True)
    return path


def _live_compare(session: Session, renderer: FrameRenderer, size: tuple[int, int]) -> Scene | None:
    """The live compare frame (tiles, or the difference view) when the panel asks for one."""
    if not session.live.active():
        return None
    try:
        variants, columns = session.live.variants(session.lesson)
    except SandboxError as exc:
        session.compare_error = str(exc)
        return None
    session.compare_error = ""
    variants = [replace(v, scene=session.camera.apply(with_samples(v.scene, session.samples))) for v in variants]
    return compare_scene(variants, columns, size, renderer, session.live.difference)


def _arrow_key_names(glfw: Any) -> dict[int, str]:
    return {glfw.KEY_LEFT: "left", glfw.KEY_RIGHT: "right", glfw.KEY_UP: "up", glfw.KEY_DOWN: "down"}


def attach_camera_input(window: Any, scene_source: Callable[[], Scene]) -> tuple[CameraInput, frozenset[int]]:
    """Give a glfw window the shared camera controls (:mod:`glsandbox.camera`).

    W/S move along the view, A/D turn 15° about the camera, Z/X move up and
    down, arrow keys and a left-button drag orbit, the scroll wheel zooms.
    Keys reach the camera through the window's key handler (which passes
    them by name); this wires the mouse and returns the camera and the key
    codes that repeat while held.
    """
    import glfw

    camera_input = CameraInput()
    drag: dict[str, Any] = {"last": None}

    def on_button(win: object, button: int, action: int, mods: int) -> None:
        if button == glfw.MOUSE_BUTTON_LEFT:
            drag["last"] = glfw.get_cursor_pos(win) if action == glfw.PRESS else None

    def on_cursor(win: object, x: float, y: float) -> None:
        if drag["last"] is not None:
            last_x, last_y = drag["last"]
            drag["last"] = (x, y)
            camera_input.drag(x - last_x, y - last_y, scene_source())

    def on_scroll(win: object, dx: float, dy: float) -> None:
        camera_input.scroll(dy, scene_source())

    glfw.set_mouse_button_callback(window, on_button)
    glfw.set_cursor_pos_callback(window, on_cursor)
    glfw.set_scroll_callback(window, on_scroll)
    letters = (glfw.KEY_W, glfw.KEY_A, glfw.KEY_S, glfw.KEY_D, glfw.KEY_Z, glfw.KEY_X)
    return camera_input, frozenset((*letters, *_arrow_key_names(glfw)))
