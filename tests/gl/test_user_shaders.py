"""A node's own shader (glsandbox/gl/user_shaders.py; docs/your-own.md, "Your own shader"): scene files, Python, the
errors that name the user's file, --set u.NAME, reload and the file watch,
the ray tracer's note, and the toon example."""

from __future__ import annotations

import os
import re
import shutil
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from support import REPO_ROOT as REPO
from support import need

from glsandbox import cli
from glsandbox.errors import SandboxError
from glsandbox.files import load_png
from glsandbox.frame import HeadlessRenderer
from glsandbox.geometry import builtin_mesh
from glsandbox.app.file_watch import FileWatch
from glsandbox.lesson import find_lesson
from glsandbox.plan import plan
from glsandbox.scene import SHADER_INPUTS, Motion, Node, Scene, moved_scene
from glsandbox.scene_file import load_scene

TOON = REPO / "examples" / "toon" / "toon.toml"

TINT = """#version 330 core
// A flat colour of the scene's choosing.
uniform vec3 tint;
uniform float unused_knob;   // declared, never read: the compiler drops it
#if defined(VERTEX_SHADER)
#include "common/transform.glsl"
in vec3 in_position;
void main() { gl_Position = to_clip(in_position); }
#elif defined(FRAGMENT_SHADER)
out vec4 frag_color;
void main() {
    frag_color = vec4(tint, 1.0);
}
#endif
"""

SCENE = """name = "tinted"
[[nodes]]
name = "box"
mesh = "cube24"
shader = "tint.glsl"
[nodes.uniforms]
tint = [0, 1, 0]
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "tint.glsl").write_text(TINT)
    (tmp_path / "scene.toml").write_text(SCENE)
    return tmp_path


def render(folder: Path, capsys, *settings: str, scene: str = "scene.toml") -> tuple[int, str, Path]:
    """``glsandbox render`` in this process: (exit status, stderr, the PNG path)."""
    out = folder / "out.png"
    args = ["render", str(folder / scene), "--size", "64x64", "--out", str(out)]
    for item in settings:
        args += ["--set", item]
    status = cli.main(args)
    return status, capsys.readouterr().err, out


def assert_error(folder: Path, capsys, *fragments: str, settings: tuple[str, ...] = ()) -> str:
    status, err, out = render(folder, capsys, *settings)
    lines = err.strip().splitlines()
    assert status == 2 and len(lines) == 1 and lines[0].startswith("error: "), err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert not out.exists()
    return lines[0]


@pytest.fixture
def fresh(gl):
    """A renderer of the test's own: reloading recompiles every program an executor holds,
    and the shared one holds other tests' shaders."""
    with HeadlessRenderer() as renderer:
        yield renderer


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


# --- reading: scene files and Python -------------------------------------------


def test_a_scene_file_names_a_shader_relative_to_itself_with_its_uniforms(folder: Path) -> None:
    scene = load_scene(folder / "scene.toml")
    node = scene.nodes[0]
    assert node.shader == folder / "tint.glsl"
    assert dict(node.uniforms) == {"tint": (0.0, 1.0, 0.0)}
    variant = plan(scene).programs[0]
    assert variant.user and variant.shader == str(folder / "tint.glsl")
    assert f"box with {folder / 'tint.glsl'}[NUM_LIGHTS=0]" in plan(scene).describe()


def test_python_nodes_take_a_path_and_uniforms() -> None:
    node = Node("n", builtin_mesh("cube24"), shader="my.glsl", uniforms={"k": 2, "on": True, "v": [1, 2]})
    assert node.shader == Path.cwd() / "my.glsl" and dict(node.uniforms) == {"k": 2.0, "on": True, "v": (1.0, 2.0)}
    for bad, message in (({"k": "x"}, "uniform k must be a number"), ({"v": [1]}, "must be 2 or 3 or 4 numbers"),
                         ({"k": float("inf")}, "must be a finite number"), ({"m_model": 1}, "set by the renderer"),
                         ({"2x": 1}, "not a GLSL uniform name")):
        with pytest.raises(SandboxError, match=message):
            Node("n", builtin_mesh("cube24"), shader="my.glsl", uniforms=bad)
    with pytest.raises(SandboxError, match="uniforms need a shader"):
        Node("n", builtin_mesh("cube24"), uniforms={"k": 1})


@pytest.mark.parametrize(("old", "new", "expected"), [
    ('shader = "tint.glsl"', 'shader = "nope.glsl"', r"scene.toml:5: nodes\[0\].shader: shader file .*nope.glsl not found"),
    ("tint = [0, 1, 0]", "tint = [0, 1]\nk = [1]", r"scene.toml:8: nodes\[0\].uniforms.k must be 2 or 3 or 4 numbers"),
    ("tint = [0, 1, 0]", 'tint = "green"', r"scene.toml:7: nodes\[0\].uniforms.tint must be a number"),
    ("tint = [0, 1, 0]", "m_view = 1", r"scene.toml:7: nodes\[0\].uniforms.m_view: set by the renderer"),
    ('shader = "tint.glsl"\n', "", r"scene.toml:5: nodes\[0\].uniforms: needs shader"),
])
def test_scene_file_mistakes_name_the_line_and_key(folder: Path, old: str, new: str, expected: str) -> None:
    edit(folder / "scene.toml", old, new)
    with pytest.raises(SandboxError, match=expected):
        load_scene(folder / "scene.toml")


def test_the_docs_table_lists_exactly_the_inputs_the_renderer_gives() -> None:
    readme = (REPO / "docs" / "your-own.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Your own shader"):]
    section = section.split("\n## ", 1)[0]
    rows = re.findall(r"^\| `(\w+)` \| `([^`]+)` \|", section, flags=re.M)
    assert rows == [(name, glsl) for name, glsl, *_ in SHADER_INPUTS]


# --- rendering and the errors, end to end through the command ------------------


def test_the_shader_draws_with_its_uniforms_and_set_overrides_them(folder: Path, capsys, gl) -> None:
    status, err, out = render(folder, capsys)
    assert status == 0, err
    assert tuple(load_png(out)[32, 32]) == (0, 255, 0, 255)
    status, err, out = render(folder, capsys, "u.tint=1,0,1")
    assert status == 0, err
    assert tuple(load_png(out)[32, 32]) == (255, 0, 255, 255)
    # Declared but unused: the compiler dropped it, so there is nothing to set and nothing wrong.
    status, err, _ = render(folder, capsys, "u.unused_knob=3")
    assert status == 0 and err == ""


def test_a_python_node_names_its_shader_relative_to_the_working_folder(folder: Path, monkeypatch, fresh) -> None:
    gl = fresh
    monkeypatch.chdir(folder)
    node = Node("box", builtin_mesh("cube24"), shader="tint.glsl", uniforms={"tint": (1, 0, 0)})
    image = gl.render_scene(Scene("python", nodes=(node,)), (32, 32)).image
    assert tuple(image[16, 16]) == (255, 0, 0, 255)
    # 'in vec4 in_position' takes the three floats too (w = 1); an integer attribute is refused.
    edit(folder / "tint.glsl", "in vec3 in_position;\nvoid main() { gl_Position = to_clip(in_position); }",
         "in vec4 in_position;\nvoid main() { gl_Position = m_proj * m_view * m_model * in_position; }")
    moved = replace(node, shader=folder / "tint.glsl", uniforms={"tint": (0, 0, 1)})
    assert tuple(gl.render_scene(Scene("python", nodes=(moved,)), (32, 32)).image[16, 16]) == (0, 0, 255, 255)
    edit(folder / "tint.glsl", "in vec4 in_position;", "in ivec4 in_position;")
    edit(folder / "tint.glsl", "* in_position;", "* vec4(in_position);")
    with pytest.raises(SandboxError, match="attribute in_position must be a float vector: 'in vec3 in_position'"):
        gl.executor.reload_shaders()  # compiled programs are kept until a reload (R, or a save in the window)


def test_a_textured_material_gives_the_shader_its_texture(folder: Path, gl) -> None:
    # TEXTURED is defined and u_texture holds the material's texture on unit 0: a shader that
    # samples it as basic.glsl does draws what basic.glsl draws.
    (folder / "textured.glsl").write_text("""#version 330 core
#if defined(VERTEX_SHADER)
#include "common/transform.glsl"
in vec3 in_position;
in vec2 in_uv;
out vec2 v_uv;
void main() { v_uv = in_uv; gl_Position = to_clip(in_position); }
#elif defined(FRAGMENT_SHADER)
uniform vec4 u_color;
in vec2 v_uv;
#ifdef TEXTURED
uniform sampler2D u_texture;
#endif
out vec4 frag_color;
void main() {
#ifdef TEXTURED
    frag_color = u_color * texture(u_texture, v_uv);
#else
    frag_color = vec4(1.0, 0.0, 1.0, 1.0);
#endif
}
#endif
""")
    (folder / "textured.toml").write_text('[[nodes]]\nmesh = "cube24"\nrotate = [20, 30, 0]\ntexture = "checker"\n'
                                          'color = [1, 0.8, 0.6]\nshader = "textured.glsl"\n')
    scene = load_scene(folder / "textured.toml")
    builtin = replace(scene, nodes=(replace(scene.nodes[0], shader=None),))
    own = gl.render_scene(scene, (64, 48)).image
    np.testing.assert_array_equal(own, gl.render_scene(builtin, (64, 48)).image)
    assert len({tuple(p) for p in own.reshape(-1, 4)}) > 4  # the checker shows


def test_compile_errors_name_the_users_file_and_line(folder: Path, capsys, gl) -> None:
    edit(folder / "tint.glsl", "vec4(tint, 1.0)", "vec4(tint, 1.0) * missing_thing")
    assert_error(folder, capsys, f"shader does not compile: {folder / 'tint.glsl'}:12: ", "missing_thing")


def test_errors_in_the_users_own_include_name_that_file(folder: Path, capsys, gl) -> None:
    (folder / "lib").mkdir()
    (folder / "lib" / "colors.glsl").write_text("// helpers\nvec3 brighten(vec3 c) {\n    return c * nope;\n}\n")
    edit(folder / "tint.glsl", "out vec4 frag_color;", '#include "lib/colors.glsl"\nout vec4 frag_color;')
    edit(folder / "tint.glsl", "vec4(tint, 1.0)", "vec4(brighten(tint), 1.0)")
    assert_error(folder, capsys, f"shader does not compile: {folder / 'lib' / 'colors.glsl'}:3: ")
    (folder / "lib" / "colors.glsl").write_text("vec3 brighten(vec3 c) { return min(c * 2.0, 1.0); }\n")
    status, err, out = render(folder, capsys, "u.tint=0.25,0.25,0.25")
    assert status == 0, err
    assert tuple(load_png(out)[32, 32]) == (128, 128, 128, 255)  # the include was used


def test_a_missing_include_names_the_line_that_asks_for_it(folder: Path, capsys, gl) -> None:
    edit(folder / "tint.glsl", '#include "common/transform.glsl"', '#include "common/transfrom.glsl"')
    assert_error(folder, capsys, f"{folder / 'tint.glsl'}:6: #include \"common/transfrom.glsl\" not found")


@pytest.mark.parametrize(("old", "new", "missing"), [
    ("#elif defined(FRAGMENT_SHADER)", "#else", "FRAGMENT_SHADER"),
    ("#if defined(VERTEX_SHADER)", "#if 1", "VERTEX_SHADER"),
])
def test_a_missing_stage_is_named(folder: Path, capsys, gl, old: str, new: str, missing: str) -> None:
    edit(folder / "tint.glsl", old, new)
    assert_error(folder, capsys, f"{folder / 'tint.glsl'}: no {missing} section")


def test_a_link_error_names_the_users_file(folder: Path, capsys, gl) -> None:
    # A function declared but defined nowhere: each stage compiles, the link finds no body.
    edit(folder / "tint.glsl", "out vec4 frag_color;", "vec3 defined_nowhere(vec3 c);\nout vec4 frag_color;")
    edit(folder / "tint.glsl", "vec4(tint, 1.0)", "vec4(defined_nowhere(tint), 1.0)")
    assert_error(folder, capsys, f"{folder / 'tint.glsl'}: shader does not link")


@pytest.mark.parametrize(("old", "new", "settings", "expected"), [
    ("tint = [0, 1, 0]", "tint = 0.5", (), "uniform tint is a vec3, but node 'box' gives it 0.5"),
    ("tint = [0, 1, 0]", "tint = true", (), "uniform tint is a vec3, but node 'box' gives it true"),
    ("tint = [0, 1, 0]", "tint = [0, 1, 0]\ntnit = 1", (), "node 'box' sets uniform tnit, which the shader does "
                                                           "not declare (it declares: "),
    (None, None, ("u.tint=1,0",), "uniform tint is a vec3, but --set u.tint gives it 1, 0"),
])
def test_uniform_mistakes_name_the_users_file(folder: Path, capsys, gl, old, new, settings, expected) -> None:
    if old is not None:
        edit(folder / "scene.toml", old, new)
    line = assert_error(folder, capsys, expected, settings=settings)
    assert line.startswith(f"error: {folder / 'tint.glsl'}: ")


def test_integer_and_matrix_uniforms_are_checked_for_what_they_take(folder: Path, capsys, gl) -> None:
    edit(folder / "tint.glsl", "uniform vec3 tint;", "uniform vec3 tint;\nuniform int steps;\nuniform mat3 turn;")
    edit(folder / "tint.glsl", "vec4(tint, 1.0)", "vec4(turn * tint / float(steps), 1.0)")
    edit(folder / "scene.toml", "tint = [0, 1, 0]", "tint = [0, 1, 0]\nsteps = 2.5")
    assert_error(folder, capsys, "uniform steps is a int, but node 'box' gives it 2.5")
    edit(folder / "scene.toml", "steps = 2.5", "steps = 2\nturn = 1")
    assert_error(folder, capsys, "uniform turn is a mat3; node 'box' may set float, int, uint, bool")


def test_an_attribute_the_mesh_lacks_is_named(folder: Path, capsys, gl) -> None:
    edit(folder / "tint.glsl", "in vec3 in_position;", "in vec3 in_position;\nin vec2 in_uv;\nout vec2 v_uv;")
    edit(folder / "tint.glsl", "void main() { gl_Position", "void main() { v_uv = in_uv; gl_Position")
    edit(folder / "tint.glsl", "out vec4 frag_color;", "in vec2 v_uv;\nout vec4 frag_color;")
    edit(folder / "tint.glsl", "vec4(tint, 1.0)", "vec4(tint * v_uv.x, 1.0)")
    edit(folder / "scene.toml", 'mesh = "cube24"', 'mesh = "triangle"')
    assert_error(folder, capsys, f"{folder / 'tint.glsl'}: in vec2 in_uv needs texture coordinates (uvs), "
                                 "which node 'box''s mesh 'triangle' does not have")
    edit(folder / "tint.glsl", "in vec2 in_uv;", "in vec2 in_tangent;")
    edit(folder / "tint.glsl", "v_uv = in_uv;", "v_uv = in_tangent;")
    assert_error(folder, capsys, "attribute in_tangent is none the renderer gives (in_position, in_normal, in_uv")


def test_set_u_needs_a_shader_that_declares_it(folder: Path, capsys, gl) -> None:
    assert_error(folder, capsys, "--set u.tnit: no shader of the scene declares uniform tnit", settings=("u.tnit=1",))
    assert_error(folder, capsys, "--set u.tint=green: expected a number, on/off, or 2 to 4 numbers",
                 settings=("u.tint=green",))
    assert_error(folder, capsys, "--set u.tint=: expected a number", settings=("u.tint=",))
    assert_error(folder, capsys, "--set u.tint=1,2,3,4,5: value must be 2 or 3 or 4 numbers",
                 settings=("u.tint=1,2,3,4,5",))
    assert_error(folder, capsys, "--set u.tint=nan: value must be a finite number", settings=("u.tint=nan",))
    assert_error(folder, capsys, "--set u.m_proj: set by the renderer", settings=("u.m_proj=1",))
    with pytest.raises(SandboxError, match="--set u.tint: no node of indexed_cube has a shader of its own"):
        find_lesson("indexed_cube").from_settings(["u.tint=1,0,0"]).scene()


# --- the toon example ----------------------------------------------------------


def test_the_toon_example_renders_bands_unlike_the_same_scene_without_its_shader(gl) -> None:
    scene = load_scene(TOON)
    plain = replace(scene, nodes=tuple(replace(n, shader=None, uniforms={}) for n in scene.nodes))
    toon_image = gl.render_scene(scene, (320, 240)).image.astype(int)
    plain_image = gl.render_scene(plain, (320, 240)).image.astype(int)
    # The ball (its left half, away from the box): orange pixels.
    ball = toon_image[60:140, 70:150]
    is_ball = (ball[..., 0] > ball[..., 2] + 40)
    assert is_ball.sum() > 1500
    toon_tones = {tuple(p) for p in ball[is_ball]}
    plain_ball = plain_image[60:140, 70:150]
    plain_tones = {tuple(p) for p in plain_ball[plain_ball[..., 0] > plain_ball[..., 2] + 40]}
    # Phong shades the sphere smoothly; the toon shader in 3 bands, a highlight and an outline
    # (a few more where the rasterizer blends edges: none here, no MSAA).
    assert len(plain_tones) > 200
    assert len(toon_tones) <= 8
    assert np.abs(toon_image - plain_image).max() > 60
    # The floor has no shader of its own: drawn alike.
    np.testing.assert_array_equal(toon_image[230:, :], plain_image[230:, :])
    # u.bands=6 (over both nodes' own values) gives more tones.
    more = gl.render(find_lesson(str(TOON)).from_settings(["u.bands=6"]), (320, 240)).image[60:140, 70:150]
    assert len({tuple(p) for p in more[more[..., 0] > more[..., 2] + 40]}) > len(toon_tones)


def test_plan_shows_the_file_and_the_ray_tracer_note(capsys) -> None:
    assert cli.main(["plan", str(TOON)]) == 0
    out = capsys.readouterr().out
    assert f"ball with {TOON.parent / 'toon.glsl'}[NUM_LIGHTS=1]" in out
    assert "notes:" not in out
    assert cli.main(["plan", str(TOON), "--set", "renderer=ray"]) == 0
    notes = capsys.readouterr().out.split("notes:\n")[1].splitlines()
    assert notes == [f"  viewport 0 is ray-traced: the ray tracer cannot run GLSL, so node {name!r} (shader "
                     f"{TOON.parent / 'toon.glsl'}) is traced with its material (phong)" for name in ("ball", "box")]


def test_a_traced_viewport_traces_the_material_and_says_so_once(capsys) -> None:
    lesson = find_lesson(str(TOON)).from_settings(["renderer=ray_numpy"])
    plain_scene = lesson.scene()
    plain_scene = replace(plain_scene, nodes=tuple(replace(n, shader=None, uniforms={}) for n in plain_scene.nodes))
    try:
        renderer = HeadlessRenderer()
    except SandboxError as exc:
        need("headless OpenGL", str(exc))
    with renderer:
        first = renderer.render(lesson, (96, 72)).image
        second = renderer.render(lesson, (96, 72)).image  # a second frame: no second warning
        warnings = capsys.readouterr().err.splitlines()
        expected = renderer.render_scene(plain_scene, (96, 72)).image
    assert warnings == [f"warning: viewport 0 is ray-traced: the ray tracer cannot run GLSL, so node {name!r} "
                        f"(shader {TOON.parent / 'toon.glsl'}) is traced with its material (phong)"
                        for name in ("ball", "box")]
    np.testing.assert_array_equal(first, expected)
    np.testing.assert_array_equal(second, expected)


# --- reload and the file watch -------------------------------------------------


def test_the_watch_reports_a_saved_file_once(tmp_path: Path) -> None:
    path = tmp_path / "a.glsl"
    path.write_text("one")
    files = [path]
    watch = FileWatch(lambda: files, interval=0.25)
    assert not watch.changed(now=0.0)  # first sight: recorded
    path.write_text("two, longer")
    assert not watch.changed(now=0.1)  # within the interval: the disk is not looked at
    assert watch.changed(now=0.3)
    assert not watch.changed(now=0.6)  # reported once
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10**9))  # same size, later time
    assert watch.changed(now=0.9)
    path.unlink()  # an editor replacing the file: gone, then back
    assert watch.changed(now=1.2)
    path.write_text("three")
    assert watch.changed(now=1.5)


def test_a_save_reloads_the_users_shader_and_a_broken_one_keeps_the_last_good(folder: Path, fresh) -> None:
    gl = fresh
    scene = load_scene(folder / "scene.toml")
    shader = folder / "tint.glsl"
    watch = FileWatch(gl.executor.shader_files, interval=0.0)
    assert tuple(gl.render_scene(scene, (32, 32)).image[16, 16]) == (0, 255, 0, 255)
    assert shader in gl.executor.shader_files()
    assert any(path.name == "transform.glsl" for path in gl.executor.shader_files())  # its include too
    assert not watch.changed()

    def save(text: str) -> None:
        shader.write_text(text)
        stat = shader.stat()  # a later time, whatever the file system's clock resolution
        os.utime(shader, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9 * (1 + len(text) % 7)))

    save(TINT.replace("vec4(tint, 1.0)", "vec4(tint.gbr, 1.0)"))
    assert watch.changed()
    gl.executor.reload_shaders()
    assert tuple(gl.render_scene(scene, (32, 32)).image[16, 16]) == (255, 0, 0, 255)
    save(TINT.replace("vec4(tint, 1.0)", "vec4(tint, 1.0) * broken"))
    assert watch.changed()
    with pytest.raises(SandboxError, match=f"{re.escape(str(shader))}:12: .*broken"):
        gl.executor.reload_shaders()
    assert tuple(gl.render_scene(scene, (32, 32)).image[16, 16]) == (255, 0, 0, 255)  # the last good program
    # A program that compiles but no longer fits the node (tint became a float): refused too.
    save(TINT.replace("uniform vec3 tint;", "uniform float tint;").replace("vec4(tint, 1.0)", "vec4(tint)"))
    with pytest.raises(SandboxError, match="uniform tint is a float, but node 'box' gives it 0, 1, 0"):
        gl.executor.reload_shaders()
    assert tuple(gl.render_scene(scene, (32, 32)).image[16, 16]) == (255, 0, 0, 255)


def test_frames_of_a_kept_plan_see_a_reload_and_changed_uniform_values(folder: Path, fresh) -> None:
    """The executor keeps each plan's prepared passes and draws while the plan is the same object
    (a scene moved only by time); a reloaded program, a node's other uniform values and other
    ``--set u.NAME`` values still reach its frames."""
    gl = fresh
    scene = load_scene(folder / "scene.toml")
    size = (32, 32)
    kept = gl.plan(moved_scene(scene, Motion(camera=scene.camera)))  # moved: the renderer keeps its plan
    target = gl.target(size, kept.buffers)

    def pixel(drawn: Scene) -> tuple[int, ...]:
        gl.executor.render(drawn, target.framebuffer, size, kept)
        return tuple(target.read()[16, 16])

    assert pixel(scene) == (0, 255, 0, 255)
    assert gl.plan(moved_scene(scene, Motion(camera=scene.camera))) is kept
    box = scene.nodes[0]
    assert pixel(replace(scene, nodes=(replace(box, uniforms={"tint": (1, 0, 0)}),))) == (255, 0, 0, 255)
    assert pixel(replace(scene, uniform_overrides={"tint": (0, 0, 1)})) == (0, 0, 255, 255)
    assert pixel(scene) == (0, 255, 0, 255)
    shader = folder / "tint.glsl"
    shader.write_text(TINT.replace("vec4(tint, 1.0)", "vec4(tint.gbr, 1.0)"))
    gl.executor.reload_shaders()
    assert pixel(scene) == (255, 0, 0, 255)


@pytest.mark.slow
def test_saving_the_shader_reloads_it_in_the_window(folder: Path, xvfb_display: str) -> None:
    from support import LessonWindow

    if shutil.which("xdotool") is None:
        need("xdotool", "not installed (apt-get install xdotool)")
    shader = folder / "tint.glsl"
    win = LessonWindow(xvfb_display, folder, "glsandbox.cli", "run", str(folder / "scene.toml"), "--size", "320x240")
    try:
        win.wait_title(lambda t: "fps" in t)
        win.key("F1")  # the panel hides: the pixel looked at is the frame's
        win._wait(lambda: tuple(win.screen()[120, 160]) == (0, 255, 0))
        shader.write_text(TINT.replace("vec4(tint, 1.0)", "vec4(tint.gbr, 1.0)"))  # saved: no key pressed
        win._wait(lambda: tuple(win.screen()[120, 160]) == (255, 0, 0))
        time.sleep(0.05)
        shader.write_text(TINT.replace("vec4(tint, 1.0)", "vec4(tint, 1.0) * broken"))
        title = win.wait_title(lambda t: "shader error" in t)
        assert "tint.glsl:12" in title and "broken" in title
        assert tuple(win.screen()[120, 160]) == (255, 0, 0)  # still the last good program
    finally:
        code = win.close()
    assert code == 0
    err = win.proc.stderr.read()
    assert "shaders reloaded" in err and f"error: shader does not compile: {shader.name}:12:" in err  # relative to the working folder
