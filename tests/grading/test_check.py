"""`glsandbox check`: one lesson against a reference, and a folder of submissions."""

from __future__ import annotations

import csv
import json
import re
import uuid
from pathlib import Path

import numpy as np
import pytest

from glsandbox.files import load_png, save_png
from glsandbox.measure.golden import compare_images
from support import SPIN, assert_user_error, glsandbox

pytestmark = pytest.mark.slow

SIZE = "64x48"


def outcomes(stdout: str) -> dict[str, str]:
    """name -> outcome, from the ``[i/n] OUTCOME name: ...`` lines printed as each submission finishes."""
    found = {}
    for line in stdout.splitlines():
        match = re.match(r"\[\d+/\d+\] (PASS|FAIL|BROKEN|TIMEOUT|CRASHED|OUT OF MEMORY) +(.*?): ", line)
        if match:
            found[match.group(2)] = match.group(1)
    return found

#: Leaves the GL context broken (wireframe, a 4x4 scissor behind moderngl's back), then raises:
#: on a shared context the next submission would draw wrong; each gets a fresh one.
VANDAL = '''
import moderngl
from glsandbox import Lesson, Scene

class Vandal(Lesson):
    def build(self) -> Scene:
        ctx = moderngl.get_context()
        ctx.wireframe = True
        ctx.enable_direct(0x0C11)  # GL_SCISSOR_TEST
        ctx.scissor = (0, 0, 4, 4)
        raise RuntimeError("left the GL state broken")
'''


def lesson_file(folder: Path, name: str = "spin.py", text: str = SPIN) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_missing_reference_update_pass_fail_and_artifacts(tmp_path: Path, gl) -> None:
    lesson = lesson_file(tmp_path)
    ref = tmp_path / "ref.png"
    assert_user_error(glsandbox("check", str(lesson), "--golden", str(ref)), f"reference {ref} not found", "--update")
    assert not ref.exists()

    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--update", "--size", SIZE, "--set", "time=0.5")
    assert proc.returncode == 0, proc.stderr
    assert f"wrote reference {ref}" in proc.stdout
    reference = load_png(ref)
    assert reference.shape == (48, 64, 4)  # --size; later checks take the reference's size

    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--set", "time=0.5")
    assert proc.returncode == 0, proc.stderr
    assert "PASS: identical (3072 pixels)" in proc.stdout
    assert not (tmp_path / "ref-diff.png").exists()

    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--set", "time=0.5", "--set", "speed=0")
    assert proc.returncode == 1, proc.stderr
    line = next(text for text in proc.stdout.splitlines() if "FAIL" in text)
    assert "bad of 3072 pixels" in line and "max channel diff" in line and "(threshold 2)" in line
    actual, expected, diff = (tmp_path / f"ref-{kind}.png" for kind in ("actual", "expected", "diff"))
    assert np.array_equal(load_png(expected), reference)
    assert not compare_images(load_png(actual), reference).passed
    assert load_png(diff).shape == reference.shape
    assert np.array_equal(load_png(ref), reference)  # a failing check never touches the reference

    # the same difference passes when the tolerances allow it
    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--set", "time=0.5", "--set", "speed=0",
                     "--tolerance", "max_bad_share=1")
    assert proc.returncode == 0, proc.stdout

    # --update keeps a passing reference byte for byte, rewrites a failing one
    before = ref.read_bytes()
    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--update", "--set", "time=0.5")
    assert proc.returncode == 0 and "unchanged" in proc.stdout and ref.read_bytes() == before
    proc = glsandbox("check", str(lesson), "--golden", str(ref), "--update", "--set", "time=0.5", "--set", "speed=0")
    assert proc.returncode == 0 and "rewrote reference" in proc.stdout
    assert np.array_equal(load_png(ref), load_png(actual))


def test_check_a_builtin_lesson_and_a_scene_file(tmp_path: Path, gl) -> None:
    ref = tmp_path / "cube.png"
    save_png(gl.render(__import__("glsandbox.lesson").lesson.find_lesson("indexed_cube")(time=0.5), (80, 60)).image,
             ref)
    proc = glsandbox("check", "indexed_cube", "--golden", str(ref), "--set", "time=0.5")
    assert proc.returncode == 0 and "identical" in proc.stdout, proc.stdout + proc.stderr
    room = Path(__file__).parents[2] / "examples" / "mirror_room.toml"
    proc = glsandbox("check", str(room), "--golden", str(ref))
    assert proc.returncode == 1 and "FAIL" in proc.stdout


def test_check_bad_input_is_one_line_exit_2(tmp_path: Path, gl) -> None:
    lesson = lesson_file(tmp_path)
    ref = tmp_path / "ref.png"
    garbage = tmp_path / "garbage.png"
    garbage.write_bytes(b"not a png at all")
    (tmp_path / "subs").mkdir()
    cases = [
        (["--golden", str(tmp_path / "ref.jpg")], "the reference must be a .png file"),
        (["--golden", str(garbage)], "not a PNG image"),
        (["--golden", str(ref), "--tolerance", "threshold=1.5", "--update"], "threshold is a whole number"),
        (["--golden", str(ref), "--tolerance", "max_bad_share=2", "--update"], "max_bad_share is a fraction"),
        (["--golden", str(ref), "--tolerance", "fuzz=1", "--update"], "expected threshold=LEVELS"),
        (["--golden", str(ref), "--update", "--set", "nope=1"], "has no parameter 'nope'"),
        (["--golden", str(ref), "--csv", str(tmp_path / "r.csv"), "--update"], "give a folder"),
    ]
    for extra, fragment in cases:
        assert_user_error(glsandbox("check", str(lesson), *extra), fragment)
    assert_user_error(glsandbox("check", str(tmp_path / "subs"), "--golden", str(ref), "--update"),
                      "give one lesson, not the folder")
    for update in (["--update"], []):  # the lesson's mistake is the one said, whether or not the reference exists
        assert_user_error(glsandbox("check", str(tmp_path / "missing.py"), "--golden", str(ref), *update),
                          "missing.py not found")
    assert_user_error(glsandbox("check", str(tmp_path / "subs"), "--golden", str(ref)), "no .py or .toml lesson files")
    lesson_file(tmp_path / "subs")
    assert_user_error(glsandbox("check", str(tmp_path / "subs"), "--golden", str(ref)),
                      f"reference {ref} not found", "--update")
    assert not ref.exists() and not (tmp_path / "r.csv").exists()
    # a lesson whose own build() raises: one line naming its file and line
    crash = lesson_file(tmp_path, "crash.py", VANDAL.replace("ctx = moderngl.get_context()", "{}['x']"))
    assert_user_error(glsandbox("check", str(crash), "--golden", str(ref), "--update"), f"KeyError at {crash}:7")


def test_a_folder_of_submissions(tmp_path: Path, gl) -> None:
    ref = tmp_path / "ref.png"
    good = lesson_file(tmp_path / "spare")
    assert glsandbox("check", str(good), "--golden", str(ref), "--update", "--size", SIZE).returncode == 0
    subs = tmp_path / "subs"
    lesson_file(subs, "b_alice.py")
    lesson_file(subs, "c_bob.py", SPIN.replace('Param("speed", 1.0', 'Param("speed", 0.0').replace(
        "rotate_y(", "rotate_x(0.4) @ transforms.rotate_y("))
    lesson_file(subs, "d_carol/lesson.py")
    (subs / "d_carol" / "notes.toml").write_text("# a .py in the folder is the submission\n")
    lesson_file(subs, "e_dave.py", "def oops(:\n")
    lesson_file(subs, "f_erin.toml", 'name = "x"\n[[nodes]]\nmesh = "cube"\ncolor = [2, 0, 0]\n')
    lesson_file(subs, "a_vandal.py", VANDAL)
    (subs / "g_empty").mkdir()
    proc = glsandbox("check", str(subs), "--golden", str(ref), "--csv", str(tmp_path / "out" / "r.csv"),
                     "--json", str(tmp_path / "out" / "r.json"))
    assert proc.returncode == 1, proc.stderr
    assert outcomes(proc.stdout) == {"a_vandal": "BROKEN", "b_alice": "PASS", "c_bob": "FAIL", "d_carol": "PASS",
                                     "e_dave": "BROKEN", "f_erin": "BROKEN", "g_empty": "BROKEN"}
    # the vandal's broken context did not reach the next submission: alice is identical
    assert "PASS   b_alice: identical (3072 pixels)" in proc.stdout
    assert "e_dave.py:1: syntax error" in proc.stdout and "f_erin.toml:4: nodes[0].color" in proc.stdout
    assert "RuntimeError at" in proc.stdout and "a_vandal.py:11: left the GL state broken" in proc.stdout
    assert "2 passed, 1 failed, 4 broken, 0 timed out, 0 crashed, 0 out of memory of 7" in proc.stdout
    assert [f"[{n}/7]" in proc.stdout for n in range(1, 8)] == [True] * 7  # one line as each finishes
    bob = tmp_path / "ref-results" / "c_bob-diff.png"
    assert bob.exists() and not (tmp_path / "ref-results" / "b_alice-diff.png").exists()

    rows = list(csv.DictReader((tmp_path / "out" / "r.csv").open()))
    assert [r["status"] for r in rows] == ["BROKEN", "PASS", "FAIL", "PASS", "BROKEN", "BROKEN", "BROKEN"]
    assert float(rows[2]["bad_share"]) > 0.0005 and int(rows[2]["max_diff"]) > 2 and rows[1]["bad_pixels"] == "0"
    report = json.loads((tmp_path / "out" / "r.json").read_text())
    assert (report["pass"], report["fail"], report["broken"]) == (2, 1, 4)
    assert report["submissions"][4]["error"].endswith("e_dave.py:1: syntax error: invalid syntax")

    # all passing: exit 0
    for path in (subs / "c_bob.py", subs / "e_dave.py", subs / "f_erin.toml", subs / "a_vandal.py"):
        path.unlink()
    (subs / "g_empty").rmdir()
    proc = glsandbox("check", str(subs), "--golden", str(ref))
    assert proc.returncode == 0, proc.stdout
    assert "2 passed, 0 failed, 0 broken, 0 timed out, 0 crashed, 0 out of memory of 2" in proc.stdout


def test_a_shader_that_does_not_compile_is_broken_and_the_others_go_on(tmp_path: Path, gl) -> None:
    # The built-in solid program replaced by one that does not compile (GLSANDBOX_SHADER_DIR):
    # the submission drawing a cube is BROKEN with the shader's file and line, the empty one passes.
    shaders = tmp_path / "shaders"
    shaders.mkdir()
    (shaders / "basic.glsl").write_text("#version 330 core\nthis is not glsl\n")
    subs = tmp_path / "subs"
    lesson_file(subs, "a_cube.toml", 'name = "cube"\n[[nodes]]\nmesh = "cube"\n')
    lesson_file(subs, "b_empty.toml", 'name = "empty"\n')
    ref = tmp_path / "ref.png"
    assert glsandbox("check", str(subs / "b_empty.toml"), "--golden", str(ref), "--update", "--size", SIZE,
                     env={"GLSANDBOX_SHADER_DIR": str(shaders)}).returncode == 0
    proc = glsandbox("check", str(subs), "--golden", str(ref), env={"GLSANDBOX_SHADER_DIR": str(shaders)})
    assert proc.returncode == 1
    assert f"] BROKEN a_cube: shader does not compile: {shaders / 'basic.glsl'}:2:" in proc.stdout
    assert "] PASS   b_empty: identical" in proc.stdout


def test_submissions_with_their_own_shader_files(tmp_path: Path, gl) -> None:
    """A teacher's folder where each student's scene draws its ball with the student's own
    shader file: the reference student's passes, a shader computing another colour fails,
    one that does not compile is BROKEN naming the student's file and line. The shaders are new to
    Mesa's on-disk cache: a renderer forked from the warm template once hung writing to it (TIMEOUT)."""
    subs = tmp_path / "subs"
    scene = ('name = "ball"\n[camera]\neye = [0, 0, 4]\n[[lights]]\nposition = [1, 2, 4]\n'
             '[[nodes]]\nname = "ball"\nmesh = "sphere"\nshading = "phong"\nshader = "ball.glsl"\n'
             '[nodes.uniforms]\ngain = 1.0\n')
    body = ('#version 330 core\n#include "common/lighting.glsl"\nuniform float gain;\n'
            '#if defined(VERTEX_SHADER)\n#include "common/transform.glsl"\nuniform mat3 m_normal;\n'
            'in vec3 in_position;\nin vec3 in_normal;\nout vec3 v_world;\nout vec3 v_normal;\n'
            'void main() { vec4 w = m_model * vec4(in_position, 1.0); gl_Position = m_proj * m_view * w;\n'
            '  v_world = w.xyz; v_normal = m_normal * in_normal; }\n'
            '#elif defined(FRAGMENT_SHADER)\nin vec3 v_world;\nin vec3 v_normal;\nout vec4 frag_color;\n'
            'void main() { frag_color = vec4(gain * shade(v_world, normalize(v_normal), COLOR), 1.0); }\n#endif\n')
    shaders = {"a_ann": body.replace("COLOR", "u_color.rgb"),
               "b_ben": body.replace("COLOR", "vec3(0.2, 1.0, 0.2)"),
               "c_cem": body.replace("COLOR", "u_color.rgb").replace("frag_color = vec4", "frag_colour = vec4")}
    fresh = f"// {uuid.uuid4().hex}\n"  # no process has compiled these shaders before (Mesa's cache misses)
    for student, text in shaders.items():
        lesson_file(subs / student, "ball.toml", scene)
        (subs / student / "ball.glsl").write_text(text + fresh)
    ref = tmp_path / "ref.png"
    proc = glsandbox("check", str(subs / "a_ann" / "ball.toml"), "--golden", str(ref), "--update", "--size", SIZE)
    assert proc.returncode == 0, proc.stderr
    assert glsandbox("check", str(subs / "a_ann" / "ball.toml"), "--golden", str(ref),
                     "--set", "u.gain=0.5").returncode == 1  # the uniform reaches the student's shader
    proc = glsandbox("check", str(subs), "--golden", str(ref))
    assert proc.returncode == 1
    assert outcomes(proc.stdout) == {"a_ann": "PASS", "b_ben": "FAIL", "c_cem": "BROKEN"}
    broken = next(line for line in proc.stdout.splitlines() if "] BROKEN" in line)
    # The student's line names the shader as the student wrote it, relative to their folder.
    assert "BROKEN c_cem: shader does not compile: ball.glsl:" in broken, broken


CUBE = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'


def test_explain_tells_a_failed_pictures_first_differing_pixel(tmp_path: Path, gl) -> None:
    """``check --explain``: the wrong submission's first differing pixel (row by row) is told in its own
    frame by its confined renderer, in the HTML page; the right one has no story."""
    from support import run_cli

    (tmp_path / "model.toml").write_text(CUBE)
    ref = tmp_path / "ref.png"
    assert run_cli("check", str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size",
                   "64x48").returncode == 0
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "right.toml").write_text(CUBE)
    (subs / "wrong.toml").write_text(CUBE.replace('mesh = "cube"', 'mesh = "sphere"'))
    page = tmp_path / "r.html"
    proc = run_cli("check", str(subs), "--golden", str(ref), "--explain", "--html", str(page))
    assert proc.returncode == 1, proc.stderr
    text = page.read_text()
    assert text.count("(the first that differs)") == 1
    pixel = re.search(r"why pixel (\d+),(\d+) \(the first that differs\)", text)
    assert pixel is not None
    assert f"wrong: pixel {pixel[1]},{pixel[2]} of 64x48, rasterised" in text  # its own story, pass by pass
    assert "Final colour" in text
    portable = tmp_path / "p.html"  # the portable path (a teacher's laptop) brings the story back too
    assert run_cli("check", str(subs), "--golden", str(ref), "--explain", "--html", str(portable),
                   env={"GLSANDBOX_ISOLATION": "portable"}).returncode == 1
    assert f"why pixel {pixel[1]},{pixel[2]} (the first that differs)" in portable.read_text()


def test_the_first_difference_is_the_first_pixel_past_the_threshold_row_by_row(tmp_path: Path) -> None:
    from glsandbox.grading.check import first_difference
    from glsandbox.grading.rubric import Check

    expected = np.zeros((4, 5, 4), np.uint8)
    actual = expected.copy()
    actual[1, 3, 0] = 2  # within the default threshold (2 levels)
    actual[2, 1, 1] = 30
    actual[3, 0, 2] = 30
    check = Check("c", tmp_path / "c.png")
    assert first_difference(actual, expected, check) == (1, 2)
    assert first_difference(actual, expected, Check("c", tmp_path / "c.png", tolerances={"threshold": 40})) is None
    assert first_difference(actual[:3], expected, check) is None


def test_a_hidden_checks_story_is_not_on_the_students_page(tmp_path: Path) -> None:
    from glsandbox.grading.check import CheckResult, Outcome
    from glsandbox.grading.reports import student_text
    from glsandbox.grading.rubric import Check

    shown_check, hidden_check = Check("shown", tmp_path / "a.png"), Check("hidden", tmp_path / "b.png", hidden=True)
    outcomes = [Outcome(shown_check, "FAIL", first_difference=(3, 4), story="SHOWN STORY <b>"),
                Outcome(hidden_check, "FAIL", first_difference=(5, 6), story="HIDDEN STORY")]
    page = student_text([CheckResult("ann", tmp_path / "ann", outcomes)], "t")
    assert "why pixel 3,4" in page and "SHOWN STORY &lt;b&gt;" in page
    assert "HIDDEN STORY" not in page and "5,6" not in page
