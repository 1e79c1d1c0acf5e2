"""The interactive window: the course's render loop on a glfw window.

:func:`run_window` clears, draws and swaps each frame, with ESC to quit,
F12 for a screenshot, R to reload shaders, the shared camera keys
(:mod:`glsandbox.camera`), the frame rate in the title, and resizing. Each
frame is drawn exactly as headless draws it (:class:`glsandbox.frame.FrameRenderer`,
into an offscreen target with the plan's buffers) and its colour copied onto
the window, so the window shows the headless pixels. The live controls
(:mod:`glsandbox.panel`, F1 hides them; the optional ``panel`` extra) are drawn over the copy, never into
the frame, and change the lesson's values, the clock, MSAA and live compare
(:class:`glsandbox.controls.Session`).
"""

from __future__ import annotations

import sys
import time as _time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from glsandbox.camera import CameraInput
from glsandbox.controls import Clock, Session, compare_scene
from glsandbox.errors import SandboxError
from glsandbox.files import next_numbered, save_png
from glsandbox.frame import DEFAULT_SIZE, FrameRenderer, InteractiveResolution, with_samples
from glsandbox.gl.context import open_context
from glsandbox.file_watch import FileWatch
from glsandbox.lesson import Lesson, lesson_source, user_code_error
from glsandbox.lesson import reload_lesson as reload_lesson_file
from glsandbox.scene import Scene

__all__ = ["attach_camera_input", "run_window"]


def run_window(lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0,
               backend: str | None = None, screenshot_dir: Path = Path("screenshots"),
               max_frames: int | None = None, instead: str | None = None) -> None:
    """Open a window and run the lesson until ESC or the window closes.

    Keys: ESC quits; F1 hides or shows the panel; F2 prints the story of the pixel under
    the mouse cursor (``glsandbox explain``); F12 writes ``screenshots/<lesson>-<n>.png``
    (the next free ``n``; the frame without the panel); R reloads the
    shaders from disk (a broken shader keeps the last good program and shows
    its error in the title and on stderr), as saving a node's own shader file
    does; a lesson from a file (``.py`` or ``.toml``) is read again on R and on
    save, a mistake keeping the last good lesson with its error shown the
    same way; other keys go to the lesson.
    ``instead`` is what the errors offer when no window can open (the
    command's headless form, e.g. ``glsandbox render``).

    Each frame is drawn as headless draws it (a :class:`FrameRenderer`
    target with the plan's buffers, ``samples`` MSAA resolved there) and
    copied onto the window, so the window shows the headless pixels.
    """
    import glfw

    from glsandbox.panel import open_panel  # imgui only where a window opens (not for headless commands)

    instead = instead or f"or render it headless: glsandbox render {lesson.name} --out FILE.png"
    host = open_context(backend if backend not in (None, "auto") else "auto", window=True, size=size,
                        title=f"glsandbox: {lesson.name}", instead=instead)
    if host.backend != "window":
        host.release()
        raise SandboxError(f"no display for a window: set DISPLAY or run under Xvfb, {instead}")
    renderer = FrameRenderer(host)
    executor = renderer.executor
    motion = InteractiveResolution()  # ray-traced viewports: coarser while the camera moves
    state = {"lesson": lesson, "error": "", "lesson_error": "", "shoot": False, "explain": False}
    session = Session(lesson, Clock(lesson.time, glfw.get_time()), samples, CameraInput())
    pending: list[int] = []

    def on_key(window: object, key: int, scancode: int, action: int, mods: int) -> None:
        if action == glfw.PRESS or (action == glfw.REPEAT and key in repeat_keys):
            pending.append(key)

    glfw.set_key_callback(host.window, on_key)
    source = lesson_source(type(lesson))  # a lesson .py or scene .toml file: saving it reloads the lesson
    last_good: dict[str, Scene] = {}

    # Three kinds of lesson error: reading its file again failed (kept until a read
    # succeeds), building a frame failed (kept until a frame builds), or drawing the
    # built frame failed (a value the renderer refuses: kept until a frame draws).
    lesson_errors = {"file": "", "frame": "", "draw": ""}

    def report_lesson_error(kind: str, error: str) -> None:
        if error and error != lesson_errors[kind]:
            print(f"error: {error}", file=sys.stderr, flush=True)
        lesson_errors[kind] = error
        state["lesson_error"] = session.lesson_error = next((e for e in lesson_errors.values() if e), "")

    def draw(scene: Scene, size: tuple[int, int]) -> tuple[Any, Any]:
        """Draw ``scene``; when the renderer refuses it after a good frame (a value set in
        the panel that only drawing finds wrong), draw the last good scene, the error on screen."""
        try:
            drawn = renderer.draw(scene, size, motion.resolution(scene))
        except SandboxError as exc:
            if "drawn" not in last_good:
                raise
            report_lesson_error("draw", str(exc))
            return renderer.draw(last_good["drawn"], size, motion.resolution(last_good["drawn"]))
        last_good["drawn"] = scene
        if lesson_errors["draw"]:
            report_lesson_error("draw", "")
        return drawn

    def lesson_scene() -> Scene:
        """The lesson's scene; while its file (or a value) has a mistake, the last good one,
        the error on screen. A built-in lesson's own exceptions, and a first frame that
        fails, end the window as before."""
        try:
            scene = state["lesson"].scene()
        except Exception as exc:
            if "scene" not in last_good or not (isinstance(exc, SandboxError) or source is not None):
                raise
            report_lesson_error("frame", str(exc if isinstance(exc, SandboxError) else user_code_error(exc)))
            return last_good["scene"]
        last_good["scene"] = scene
        if lesson_errors["frame"]:
            report_lesson_error("frame", "")
        return scene

    def reload_lesson() -> None:
        try:
            fresh = reload_lesson_file(state["lesson"])
        except SandboxError as exc:
            report_lesson_error("file", str(exc))
            return
        state["lesson"] = session.lesson = fresh
        report_lesson_error("file", "")
        print("lesson reloaded", file=sys.stderr, flush=True)

    lesson_watch = FileWatch(lambda: [source] if source is not None else [])
    camera_input, repeat_keys = attach_camera_input(host.window, lesson_scene)
    session.camera = camera_input
    try:
        panel = open_panel(host.window)  # chained in front of the callbacks above (none without imgui-bundle)
    except Exception:
        renderer.close()
        host.release()
        raise

    def reload_shaders() -> None:
        try:
            executor.reload_shaders()
            state["error"] = ""
            print("shaders reloaded", file=sys.stderr, flush=True)
        except SandboxError as exc:
            state["error"] = str(exc)
            print(f"error: {exc}", file=sys.stderr, flush=True)
        session.shader_error = state["error"]  # the panel shows it too

    watch = FileWatch(executor.shader_files)  # nodes' own shader files: saving one reloads

    def handle(key: int) -> None:
        if key == glfw.KEY_ESCAPE:
            glfw.set_window_should_close(host.window, True)
        elif key == glfw.KEY_F1:
            panel.toggle()  # without imgui-bundle: one line saying how to install the panel
        elif key == glfw.KEY_F12:
            state["shoot"] = True  # taken from the next frame's target, before the panel is drawn
        elif key == glfw.KEY_F2:
            state["explain"] = True  # the pixel under the cursor, in the next frame's scene
        elif key == glfw.KEY_R:
            reload_shaders()
            if source is not None:
                reload_lesson()
        else:
            name = glfw.get_key_name(key, 0) or {glfw.KEY_TAB: "tab", glfw.KEY_SPACE: "space"}.get(key, "") \
                or _arrow_key_names(glfw).get(key, "")
            if name and not camera_input.key(name, lesson_scene()):
                state["lesson"].on_key(name)

    frames, fps_frames, fps_start, fps = 0, 0, _time.perf_counter(), 0.0
    try:
        while not glfw.window_should_close(host.window):
            glfw.poll_events()
            while pending:
                handle(pending.pop(0))
            if watch.changed():
                reload_shaders()
            if lesson_watch.changed():
                reload_lesson()
            current: Lesson = state["lesson"]
            if current.animated:
                current.values["time"] = session.clock.time(glfw.get_time())
            width, height = glfw.get_framebuffer_size(host.window)
            if width > 0 and height > 0:  # minimised windows have no framebuffer
                # The camera keys' camera, once moved, replaces the scene's.
                scene = camera_input.apply(with_samples(lesson_scene(), session.samples))
                scene = _live_compare(session, renderer, (width, height)) or scene
                frame_plan, target = draw(scene, (width, height))
                if state["shoot"]:
                    state["shoot"] = False
                    screenshot(target.read(), next_numbered(screenshot_dir, lesson.name))
                if state["explain"]:
                    state["explain"] = False
                    explain_cursor(host.window, scene, (width, height), renderer, current.name)
                    target.framebuffer.use()
                session.record((width, height), frame_plan)
                host.raw.blit_color(target.resolved().glo, host.ctx.screen.glo, (width, height))
                host.ctx.screen.use()
                panel.draw(session)
                glfw.swap_buffers(host.window)
            frames += 1
            fps_frames += 1
            now = _time.perf_counter()
            if now - fps_start >= 0.5:
                fps = fps_frames / (now - fps_start)
                fps_frames, fps_start = 0, now
                suffix = "".join(f" | {what} error: {state[key]}" for what, key in
                                 (("lesson", "lesson_error"), ("shader", "error")) if state[key])
                glfw.set_window_title(host.window, f"glsandbox: {current.name} | {fps:.0f} fps{suffix}")
            if max_frames is not None and frames >= max_frames:
                break
    finally:
        panel.close()
        renderer.close()
        host.release()


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
