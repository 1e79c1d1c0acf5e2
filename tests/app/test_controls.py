"""The live controls' model (no imgui, no GL): widgets per parameter, --set text, the clock."""

from __future__ import annotations

import shlex

import pytest
from support import write_uniform_scene

from glsandbox.camera import CameraInput
from glsandbox.app.controls import (Clock, LiveCompare, Session, camera_numbers, control_for, lesson_controls,
                                number_range, set_line, shader_uniforms, to_text, uniform_controls, uniform_value)
from glsandbox.errors import SandboxError
from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.transforms import ORDERS


def test_every_lesson_parameter_has_a_fitting_control_and_its_value_round_trips() -> None:
    for cls in all_lessons():
        lesson = cls()
        controls = {c.param.name: c for c in lesson_controls(lesson)}
        assert set(controls) == {p.name for p in cls.all_params()} - {"time", "camera"}, cls.name
        for name, control in controls.items():
            param, value = control.param, lesson.values[name]
            assert param.parse(to_text(param, value)) == value, (cls.name, name)
            expected = ("combo" if param.choices or name == "order" else "checkbox" if param.kind is bool
                        else "slider_int" if param.kind is int else "slider_float" if param.kind is float else "text")
            assert control.kind == expected, (cls.name, name)
            if control.kind.startswith("slider"):
                assert control.low <= value <= control.high
                assert param.minimum is None or control.low >= param.minimum
                assert param.maximum is None or control.high <= param.maximum


def test_the_order_parameter_offers_the_six_orders() -> None:
    lesson = find_lesson("transform_order")()
    order = next(c for c in lesson_controls(lesson) if c.param.name == "order")
    assert order.kind == "combo" and order.options == ORDERS and len(ORDERS) == 6


def test_number_ranges_follow_the_bounds_and_widen_for_the_current_value() -> None:
    phong = {p.name: p for p in find_lesson("phong").all_params()}
    assert number_range(phong["lights"], 2) == (0, 2)
    assert number_range(phong["speed"], 0.8) == (-3.2, 3.2)
    assert number_range(phong["speed"], 9.0) == (-3.2, 9.0)  # keys or --set took it further
    assert control_for(phong["speed"], 0.8).kind == "slider_float"


def test_floats_and_cameras_print_as_the_exact_text_that_parses_back() -> None:
    mirror = {p.name: p for p in find_lesson("mirror").all_params()}
    value = 0.1 + 0.2  # 0.30000000000000004: the shortest repr keeps every bit
    assert mirror["lx"].parse(to_text(mirror["lx"], value)) == value
    numbers = (0.1 + 0.2, 3.0, 10.0, 1e-7, 0.0, 0.0, 45.0, 0.01, 100.0)
    assert mirror["camera"].parse(to_text(mirror["camera"], numbers)) == numbers
    with pytest.raises(SandboxError, match="camera=1,2,3: expected eye"):
        mirror["camera"].parse("1,2,3")


def test_set_line_lists_the_changed_values_and_the_moved_camera() -> None:
    cls = find_lesson("indexed_cube")
    lesson = cls(speed=0.0, flip="front", time=1.5)
    assert set_line(lesson, (320, 240)) == "--size 320x240 --set time=1.5 --set speed=0.0 --set flip=front"
    camera = CameraInput()
    assert camera_numbers(camera) is None
    camera.key("a", lesson.scene())
    line = set_line(lesson, (320, 240), 4, camera_numbers(camera))
    args = shlex.split(line)
    assert args[:4] == ["--size", "320x240", "--samples", "4"]
    settings = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    rebuilt = cls.from_settings(settings)
    assert rebuilt.values["speed"] == 0.0 and rebuilt.values["flip"] == "front"
    assert rebuilt.scene().camera == camera.apply(lesson.scene()).camera  # the same floats, bit for bit


def test_the_clock_runs_pauses_scrubs_and_steps() -> None:
    clock = Clock(2.0, wall=100.0)
    assert clock.time(101.5) == 3.5
    clock.pause(True, 101.5)
    assert clock.time(200.0) == 3.5
    clock.pause(False, 200.0)
    assert clock.time(201.0) == 4.5
    clock.set(10.0, 201.0)
    assert clock.time(202.0) == 11.0
    clock.step(-0.5, 202.0)
    assert clock.paused and clock.time(300.0) == 10.5
    clock.set(-3.0, 300.0)
    assert clock.time(300.0) == 0.0  # time is never negative (the parameter's minimum)


def test_live_compare_builds_the_compare_variants_from_the_current_values() -> None:
    lesson = find_lesson("phong")(speed=0.0)
    live = LiveCompare("shading", ["phong", "gouraud"], enabled=True)
    assert live.active() and not LiveCompare("shading", ["phong"], enabled=True).active()
    variants, columns = live.variants(lesson)
    assert [v.label for v in variants] == ["shading=phong", "shading=gouraud"] and columns == 2
    assert repr(variants[1].scene) == repr(find_lesson("phong")(speed=0.0, shading="gouraud").scene())
    with pytest.raises(SandboxError, match="shading=flat: expected one of"):
        LiveCompare("shading", ["phong", "flat"], enabled=True).variants(lesson)


def test_the_session_keeps_the_drawn_frame_not_later_edits() -> None:
    from glsandbox.app.controls import Session
    from glsandbox.plan import plan

    lesson = find_lesson("phong")(speed=0.0)
    session = Session(lesson, Clock(0.0, 0.0), 2, CameraInput())
    assert session.drawn_line() == "" and session.plan_text() == ""
    session.record((320, 240), plan(lesson.scene()))
    lesson.values["specular"] = False  # a panel edit after the frame: the next frame's
    assert session.drawn_line() == "--size 320x240 --samples 2 --set speed=0.0"
    assert session.plan_text() == plan(find_lesson("phong")(speed=0.0).scene()).describe()


def scene_file_with_uniforms(tmp_path):
    from glsandbox.lesson import scene_file_lesson

    return scene_file_lesson(write_uniform_scene(tmp_path))


def test_a_scene_files_uniforms_get_widgets_typed_from_their_values(tmp_path) -> None:
    cls = scene_file_with_uniforms(tmp_path)
    lesson = cls()
    uniforms = shader_uniforms(lesson.scene())
    assert uniforms == {"gain": 0.5, "base_color": (1.0, 0.5, 0.0), "offset": (0.1, 0.2), "flat_look": True}
    controls = {c.param.name: c for c in uniform_controls(uniforms)}
    assert {name: c.kind for name, c in controls.items()} == {
        "u.gain": "slider_float", "u.base_color": "color", "u.offset": "drag_floats", "u.flat_look": "checkbox"}
    gain = controls["u.gain"]
    assert (gain.low, gain.high) == number_range(gain.param, 0.5) == (-2.0, 2.0)
    assert controls["u.base_color"].param.default == (1.0, 0.5, 0.0)
    # A widget's output becomes the value --set u.NAME would give, and the next scene has it.
    assert uniform_value(controls["u.base_color"], [0.2, 1.5, -0.1]) == (0.2, 1.0, 0.0)
    assert uniform_value(controls["u.offset"], [3, -4]) == (3.0, -4.0)
    assert uniform_value(gain, 1) == 1.0 and uniform_value(controls["u.flat_look"], 0) is False
    lesson.values["u.gain"] = uniform_value(gain, 1.25)
    lesson.values["u.base_color"] = (0.0, 1.0, 0.0)
    moved = shader_uniforms(lesson.scene())
    assert moved["gain"] == 1.25 and moved["base_color"] == (0.0, 1.0, 0.0) and moved["offset"] == (0.1, 0.2)
    # The window's copied line carries them: rendering it headless gives the same uniforms.
    args = shlex.split(set_line(lesson, (64, 48)))
    settings = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    assert "u.gain=1.25" in settings and "u.base_color=0.0,1.0,0.0" in settings
    assert shader_uniforms(cls.from_settings(settings).scene()) == moved


def test_the_session_keeps_the_drawn_scenes_uniforms_and_a_scene_without_gets_none(tmp_path) -> None:
    lesson = scene_file_with_uniforms(tmp_path)()
    session = Session(lesson, Clock(0.0, 0.0), 0, CameraInput())
    assert session.uniforms == {} and uniform_controls(session.uniforms) == []
    session.record((64, 48), None, lesson.scene())
    assert set(session.uniforms) == {"gain", "base_color", "offset", "flat_look"}
    session.record((64, 48), None, find_lesson("phong")().scene())
    assert session.uniforms == {}
    with pytest.raises(SandboxError, match="u.offset"):
        uniform_value(uniform_controls({"offset": (0.0, 0.0)})[0], [float("inf"), 0.0])
