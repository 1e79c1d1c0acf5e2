"""Limits on a user's shader text, checked before the driver sees it.

An ``#include`` chain 3,000 files deep was a RecursionError traceback;
``float a[100000000];`` kept llvmpipe compiling for minutes (or aborted the
process). Both are now one line naming the file and line.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from support import EXAMPLES_DIR, assert_user_error, run_cli

from glsandbox import SandboxError
from glsandbox.gl.shader_limits import MAX_ARRAY_ELEMENTS, check_array_sizes
from glsandbox.gl.shaders import MAX_INCLUDE_DEPTH, MAX_INCLUDES, MAX_SHADER_LINES, assemble, shader_root

TOON = (EXAMPLES_DIR / "toon" / "toon.glsl").read_text()
SCENE = (EXAMPLES_DIR / "toon" / "toon.toml").read_text()


def user_shader(folder: Path, extra: str, name: str = "mine.glsl") -> Path:
    """The toon example with ``extra`` lines put before its fragment stage's main()."""
    head, main, tail = TOON.rpartition("void main")
    path = folder / name
    path.write_text(head + extra + "\n" + main + tail)
    return path


def line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


def refusal(path: Path) -> str:
    with pytest.raises(SandboxError) as excinfo:
        assemble(str(path), "fragment_shader", (("NUM_LIGHTS", "1"),), user=True)
    text = str(excinfo.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize("declaration, elements", [
    ("float big[100000000];", "100,000,000"),
    ("uniform vec4 big[5000];", "5,000"),
    ("#define N 10000\nconst int M = N * 10;\nfloat big[M][2];", "200,000"),
    ("const int K = 1 << 20;\nint big[K];", "1,048,576"),
    ("float[0x2000] big;", "8,192"),
    ("float small[4], big[64][128];", "8,192"),
    ("float big[65536 * 65536 * 65536 * 65536 * 65536];", "more than 2^62"),
])
def test_an_array_above_the_limit_is_refused_with_its_file_and_line(tmp_path: Path, declaration: str,
                                                                    elements: str) -> None:
    path = user_shader(tmp_path, declaration)
    text = refusal(path)
    assert text.startswith(f"{path}:{line_of(path, 'big')}: array "), text
    assert f"has {elements} elements" in text and f"at most {MAX_ARRAY_ELEMENTS:,} per array" in text


@pytest.mark.parametrize("declaration", [
    "float kernel[25];",
    f"float most[{MAX_ARRAY_ELEMENTS}];",
    "#define TAPS 9\nconst float weights[TAPS] = float[TAPS](1, 2, 3, 4, 5, 4, 3, 2, 1);",
    "// float commented[100000000];\n/* float also[100000000];\n */",
    "float sized_by_a_call[int(3.5)];",  # not an integer constant here: the compiler's to judge
])
def test_arrays_within_the_limit_or_not_constant_pass(tmp_path: Path, declaration: str) -> None:
    path = user_shader(tmp_path, declaration)
    source = assemble(str(path), "fragment_shader", (("NUM_LIGHTS", "1"),), user=True)
    assert declaration.splitlines()[0] in source.text


def test_only_the_users_lines_are_looked_at(tmp_path: Path) -> None:
    """The built-in shaders' sizes come from the loader's defines (the GLSL ray tracer's
    records), so their lines are not read; a user's file including them passes."""
    builtin = shader_root() / "common" / "lighting.glsl"
    text = "#version 330 core\nuniform vec4 u_records[NODE_COUNT * 4];\n"
    check_array_sizes(text, [(builtin, 1), (builtin, 2)], shader_root())  # no error
    mine = tmp_path / "mine.glsl"
    with pytest.raises(SandboxError, match=r"mine.glsl:2: array \[5000\] has 5,000 elements"):
        check_array_sizes("#version 330 core\nfloat a[5000];\n", [(mine, 1), (mine, 2)], shader_root())


def test_an_include_chain_3000_deep_is_one_line(tmp_path: Path) -> None:
    for i in range(3000):
        (tmp_path / f"i{i}.glsl").write_text(f'#include "i{i + 1}.glsl"\n' if i < 2999 else "float f() {return 1.0;}\n")
    path = user_shader(tmp_path, '#include "i0.glsl"')
    text = refusal(path)
    deepest = tmp_path / f"i{MAX_INCLUDE_DEPTH - 1}.glsl"
    assert text.startswith(f"{deepest}:1: #include nested more than {MAX_INCLUDE_DEPTH} files deep (from {path})")


def test_includes_within_the_depth_pass(tmp_path: Path) -> None:
    depth = MAX_INCLUDE_DEPTH - 2  # the user's file and lighting.glsl's own level count too
    for i in range(depth):
        (tmp_path / f"i{i}.glsl").write_text(f'#include "i{i + 1}.glsl"\n' if i < depth - 1 else "// end\n")
    path = user_shader(tmp_path, '#include "i0.glsl"')
    assert "// end" in assemble(str(path), "fragment_shader", (("NUM_LIGHTS", "1"),), user=True).text


def test_an_include_tree_that_grows_as_a_power_is_stopped(tmp_path: Path) -> None:
    """No cycle and no deep chain, but 10 includes of 10 includes of ...: the include count stops it."""
    levels = 5
    for level in range(levels):
        inner = "\n".join([f'#include "l{level + 1}.glsl"'] * 10) if level < levels - 1 else "float x;"
        (tmp_path / f"l{level}.glsl").write_text(inner + "\n")
    path = user_shader(tmp_path, '#include "l0.glsl"')
    assert f"more than {MAX_INCLUDES:,} #include lines followed" in refusal(path)


def test_a_shader_of_too_many_lines_is_stopped(tmp_path: Path) -> None:
    (tmp_path / "long.glsl").write_text("// a comment\n" * (MAX_SHADER_LINES // 4))
    path = user_shader(tmp_path, '#include "long.glsl"\n' * 5)
    text = refusal(path)
    assert text.startswith(f"{tmp_path / 'long.glsl'}:") and f"has more than {MAX_SHADER_LINES:,} lines" in text


def test_the_cli_renders_nothing_and_says_one_line(tmp_path: Path, gl) -> None:
    user_shader(tmp_path, "float big[100000000];", name="toon.glsl")
    scene = tmp_path / "toon.toml"
    scene.write_text(SCENE)
    run = run_cli("render", str(scene), "--size", "32x24", "--out", str(tmp_path / "out.png"), unchanged=tmp_path)
    assert_user_error(run, f"{tmp_path / 'toon.glsl'}:", "100,000,000 elements")


def test_an_edited_copy_of_the_built_in_shaders_passes(tmp_path: Path) -> None:
    """GLSANDBOX_SHADER_DIR's copies are the user's files, but the GLSL ray tracer's record
    arrays are sized by the loader's defines, which a copy does not spell out: not refused."""
    import shutil

    copy = tmp_path / "shaders"
    shutil.copytree(shader_root(), copy)
    defines = (("NUM_LIGHTS", "2"), ("NODE_COUNT", "100000"), ("TRI_COUNT", "100000"))
    for stage in ("vertex_shader", "fragment_shader"):
        source = assemble("raytrace", stage, defines, root=copy)
        assert any(path.is_relative_to(copy) for path, _ in source.origins)
