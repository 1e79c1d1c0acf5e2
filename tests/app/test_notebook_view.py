"""glsandbox.view and widget() in a real Jupyter kernel, driven the way a browser drives them.

The test plays the front end: it starts an IPython kernel (jupyter_client),
runs a cell, reads the widgets' comm messages from the kernel, and sends
back what jupyter_rfb's JavaScript sends (the view is visible, its size, a
pointer drag, a wheel turn, frame confirmations). The frames that come back
are decoded and compared with the same scene rendered here.
"""

from __future__ import annotations

import ast
import base64
import io
import json
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import Any

import jupyter_client  # the dev group has it (and ipykernel, and the notebook extra)
import numpy as np
import pytest
from PIL import Image
from support import REPO_ROOT

from glsandbox.lesson import find_lesson
from glsandbox.scene import Camera

pytestmark = pytest.mark.slow
SIZE = (160, 120)
TIMEOUT = 120.0


def decode(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"))


class FrontEnd:
    """A kernel and the few front-end messages jupyter_rfb's widget understands."""

    def __init__(self, client: Any) -> None:
        self.client = client
        self.frames: list[tuple[str, bytes]] = []  # (mimetype, data) of each framebufferdata message
        self.opened: dict[str, dict] = {}  # comm id -> the widget's first state

    def execute(self, code: str, expressions: dict[str, str] | None = None) -> tuple[list[dict], dict]:
        """Run a cell; its outputs (display_data/execute_result contents) and user expressions."""
        msg_id = self.client.execute(code, user_expressions=expressions or {})
        outputs: list[dict] = []
        self.pump(lambda m: m["parent_header"].get("msg_id") == msg_id and m["msg_type"] == "status"
                  and m["content"]["execution_state"] == "idle", outputs)
        reply = self.client.get_shell_msg(timeout=TIMEOUT)
        while reply["parent_header"].get("msg_id") != msg_id:  # replies to earlier requests
            reply = self.client.get_shell_msg(timeout=TIMEOUT)
        assert reply["content"]["status"] == "ok", reply["content"]
        return outputs, reply["content"]["user_expressions"]

    def value(self, expression: str) -> Any:
        """A value of numbers, strings and lists computed in the kernel (its repr read back exactly)."""
        _, found = self.execute("", {"x": expression})
        assert found["x"]["status"] == "ok", found["x"]
        return ast.literal_eval(found["x"]["data"]["text/plain"])

    def pump(self, until: Callable[[dict], bool], outputs: list[dict] | None = None) -> None:
        """Read the kernel's broadcast messages until one satisfies ``until``."""
        deadline = time.monotonic() + TIMEOUT
        while True:
            msg = self.client.get_iopub_msg(timeout=max(0.1, deadline - time.monotonic()))
            kind, content = msg["msg_type"], msg["content"]
            if kind == "comm_open":
                self.opened[content["comm_id"]] = content["data"].get("state", {})
            elif kind == "comm_msg" and content["data"].get("method") == "custom":
                event = content["data"]["content"]
                if event.get("type") == "framebufferdata":
                    self.frames.append((event["mimetype"], bytes(msg["buffers"][0])))
                    # the browser confirms each frame; the widget keeps at most 2 unconfirmed
                    self.update(content["comm_id"], {"_frame_feedback": {
                        "index": event["index"], "timestamp": event["timestamp"], "localtime": time.time()}})
            elif kind in ("display_data", "execute_result") and outputs is not None:
                outputs.append(content)
            elif kind == "error":
                raise AssertionError("\n".join(content["traceback"]))
            if until(msg):
                return

    def send(self, comm_id: str, data: dict) -> None:
        self.client.shell_channel.send(self.client.session.msg("comm_msg", {"comm_id": comm_id, "data": data}))

    def update(self, comm_id: str, state: dict) -> None:
        self.send(comm_id, {"method": "update", "state": state, "buffer_paths": []})

    def event(self, comm_id: str, **event: Any) -> None:
        self.send(comm_id, {"method": "custom", "content": {"timestamp": time.time(), **event}})

    def show_view(self, code: str) -> tuple[str, list[dict], np.ndarray]:
        """Run a cell that makes a view; then, as the browser does, show it and give its size.
        Returns the canvas's comm id, the cell's outputs and the first frame drawn."""
        outputs, _ = self.execute(code)
        comm = [cid for cid, state in self.opened.items() if state.get("css_width") == f"{SIZE[0]}px"][-1]
        self.update(comm, {"_has_visible_views": True})
        self.event(comm, type="resize", width=SIZE[0], height=SIZE[1], ratio=1.0)
        return comm, outputs, self.next_lossless_frame()

    def drag(self, comm: str, *points: tuple[int, int]) -> None:
        """Press the left button at the first point, move through the others, release at the last."""
        (x, y), *moves = points
        self.event(comm, type="pointer_down", x=x, y=y, button=1, buttons=[1], modifiers=[])
        for x, y in moves:
            self.event(comm, type="pointer_move", x=x, y=y, button=1, buttons=[1], modifiers=[])
        self.event(comm, type="pointer_up", x=x, y=y, button=1, buttons=[], modifiers=[])

    def next_lossless_frame(self) -> np.ndarray:
        """Wait for the next PNG frame (JPEGs are sent while the camera moves, a PNG once it rests)."""
        start = len(self.frames)
        self.pump(lambda m: any(kind == "image/png" for kind, _ in self.frames[start:]))
        return decode(next(data for kind, data in self.frames[start:] if kind == "image/png"))


@pytest.fixture(scope="module")
def kernel(tmp_path_factory: pytest.TempPathFactory) -> Iterator[FrontEnd]:
    # A kernel spec of our own, for this interpreter: whatever "python3" means on the machine.
    spec_dir = tmp_path_factory.mktemp("jupyter") / "kernels" / "glsandbox-test"
    spec_dir.mkdir(parents=True)
    (spec_dir / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "glsandbox test", "language": "python"}))
    manager = jupyter_client.KernelManager(kernel_name="glsandbox-test", transport="ipc",
                                           ip=str(spec_dir.parent.parent / "kernel"))
    manager.kernel_spec_manager.kernel_dirs = [str(spec_dir.parent)]
    manager.start_kernel(cwd=str(REPO_ROOT))
    client = manager.client()
    client.start_channels()
    try:
        client.wait_for_ready(timeout=TIMEOUT)
        front = FrontEnd(client)
        front.execute("import glsandbox")
        yield front
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


def output_png(outputs: list[dict]) -> np.ndarray:
    bundles = [o["data"] for o in outputs if "image/png" in o["data"]]
    assert len(bundles) == 1, [list(o["data"]) for o in outputs]
    assert "application/vnd.jupyter.widget-view+json" in bundles[0]  # a live notebook draws the widget
    assert not bundles[0]["text/plain"].startswith("VBox(")
    return decode(base64.b64decode(bundles[0]["image/png"]))


def camera_of(front: FrontEnd, view: str = "v") -> Camera:
    """The camera of the kernel's view ``view`` (a variable name in the kernel)."""
    eye, target, up, fov, near, far = front.value(
        f"[[list(c.eye), list(c.target), list(c.up), c.fov_y, c.near, c.far] for c in [{view}.canvas.scene().camera]][0]")
    return Camera(eye=tuple(eye), target=tuple(target), up=tuple(up), fov_y=fov, near=near, far=far)


def test_widget_leaves_its_picture_in_the_saved_output(kernel: FrontEnd, gl) -> None:
    outputs, _ = kernel.execute(f"glsandbox.widget('phong', {SIZE}, specular=False)")
    expected = gl.render(find_lesson("phong")(specular=False), SIZE).image
    np.testing.assert_array_equal(output_png(outputs), expected)


def test_view_draws_orbits_on_a_drag_and_zooms_on_the_wheel(kernel: FrontEnd, gl) -> None:
    comm, outputs, first = kernel.show_view(f"v = glsandbox.view('phong', {SIZE})\nv")
    assert len(outputs) == 1  # the box alone: its picture and its widget
    phong = find_lesson("phong")()
    first_expected = gl.render(phong, SIZE).image
    np.testing.assert_array_equal(output_png(outputs), first_expected)  # the picture for static viewers
    np.testing.assert_array_equal(first, first_expected)  # the browser's first frame
    start_camera = camera_of(kernel)

    # A drag with the left button, 40 pixels to the right: the camera orbits its focus.
    kernel.drag(comm, (60, 60), (70, 60), (80, 60), (90, 60), (100, 60))
    orbited = kernel.next_lossless_frame()
    moved = camera_of(kernel)
    assert moved.eye != start_camera.eye
    radius = np.linalg.norm(np.subtract(start_camera.eye, start_camera.target))
    assert np.linalg.norm(np.subtract(moved.eye, moved.target)) == pytest.approx(radius)  # an orbit keeps the distance
    assert np.abs(orbited.astype(int) - first_expected).mean() > 1.0
    np.testing.assert_array_equal(orbited, gl.render_scene(replace(phong.scene(), camera=moved), SIZE).image)

    # The wheel rolled towards the user (negative deltaY): zoom in, nearer the focus.
    kernel.event(comm, type="wheel", x=80, y=60, dx=0.0, dy=-200.0, buttons=[], modifiers=[])
    zoomed = kernel.next_lossless_frame()
    near = camera_of(kernel)
    assert np.linalg.norm(np.subtract(near.eye, near.target)) == pytest.approx(radius * 0.9 ** 2)
    np.testing.assert_array_equal(zoomed, gl.render_scene(replace(phong.scene(), camera=near), SIZE).image)
    assert kernel.value("len(v.canvas.frame_ms)") >= 3


def test_view_time_slider_redraws_at_that_moment(kernel: FrontEnd, gl) -> None:
    kernel.show_view(f"w = glsandbox.view('transform_order', {SIZE})")
    slider = [cid for cid, state in kernel.opened.items() if state.get("description") == "time"][-1]
    kernel.update(slider, {"value": 2.5})  # the user drags the time slider
    lesson = find_lesson("transform_order")
    np.testing.assert_array_equal(kernel.next_lossless_frame(), gl.render(lesson(time=2.5), SIZE).image)
    play = [cid for cid, state in kernel.opened.items() if state.get("_model_name") == "PlayModel"][-1]
    kernel.update(play, {"value": 20})  # the play button's 20th step: 20 x 0.05 s
    assert kernel.value("w.time.value") == pytest.approx(1.0)
    np.testing.assert_array_equal(kernel.next_lossless_frame(), gl.render(lesson(time=1.0), SIZE).image)


def test_a_ray_traced_view_is_coarse_while_dragged_and_full_once_it_rests(kernel: FrontEnd, gl) -> None:
    comm, _, _ = kernel.show_view(f"r = glsandbox.view('ray_interactive', {SIZE})")
    kernel.drag(comm, (60, 60), (90, 50))
    coarse = kernel.next_lossless_frame()  # the drag's frame, traced at a quarter of the pixels each way
    camera = camera_of(kernel, "r")
    full = gl.render_scene(replace(find_lesson("ray_interactive")().scene(), camera=camera), SIZE).image
    assert not np.array_equal(coarse, full)
    np.testing.assert_array_equal(kernel.next_lossless_frame(), full)  # drawn again once the camera rests
