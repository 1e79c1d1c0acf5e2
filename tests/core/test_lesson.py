"""Lessons from files outside the package: loading, their errors, reloading, the window's keys on them
(`glsandbox new` and `tour --lessons`: tests/cli/test_cli.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from glsandbox.errors import SandboxError
from glsandbox.files import load_png
from glsandbox.lesson import all_lessons, find_lesson, lesson_files
from glsandbox.measure.golden import compare_images
from support import SPIN, LessonWindow, assert_user_error, run_cli, wait_for

NAMELESS = '''
from glsandbox import Lesson, Node, Scene, geometry

class Box(Lesson):
    def build(self) -> Scene:
        return Scene("box", nodes=(Node("cube", geometry.cube()),))
'''


def test_a_lesson_file_loads_with_its_parameters_and_leaves_the_registry_alone(tmp_path: Path) -> None:
    builtin = {cls.name: cls for cls in all_lessons()}
    path = tmp_path / "spin.py"
    path.write_text(SPIN)
    cls = find_lesson(str(path))
    assert cls.__name__ == "Spin" and cls.name == "phong"
    lesson = cls.from_settings(["speed=2", "time=0.25"])
    assert lesson.values["speed"] == 2.0 and lesson.time == 0.25
    # @register in a user's file reaches neither the registry nor the tour
    assert {c.name: c for c in all_lessons()} == builtin
    assert find_lesson("phong") is builtin["phong"]
    # loaded afresh each time: an edited file is seen
    path.write_text(SPIN.replace('"radians per second"', '"turns"'))
    assert find_lesson(str(path)).params[0].help == "turns"


def test_a_nameless_lesson_takes_the_file_stem_and_a_helper_module_beside_it_imports(tmp_path: Path) -> None:
    (tmp_path / "box_helpers.py").write_text("SIZE = 3\n")
    path = tmp_path / "my_box.py"
    path.write_text("import box_helpers\n" + NAMELESS)
    cls = find_lesson(str(path))
    assert cls.name == "my_box" and "my_box.py" in cls.title
    assert str(tmp_path) not in __import__("sys").path  # the folder was on sys.path only while importing


def test_unknown_lesson_suggests_the_closest_name() -> None:
    with pytest.raises(SandboxError, match="did you mean 'indexed_cube'"):
        find_lesson("indexed_cub")


def test_lesson_picks_one_of_several(tmp_path: Path) -> None:
    path = tmp_path / "two.py"
    path.write_text(NAMELESS + NAMELESS.replace("class Box", "class Other").split("\n", 3)[3] + "\nLESSON = Other\n")
    assert find_lesson(str(path)).__name__ == "Other"


@pytest.mark.parametrize("text, fragments", [
    (None, ["lesson file", "missing.py not found"]),
    ("x = (\n", ["bad.py:1: syntax error"]),
    ("import math\n\nx = 1 / 0\n", ["bad.py:3: ZeroDivisionError while importing: division by zero"]),
    ("import no_such_module_here\n", ["bad.py:1: ModuleNotFoundError while importing", "no_such_module_here"]),
    ("import sys\nsys.exit(3)\n", ["bad.py: exited while importing", "__main__"]),
    ("x = 1\n", ["bad.py: defines no Lesson subclass"]),
    (NAMELESS + NAMELESS.replace("class Box", "class Other").split("\n", 3)[3],
     ["bad.py: defines 2 Lesson subclasses (Box, Other)", "LESSON = TheClass"]),
    ("LESSON = 3\n", ["bad.py: LESSON must be a Lesson subclass, got 3"]),
])
def test_bad_lesson_files_are_one_line_naming_the_file(tmp_path: Path, text: str | None, fragments: list[str]) -> None:
    path = tmp_path / ("missing.py" if text is None else "bad.py")
    if text is not None:
        path.write_text(text)
    with pytest.raises(SandboxError) as caught:
        find_lesson(str(path))
    for fragment in fragments:
        assert fragment in str(caught.value), str(caught.value)


def test_bad_lesson_files_end_to_end(tmp_path: Path) -> None:
    (tmp_path / "bad.py").write_text("import math\n\nx = 1 / 0\n")
    (tmp_path / "notes.txt").write_text("hello\n")
    out = tmp_path / "x.png"
    for command in ("render", "plan", "compare", "run"):
        extra = ["--out", str(out)] if command == "render" else []
        assert_user_error(run_cli(command, str(tmp_path / "bad.py"), *extra), "bad.py:3: ZeroDivisionError")
    assert_user_error(run_cli("render", str(tmp_path / "notes.txt"), "--out", str(out)),
                      "notes.txt: expected a lesson name, a lesson .py file or a scene .toml file")
    assert_user_error(run_cli("render", str(tmp_path), "--out", str(out)), "expected a lesson name")
    assert_user_error(run_cli("render", str(tmp_path / "nope.py"), "--out", str(out)), "nope.py not found")
    assert not out.exists()


def test_render_plan_and_compare_a_lesson_file(tmp_path: Path, gl) -> None:
    path = tmp_path / "spin.py"
    path.write_text(SPIN)
    out = tmp_path / "spin.png"
    proc = run_cli("render", str(path), "--out", str(out), "--size", "64x48", "--set", "speed=2")
    assert proc.returncode == 0, proc.stderr
    image = load_png(out)
    assert image.shape == (48, 64, 4) and (image[24, 32, :3] > 200).all()  # the white cube in the middle
    assert "plan for phong" in run_cli("plan", str(path)).stdout
    proc = run_cli("compare", str(path), "--vary", "time=0,1", "--size", "128x48", "--out", str(tmp_path / "c.png"))
    assert proc.returncode == 0, proc.stderr
    assert "distinct pictures: 2" in proc.stdout
    assert_user_error(run_cli("render", str(path), "--out", str(out), "--set", "sped=2"),
                      "has no parameter 'sped'", "did you mean 'speed'")


def test_lesson_files_rule(tmp_path: Path) -> None:
    for name in ("b.py", "b.toml", "a.toml", "notes.txt", "_private.py", "sub/lesson.py", "sub/scene.toml",
                 "scene_only/x.toml", "empty/readme.md", "two/p.py", "two/q.py"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    found = {name: path.relative_to(tmp_path).as_posix() for name, path in lesson_files(tmp_path)}
    assert found == {"a": "a.toml", "b.py": "b.py", "b.toml": "b.toml", "sub": "sub/lesson.py",
                     "scene_only": "scene_only/x.toml", "empty": "empty", "two": "two"}


@pytest.mark.slow
def test_a_lesson_file_in_a_window_with_the_window_keys(window_env: str, tmp_path: Path, gl) -> None:
    assert run_cli("new", "mine", "--dir", str(tmp_path)).returncode == 0
    win = LessonWindow(window_env, tmp_path, "glsandbox.cli", "run", "mine.py", "--size", "320x240",
                       "--set", "speed=0")
    try:
        assert win.wait_title(lambda t: "fps" in t).startswith("glsandbox: mine | ")
        win.key("F12")
        shot = load_png(wait_for(tmp_path / "screenshots" / "mine-1.png"))
    finally:
        code = win.close()
    assert code == 0
    headless = gl.render(find_lesson(str(tmp_path / "mine.py")).from_settings(["speed=0"]), (320, 240)).image
    assert compare_images(shot, headless).passed  # the window shows what headless renders


def test_a_lesson_file_may_subclass_a_builtin_lesson(tmp_path: Path) -> None:
    # In a fresh interpreter, so the user's file is the first to import lessons.triangle
    # (its @register runs inside the loader, and must survive it).
    import subprocess
    import sys

    path = tmp_path / "my_triangle.py"
    path.write_text("from glsandbox.lessons.triangle import Triangle\n\nclass MyTriangle(Triangle):\n    name = 'my_triangle'\n")
    script = ("import sys; from glsandbox.lesson import find_lesson; "
              "cls = find_lesson(sys.argv[1]); base = find_lesson('triangle'); "
              "print(cls.__name__, cls.name, issubclass(cls, base), base.name)")
    proc = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True, timeout=120)
    assert proc.stdout.split() == ["MyTriangle", "my_triangle", "True", "triangle"], proc.stderr


COLORED = '''
from glsandbox import Lesson, Scene

class Flat(Lesson):
    def build(self) -> Scene:
        return Scene("flat", clear_color=COLOR)
'''


@pytest.mark.slow
def test_saving_a_lesson_file_reloads_it_in_the_window(window_env: str, tmp_path: Path) -> None:
    """Saving the lesson file redraws the window with the new code; a mistake saved (a syntax
    error, an exception in build()) keeps the last good lesson drawing and shows the error
    with the file and line; the fixed file draws again."""
    path = tmp_path / "flat.py"
    path.write_text(COLORED.replace("COLOR", "(0.0, 1.0, 0.0, 1.0)"))
    win = LessonWindow(window_env, tmp_path, "glsandbox.cli", "run", "flat.py", "--size", "320x240")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.key("F1")  # the panel hides: the pixel looked at is the frame's
        win._wait(lambda: tuple(win.screen()[120, 160]) == (0, 255, 0))
        path.write_text(COLORED.replace("COLOR", "(1.0, 0.0, 0.0, 1.0)"))  # saved: no key pressed
        win._wait(lambda: tuple(win.screen()[120, 160]) == (255, 0, 0))
        path.write_text(COLORED.replace("COLOR", "(1.0, 0.0, 0.0, 1.0))"))  # one parenthesis too many
        title = win.wait_title(lambda t: "lesson error" in t)
        assert "flat.py:6: syntax error" in title, title  # the path as given: run flat.py
        assert tuple(win.screen()[120, 160]) == (255, 0, 0)  # still the last good lesson
        path.write_text(COLORED.replace("COLOR", "(0.0, 0.0, 1.0, 1.0)").replace("return", "1 / 0\n        return"))
        win.wait_title(lambda t: "ZeroDivisionError" in t and "flat.py:6" in t)
        path.write_text(COLORED.replace("COLOR", "(0.0, 0.0, 1.0, 1.0)"))
        win._wait(lambda: tuple(win.screen()[120, 160]) == (0, 0, 255))
        assert "lesson error" not in win.wait_title(lambda t: "fps" in t and "error" not in t)
    finally:
        code = win.close()
    assert code == 0
    err = win.proc.stderr.read()
    assert err.count("lesson reloaded") == 2 and "error: flat.py:6: syntax error" in err


def test_reloading_a_lesson_file_keeps_the_values_it_still_accepts(tmp_path: Path) -> None:
    from glsandbox.lesson import lesson_source, reload_lesson

    path = tmp_path / "spin.py"
    path.write_text(SPIN)
    lesson = find_lesson(str(path))(speed=2.5, time=1.25)
    assert lesson_source(type(lesson)) == path
    path.write_text(SPIN.replace('params = (Param("speed", 1.0, "radians per second"),)',
                                 'params = (Param("speed", 1.0, "radians per second"), Param("size", 0.5, "edge"))'))
    fresh = reload_lesson(lesson)
    assert type(fresh) is not type(lesson) and fresh.values["speed"] == 2.5 and fresh.time == 1.25
    assert fresh.values["size"] == 0.5  # the new parameter at its default
    path.write_text(SPIN.replace("speed", "rate"))
    assert reload_lesson(fresh).values["rate"] == 1.0  # a parameter gone: the new one's default
    path.write_text(SPIN.replace("return Scene", "return undefined_name or Scene"))
    with pytest.raises(SandboxError, match=r"NameError at .*spin\.py:\d+: name 'undefined_name' is not defined"):
        reload_lesson(fresh)
    with pytest.raises(SandboxError, match="built in"):
        reload_lesson(find_lesson("triangle")())
    scene_file = tmp_path / "box.toml"
    scene_file.write_text('name = "box"\n')
    assert lesson_source(find_lesson(str(scene_file))) == scene_file
