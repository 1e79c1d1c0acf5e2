"""Errors a student meets on the first day: one line naming their file (and line),
relative to their folder, with nothing printed before it; output names that never clash."""

from __future__ import annotations

from pathlib import Path

from PIL import Image
from support import assert_user_error, run_cli

from glsandbox.measure.compare import default_out

SHADER = "#version 330 core\n#if defined(VERTEX_SHADER)\nvoid main() {{ gl_Position = vec4(0) }}\n" \
         "#elif defined(FRAGMENT_SHADER)\nout vec4 c; void main() {{ c = vec4(1); }}\n#endif\n{tail}"


def _scene(folder: Path, node: str) -> Path:
    path = folder / "scene.toml"
    path.write_text(f'[[nodes]]\nname = "box"\nmesh = "plane"\n{node}\n')
    return path


def test_a_shader_error_is_relative_to_the_users_folder_and_a_nul_byte_is_refused(tmp_path: Path, gl) -> None:
    (tmp_path / "bad.glsl").write_text(SHADER.format(tail=""))
    _scene(tmp_path, 'shader = "bad.glsl"')
    proc = run_cli("render", "scene.toml", "--out", str(tmp_path / "o.png"), cwd=tmp_path, unchanged=tmp_path)
    assert_user_error(proc, "bad.glsl:3:")
    assert str(tmp_path) not in proc.stderr
    (tmp_path / "bad.glsl").write_bytes(SHADER.format(tail="").replace("vec4(0) }", "vec4(0); }").encode()
                                        + b"// cut\x00short\n")
    proc = run_cli("render", "scene.toml", "--out", str(tmp_path / "o.png"), cwd=tmp_path, unchanged=tmp_path)
    assert_user_error(proc, "bad.glsl:7: shader file holds a NUL byte")


def test_an_obj_at_1e300_prints_no_numpy_warning_before_its_error_line(tmp_path: Path) -> None:
    (tmp_path / "big.obj").write_text("v 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 2 3\n")
    proc = run_cli("render", "model", "--set", "mesh=big.obj", "--out", str(tmp_path / "o.png"), cwd=tmp_path)
    assert_user_error(proc, "model file big.obj")  # one line: no RuntimeWarning lines above it


def test_a_decompression_bomb_given_as_golden_is_one_error_line(tmp_path: Path) -> None:
    Image.new("1", (20000, 20000)).save(tmp_path / "bomb.png")  # 48 KB on disk, 1.6 GB as RGBA
    proc = run_cli("check", "triangle", "--golden", str(tmp_path / "bomb.png"), cwd=tmp_path)
    assert_user_error(proc, "bomb.png: too large to decode safely")


def test_compare_of_a_lesson_file_and_a_scene_file_of_one_name_write_different_files() -> None:
    assert default_out("my_lesson", "my_lesson.py") != default_out("my_lesson", "my_lesson.toml")
    assert default_out("my_lesson", "lessons/my_lesson.py") == Path("compare_my_lesson_py.png")
    assert default_out("phong", "phong") == Path("compare_phong.png")
