"""A student's plain mistakes in a lesson file are one line, in every command and in Python.

Each mistake below was a 26-46-line traceback from inside glsandbox, or a torn
picture with exit 0. Now each command that loads the lesson (render with each
renderer, plan, check, run) exits 2 with one ``error:`` line naming the file,
the line and the value, and writes nothing; the same mistake made in Python
raises :class:`SandboxError` with one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support import assert_user_error, glsandbox, run_cli

from glsandbox import Lesson, Mesh, Node, Param, SandboxError, Scene, geometry
from glsandbox.files import save_png

HEADER = "import numpy as np\nfrom glsandbox import Lesson, Mesh, Node, Param, Scene, geometry\n\n\n"
# The class statement is on line 5, the first line of build()'s body on line 7.
BUILD = "class Mine(Lesson):\n    def build(self):\n        {}\n"


def body(code: str) -> str:
    return HEADER + BUILD.format(code)


#: name -> (the lesson file, what its one error line must say)
MISTAKES: dict[str, tuple[str, list[str]]] = {
    "build returns None": (body('Scene("s")'), [":6:", "Mine.build() returned None", "forgotten return"]),
    "build returns an int": (body("return 5"), [":6:", "returned 5 (type int)", "must return a glsandbox.Scene"]),
    "build returns a str": (body('return "cube"'), [":6:", "returned 'cube' (type str)"]),
    "build returns a dict": (body('return {"nodes": ()}'), [":6:", "(type dict)"]),
    "nodes are numbers": (body('return Scene("s", nodes=(1, 2))'), [":7:", "nodes[0] must be a Node, got 1"]),
    "one node without a tuple": (body('return Scene("s", nodes=Node("c", geometry.cube()))'),
                                 [":7:", "nodes must be a tuple or list of Node", "needs a comma"]),
    "a mesh's name where a Mesh goes": (body('return Scene("s", nodes=(Node("c", "cube"),))'),
                                        [":7:", "node 'c': mesh must be a Mesh", "builtin_mesh('cube')",
                                         "got 'cube'"]),
    "params = 5": (HEADER + "class Mine(Lesson):\n    params = 5\n\n    def build(self):\n"
                   "        return Scene('s')\n", [":5:", "class Mine: params must be a tuple of Param", "got 5"]),
    "NaN positions": (body('return Scene("s", nodes=(Node("m", Mesh("m", np.array([(0, 0, 0), (1, 0, 0), '
                           '(np.nan, 1, 0)]))),))'), [":7:", "mesh 'm': positions[2] is not finite", "nan"]),
    "an index past the vertices": (body('return Scene("s", nodes=(Node("m", Mesh("m", np.eye(3), '
                                        'np.array([0, 1, 7], dtype=np.uint32))),))'),
                                   [":7:", "mesh 'm': indices[2] = 7 names no vertex", "it has 3"]),
    "a default not among the choices": (HEADER + "class Mine(Lesson):\n    params = (Param('mode', 'x', 'm', "
                                        "choices=('a', 'b')),)\n\n    def build(self):\n        return Scene('s')\n",
                                        [":6:", "Param 'mode': default 'x' is not one of its choices (a, b)"]),
    "two params with one name": (HEADER + "class Mine(Lesson):\n    params = (Param('k', 1.0, 'a'), "
                                 "Param('k', 2.0, 'b'))\n\n    def build(self):\n        return Scene('s')\n",
                                 [":5:", "class Mine: parameter 'k' defined again", "two parameters"]),
    "a param named like a shared one": (HEADER + "class Mine(Lesson):\n    params = (Param('time', 1.0, 'a'),)\n\n"
                                        "    def build(self):\n        return Scene('s')\n",
                                        [":5:", "parameter 'time' defined again", "every lesson has it"]),
}


def one_error(folder: Path, *args: str) -> str:
    """Run the CLI in this process; the contract (exit 2, one ``error:`` line, nothing left in
    ``folder``) is checked by :func:`support.run_cli`; returns the line."""
    run = run_cli(*args, unchanged=folder)
    assert run.returncode == 2, run
    return run.stderr.strip()


@pytest.fixture
def lesson_file(tmp_path: Path, request: pytest.FixtureRequest) -> tuple[Path, list[str]]:
    source, expected = MISTAKES[request.param]
    path = tmp_path / "mine.py"
    path.write_text(source)
    return path, expected


def assert_names(line: str, path: Path, expected: list[str]) -> None:
    assert str(path) in line, line
    for part in expected:
        assert part in line, (part, line)


@pytest.mark.parametrize("lesson_file", list(MISTAKES), indirect=True)
def test_render_with_each_renderer_and_plan_say_one_line(lesson_file, tmp_path: Path, gl) -> None:
    path, expected = lesson_file
    out = tmp_path / "out.png"
    for renderer in ("raster", "ray", "ray_numpy"):
        line = one_error(tmp_path, "render", str(path), "--size", "32x24", "--set", f"renderer={renderer}",
                         "--out", str(out))
        assert_names(line, path, expected)
    assert_names(one_error(tmp_path, "plan", str(path)), path, expected)


@pytest.mark.parametrize("lesson_file", ["build returns None", "an index past the vertices",
                                         "a default not among the choices"], indirect=True)
def test_check_against_a_golden_says_one_line(lesson_file, tmp_path: Path, gl) -> None:
    path, expected = lesson_file
    reference = tmp_path / "ref.png"
    save_png(np.zeros((24, 32, 4), dtype=np.uint8), reference)
    before = reference.read_bytes()
    assert_names(one_error(tmp_path, "check", str(path), "--golden", str(reference)), path, expected)
    assert reference.read_bytes() == before


@pytest.mark.slow
@pytest.mark.parametrize("lesson_file", ["build returns None", "NaN positions", "params = 5"], indirect=True)
def test_run_says_one_line_and_leaves_no_window(lesson_file, tmp_path: Path, xvfb_display: str) -> None:
    """``glsandbox run`` in its own process (a window and this process's EGL context do not mix)."""
    path, expected = lesson_file
    before = set(tmp_path.rglob("*"))
    proc = glsandbox("run", str(path), env={"DISPLAY": xvfb_display, "WAYLAND_DISPLAY": ""}, cwd=tmp_path)
    assert_user_error(proc)
    assert_names(proc.stderr.strip(), path, expected)
    assert set(tmp_path.rglob("*")) == before


# --- the same mistakes made in Python ------------------------------------------


def one_line(excinfo: pytest.ExceptionInfo[SandboxError]) -> str:
    text = str(excinfo.value)
    assert "\n" not in text
    return text


def test_build_returning_something_else_is_refused_with_its_file_and_line() -> None:
    for value, shown in ((None, "returned None (a forgotten return?)"), (3, "returned 3 (type int)"),
                         ("s", "returned 's' (type str)"), ({}, "returned {} (type dict)")):
        class Mine(Lesson):
            name = "mine"

            def build(self, value=value):
                return value

        with pytest.raises(SandboxError) as excinfo:
            Mine().scene()
        text = one_line(excinfo)
        assert shown in text and f"{__file__}:" in text, text


def test_scene_and_node_parts_of_the_wrong_kind_are_refused() -> None:
    cube = geometry.cube()
    for make, shown in ((lambda: Scene("s", nodes=(1, 2)), "scene 's': nodes[0] must be a Node, got 1"),
                        (lambda: Scene("s", lights=((0, 1, 0),)), "lights[0] must be a Light"),
                        (lambda: Scene("s", camera=None), "camera must be a Camera, got None"),
                        (lambda: Scene("s", samples="4"), "samples must be a whole number >= 0, got '4'"),
                        (lambda: Node("c", "cube"), "node 'c': mesh must be a Mesh"),
                        (lambda: Node("c", cube, material="red"), "material must be a Material, got 'red'")):
        with pytest.raises(SandboxError) as excinfo:
            make()
        assert shown in one_line(excinfo)
    # what is right still passes: lists become tuples, None stays None
    scene = Scene("s", nodes=[Node("c", cube)], mirror=None)
    assert isinstance(scene.nodes, tuple)


def test_a_mesh_is_checked_where_it_is_made() -> None:
    three = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0)], dtype=np.float64)
    cases = [
        (lambda: Mesh("m", np.array([(0, 0, 0), (1, 0, 0), (np.nan, 1, 0)])), "positions[2] is not finite"),
        (lambda: Mesh("m", three, np.array([0, 1, 3])), "indices[2] = 3 names no vertex; it has 3 (indices 0..2)"),
        (lambda: Mesh("m", three, np.array([0, -1, 2])), "indices[1] = -1 names no vertex"),
        (lambda: Mesh("m", three, np.array([0.0, 1.0, 2.0])), "indices must be a flat array of integers"),
        (lambda: Mesh("m", three, np.array([0, 1, 2, 0])), "4 indices do not make whole triangles"),
        (lambda: Mesh("m", three[:2]), "2 vertices do not make whole triangles"),
        (lambda: Mesh("m", three, normals=np.zeros((2, 3))), "2 normals for 3 positions"),
        (lambda: Mesh("m", three, uvs=np.zeros((3, 3))), "uvs must be an (N, 2) array"),
        (lambda: Mesh("m", "abc"), "positions must be an array of numbers"),
    ]
    for make, shown in cases:
        with pytest.raises(SandboxError) as excinfo:
            make()
        assert f"mesh 'm': {shown}" in one_line(excinfo)
    # lists are taken, (T, 3) indices are the flat buffer, and the arrays are frozen
    mesh = Mesh("ok", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    assert mesh.positions.dtype == np.float64 and mesh.indices.tolist() == [0, 1, 2]
    assert mesh.element_count == 3 and not mesh.positions.flags.writeable
    assert Mesh("strip", three[:2], mode="triangle_strip").triangle_indices().shape == (0, 3)


def test_every_built_in_mesh_passes_the_check() -> None:
    for name, make in geometry.BUILTIN_MESHES.items():
        mesh = make()
        assert mesh.indices is None or int(mesh.indices.max()) < mesh.vertex_count, name


def test_lesson_class_mistakes_are_refused_where_the_class_is_defined() -> None:
    with pytest.raises(SandboxError) as excinfo:
        class Five(Lesson):
            params = 5
    text = one_line(excinfo)
    assert "class Five: params must be a tuple of Param(...), got 5" in text and f"{__file__}:" in text

    with pytest.raises(SandboxError) as excinfo:
        Param("mode", "x", "m", choices=("a", "b"))
    assert one_line(excinfo) == "Param 'mode': default 'x' is not one of its choices (a, b)"

    with pytest.raises(SandboxError) as excinfo:
        Param("speed", 5.0, "s", minimum=0.0, maximum=1.0)
    assert "default 5.0 is outside its range 0.0..1.0" in one_line(excinfo)

    with pytest.raises(SandboxError) as excinfo:
        class Twice(Lesson):
            params = (Param("k", 1.0, "a"), Param("k", 2.0, "b"))
    assert "class Twice: parameter 'k' defined again (two parameters have that name)" in one_line(excinfo)

    with pytest.raises(SandboxError) as excinfo:
        class Ray(Lesson):
            defaults = {"renderer": "rays"}
    assert "defaults renderer='rays' is not one of raster, ray, ray_numpy" in one_line(excinfo)

    class Listed(Lesson):  # a list of Params is taken as a tuple
        params = [Param("k", 1.0, "a")]
    assert Listed.params == (Param("k", 1.0, "a"),) and Listed(k=2.0).values["k"] == 2.0


def test_every_built_in_lesson_still_loads() -> None:
    from glsandbox.lesson import all_lessons

    lessons = all_lessons()
    assert len(lessons) > 10
    for cls in lessons:  # each has valid params and defaults (checked as it was defined)
        assert cls().values["renderer"] == cls.defaults.get("renderer", "raster")


def test_a_mesh_of_a_lesson_is_checked_once_not_per_frame(monkeypatch) -> None:
    """The cached built-in meshes are made once: drawing them again costs no check."""
    calls = []
    original = geometry.check_mesh_arrays
    monkeypatch.setattr(geometry, "check_mesh_arrays", lambda mesh: calls.append(mesh.name) or original(mesh))
    from glsandbox.lesson import find_lesson

    lesson = find_lesson("indexed_cube")()
    lesson.scene()  # may make (and check) the lesson's meshes once
    first = len(calls)
    for t in (0.1, 0.2, 0.3):
        lesson.at(t).scene()
    assert len(calls) == first, calls[first:]

