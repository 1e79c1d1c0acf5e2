"""Running lessons: headless renders, and the interactive window loop.

Both draw through a :class:`FrameRenderer`: the plan's offscreen target, with
exactly the depth, stencil and MSAA the plan lists. Headless:
:class:`HeadlessRenderer` opens a context and reads the frames back. Window:
:func:`run_window` is the course's render loop (clear, draw, swap), copying
each frame onto the window, with ESC to quit, F12 for a screenshot, R to
reload shaders, the frame rate in the title, and resizing.
"""

from __future__ import annotations

import argparse
import sys
import time as _time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from glsandbox.camera import CameraInput
from glsandbox.errors import SandboxError
from glsandbox.gl.context import BACKENDS, GLHost, open_context
from glsandbox.gl.executor import Executor
from glsandbox.gl.target import OffscreenTarget
from glsandbox.golden import save_png
from glsandbox.lesson import Lesson
from glsandbox.plan import Buffers, Plan, plan
from glsandbox.raytrace.render import InteractiveResolution, trace_viewports
from glsandbox.scene import Scene

DEFAULT_SIZE = (640, 480)


@dataclass
class Frame:
    """One rendered frame: the pixels, the plan that made them, and its cost."""

    image: np.ndarray  # (H, W, 4) uint8, top row first
    plan: Plan
    seconds: float


def with_samples(scene: Scene, samples: int) -> Scene:
    """The scene with the requested MSAA sample count (0 or 1: none)."""
    if samples < 0:
        raise SandboxError(f"--samples {samples}: must be 0 or more")
    from dataclasses import replace

    return replace(scene, samples=samples) if samples != scene.samples else scene


class FrameRenderer:
    """Draws scenes into offscreen targets on one context, reusing programs and targets.

    Every frame goes into a target made for its plan, so a frame has the
    buffers its plan lists whether it ends up read back (headless) or copied
    onto a window, whose own framebuffer has fixed ones (24-bit integer
    depth, no float depth for reverse-Z).
    """

    #: Targets kept for reuse; a window being resized makes one per size.
    KEEP_TARGETS = 8

    def __init__(self, host: GLHost) -> None:
        self.host = host
        self.executor = Executor(host)
        self._targets: dict[tuple[tuple[int, int], Buffers], OffscreenTarget] = {}

    def target(self, size: tuple[int, int], buffers: Buffers) -> OffscreenTarget:
        key = (size, buffers)
        target = self._targets.get(key)
        if target is None:
            if len(self._targets) >= self.KEEP_TARGETS:  # drop the oldest
                self._targets.pop(next(iter(self._targets))).release()
            target = self._targets[key] = OffscreenTarget(self.host, size, buffers)
        return target

    def draw(self, scene: Scene, size: tuple[int, int],
             ray_resolution: float = 1.0) -> tuple[Plan, OffscreenTarget]:
        """Draw one frame; returns its plan and the target holding it.
        ``ray_resolution`` < 1 traces ray-traced viewports coarser (the window while moving)."""
        self.host.make_current()
        scene = trace_viewports(scene, size, self.host.ctx, ray_resolution)  # renderer=ray viewports: traced images
        frame_plan = plan(scene)
        target = self.target(size, frame_plan.buffers)
        self.executor.render(scene, target.framebuffer, size, frame_plan)
        return frame_plan, target

    def close(self) -> None:
        self.host.make_current()  # deletes must reach this context's objects
        for target in self._targets.values():
            target.release()
        self._targets.clear()
        self.executor.release()


class HeadlessRenderer(FrameRenderer):
    """Renders lessons offscreen on a context of its own and reads the frames back."""

    def __init__(self, backend: str | None = None) -> None:
        super().__init__(open_context(backend))

    def render_scene(self, scene: Scene, size: tuple[int, int]) -> Frame:
        start = _time.perf_counter()
        frame_plan, target = self.draw(scene, size)
        image = target.read()
        return Frame(image, frame_plan, _time.perf_counter() - start)

    def render(self, lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0) -> Frame:
        return self.render_scene(with_samples(lesson.scene(), samples), size)

    def close(self) -> None:
        super().close()
        self.host.release()

    def __enter__(self) -> HeadlessRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def check_writable(path: Path) -> None:
    """Refuse an output path we cannot write, before any work is done."""
    import os

    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise SandboxError(f"--out {path}: is a folder, expected a .png file name")
    if path.suffix.lower() != ".png":
        raise SandboxError(f"--out {path}: the output must be a .png file")
    if not parent.is_dir():
        raise SandboxError(f"--out {path}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise SandboxError(f"--out {path}: not writable")


def render_to_file(lesson: Lesson, out: Path, size: tuple[int, int], samples: int = 0,
                   backend: str | None = None) -> Frame:
    """Render one lesson headless and write it as a PNG (atomically)."""
    check_writable(out)
    with HeadlessRenderer(backend) as renderer:
        frame = renderer.render(lesson, size, samples)
    write_png(frame.image, out)
    return frame


def write_png(image: np.ndarray, out: Path) -> None:
    """Write a PNG atomically; an OS failure becomes a one-line error naming the file."""
    try:
        save_png(image, out)
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot write ({exc.strerror or exc})") from None


# --- the window -------------------------------------------------------------


def run_window(lesson: Lesson, size: tuple[int, int] = DEFAULT_SIZE, samples: int = 0,
               backend: str | None = None, screenshot_dir: Path = Path("screenshots"),
               max_frames: int | None = None) -> None:
    """Open a window and run the lesson until ESC or the window closes.

    Keys: ESC quits; F12 writes ``screenshots/<lesson>-<n>.png``; R reloads the
    shaders from disk (a broken shader keeps the last good program and shows
    its error in the title and on stderr); other keys go to the lesson.

    Each frame is drawn as headless draws it (a :class:`FrameRenderer`
    target with the plan's buffers, ``samples`` MSAA resolved there) and
    copied onto the window, so the window shows the headless pixels.
    """
    import glfw

    host = open_context(backend if backend not in (None, "auto") else "auto", window=True, size=size,
                        title=f"glsandbox: {lesson.name}")
    if host.backend != "window":
        host.release()
        raise SandboxError("no display for a window: set DISPLAY or run under Xvfb, or use --headless")
    renderer = FrameRenderer(host)
    executor = renderer.executor
    motion = InteractiveResolution()  # ray-traced viewports: coarser while the camera moves
    state = {"lesson": lesson, "error": "", "shots": 0}
    start_time = lesson.time
    clock_start = glfw.get_time()
    pending: list[int] = []

    def on_key(window: object, key: int, scancode: int, action: int, mods: int) -> None:
        if action == glfw.PRESS or (action == glfw.REPEAT and key in repeat_keys):
            pending.append(key)

    glfw.set_key_callback(host.window, on_key)
    camera_input, repeat_keys = attach_camera_input(host.window, lambda: state["lesson"].scene())

    def handle(key: int) -> None:
        if key == glfw.KEY_ESCAPE:
            glfw.set_window_should_close(host.window, True)
        elif key == glfw.KEY_F12:
            screenshot_dir.mkdir(parents=True, exist_ok=True)
            state["shots"] += 1
            path = screenshot_dir / f"{lesson.name}-{state['shots']}.png"
            width, height = glfw.get_framebuffer_size(host.window)
            data = host.ctx.screen.read(viewport=(0, 0, width, height), components=4, alignment=1)
            image = np.frombuffer(data, dtype=np.uint8).reshape(height, width, 4)[::-1]
            save_png(np.ascontiguousarray(image), path)
            print(f"screenshot: {path}", file=sys.stderr, flush=True)
        elif key == glfw.KEY_R:
            try:
                executor.reload_shaders()
                state["error"] = ""
                print("shaders reloaded", file=sys.stderr, flush=True)
            except SandboxError as exc:
                state["error"] = str(exc)
                print(f"error: {exc}", file=sys.stderr, flush=True)
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


# --- ``python -m lessons.<module>`` ----------------------------------------


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` -> (W, H), refusing anything else with the value named."""
    w, sep, h = text.lower().partition("x")
    try:
        size = (int(w), int(h))
    except ValueError:
        size = (0, 0)
    if not sep or size[0] <= 0 or size[1] <= 0 or max(size) > 16384:
        raise SandboxError(f"--size {text!r}: expected WIDTHxHEIGHT with positive integers, e.g. 640x480")
    return size


def add_render_options(parser: argparse.ArgumentParser) -> None:
    """The options shared by every command that renders."""
    parser.add_argument("--size", default=None, help="frame size WxH (default 640x480)")
    parser.add_argument("--samples", type=int, default=0, help="MSAA samples (0: none)")
    parser.add_argument("--backend", default=None, help=f"one of {', '.join(BACKENDS)} "
                        "(default: GLSANDBOX_BACKEND or auto)")
    parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                        help="a lesson parameter (repeatable); every lesson has time=SECONDS")


def lesson_main(lesson_cls: type[Lesson], argv: list[str] | None = None) -> int:
    """Entry point of a lesson module: a window, or ``--headless --out FILE.png``."""
    from glsandbox.cli import run_guarded

    parser = argparse.ArgumentParser(prog=f"python -m lessons.{lesson_cls.name}",
                                     description=f"{lesson_cls.title} ({lesson_cls.course_section})")
    add_render_options(parser)
    parser.add_argument("--headless", action="store_true", help="render offscreen instead of opening a window")
    parser.add_argument("--out", type=Path, default=None, help="with --headless: the PNG to write")
    args = parser.parse_args(argv)

    def body() -> int:
        lesson = lesson_cls.from_settings(args.settings)
        size = parse_size(args.size) if args.size else DEFAULT_SIZE
        if args.headless:
            out = args.out or Path(f"{lesson_cls.name}.png")
            frame = render_to_file(lesson, out, size, args.samples, args.backend)
            print(f"wrote {out} ({size[0]}x{size[1]}, {frame.seconds * 1000:.1f} ms)")
        else:
            run_window(lesson, size, args.samples, args.backend)
        return 0

    return run_guarded(body)
