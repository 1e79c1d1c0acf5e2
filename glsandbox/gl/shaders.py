"""Shader files: ``#include``, ``#define`` variants, errors mapped back to files.

One ``.glsl`` file holds one program. Its stages are selected by the macros
``VERTEX_SHADER`` and ``FRAGMENT_SHADER`` that the loader defines, one per
compile::

    #version 330 core
    #include "common/transform.glsl"
    #if defined(VERTEX_SHADER)
    ...
    #elif defined(FRAGMENT_SHADER)
    ...
    #endif

Includes are spliced in with ``#line <line> <file-number>`` directives, so the
compiler's messages (Mesa writes ``<file>:<line>(<col>): error: ...``) name the
original file and line, which :func:`compile_program` puts into a one-line
:class:`SandboxError`. GLSL 3.30 and later: after ``#line N``, the next line
is line N.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.plan import ProgramVariant

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
_VERSION = re.compile(r"^\s*#\s*version\b")
_STAGES = {"vertex_shader": "VERTEX_SHADER", "fragment_shader": "FRAGMENT_SHADER"}
# Mesa: "3:12(1): error: ..."; other drivers: "ERROR: 3:12: ..." or "3(12) : error ...".
_MESSAGE = re.compile(r"(?:ERROR:\s*)?(\d+)[:(](\d+)\)?(?:\(\d+\))?\s*:\s*(.*)")


def shader_root() -> Path:
    """Where the shader files are: inside the installed package (a wheel) or
    the repository's ``shaders/`` folder (a source checkout)."""
    here = Path(__file__).resolve().parent.parent
    for candidate in (here / "shaders", here.parent / "shaders"):
        if candidate.is_dir():
            return candidate
    raise SandboxError(f"shader folder not found next to {here}; is the package installed correctly?")


@dataclass
class Source:
    """A shader stage's text and the files its ``#line`` numbers refer to."""

    text: str
    files: list[Path]

    def file_name(self, number: int) -> str:
        if 0 <= number < len(self.files):
            path = self.files[number]
            try:
                return str(path.relative_to(shader_root().parent))
            except ValueError:
                return str(path)
        return f"<source {number}>"


def assemble(name: str, stage: str, defines: tuple[tuple[str, str], ...] = (), root: Path | None = None) -> Source:
    """Read ``<root>/<name>.glsl`` for one stage, with includes and defines."""
    base = root or shader_root()
    files: list[Path] = []
    out: list[str] = []

    def read(path: Path, included_from: str | None, stack: tuple[Path, ...]) -> None:
        if path in stack:
            raise SandboxError(f"{included_from}: #include cycle through {path.name}")
        try:
            lines = path.read_text(encoding="utf-8").splitlines()
        except OSError:
            where = f"{included_from}: " if included_from else ""
            raise SandboxError(f"{where}shader file {path} not found") from None
        number = len(files)
        files.append(path)
        for line_no, line in enumerate(lines, start=1):
            if _VERSION.match(line):
                if included_from is not None:
                    raise SandboxError(f"{path}:{line_no}: #version is only allowed in the top file")
                out.append(line)
                out.append(f"#define {_STAGES[stage]}")
                out.extend(f"#define {k} {v}".rstrip() for k, v in defines)
                out.append(f"#line {line_no + 1} {number}")
                continue
            include = _INCLUDE.match(line)
            if include:
                read(base / include.group(1), f"{path}:{line_no}", (*stack, path))
                out.append(f"#line {line_no + 1} {number}")
                continue
            out.append(line)

    top = base / f"{name}.glsl"
    if not top.is_file():
        known = sorted(p.stem for p in base.glob("*.glsl"))
        raise SandboxError(f"shader {name!r} not found in {base}; known: {', '.join(known)}")
    read(top, None, ())
    if not out or not _VERSION.match(out[0]):
        raise SandboxError(f"{top}:1: a shader file must start with #version")
    return Source("\n".join(out) + "\n", files)


def _first_error(log: str, source: Source, stage: str) -> str:
    for line in log.splitlines():
        m = _MESSAGE.match(line.strip())
        if m and ("error" in m.group(3).lower() or line.strip().upper().startswith("ERROR")):
            message = re.sub(r"^error:\s*", "", m.group(3).strip(), flags=re.I)
            return f"{source.file_name(int(m.group(1)))}:{m.group(2)}: {message} ({stage.replace('_', ' ')})"
    first = next((ln.strip() for ln in log.splitlines() if "error" in ln.lower()), log.strip())
    return f"{source.file_name(0)}: {first} ({stage.replace('_', ' ')})"


def compile_program(ctx: moderngl.Context, variant: ProgramVariant, root: Path | None = None) -> moderngl.Program:
    """Compile and link a program variant; errors name the file and line."""
    sources = {stage: assemble(variant.shader, stage, variant.defines, root) for stage in _STAGES}
    try:
        return ctx.program(**{stage: src.text for stage, src in sources.items()})
    except moderngl.Error as exc:
        log = str(exc)
        # moderngl prefixes the failing stage's log with its name and a rule.
        for stage, src in sources.items():
            if f"\n{stage}\n" in f"\n{log}":
                raise SandboxError(f"shader does not compile: {_first_error(log, src, stage)}") from None
        raise SandboxError(f"shader {variant.key} does not link: {' '.join(log.split())}") from None
