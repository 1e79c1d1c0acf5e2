"""``glsandbox.view``: a lesson you can orbit in Jupyter (jupyter_rfb).

A remote frame buffer widget: the browser sends pointer and wheel events to
the kernel as comm messages, the kernel renders the lesson headless (the
notebook helpers' shared renderer) and sends the frame back as a JPEG while
the camera moves, then a lossless PNG once it rests; a ray-traced lesson is
traced at a quarter of the resolution each way while the camera moves, as in
the window, and again in full when it rests. Drag orbits the camera
about its focus, the wheel zooms towards it, a double click puts the lesson's
own camera back: the window's camera (:class:`glsandbox.camera.CameraInput`),
fed by the browser instead of glfw. Under the picture a play button and a
slider set the lesson's ``time``.

This module needs the ``notebook`` extra (jupyter_rfb and ipywidgets);
:func:`glsandbox.app.notebook.view` imports it and says what to install when it
is missing.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any, NamedTuple

import ipywidgets
from IPython.utils.capture import capture_output
import numpy as np
from jupyter_rfb import RemoteFrameBuffer

from glsandbox.camera import CameraInput
from glsandbox.errors import SandboxError
from glsandbox.frame import FrameRenderer, InteractiveResolution
from glsandbox.lesson import Lesson
from glsandbox.scene import Scene

#: Browsers report a wheel notch as about 100 pixels of deltaY (jupyter_rfb
#: passes them through); the window's scroll counts notches.
WHEEL_PIXELS_PER_NOTCH = 100.0
#: The play button's step: 20 frames a second of lesson time.
PLAY_STEP_SECONDS = 0.05
#: The time slider's range (a lesson whose own time is later gets a longer slider).
TIME_RANGE_SECONDS = 10.0
#: The largest frame the view renders, whatever the browser asks for (a resize
#: larger than this is drawn at this size and scaled by the browser).
MAX_SIDE = 2048


class LessonCanvas(RemoteFrameBuffer):
    """The orbitable picture. ``camera`` is the interactive camera (``camera.camera``
    stays None until the first drag or wheel); ``frame_ms`` holds the render
    time of each frame drawn; ``last_image`` the last frame, (H, W, 4) uint8."""

    def __init__(self, lesson: Lesson, renderer_source: Any, size: tuple[int, int]) -> None:
        # jupyter_rfb displays its output area (where errors in callbacks go) in the cell as it is
        # made; held back here, make_view puts it in the box instead, so the cell's output is the
        # box alone (a static viewer shows its picture, not an "RFBOutputContext()" line).
        with capture_output(stdout=True, stderr=False, display=True):
            super().__init__(css_width=f"{size[0]}px", css_height=f"{size[1]}px", resizable=True, cursor="grab")
        self.lesson = lesson
        self._renderer_source = renderer_source  # () -> FrameRenderer, opened on first draw
        self.size = size
        self.camera = CameraInput()
        self.motion = InteractiveResolution()
        self.resolution = 1.0
        self.last_image: np.ndarray | None = None
        self.frame_ms: list[float] = []
        self.error = ""
        self._drag_from: tuple[float, float] | None = None

    # --- what is drawn ------------------------------------------------------

    def scene(self) -> Scene:
        """The lesson's scene seen through the view's camera."""
        return self.camera.apply(self.lesson.scene())

    def draw(self, resolution: float | None = None) -> np.ndarray:
        """Render one frame now (``get_frame`` calls this; tests and benchmarks may too).

        A ray-traced viewport is traced at ``resolution`` of its pixels each way;
        by default the window's rule (:class:`~glsandbox.frame.InteractiveResolution`):
        coarse while the camera moves, full once it has rested."""
        renderer: FrameRenderer = self._renderer_source()
        scene = self.scene()
        if resolution is None:  # only a ray-traced viewport has a resolution to lower
            traced = any(vp.renderer != "raster" for vp in scene.viewports)
            resolution = self.motion.resolution(scene) if traced else 1.0
        self.resolution = resolution
        start = time.perf_counter()
        _, target = renderer.draw(scene, self.size, self.resolution)
        self.last_image = target.read().copy()
        self.frame_ms.append((time.perf_counter() - start) * 1000.0)
        return self.last_image

    def get_frame(self) -> np.ndarray | None:
        try:
            image = self.draw()
        except SandboxError as exc:  # a lesson value that fails: keep the last picture, say why once
            self.error = f"error: {exc}"
            self.print(self.error)
            return None
        self.error = ""
        if self.resolution < 1.0:  # a coarse frame: draw it again at full resolution once the camera rests
            self._redraw_later(self.motion.settle + 0.05)
        return image

    def _redraw_later(self, seconds: float) -> None:
        try:
            asyncio.get_running_loop().call_later(seconds, self.request_draw)
        except RuntimeError:  # no event loop (outside a kernel): nothing draws later anyway
            pass

    # --- what the browser sends ---------------------------------------------

    def handle_event(self, event: dict) -> None:
        kind = event.get("type") or event.get("event_type")
        if kind == "resize":
            # The browser's logical size times its pixel ratio: sharp on a high-DPI screen.
            ratio = float(event.get("ratio") or event.get("pixel_ratio") or 1.0)
            width = max(1, min(MAX_SIDE, round(float(event["width"]) * ratio)))
            height = max(1, min(MAX_SIDE, round(float(event["height"]) * ratio)))
            self.size = (width, height)
        elif kind == "pointer_down" and event.get("button") == 1:
            self._drag_from = (float(event["x"]), float(event["y"]))
            self.cursor = "grabbing"
        elif kind == "pointer_move" and self._drag_from is not None:
            x, y = float(event["x"]), float(event["y"])
            self.camera.drag(x - self._drag_from[0], y - self._drag_from[1], self.lesson.scene())
            self._drag_from = (x, y)
            self.request_draw()
        elif kind == "pointer_up":
            self._drag_from = None
            self.cursor = "grab"
        elif kind == "wheel":
            # Wheel down (positive deltaY) pulls back, as the window's scroll does.
            self.camera.scroll(-float(event["dy"]) / WHEEL_PIXELS_PER_NOTCH, self.lesson.scene())
            self.request_draw()
        elif kind == "double_click":
            self.camera.reset()
            self.request_draw()

    def set_time(self, seconds: float) -> None:
        self.lesson = self.lesson.at(float(seconds))
        self.request_draw()


class ViewParts(NamedTuple):
    canvas: LessonCanvas
    time: ipywidgets.FloatSlider
    play: ipywidgets.Play
    #: top to bottom: the canvas, the play button and slider, a line of help, the canvas's output area
    children: list[Any]


def make_view(lesson: Lesson, renderer_source: Any, size: tuple[int, int]) -> ViewParts:
    """The canvas above a play button and a time slider; :func:`glsandbox.app.notebook.view` boxes them."""
    canvas = LessonCanvas(lesson, renderer_source, size)
    end = max(TIME_RANGE_SECONDS, lesson.time)
    slider = ipywidgets.FloatSlider(value=lesson.time, min=0.0, max=end, step=PLAY_STEP_SECONDS,
                                    description="time", continuous_update=True,
                                    layout=ipywidgets.Layout(width="100%"))
    # The play button counts steps in the browser; each step sets the slider, the slider redraws.
    play = ipywidgets.Play(value=round(lesson.time / PLAY_STEP_SECONDS), min=0,
                           max=round(end / PLAY_STEP_SECONDS), interval=round(PLAY_STEP_SECONDS * 1000),
                           description="play")
    play.observe(lambda change: setattr(slider, "value", change["new"] * PLAY_STEP_SECONDS), names="value")
    slider.observe(lambda change: canvas.set_time(change["new"]), names="value")
    hint = ipywidgets.HTML("<small>drag: orbit &middot; wheel: zoom &middot; double click: the lesson's camera</small>")
    return ViewParts(canvas, slider, play, [canvas, ipywidgets.HBox([play, slider]), hint, canvas._output_context])
