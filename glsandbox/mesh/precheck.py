"""Model files checked before a reader builds anything from them: text formats line by line, and size.

trimesh reads the formats (:mod:`glsandbox.mesh.load`), but a text file cut
short, or with a face line that does not hold the vertex count it starts
with, reads as *part* of a model without a word. So before trimesh sees
them:

- **ASCII PLY**: the header's elements and properties, then every element
  line: the data must hold as many lines as the header counts, each with its
  properties' values (a list property: its count, then that many values);
- **OFF**: the ``OFF`` keyword line (``COFF``, ``NOFF``, ... too), the counts
  line, the vertex lines, and every face line holding the vertex count it
  starts with (plus at most 4 colour values);
- **OBJ**: text that is not UTF-8 is read as Latin-1 (a comment written by
  an old exporter is no reason to refuse a model);

each problem is one :class:`SandboxError` naming the file and line. Then the
**size**: the triangles the header says (PLY, OFF, binary STL, OBJ's ``f``
lines) times :data:`BYTES_PER_TRIANGLE`, the peak a load and its first frame
need (for an OBJ, at least what trimesh's parse of its text needs, by its bytes and lines:
:func:`needed_bytes`), is checked against a limit *before* any array is made
(:func:`check_memory`); a glTF's count is known only once read, and is
checked then, before glsandbox's own arrays. The limit is three quarters of
the memory the system has available, or the environment variable
``GLSANDBOX_MODEL_MEMORY`` (bytes, or with a unit: ``512M``, ``8G``).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from glsandbox.errors import SandboxError

__all__ = ["BYTES_PER_TRIANGLE", "MEMORY_ENV", "OBJ_BYTES_PER_FILE_BYTE", "OBJ_BYTES_PER_LINE", "check_memory",
           "checked_data", "claimed_triangles", "memory_limit", "needed_bytes"]

#: The memory a model needs per triangle to be loaded and drawn, at the peak (measured by
#: ``glsandbox bench``'s model rows at 165-206 bytes for binary files; rounded up).
BYTES_PER_TRIANGLE = 256

#: An OBJ's text costs trimesh's reader, at its peak, this many bytes per byte of the file plus
#: :data:`OBJ_BYTES_PER_LINE` per line (its copies of the text, and a Python string per line).
#: Measured (traced peak of a load, numpy 2.4): 348 bytes per triangle for a triangle repeated, 36
#: bytes and 4 lines each; 572 for the bunny's ``f a//a``, 69 bytes and 2 lines; 745 with uvs and
#: normals, 95 bytes and 2.5 lines. numpy 2.5's ``unique`` takes about 14% more on the repeated
#: triangle (396 a triangle), so the rule keeps a margin: 468, 693 and 945 for those three. Before
#: glsandbox's own arrays exist, so an OBJ needs the larger of this and :data:`BYTES_PER_TRIANGLE`
#: per triangle.
OBJ_BYTES_PER_FILE_BYTE = 9
OBJ_BYTES_PER_LINE = 36

#: The environment variable that sets the memory a model may use (bytes, or ``512M``, ``8G``).
MEMORY_ENV = "GLSANDBOX_MODEL_MEMORY"

#: Without the variable: this share of the memory the system has available.
AVAILABLE_SHARE = 0.75

#: The PLY scalar types (both spellings).
_PLY_TYPES = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16",
              "uint16", "int32", "uint32", "float32", "float64"}
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def checked_data(p: Path, data: bytes, file_type: str) -> bytes:
    """The file's bytes, checked (module docstring), as the reader should get them."""
    if file_type == "ply" and data[:3] == b"ply":
        header_end, elements, ascii_data = _ply_header(p, data)
        if ascii_data:
            _check_ply_lines(p, data, header_end, elements)
    elif file_type == "off":
        _check_off(p, data)
    elif file_type == "stl":
        _check_stl(p, data)
    elif file_type == "obj" and not data.isascii():  # (ASCII is UTF-8: no decoding to find out)
        try:
            data.decode("utf-8")
        except UnicodeDecodeError:  # Latin-1 maps every byte to a character: always readable
            data = data.decode("latin-1").encode("utf-8")
    return data


def claimed_triangles(data: bytes, file_type: str) -> int | None:
    """How many triangles the file says it has, from its header or lines, without reading its data
    (None where that cannot be told cheaply: glTF). A polygon counts as one (a lower bound)."""
    if file_type == "ply" and data[:3] == b"ply":
        end = data.find(b"end_header")
        match = re.search(rb"^element\s+face\s+(\d+)", data[:end if end >= 0 else 0], re.MULTILINE)
        return int(match.group(1)) if match else None
    if file_type == "off":
        counts = _off_counts_line(data)
        return counts[1] if counts else None
    if file_type == "stl" and len(data) >= 84:
        count = int.from_bytes(data[80:84], "little")
        if len(data) == 84 + 50 * count:  # a binary STL: its count is its size (else the reader refuses it)
            return count
        return data.count(b"endfacet")  # ASCII: one per facet
    if file_type == "obj":
        return data.count(b"\nf ") + data.startswith(b"f ")
    return None


def memory_limit() -> int:
    """The bytes a model may need: :data:`MEMORY_ENV` if set, else a share of the available memory."""
    text = os.environ.get(MEMORY_ENV, "").strip()
    if text:
        match = re.fullmatch(r"(\d+(?:\.\d+)?)\s*([KMGT]?)i?B?", text, re.IGNORECASE)
        if not match:
            raise SandboxError(f"{MEMORY_ENV}={text!r}: expected a number of bytes, or one with a unit "
                               "(512M, 8G)")
        return int(float(match.group(1)) * _UNITS[match.group(2).upper()])
    return int(_available_bytes() * AVAILABLE_SHARE)


def needed_bytes(triangles: int, file_type: str = "", data: bytes = b"") -> int:
    """The memory loading and drawing a model needs at the peak: :data:`BYTES_PER_TRIANGLE` per
    triangle, or for an OBJ (``data``: its text) trimesh's parse of the text if that is more
    (:data:`OBJ_BYTES_PER_FILE_BYTE`, :data:`OBJ_BYTES_PER_LINE`)."""
    need = triangles * BYTES_PER_TRIANGLE
    if file_type == "obj":
        need = max(need, len(data) * OBJ_BYTES_PER_FILE_BYTE + (data.count(b"\n") + 1) * OBJ_BYTES_PER_LINE)
    return need


def check_memory(p: Path, triangles: int, need: int | None = None) -> None:
    """Refuse a model whose triangles need more memory than :func:`memory_limit` allows: one line
    with the count, the memory it needs (``need``, else :func:`needed_bytes` of the count), the
    limit and how to raise it."""
    need = needed_bytes(triangles) if need is None else need
    limit = memory_limit()
    if need > limit:
        raise SandboxError(f"model file {p}: {triangles:,} triangles need about {_size(need)} of memory to load "
                           f"and draw, more than the {_size(limit)} allowed (set {MEMORY_ENV}, e.g. "
                           f"{MEMORY_ENV}={_suggest(need)}, to allow more)")


def _available_bytes() -> int:
    """MemAvailable from ``/proc/meminfo`` (Linux), else the physical memory, else 4 GiB."""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 4 << 30


def _size(n: int) -> str:
    """``1.2 GB``, ``350 MB``."""
    return f"{n / 1e9:.1f} GB" if n >= 1e9 else f"{max(n / 1e6, 0.1):.1f} MB"


def _suggest(n: int) -> str:
    """A value for the variable that covers ``n`` bytes, in whole gigabytes."""
    return f"{-(-n // (1 << 30))}G"


# --- STL --------------------------------------------------------------------


def _check_stl(p: Path, data: bytes) -> None:
    """An STL is binary (an 80-byte header, a triangle count n, then 50 bytes a triangle: exactly
    84 + 50·n bytes) or ASCII (``solid`` first). Anything else is refused here, not left to the
    reader, which may take arbitrary bytes for an ASCII file with no facets."""
    binary = len(data) >= 84 and len(data) == 84 + 50 * int.from_bytes(data[80:84], "little")
    if not binary and not data.lstrip()[:5].lower() == b"solid":
        raise SandboxError(f"model file {p}: not a readable STL file: neither binary (84 + 50 bytes a triangle, "
                           f"{len(data)} bytes here) nor ASCII (no 'solid' first)")


# --- PLY --------------------------------------------------------------------


def _ply_header(p: Path, data: bytes) -> tuple[int, list[tuple[str, int, list[str | None]]], bool]:
    """``(byte offset after end_header, elements, ascii)``: each element is ``(name, count, properties)``,
    a property ``None`` for a scalar and its name for a list."""
    end = data.find(b"end_header")
    if end < 0:
        raise SandboxError(f"model file {p}: not a readable PLY file: its header has no end_header line")
    newline = data.find(b"\n", end)
    header_end = len(data) if newline < 0 else newline + 1
    elements: list[tuple[str, int, list[str | None]]] = []
    ascii_data = False
    lines = data[:end].decode("latin-1").split("\n")
    for number, raw in enumerate(lines, start=1):
        words = raw.split()
        if not words or words[0] in ("ply", "comment", "obj_info"):
            continue
        where = f"model file {p}, line {number}"
        if words[0] == "format":
            ascii_data = len(words) > 1 and words[1] == "ascii"
        elif words[0] == "element":
            if len(words) != 3 or not words[2].isdigit():
                raise SandboxError(f"{where}: expected 'element NAME COUNT', got {raw.strip()!r}")
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            list_ok = len(words) == 5 and words[1] == "list" and words[2] in _PLY_TYPES and words[3] in _PLY_TYPES
            scalar_ok = len(words) == 3 and words[1] in _PLY_TYPES
            if not elements or not (list_ok or scalar_ok):
                raise SandboxError(f"{where}: not a PLY property line: {raw.strip()!r}")
            elements[-1][2].append(words[4] if list_ok else None)
        else:
            raise SandboxError(f"{where}: not a PLY header line: {raw.strip()!r}")
    return header_end, elements, ascii_data


def _check_ply_lines(p: Path, data: bytes, header_end: int, elements: list[tuple[str, int, list[str | None]]]) -> None:
    """Every element line of an ASCII PLY holds its properties' values, and there are as many as declared."""
    first_line = data[:header_end].count(b"\n") + 1
    lines = data[header_end:].split(b"\n")
    at = 0  # the next line of the data
    for name, count, properties in elements:
        scalars = sum(1 for prop in properties if prop is None)
        lists = len(properties) - scalars
        done = 0
        while done < count:
            while at < len(lines) and not lines[at].strip():
                at += 1
            if at >= len(lines):
                last = data.rstrip().count(b"\n") + 1
                raise SandboxError(f"model file {p}, line {last}: the data ends after {done:,} of the "
                                   f"{count:,} {name} lines its header declares (a cut-short file)")
            values = lines[at].split()
            if lists == 0 and len(values) != scalars:
                _ply_mismatch(p, first_line + at, name, f"{len(values)} values, expected {scalars}")
            elif lists == 1 and properties[0] is not None and scalars == 0:
                # The common face line: COUNT i1 .. iCOUNT.
                if not values[0].isdigit() or len(values) != 1 + int(values[0]):
                    _ply_mismatch(p, first_line + at, name,
                                  f"{len(values)} values, but it starts with the count {values[0].decode('latin-1')!r}"
                                  f" (expected that many values after it)")
            elif lists:
                _check_ply_mixed(p, first_line + at, name, properties, values)
            at += 1
            done += 1


def _check_ply_mixed(p: Path, line: int, name: str, properties: list[str | None], values: list[bytes]) -> None:
    """An element line with list properties among scalars: walk the properties in order."""
    i = 0
    for prop in properties:
        if prop is None:
            i += 1
            continue
        if i >= len(values) or not values[i].isdigit():
            _ply_mismatch(p, line, name, f"no count for its list {prop!r}")
        i += 1 + int(values[i])
    if i != len(values):
        _ply_mismatch(p, line, name, f"{len(values)} values, expected {i} from its properties")


def _ply_mismatch(p: Path, line: int, name: str, what: str) -> None:
    raise SandboxError(f"model file {p}, line {line}: a {name} line with {what}")


# --- OFF --------------------------------------------------------------------


def _content_lines(data: bytes) -> list[tuple[int, list[bytes]]]:
    """``(line number, words)`` of the lines with words in them, ``#`` comments removed."""
    found = []
    for number, raw in enumerate(data.split(b"\n"), start=1):
        words = raw.split(b"#", 1)[0].split()
        if words:
            found.append((number, words))
    return found


def _off_counts_line(data: bytes) -> tuple[int, int] | None:
    """The vertex and face counts of an OFF file, or None if its start is not the OFF layout."""
    head = _content_lines(data[:4096])
    if len(head) < 2 or not head[0][1][0].endswith(b"OFF"):
        return None
    words = head[0][1][1:] or head[1][1]
    if len(words) < 2 or not (words[0].isdigit() and words[1].isdigit()):
        return None
    return int(words[0]), int(words[1])


def _check_off(p: Path, data: bytes) -> None:
    """The OFF keyword, the counts, and every vertex and face line (module docstring)."""
    lines = _content_lines(data)
    if not lines or not lines[0][1][0].endswith(b"OFF") or lines[0][1][0].startswith(b"#"):
        line = lines[0][0] if lines else 1
        raise SandboxError(f"model file {p}, line {line}: an OFF file starts with the word OFF "
                           "(its header line is missing)")
    keyword_line, words = lines[0]
    if b"BINARY" in (w.upper() for w in words[1:]):
        return  # binary OFF: trimesh's reader checks its sizes
    rest = lines[1:]
    counts = words[1:]
    counts_line = keyword_line
    if not counts:
        if not rest:
            raise SandboxError(f"model file {p}, line {keyword_line}: the file ends after its OFF line "
                               "(no vertex and face counts)")
        counts_line, counts = rest[0]
        rest = rest[1:]
    if len(counts) < 2 or not all(c.isdigit() for c in counts[:2]):
        raise SandboxError(f"model file {p}, line {counts_line}: expected the vertex and face counts, "
                           f"got {b' '.join(counts).decode('latin-1')!r}")
    vertices, faces = int(counts[0]), int(counts[1])
    if len(rest) < vertices + faces:
        have_v = min(len(rest), vertices)
        have_f = max(0, len(rest) - vertices)
        last = rest[-1][0] if rest else counts_line
        raise SandboxError(f"model file {p}, line {last}: the data ends after {have_v:,} of {vertices:,} vertices "
                           f"and {have_f:,} of {faces:,} faces its header declares (a cut-short file)")
    for number, values in rest[:vertices]:
        if len(values) < 3:
            raise SandboxError(f"model file {p}, line {number}: a vertex line with {len(values)} values, "
                               "expected at least 3 (x y z)")
    for number, values in rest[vertices:vertices + faces]:
        n = int(values[0]) if values[0].isdigit() else -1
        if n < 0 or not (1 + n <= len(values) <= 1 + n + 4):
            raise SandboxError(f"model file {p}, line {number}: a face line with {len(values)} values, but it "
                               f"starts with the count {values[0].decode('latin-1')!r} (expected that many vertex "
                               "indices after it, then at most 4 colour values)")
