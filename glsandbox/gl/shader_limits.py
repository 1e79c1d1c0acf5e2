"""A cheap look at a user's shader text before the driver compiles it: array sizes.

llvmpipe (Mesa's CPU driver, what the course machines render with) compiles an
array in time that grows faster than its size: a dynamically indexed
``float a[1000]`` in a fragment shader took about 0.9 s to compile and first
draw here, ``a[4096]`` about 9 s, ``a[16384]`` 43 s, and ``a[100000000]``
runs for minutes or aborts the process (``std::bad_alloc``); a uniform array
of 10^8 floats is refused by the linker only after about 40 s. So glsandbox
refuses, before compiling, any array in a file of the user's with more than
:data:`MAX_ARRAY_ELEMENTS` elements (all its dimensions multiplied), naming
the file and line. Textures and uniform blocks are the way to hand a shader
more data.

The sizes are read as the preprocessor and the compiler would fold them when
they are integer constants: literals (``100``, ``0x40``, ``8u``), names
``#define``'d in the user's files, and ``const int`` names, joined with
``+ - * / % << >>`` and parentheses. A size made some other way (a function
call, a macro with arguments, a define the loader adds such as ``NUM_LIGHTS``)
is left to the compiler. Lines of the built-in shader folder are not looked
at: their sizes come from the loader's own defines.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from glsandbox.errors import SandboxError

#: The most elements one array in a user's shader may have (all dimensions multiplied).
MAX_ARRAY_ELEMENTS = 4096

_COMMENTS = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_DEFINE = re.compile(r"^\s*#\s*define\s+([A-Za-z_]\w*)\b(?!\()\s*(.*)$")
_CONST_INT = re.compile(r"\bconst\s+(?:(?:lowp|mediump|highp)\s+)?u?int\s+([A-Za-z_]\w*)\s*=\s*([^;,]+)")
# One or more bracket groups in a row: a[2][3], float[8], u[N * 4].
_BRACKETS = re.compile(r"(?:\[[^\[\]]*\]\s*)+")
_NAME = re.compile(r"\b[A-Za-z_]\w*")  # not the x of 0x40 or the u of 8u
_INT_LITERAL = re.compile(r"\b(0[xX][0-9a-fA-F]+|\d+)[uU]?\b")
# Beyond this, a value is "too large" whatever it is (no huge integers are ever made).
_CAP = 1 << 62


def check_array_sizes(text: str, origins: list[tuple[Path, int]], builtin_root: Path,
                      injected: set[int] | frozenset[int] = frozenset()) -> None:
    """Refuse an array above :data:`MAX_ARRAY_ELEMENTS` in the lines of ``text`` that come
    from files outside ``builtin_root`` (``origins`` gives each line's file and line).
    The lines at the indices in ``injected`` are the loader's own defines: not the user's,
    so a size made of them (``NODE_COUNT * NODE_RECORDS``) is not judged."""
    lines = _COMMENTS.sub(lambda m: "\n" * m.group(0).count("\n"), text).split("\n")
    root = builtin_root.resolve()
    outside = {path: not path.resolve().is_relative_to(root) for path in {path for path, _ in origins}}
    own = [i for i, (path, _) in enumerate(origins[:len(lines)]) if outside[path] and i not in injected]
    if not own:
        return
    names: dict[str, str] = {}
    for i in own:  # the user's #defines and const ints, in order (a later one wins)
        define = _DEFINE.match(lines[i])
        if define:
            names[define.group(1)] = define.group(2).strip()
        for const in _CONST_INT.finditer(lines[i]):
            names[const.group(1)] = const.group(2).strip()
    for i in own:
        if "[" not in lines[i] or _DEFINE.match(lines[i]):
            continue
        for group in _BRACKETS.finditer(lines[i]):
            elements = 1
            for size in re.findall(r"\[([^\[\]]*)\]", group.group(0)):
                value = _constant(size, names)
                if value is None:
                    elements = None
                    break
                elements = min(elements * max(value, 1), _CAP)
            if elements is not None and elements > MAX_ARRAY_ELEMENTS:
                path, line = origins[i]
                shown = f"{elements:,}" if elements < _CAP else "more than 2^62"
                raise SandboxError(f"{path}:{line}: array {group.group(0).strip()} has {shown} elements; "
                                   f"glsandbox allows at most {MAX_ARRAY_ELEMENTS:,} per array in a shader "
                                   "(llvmpipe takes seconds to minutes over larger ones; hand more data in a texture)")


def _constant(expression: str, names: dict[str, str], depth: int = 0) -> int | None:
    """The integer an array size folds to, or None when it is not such a constant."""
    if depth > 16 or not expression.strip():
        return None
    text = expression
    for name in set(_NAME.findall(expression)):
        if name not in names:
            return None
        value = _constant(names[name], names, depth + 1)
        if value is None:
            return None
        text = re.sub(rf"\b{name}\b", str(value), text)
    text = _INT_LITERAL.sub(lambda m: str(int(m.group(1), 0) if m.group(1).lower().startswith("0x")
                                          else int(m.group(1))), text)
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return None
    return _fold(tree.body)


def _fold(node: ast.AST) -> int | None:
    """Integer arithmetic as GLSL folds it, capped at :data:`_CAP` (no huge numbers made)."""
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return min(node.value, _CAP)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        value = _fold(node.operand)
        return None if value is None else (-value if isinstance(node.op, ast.USub) else value)
    if not isinstance(node, ast.BinOp):
        return None
    left, right = _fold(node.left), _fold(node.right)
    if left is None or right is None:
        return None
    if isinstance(node.op, ast.Add):
        result = left + right
    elif isinstance(node.op, ast.Sub):
        result = left - right
    elif isinstance(node.op, ast.Mult):
        result = left * right
    elif isinstance(node.op, (ast.Div, ast.FloorDiv, ast.Mod)) and right != 0:
        quotient = abs(left) // abs(right) * (1 if (left < 0) == (right < 0) else -1)  # GLSL truncates
        result = quotient if not isinstance(node.op, ast.Mod) else left - quotient * right
    elif isinstance(node.op, ast.LShift) and 0 <= right < 64:
        result = left << right
    elif isinstance(node.op, ast.RShift) and 0 <= right < 64:
        result = left >> right
    else:
        return None
    return max(min(result, _CAP), -_CAP)
