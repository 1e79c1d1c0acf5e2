"""The interactive window: the course's render loop on a glfw window.

:func:`run_window` clears, draws and swaps each frame, with ESC to quit,
F12 for a screenshot, R to reload shaders, the shared camera keys
(:mod:`glsandbox.camera`), the frame rate in the title, and resizing. Each
frame is drawn exactly as headless draws it (:class:`glsandbox.frame.FrameRenderer`,
into an offscreen target with the plan's buffers) and its colour copied onto
the window, so the window shows the headless pixels.
"""

from __future__ import annotations

import sys
import time as _time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from glsandbox.camera import CameraInput
from glsandbox.errors import SandboxError
from glsandbox.files import next_numbered, save_png
from glsandbox.frame import DEFAULT_SIZE, FrameRenderer, InteractiveResolution, with_samples
from glsandbox.gl.context import open_context
from glsandbox.gl.shader_watch import ShaderWatch
from glsandbox.lesson import Lesson
from glsandbox.scene import Scene

__all__ = ["attach_camera_input", "run_window"]


def run_window(lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0,
               backend: str | None = None, screenshot_dir: Path = Path("screenshots"),
               max_frames: int | None = None, instead: str | None = None) -> None:
    """Open a window and run the lesson until ESC or the window closes.

    Keys: ESC quits; F12 writes ``screenshots/<lesson>-<n>.png`` (the next free ``n``); R reloads the
    shaders from disk (a broken shader keeps the last good program and shows
    its error in the title and on stderr), as saving a node's own shader file
    does; other keys go to the lesson.
    ``instead`` is what the errors offer when no window can open (the
    command's headless form, e.g. ``glsandbox render``).

    Each frame is drawn as headless draws it (a :class:`FrameRenderer`
    target with the plan's buffers, ``samples`` MSAA resolved there) and
    copied onto the window, so the window shows the headless pixels.
    """
    import glfw

    instead = instead or f"or render it headless: glsandbox render {lesson.name} --out FILE.png"
    host = open_context(backend if backend not in (None, "auto") else "auto", window=True, size=size,
                        title=f"glsandbox: {lesson.name}", instead=instead)
    if host.backend != "window":
        host.release()
        raise SandboxError(f"no display for a window: set DISPLAY or run under Xvfb, {instead}")
    renderer = FrameRenderer(host)
    executor = renderer.executor
    motion = InteractiveResolution()  # ray-traced viewports: coarser while the camera moves
    state = {"lesson": lesson, "error": ""}
    start_time = lesson.time
    clock_start = glfw.get_time()
    pending: list[int] = []

    def on_key(window: object, key: int, scancode: int, action: int, mods: int) -> None:
        if action == glfw.PRESS or (action == glfw.REPEAT and key in repeat_keys):
            pending.append(key)

    glfw.set_key_callback(host.window, on_key)
    camera_input, repeat_keys = attach_camera_input(host.window, lambda: state["lesson"].scene())

    def reload_shaders() -> None:
        try:
            executor.reload_shaders()
            state["error"] = ""
            print("shaders reloaded", file=sys.stderr, flush=True)
        except SandboxError as exc:
            state["error"] = str(exc)
            print(f"error: {exc}", file=sys.stderr, flush=True)

    watch = ShaderWatch(executor.shader_files)  # nodes' own shader files: saving one reloads

    def handle(key: int) -> None:
        if key == glfw.KEY_ESCAPE:
            glfw.set_window_should_close(host.window, True)
        elif key == glfw.KEY_F12:
            screenshot_dir.mkdir(parents=True, exist_ok=True)
            path = next_numbered(screenshot_dir, lesson.name)
            width, height = glfw.get_framebuffer_size(host.window)
            data = host.ctx.screen.read(viewport=(0, 0, width, height), components=4, alignment=1)
            image = np.ascontiguousarray(np.frombuffer(data, dtype=np.uint8).reshape(height, width, 4)[::-1])
            # What the screen shows: the window is opaque whatever its framebuffer's alpha
            # holds (the frame copied there has alpha 1, glsandbox.gl.target, but a driver
            # whose blit honours the colour mask would leave the window's own alpha).
            image[..., 3] = 255
            save_png(image, path)
            print(f"screenshot: {path}", file=sys.stderr, flush=True)
        elif key == glfw.KEY_R:
            reload_shaders()
        else:
            name = glfw.get_key_name(key, 0) or {glfw.KEY_TAB: "tab", glfw.KEY_SPACE: "space"}.get(key, "") \
                or _arrow_key_names(glfw).get(key, "")
            if name and not camera_input.key(name, state["lesson"].scene()):
                state["lesson"].on_key(name)

    frames, fps_frames, fps_start, fps = 0, 0, _time.perf_counter(), 0.0
    try:
        while not glfw.window_should_close(host.window):
            glfw.poll_events()
            while pending:
                handle(pending.pop(0))
            if watch.changed():
                reload_shaders()
            current: Lesson = state["lesson"]
            if current.animated:
                current.values["time"] = start_time + glfw.get_time() - clock_start
            width, height = glfw.get_framebuffer_size(host.window)
            if width > 0 and height > 0:  # minimised windows have no framebuffer
                # The camera keys' camera, once moved, replaces the scene's.
                scene = camera_input.apply(with_samples(current.scene(), samples))
                _, target = renderer.draw(scene, (width, height), motion.resolution(scene))
                host.raw.blit_color(target.resolved().glo, host.ctx.screen.glo, (width, height))
                glfw.swap_buffers(host.window)
            frames += 1
            fps_frames += 1
            now = _time.perf_counter()
            if now - fps_start >= 0.5:
                fps = fps_frames / (now - fps_start)
                fps_frames, fps_start = 0, now
                suffix = f" | shader error: {state['error']}" if state["error"] else ""
                glfw.set_window_title(host.window, f"glsandbox: {current.name} | {fps:.0f} fps{suffix}")
            if max_frames is not None and frames >= max_frames:
                break
    finally:
        renderer.close()
        host.release()


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
