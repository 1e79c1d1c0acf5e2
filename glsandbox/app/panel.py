"""The window's live controls: a Dear ImGui panel (``imgui-bundle``) on the window's own context.

:mod:`glsandbox.app.window` draws each frame into an offscreen target, copies it
onto the window, and only then calls :meth:`Panel.draw`: the panel is drawn
over the window's framebuffer, never into the frame, so F12 screenshots (read
from the target) and headless renders never include it. F1 hides it.

Input: the panel chains itself in front of the window's glfw callbacks. Every
event goes to ImGui; a mouse press or wheel over the panel (or while ImGui
holds the mouse: a slider being dragged) stops there, anything else goes on to
the camera and the lesson's keys. Keys stop at the panel only while ImGui
wants the keyboard (a text field being edited).

ImGui's own OpenGL 3 renderer (``imgui.backends.opengl3_*``) draws the panel;
it saves and restores the GL state it touches, so ModernGL's frames are not
disturbed. The platform side (glfw events, display size, time) is fed here
from pyGLFW rather than through imgui's glfw backend, which would need
imgui-bundle's own glfw library and window handle.

Test hook: with ``GLSANDBOX_PANEL_LAYOUT=FILE`` the panel writes the screen
rectangle of every widget (by label) as JSON whenever it changes, so a test
can click a widget with xdotool.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

from glsandbox.app.controls import (SAMPLE_CHOICES, Control, LiveCompare, Session, control_for, lesson_controls,
                                    parse_value, to_text, uniform_controls, uniform_value)
from glsandbox.errors import SandboxError
from glsandbox.files import write_text

#: The panel's width in pixels, and its margin from the window's top-right corner.
PANEL_WIDTH = 300
MARGIN = 8
#: With no input, the panel is laid out again this often (seconds): the time, the camera
#: and values changed by keys show within it; frames between draw the last layout again,
#: without its Python (about 0.4 ms of an 8 ms 800x600 phong frame on llvmpipe).
RELAYOUT_S = 1.0 / 20.0
#: The step buttons' time step: one frame at 30 frames a second.
TIME_STEP = 1.0 / 30.0
#: Section of the controls listed under "Renderer" rather than "Parameters".
RENDER_PARAMS = ("renderer", "effects")


class Panel:
    """The ImGui panel of one glfw window (see the module doc)."""

    def __init__(self, window: Any) -> None:
        import glfw
        from imgui_bundle import imgui

        self.glfw, self.imgui, self.window = glfw, imgui, window
        self.visible = True
        self.context = imgui.create_context()
        self.io = imgui.get_io()
        self.io.set_ini_filename("")  # no imgui.ini next to the user's files
        imgui.backends.opengl3_init("#version 330")
        self.rect = (0.0, 0.0, 0.0, 0.0)  # the panel's last screen rectangle (x, y, w, h)
        self.last_time = glfw.get_time()
        self.layout_path = os.environ.get("GLSANDBOX_PANEL_LAYOUT")
        self.layout: dict[str, list[float]] = {}
        self._written: dict[str, list[float]] = {}
        self.texts: dict[str, str] = {}  # text fields being edited, by parameter
        self.message = ""
        self._keys = _key_map(glfw, imgui)
        # Mouse buttons reach ImGui one per frame, never in the frame the mouse moved:
        # a widget that acts on the press (a tab) must have seen the mouse over it first,
        # and a press and release polled together (a quick click) must not cancel out.
        self._buttons: list[tuple[int, bool]] = []
        self._moved = False
        self._input = True  # an event arrived since the last layout
        self._laid_out = -1.0
        self._laid_out_visible = self.visible
        self._install()

    # --- input ------------------------------------------------------------

    def over(self, x: float, y: float) -> bool:
        """Whether the window point (x, y) is on the panel (or ImGui holds the mouse)."""
        px, py, pw, ph = self.rect
        return self.visible and (px <= x < px + pw and py <= y < py + ph or self.io.want_capture_mouse)

    def toggle(self) -> None:
        """F1: hide or show the panel."""
        self.visible = not self.visible

    def _install(self) -> None:
        glfw, io, window = self.glfw, self.io, self.window
        # pyGLFW's setters return the callback they replace: each handler below
        # feeds ImGui, then passes the event on unless the panel keeps it.
        prev: dict[str, Any] = {}

        def on_key(win: Any, key: int, scancode: int, action: int, mods: int) -> None:
            self._input = True
            self._mods(mods)
            if key in self._keys:
                io.add_key_event(self._keys[key], action != glfw.RELEASE)
            if not (self.visible and io.want_capture_keyboard and action != glfw.RELEASE) and prev["key"]:
                prev["key"](win, key, scancode, action, mods)

        def on_char(win: Any, codepoint: int) -> None:
            self._input = True
            io.add_input_character(codepoint)

        def on_button(win: Any, button: int, action: int, mods: int) -> None:
            if button < 5:
                self._buttons.append((button, action == glfw.PRESS))
            keep = action == glfw.PRESS and self.over(*glfw.get_cursor_pos(win))
            if not keep and prev["button"]:  # releases always go on: a camera drag ends
                prev["button"](win, button, action, mods)

        def on_cursor(win: Any, x: float, y: float) -> None:
            self._input = True
            io.add_mouse_pos_event(x, y)
            self._moved = True
            if prev["cursor"]:
                prev["cursor"](win, x, y)

        def on_enter(win: Any, entered: int) -> None:
            self._input = True
            if not entered:  # the mouse left the window: nothing is hovered (no tooltip stays up)
                io.add_mouse_pos_event(-3.4e38, -3.4e38)

        def on_scroll(win: Any, dx: float, dy: float) -> None:
            self._input = True
            io.add_mouse_wheel_event(dx, dy)
            if not self.over(*glfw.get_cursor_pos(win)) and prev["scroll"]:
                prev["scroll"](win, dx, dy)

        prev["key"] = glfw.set_key_callback(window, on_key)
        prev["button"] = glfw.set_mouse_button_callback(window, on_button)
        prev["cursor"] = glfw.set_cursor_pos_callback(window, on_cursor)
        prev["scroll"] = glfw.set_scroll_callback(window, on_scroll)
        glfw.set_char_callback(window, on_char)
        glfw.set_cursor_enter_callback(window, on_enter)

        # The window's sizes, kept up to date by glfw's callbacks: asking for them every
        # frame is an X server round trip each, measured 0.6 ms for the window size (a
        # tenth of an 800x600 phong frame), where the whole panel's Python takes 0.4 ms.
        def on_window_size(win: Any, width: int, height: int) -> None:
            self._input = True
            self.window_size = (width, height)
            if prev["window_size"]:
                prev["window_size"](win, width, height)

        def on_framebuffer_size(win: Any, width: int, height: int) -> None:
            self.framebuffer_size = (width, height)
            if prev["framebuffer_size"]:
                prev["framebuffer_size"](win, width, height)

        self.window_size = glfw.get_window_size(window)
        self.framebuffer_size = glfw.get_framebuffer_size(window)
        prev["window_size"] = glfw.set_window_size_callback(window, on_window_size)
        prev["framebuffer_size"] = glfw.set_framebuffer_size_callback(window, on_framebuffer_size)
        self._handlers = (on_key, on_char, on_button, on_cursor, on_enter, on_scroll,  # kept alive with the panel
                          on_window_size, on_framebuffer_size)

    def _mods(self, mods: int) -> None:
        glfw, imgui = self.glfw, self.imgui
        self.io.add_key_event(imgui.Key.mod_ctrl, bool(mods & glfw.MOD_CONTROL))
        self.io.add_key_event(imgui.Key.mod_shift, bool(mods & glfw.MOD_SHIFT))
        self.io.add_key_event(imgui.Key.mod_alt, bool(mods & glfw.MOD_ALT))

    # --- drawing ----------------------------------------------------------

    def draw(self, session: Session) -> None:
        """Lay out and draw the panel over whatever the window's framebuffer holds.

        Laid out again when input arrived, when it was shown or hidden, or
        :data:`RELAYOUT_S` after the last layout (the time, the camera and
        values changed by keys then show); a frame in between draws the last
        layout's draw lists again, without its Python.
        """
        glfw, imgui = self.glfw, self.imgui
        now = glfw.get_time()
        if not (self._input or self._buttons or self.visible != self._laid_out_visible
                or now - self._laid_out >= RELAYOUT_S):
            if self.visible:
                imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())
            return
        self._input = False
        self._laid_out, self._laid_out_visible = now, self.visible
        win_w, win_h = self.window_size
        fb_w, fb_h = self.framebuffer_size
        if win_w <= 0 or win_h <= 0:
            return
        self.io.display_size = (win_w, win_h)
        self.io.display_framebuffer_scale = (fb_w / win_w, fb_h / win_h)
        self.io.delta_time = max(now - self.last_time, 1e-4)
        self.last_time = now
        if self._buttons and not self._moved:
            self.io.add_mouse_button_event(*self._buttons.pop(0))
        self._moved = False
        imgui.backends.opengl3_new_frame()
        imgui.new_frame()
        self.layout = {}
        if self.visible:
            # Top right: lessons put their own text panels at the top left.
            imgui.set_next_window_pos((win_w - PANEL_WIDTH - MARGIN, MARGIN), imgui.Cond_.always)
            # A fixed width; the height fits the open tab, up to the window's.
            imgui.set_next_window_size_constraints((PANEL_WIDTH, 0), (PANEL_WIDTH, max(100, win_h - 2 * MARGIN)))
            imgui.set_next_window_bg_alpha(0.85)
            imgui.begin(f"{session.lesson.name} (F1 hides)", None,
                        imgui.WindowFlags_.always_auto_resize | imgui.WindowFlags_.no_move)
            x, y = imgui.get_window_pos()
            w, h = imgui.get_window_size()
            self.rect = (x, y, w, h)
            self._contents(session, now)
            imgui.end()
        else:
            self.rect = (0.0, 0.0, 0.0, 0.0)
        imgui.render()
        imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())
        self._write_layout()

    def _item(self, label: str) -> None:
        """Remember the last widget's screen rectangle under ``label`` (the layout hook)."""
        (x0, y0), (x1, y1) = self.imgui.get_item_rect_min(), self.imgui.get_item_rect_max()
        self.layout[label] = [x0, y0, x1, y1]

    def _contents(self, session: Session, now: float) -> None:
        imgui = self.imgui
        lesson = session.lesson
        imgui.text_wrapped(lesson.title or lesson.name)
        # On screen, not only in the title bar: the last good lesson and program draw meanwhile.
        for what, error in (("lesson", session.lesson_error), ("shader", session.shader_error)):
            if error:
                imgui.push_text_wrap_pos(0.0)
                imgui.text_colored((1.0, 0.5, 0.4, 1.0), f"{what} error: {error}")
                imgui.pop_text_wrap_pos()
        controls = lesson_controls(lesson)
        if not imgui.begin_tab_bar("sections"):
            return
        for title, body in (("Lesson", lambda: self._lesson(session, controls)),
                            ("Time & camera", lambda: (self._time(session, now), self._camera(session))),
                            ("Compare", lambda: self._live(session, session.live)),
                            ("Plan", lambda: imgui.text_unformatted(session.plan_text()))):
            selected, _ = imgui.begin_tab_item(title)
            self._item(title)
            if selected:
                body()
                imgui.end_tab_item()
        imgui.end_tab_bar()
        if self.message:
            imgui.text_colored((1.0, 0.5, 0.4, 1.0), self.message)

    def _lesson(self, session: Session, controls: list[Control]) -> None:
        """The lesson's own parameters, then the renderer's (renderer, effects, MSAA)."""
        imgui = self.imgui
        for control in controls:
            if control.param.name not in RENDER_PARAMS:
                self._control(session, control)
        uniforms = uniform_controls(session.uniforms)
        if uniforms:
            imgui.separator_text("shader uniforms")
            for control in uniforms:
                self._uniform(session, control)
        imgui.separator_text("renderer")
        for control in controls:
            if control.param.name in RENDER_PARAMS:
                self._control(session, control)
        index = SAMPLE_CHOICES.index(session.samples) if session.samples in SAMPLE_CHOICES else 0
        changed, index = imgui.combo("MSAA", index, [str(s) if s else "off" for s in SAMPLE_CHOICES])
        self._item("MSAA")
        if changed:
            session.samples = SAMPLE_CHOICES[index]

    def _control(self, session: Session, control: Control) -> None:
        """One parameter's widget; a change goes straight into the lesson's values (drawn next frame)."""
        imgui = self.imgui
        param, values = control.param, session.lesson.values
        name, value = param.name, values[param.name]
        if control.kind == "combo":
            index = control.options.index(value) if value in control.options else 0
            changed, index = imgui.combo(name, index, list(control.options))
            new = control.options[index]
        elif control.kind == "checkbox":
            changed, new = imgui.checkbox(name, bool(value))
        elif control.kind == "slider_int":
            changed, new = imgui.slider_int(name, int(value), int(control.low), int(control.high))
        elif control.kind == "slider_float":
            changed, new = imgui.slider_float(name, float(value), control.low, control.high, "%.3g")
        else:  # free text (a file path...): parsed by the parameter when Enter is pressed
            text = self.texts.get(name, to_text(param, value))
            entered, self.texts[name] = imgui.input_text(name, text, imgui.InputTextFlags_.enter_returns_true)
            changed, new = False, value
            if entered:
                try:
                    new, changed = parse_value(param, self.texts.pop(name)), True
                except SandboxError as exc:  # refused: shown in red, the value and the window stay
                    self.message = f"error: {exc}"
                    print(self.message, file=sys.stderr, flush=True)
        self._item(name)
        if imgui.is_item_hovered():
            imgui.set_item_tooltip(param.help)
        if changed:
            values[name] = new
            self.message = ""

    def _uniform(self, session: Session, control: Control) -> None:
        """One uniform of the scene's own shader (``u.NAME``); a change goes into the lesson's
        values, and the next frame draws the scene with it (as ``--set u.NAME=...`` does)."""
        imgui = self.imgui
        name, values = control.param.name, session.lesson.values
        value = values.get(name, control.param.default)
        if control.kind == "checkbox":
            changed, new = imgui.checkbox(name, bool(value))
        elif control.kind == "slider_float":
            changed, new = imgui.slider_float(name, float(value), control.low, control.high, "%.3g")
        elif control.kind == "color":
            edit = imgui.color_edit3 if len(value) == 3 else imgui.color_edit4
            changed, new = edit(name, [float(v) for v in value])
        else:  # 2 to 4 numbers: dragged, at a speed that fits their size
            speed = 0.01 * max(1.0, max(abs(float(v)) for v in value))
            changed, new = getattr(imgui, f"drag_float{len(value)}")(name, [float(v) for v in value], speed)
        self._item(name)
        if imgui.is_item_hovered():
            imgui.set_item_tooltip(f"{control.param.help} (--set {name}=...)")
        if changed:
            values[name] = uniform_value(control, new)
            self.message = ""

    def _time(self, session: Session, now: float) -> None:
        imgui, clock, values = self.imgui, session.clock, session.lesson.values
        imgui.separator_text("time")
        changed, paused = imgui.checkbox("pause", clock.paused)
        self._item("pause")
        if changed:
            clock.pause(paused, now)
        current = float(values["time"])
        changed, scrubbed = imgui.slider_float("time", current, 0.0, max(60.0, current), "%.2f s")
        self._item("time")
        if changed:
            clock.set(scrubbed, now)
            values["time"] = clock.time(now)
        for label, step in (("step -", -TIME_STEP), ("step +", TIME_STEP)):
            if imgui.button(label):
                clock.set(current, now)
                clock.step(step, now)
                values["time"] = clock.time(now)
            self._item(label)
            imgui.same_line()
        imgui.new_line()

    def _camera(self, session: Session) -> None:
        imgui = self.imgui
        imgui.separator_text("camera")
        fly = session.camera.camera
        camera = fly.camera() if fly is not None else session.lesson.scene().camera
        imgui.text(f"eye    {camera.eye[0]:.3f}, {camera.eye[1]:.3f}, {camera.eye[2]:.3f}")
        imgui.text(f"target {camera.target[0]:.3f}, {camera.target[1]:.3f}, {camera.target[2]:.3f}")
        imgui.text(f"turns  {fly.turns if fly is not None else 0} x 15 deg"
                   + ("" if fly is not None else " (the lesson's camera)"))
        if imgui.button("reset camera"):
            session.camera.reset()
        self._item("reset camera")
        imgui.same_line()
        if imgui.button("copy --set line"):
            line = session.drawn_line()
            self.glfw.set_clipboard_string(self.window, line)
            print(f"set line: {line}", file=sys.stderr, flush=True)
            self.message = "copied: glsandbox render LESSON + that line"
        self._item("copy --set line")
        imgui.text_disabled("glsandbox render LESSON ...")
        imgui.text_wrapped(session.drawn_line())

    def _live(self, session: Session, live: LiveCompare) -> None:
        imgui = self.imgui
        names = [p.name for p in session.lesson.all_params() if p.name not in ("camera", "effects")]
        changed, live.enabled = imgui.checkbox("split into tiles", live.enabled)
        self._item("split into tiles")
        own = [p.name for p in type(session.lesson).params]  # start with the lesson's first own parameter
        index = names.index(live.param) if live.param in names else names.index(own[0]) if own else 0
        picked, index = imgui.combo("vary", index, names)
        self._item("vary")
        if picked or live.param not in names:
            live.param = names[index]
            live.texts = suggested_values(session, live.param)
        text = self.texts.get("live", ",".join(live.texts))
        entered, self.texts["live"] = imgui.input_text("values", text, imgui.InputTextFlags_.enter_returns_true)
        self._item("values")
        if entered:
            live.texts = [t.strip() for t in self.texts.pop("live").split(",") if t.strip()]
        _, live.difference = imgui.checkbox("difference view", live.difference)
        self._item("difference view")
        if session.compare_error:
            imgui.text_colored((1.0, 0.5, 0.4, 1.0), session.compare_error)

    def _write_layout(self) -> None:
        if self.layout_path and self.layout != self._written:
            self._written = dict(self.layout)
            write_text(Path(self.layout_path), json.dumps({"rect": self.rect, "items": self.layout}))

    def close(self) -> None:
        self.imgui.backends.opengl3_shutdown()
        self.imgui.destroy_context(self.context)


#: What F1 says in a window without the panel: imgui-bundle is the optional ``panel`` extra.
INSTALL_HINT = ("the live controls panel needs imgui-bundle: pip install \"glsandbox[panel]\" "
                "(from the repository: uv sync --extra panel)")


def panel_available() -> bool:
    """Whether imgui-bundle (the ``panel`` extra) imports; only a window asks, and it needs it then."""
    try:
        import imgui_bundle  # noqa: F401
    except ImportError:
        return False
    return True


class NoPanel:
    """Stands in for :class:`Panel` when imgui-bundle is not installed.

    The window works as before (keys, camera, reloads, screenshots); F1, which
    would show the panel, prints one line saying how to install it.
    """

    visible = False

    def toggle(self) -> None:
        print(f"note: {INSTALL_HINT}", file=sys.stderr, flush=True)

    def draw(self, session: Session) -> None:
        return None

    def close(self) -> None:
        return None


def open_panel(window: Any) -> Panel | NoPanel:
    """The window's panel, or a :class:`NoPanel` when the ``panel`` extra is not installed."""
    return Panel(window) if panel_available() else NoPanel()


def suggested_values(session: Session, name: str) -> list[str]:
    """Values to start a live compare with: every choice (or order), on and off, or the value and its double."""
    param = {p.name: p for p in session.lesson.all_params()}[name]
    value = session.lesson.values[name]
    control = control_for(param, value)
    if control.kind == "combo":
        return list(control.options)
    if control.kind == "checkbox":
        return ["on", "off"]
    if control.kind.startswith("slider"):
        return [to_text(param, value), to_text(param, param.kind(value * 2 if value else 1))]
    return [to_text(param, value)]


def _key_map(glfw: Any, imgui: Any) -> dict[int, Any]:
    """glfw key codes -> ImGui keys, for the keys a text field or slider uses."""
    named = {glfw.KEY_TAB: "tab", glfw.KEY_LEFT: "left_arrow", glfw.KEY_RIGHT: "right_arrow",
             glfw.KEY_UP: "up_arrow", glfw.KEY_DOWN: "down_arrow", glfw.KEY_PAGE_UP: "page_up",
             glfw.KEY_PAGE_DOWN: "page_down", glfw.KEY_HOME: "home", glfw.KEY_END: "end",
             glfw.KEY_INSERT: "insert", glfw.KEY_DELETE: "delete", glfw.KEY_BACKSPACE: "backspace",
             glfw.KEY_SPACE: "space", glfw.KEY_ENTER: "enter", glfw.KEY_ESCAPE: "escape",
             glfw.KEY_KP_ENTER: "keypad_enter", glfw.KEY_LEFT_CONTROL: "left_ctrl",
             glfw.KEY_RIGHT_CONTROL: "right_ctrl", glfw.KEY_LEFT_SHIFT: "left_shift",
             glfw.KEY_RIGHT_SHIFT: "right_shift"}
    keys = {code: getattr(imgui.Key, name) for code, name in named.items()}
    for letter in "ACVXYZ":  # copy, paste, select all, undo in text fields
        keys[getattr(glfw, f"KEY_{letter}")] = getattr(imgui.Key, letter.lower())
    return keys
