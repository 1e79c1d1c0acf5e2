"""Benchmark: a lesson window frame with and without the live controls.

One glfw window on the window backend (under Xvfb where there is no screen:
``xvfb-run glsandbox bench --only panel``), 800x600, the phong lesson: each
frame draws the lesson into its target, copies it onto the window and swaps,
exactly as :func:`glsandbox.app.window.run_window` does; the subject also lays out
and draws the Dear ImGui panel (:class:`glsandbox.app.panel.Panel`) before the
swap. ``glFinish`` ends both, so the time is the frame's and not the queue's.
The window runs in a child process (see :func:`cases`), driven a frame at a
time. Without a display the row is skipped with a note. Goal: <= 1.15x
(measured 1.06x to 1.23x on llvmpipe under Xvfb, frames of about 8 ms).
"""

from __future__ import annotations

import subprocess
import sys
from typing import Any

LESSON = "phong"


def cases(env: Any) -> list:
    from glsandbox.gl.context import window_unavailable
    from glsandbox.measure.bench import Case, Side
    from glsandbox.app.panel import panel_available

    if not panel_available():
        env.note("skipped: panel (window frame with the live controls): imgui-bundle is not installed "
                 "(pip install \"glsandbox[panel]\")")
        return []
    if window_unavailable():  # glfw's own answer, not a guess from DISPLAY
        env.note("skipped: panel (window frame with the live controls): no display; run under Xvfb, "
                 "e.g. xvfb-run glsandbox bench --only panel")
        return []
    server: dict[str, Any] = {}

    def frame(with_panel: bool) -> Any:
        def run(k: int) -> None:
            # The window lives in a process of its own: the bench's shared EGL context is
            # current in this one, and Mesa refuses a GLX window context beside it
            # (BadAccess in glXMakeCurrent). A frame is one line there and back (~0.1 ms
            # on both sides, against frames of tens of ms).
            if not server:
                server["proc"] = subprocess.Popen([sys.executable, __file__, f"{env.size[0]}x{env.size[1]}"],
                                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
            proc = server["proc"]
            proc.stdin.write(f"{int(with_panel)} {k}\n")
            proc.stdin.flush()
            answer = proc.stdout.readline().strip()
            if answer != "ok":
                raise RuntimeError(f"panel bench window: {answer or 'exited'}")

        return run

    return [Case("window", f"{LESSON} window frame {env.size[0]}x{env.size[1]}: without -> with the panel",
                 Side("window frame, no panel", frame(False)), Side("window frame + panel", frame(True)),
                 goal=1.15, note="glfw window on the window backend (Xvfb); the panel drawn by ImGui's GL3 renderer")]


def serve(size: tuple[int, int]) -> None:
    """The window process: one frame per line ``PANEL K`` on stdin (PANEL 0 or 1), ``ok`` when drawn."""
    import glfw

    from glsandbox.camera import CameraInput
    from glsandbox.app.controls import Clock, Session
    from glsandbox.frame import FrameRenderer
    from glsandbox.gl.context import open_context
    from glsandbox.lesson import find_lesson
    from glsandbox.app.panel import Panel

    host = open_context("window", window=True, size=size, title="glsandbox: bench panel")
    glfw.swap_interval(0)  # no wait for a vertical blank: the frame's own time
    renderer, panel = FrameRenderer(host), Panel(host.window)
    lesson = find_lesson(LESSON)()
    session = Session(lesson, Clock(0.0, 0.0), 0, CameraInput())
    for line in sys.stdin:
        with_panel, k = (int(v) for v in line.split())
        glfw.poll_events()
        _, target = renderer.draw(lesson.at(k / 60.0).scene(), size)
        host.raw.blit_color(target.resolved().glo, host.ctx.screen.glo, size)
        if with_panel:
            host.ctx.screen.use()
            panel.draw(session)
        glfw.swap_buffers(host.window)
        host.ctx.finish()
        print("ok", flush=True)
    panel.close()
    renderer.close()
    host.release()


if __name__ == "__main__":
    width, height = (int(v) for v in sys.argv[1].split("x"))
    serve((width, height))
