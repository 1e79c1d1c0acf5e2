"""Shader files: includes, define variants, and errors that name the file and line."""

from __future__ import annotations

from pathlib import Path

import pytest

from glsandbox.errors import SandboxError
from glsandbox.gl.shaders import assemble, compile_program, shader_root
from glsandbox.plan import ProgramVariant

PROGRAM = """#version 330 core
#if defined(VERTEX_SHADER)
#include "common/pos.glsl"
void main() { gl_Position = position_of(vec3(0.0)); }
#elif defined(FRAGMENT_SHADER)
out vec4 frag_color;
void main() {
    frag_color = vec4(SHADE);
}
#endif
"""
INCLUDE = """// a helper
vec4 position_of(vec3 p) {
    return vec4(p, 1.0);
}
"""


@pytest.fixture
def shader_dir(tmp_path: Path) -> Path:
    (tmp_path / "common").mkdir()
    (tmp_path / "prog.glsl").write_text(PROGRAM)
    (tmp_path / "common" / "pos.glsl").write_text(INCLUDE)
    return tmp_path


def test_includes_and_defines_are_spliced_with_origins(shader_dir: Path) -> None:
    source = assemble("prog", "fragment_shader", (("SHADE", "0.5"),), root=shader_dir)
    lines = source.text.splitlines()
    assert lines[:3] == ["#version 330 core", "#define FRAGMENT_SHADER", "#define SHADE 0.5"]
    assert "vec4 position_of(vec3 p) {" in lines
    # Every assembled line knows where it came from.
    k = lines.index("    return vec4(p, 1.0);")
    assert source.locate(k + 1) == f"{shader_dir / 'common' / 'pos.glsl'}:3"
    k = lines.index("    frag_color = vec4(SHADE);")
    assert source.locate(k + 1) == f"{shader_dir / 'prog.glsl'}:8"


def test_include_cycles_and_missing_files_are_named(shader_dir: Path) -> None:
    (shader_dir / "common" / "pos.glsl").write_text('#include "common/pos.glsl"\n')
    with pytest.raises(SandboxError, match="include cycle"):
        assemble("prog", "vertex_shader", root=shader_dir)
    with pytest.raises(SandboxError, match="shader 'nope' not found"):
        assemble("nope", "vertex_shader", root=shader_dir)


def test_builtin_shaders_all_assemble() -> None:
    for path in shader_root().glob("*.glsl"):
        for stage in ("vertex_shader", "fragment_shader"):
            assert assemble(path.stem, stage).text.startswith("#version")


@pytest.mark.parametrize(
    ("file", "old", "new", "where"),
    [
        ("common/pos.glsl", "vec4(p, 1.0)", "vec4(p, 1.0) + undefined_thing", "common/pos.glsl:3"),
        ("prog.glsl", "vec4(SHADE)", "vec4(SHADE", "prog.glsl:8"),
    ],
)
def test_compile_errors_name_the_original_file_and_line(gl, shader_dir: Path, file: str, old: str, new: str,
                                                        where: str) -> None:
    path = shader_dir / file
    path.write_text(path.read_text().replace(old, new))
    with pytest.raises(SandboxError, match="shader does not compile") as info:
        compile_program(gl.host.ctx, ProgramVariant("prog", (("SHADE", "1.0"),)), root=shader_dir)
    assert str(info.value).startswith(f"shader does not compile: {shader_dir / where}: ")
    assert "\n" not in str(info.value)


def test_a_good_variant_compiles(gl, shader_dir: Path) -> None:
    program = compile_program(gl.host.ctx, ProgramVariant("prog", (("SHADE", "1.0"),)), root=shader_dir)
    assert "frag_color" not in program  # an output, not a uniform
    program.release()
