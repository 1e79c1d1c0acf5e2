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

Includes are spliced in, and the loader keeps, for every line of the
assembled text, the file and line it came from. The compiler's messages
(Mesa writes ``<string>:<line>(<col>): error: ...``) are mapped through that
table into a one-line :class:`SandboxError` naming the original file and
line. (``#line`` directives with source-string numbers would do the same in
theory, but Mesa 22 attributes some errors to the wrong string.)

A node's own shader (:attr:`glsandbox.scene.Node.shader`, a variant with
``user``) is the same form in a file of the user's: its ``#include`` lines
look next to the including file first, then in the shader folders, so
``#include "common/lighting.glsl"`` reaches the course's lighting.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.files import read_user_file
from glsandbox.gl.shader_limits import check_array_sizes
from glsandbox.plan import ProgramVariant

#: How deep ``#include`` may nest (the top file is depth 0); deeper is a mistake, most
#: likely a chain that never ends, and is refused before Python's own recursion limit.
MAX_INCLUDE_DEPTH = 32
#: The most ``#include`` lines one stage may follow, and the most lines it may
#: assemble to: a file included many times over (10 includes each including 10
#: ...) grows as a power without a cycle or a deep chain.
MAX_INCLUDES = 1_000
MAX_SHADER_LINES = 100_000

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*(?://.*)?$')
_ANY_INCLUDE = re.compile(r"^\s*#\s*include\b")
_VERSION = re.compile(r"^\s*#\s*version\b")
_STAGES = {"vertex_shader": "VERTEX_SHADER", "fragment_shader": "FRAGMENT_SHADER"}
_STAGE_MACRO = re.compile(r"\b(VERTEX_SHADER|FRAGMENT_SHADER)\b")
# "uniform [precision] type name[, name...][ = value];" (the names, not the type).
_UNIFORM_DECLARATION = re.compile(r"\buniform\s+(?:(?:lowp|mediump|highp)\s+)?\w+\s+([^;]+);")
_DECLARED_NAME = re.compile(r"^\s*([A-Za-z_]\w*)")
# Mesa: "3:12(1): error: ..."; other drivers: "ERROR: 3:12: ..." or "3(12) : error ...".
_MESSAGE = re.compile(r"(?:ERROR:\s*)?(\d+)[:(](\d+)\)?(?:\(\d+\))?\s*:\s*(.*)")


def shader_roots() -> list[Path]:
    """Folders searched for shader files, first match wins: ``GLSANDBOX_SHADER_DIR``
    (your own edited copies, e.g. to experiment and reload with R), then the
    built-in ones."""
    roots = []
    override = os.environ.get("GLSANDBOX_SHADER_DIR")
    if override:
        if not Path(override).is_dir():
            raise SandboxError(f"GLSANDBOX_SHADER_DIR={override} is not a folder")
        roots.append(Path(override).resolve())
    roots.append(shader_root())
    return roots


def find_shader_file(relative: str, roots: list[Path]) -> Path:
    """The first existing ``root/relative``, else the built-in path (reported as missing)."""
    for root in roots:
        if (root / relative).is_file():
            return root / relative
    return roots[-1] / relative


def shader_root() -> Path:
    """Where the built-in shader files are: inside the installed package (a
    wheel) or the repository's ``shaders/`` folder (a source checkout)."""
    here = Path(__file__).resolve().parent.parent
    for candidate in (here / "shaders", here.parent / "shaders"):
        if candidate.is_dir():
            return candidate
    raise SandboxError(f"shader folder not found next to {here}; is the package installed correctly?")


@dataclass
class Source:
    """A shader stage's text, and for each of its lines the file and line it came from."""

    text: str
    origins: list[tuple[Path, int]]

    def locate(self, line: int) -> str:
        """``file:line`` of line ``line`` (1-based) of the assembled text."""
        if 1 <= line <= len(self.origins):
            path, original = self.origins[line - 1]
            return f"{path}:{original}"
        return f"{self.origins[0][0]}:?" if self.origins else "<shader>"


def assemble(name: str, stage: str, defines: tuple[tuple[str, str], ...] = (), root: Path | None = None,
             *, user: bool = False) -> Source:
    """Read ``<name>.glsl`` for one stage, with includes and defines.

    ``root`` searches one folder only; by default :func:`shader_roots`.
    With ``user``, ``name`` is the path of a file of the user's; a file
    outside the shader folders includes relative to itself first.
    """
    roots = [root] if root is not None else shader_roots()
    out: list[str] = []
    origins: list[tuple[Path, int]] = []
    stages_seen: set[str] = set()  # the stage macros the files mention
    followed = [0]  # #include lines followed so far
    injected: set[int] = set()  # the loader's own lines (the stage and variant defines), by index

    def emit(text: str, path: Path, line_no: int) -> None:
        if len(out) >= MAX_SHADER_LINES:
            raise SandboxError(f"{path}:{line_no}: the shader, with its includes, has more than "
                               f"{MAX_SHADER_LINES:,} lines (a file included over and over?)")
        out.append(text)
        origins.append((path, line_no))

    def read(path: Path, included_from: str | None, stack: tuple[Path, ...]) -> None:
        if path in stack:
            raise SandboxError(f"{included_from}: #include cycle through {path.name}")
        if len(stack) > MAX_INCLUDE_DEPTH:
            raise SandboxError(f"{included_from}: #include nested more than {MAX_INCLUDE_DEPTH} files deep "
                               f"(from {stack[0]}); a chain of includes that never ends?")
        lines = _read_lines(path, included_from)
        for line_no, line in enumerate(lines, start=1):
            if _VERSION.match(line):
                if included_from is not None:
                    raise SandboxError(f"{path}:{line_no}: #version is only allowed in the top file")
                emit(line, path, line_no)
                # Injected lines are attributed to the #version line.
                injected.add(len(out))
                emit(f"#define {_STAGES[stage]}", path, line_no)
                for key, value in defines:
                    injected.add(len(out))
                    emit(f"#define {key} {value}".rstrip(), path, line_no)
                continue
            include = _INCLUDE.match(line)
            if include is None and _ANY_INCLUDE.match(line):
                raise SandboxError(f"{path}:{line_no}: expected #include \"file.glsl\", got {line.strip()!r}")
            if include:
                followed[0] += 1
                if followed[0] > MAX_INCLUDES:
                    raise SandboxError(f"{path}:{line_no}: more than {MAX_INCLUDES:,} #include lines followed "
                                       "for one shader (a file included over and over?)")
                read(_include(include.group(1), path, roots, f"{path}:{line_no}"), f"{path}:{line_no}",
                     (*stack, path))
                continue
            stages_seen.update(_STAGE_MACRO.findall(line.split("//")[0]))
            emit(line, path, line_no)

    if user:
        top = _shown(Path(name))
    else:
        top = find_shader_file(f"{name}.glsl", roots)
        if not top.is_file():
            known = sorted({p.stem for r in roots for p in r.glob("*.glsl")})
            raise SandboxError(f"shader {name!r} not found in {', '.join(map(str, roots))}; known: {', '.join(known)}")
    read(top, None, ())
    if not out or not _VERSION.match(out[0]):
        raise SandboxError(f"{top}:1: a shader file must start with #version")
    if user and _STAGES[stage] not in stages_seen:
        # Without its section the stage would compile the other stage's code, or nothing.
        # (A built-in file without one fails to compile, at the line the compiler names.)
        raise SandboxError(f"{top}: no {_STAGES[stage]} section; a shader file holds both stages: "
                           "#if defined(VERTEX_SHADER) ... #elif defined(FRAGMENT_SHADER) ... #endif")
    text = "\n".join(out) + "\n"
    check_array_sizes(text, origins, shader_root(), injected)
    return Source(text, origins)


def _include(relative: str, including: Path, roots: list[Path], where: str) -> Path:
    """The file an ``#include "relative"`` in ``including`` means: next to a file outside the
    shader folders first (a user's shader and its own includes), then the shader folders."""
    inside = any(including.resolve().is_relative_to(root.resolve()) for root in roots)
    folders = roots if inside else [including.parent, *roots]
    for folder in folders:
        if (folder / relative).is_file():
            return folder / relative
    if any((folder / relative).exists() for folder in folders):  # a folder or a pipe: read_user_file names it
        return next(folder / relative for folder in folders if (folder / relative).exists())
    raise SandboxError(f"{where}: #include \"{relative}\" not found (looked in {', '.join(map(str, folders))})")


def _shown(path: Path) -> Path:
    """A user's shader path as errors show it: relative to the working folder when inside it
    (as lesson file errors are), else as given."""
    try:
        return path.resolve().relative_to(Path.cwd().resolve()) if path.is_absolute() else path
    except (ValueError, OSError):
        return path


def _read_lines(path: Path, included_from: str | None) -> list[str]:
    """The lines of a shader file; a missing, unreadable, non-UTF-8 file or one holding a NUL
    byte (which GL would take as the end of the text) is one error naming it."""
    where = f"{included_from}: " if included_from else ""
    raw = read_user_file(path, f"{where}shader file", "a text file")
    if b"\0" in raw:
        line = raw[:raw.index(b"\0")].count(b"\n") + 1
        raise SandboxError(f"{path}:{line}: shader file holds a NUL byte (a binary file, or text cut short?)"
                           + (f", included from {included_from}" if included_from else ""))
    try:
        return raw.decode("utf-8").splitlines()
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise SandboxError(f"{path}:{line}: shader file is not UTF-8 text (byte 0x{raw[exc.start]:02x})"
                           + (f", included from {included_from}" if included_from else "")) from None


def _first_error(log: str, source: Source, stage: str) -> str:
    for line in log.splitlines():
        m = _MESSAGE.match(line.strip())
        if m and ("error" in m.group(3).lower() or line.strip().upper().startswith("ERROR")):
            message = re.sub(r"^error:\s*", "", m.group(3).strip(), flags=re.I)
            return f"{source.locate(int(m.group(2)))}: {message} ({stage.replace('_', ' ')})"
    first = next((ln.strip() for ln in log.splitlines() if "error" in ln.lower()), log.strip())
    return f"{source.locate(0)}: {first} ({stage.replace('_', ' ')})"


def compile_program(ctx: moderngl.Context, variant: ProgramVariant, root: Path | None = None) -> moderngl.Program:
    """Compile and link a program variant; errors name the file and line."""
    return compile_with_sources(ctx, variant, root)[0]


def compile_with_sources(ctx: moderngl.Context, variant: ProgramVariant,
                         root: Path | None = None) -> tuple[moderngl.Program, dict[str, Source]]:
    """:func:`compile_program`, and the assembled source of each stage (which files it read, what it declares)."""
    sources = {stage: assemble(variant.shader, stage, variant.defines, root, user=variant.user) for stage in _STAGES}
    try:
        return ctx.program(**{stage: src.text for stage, src in sources.items()}), sources
    except moderngl.Error as exc:
        log = str(exc)
        # moderngl prefixes the failing stage's log with its name and a rule.
        for stage, src in sources.items():
            if f"\n{stage}\n" in f"\n{log}":
                raise SandboxError(f"shader does not compile: {_first_error(log, src, stage)}") from None
        what = f"{variant.shader}: shader" if variant.user else f"shader {variant.key}"
        log = re.sub(r"^\s*GLSL Linker failed\s*Program\s*=+\s*", "", log)  # moderngl's header, not the log
        raise SandboxError(f"{what} does not link: {' '.join(log.split())}") from None


def declared_uniforms(sources: dict[str, Source]) -> frozenset[str]:
    """The uniform names the stages' text declares, active or not (the compiler
    drops unused ones from the program; a declaration says the name is meant)."""
    names = set()
    for source in sources.values():
        text = re.sub(r"//[^\n]*|/\*.*?\*/", " ", source.text, flags=re.S)
        for declaration in _UNIFORM_DECLARATION.finditer(text):
            for part in declaration.group(1).split(","):
                m = _DECLARED_NAME.match(part)
                if m:
                    names.add(m.group(1))
    return frozenset(names)


def source_files(sources: dict[str, Source]) -> frozenset[Path]:
    """Every file the stages were assembled from (the top file and its includes)."""
    return frozenset(path for source in sources.values() for path, _ in source.origins)
