"""``glsandbox gradescope ASSIGNMENT --out autograder.zip``: a Gradescope autograder bundle.

Gradescope builds an image from the zip's ``setup.sh`` once, unpacks the zip
into ``/autograder/source`` and, for each student, runs ``run_autograder``
with the student's files in ``/autograder/submission``; the score is read
from ``/autograder/results/results.json`` (Gradescope's "Autograder
Specifications"). The bundle holds:

- ``setup.sh``: the system packages OpenGL needs (EGL, Mesa's drivers),
  ``uv`` (through the image's own ``pip``, whatever Python it ships), a
  Python 3.12 installed by uv where every user can read it, and this very
  glsandbox version from the wheel in the bundle;
- ``run_autograder``: ``glsandbox check --one`` on the submission with the
  grading file, writing ``results.json`` (and, should glsandbox refuse the
  submission outright, a ``results.json`` that says why, score 0);
- ``assignment.grading.toml``: the grading file with every check, hidden
  ones included, its goldens in ``goldens/`` beside it (an exercise check
  has none: its cases, hidden ones too, are the wheel's);
- the wheel.

The root is ``/autograder`` unless ``GLSANDBOX_AUTOGRADER_ROOT`` names
another (how the bundle is tried on a teacher's machine).
"""

from __future__ import annotations

import base64
import csv
import hashlib
import importlib.metadata
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.grading.check import read_references
from glsandbox.measure.margin import margin_path
from glsandbox.grading.rubric import Check, Rubric, load_rubric

__all__ = ["build_bundle", "bundle_rubric", "glsandbox_wheel", "RUBRIC_NAME", "SETUP_SH", "RUN_AUTOGRADER"]

#: The grading file's name inside the bundle.
RUBRIC_NAME = "assignment.grading.toml"
#: Where setup.sh puts Python and glsandbox: outside /root, so the unprivileged user
#: each submission runs as can read them.
PREFIX = "/opt/glsandbox"

SETUP_SH = f"""#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (Ubuntu 22.04 or 24.04). It needs the package registries (apt, PyPI) and
# nothing else: glsandbox itself is the wheel beside this script.
set -euo pipefail
here="$(cd "$(dirname "${{BASH_SOURCE[0]}}")" && pwd)"
prefix="${{GLSANDBOX_PREFIX:-{PREFIX}}}"   # where Python and glsandbox go
export DEBIAN_FRONTEND=noninteractive
apt-get update
# OpenGL without a display: EGL and Mesa's software drivers (llvmpipe), OSMesa as the fallback
apt-get install -y --no-install-recommends ca-certificates python3 python3-pip \\
    libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri libgles2 libosmesa6
# uv through the image's pip, whatever Python it ships (22.04: 3.10; 24.04's pip wants
# --break-system-packages, which 22.04's pip does not know)
python3 -m pip install --upgrade uv --break-system-packages 2>/dev/null || python3 -m pip install --upgrade uv
uv="$(python3 -c 'import shutil, sysconfig, os; print(shutil.which("uv") or os.path.join(sysconfig.get_path("scripts"), "uv"))')"
# glsandbox needs Python 3.11 or newer: the image's where it has one (24.04: 3.12), else
# uv installs 3.12 (22.04 ships 3.10), where every user can read it
export UV_PYTHON_INSTALL_DIR="$prefix/python"
python="$("$uv" python find --system '>=3.11' 2>/dev/null || true)"
if [ -z "$python" ]; then
    "$uv" python install 3.12
    python=3.12
fi
"$uv" venv --python "$python" "$prefix/venv"
"$uv" pip install --python "$prefix/venv/bin/python" "$here"/glsandbox-*.whl
chmod -R a+rX "$prefix"
"$prefix/venv/bin/glsandbox" --version
"""

RUN_AUTOGRADER = f"""#!/usr/bin/env bash
# Gradescope runs this for each submission. The score is in results.json; the exit
# status is 0 even for a failing student (a non-zero one reads as the autograder failing).
root="${{GLSANDBOX_AUTOGRADER_ROOT:-/autograder}}"
export PATH="${{GLSANDBOX_PREFIX:-{PREFIX}}}/venv/bin:$PATH"   # setup.sh's glsandbox, else the one on PATH
mkdir -p "$root/results"
results="$root/results/results.json"
rm -f "$results"
cd "$root/source" || exit 1
errors="$(mktemp)"
glsandbox check --one "$root/submission" --rubric "$root/source/{RUBRIC_NAME}" --gradescope "$results" \\
    2>"$errors"
status=$?
cat "$errors" >&2
if [ ! -s "$results" ]; then   # refused before grading (no lesson in the submission, say): 0 points, and why
    python="$(dirname "$(command -v glsandbox)")/python"
    [ -x "$python" ] || python=python3
    "$python" - "$results" "$errors" "$status" <<'PY'
import json, sys
results, errors, status = sys.argv[1], sys.argv[2], sys.argv[3]
lines = [line for line in open(errors, errors="replace").read().splitlines() if line.startswith("error:")]
why = lines[-1] if lines else f"glsandbox check ended with status {{status}} and no results"
json.dump({{"score": 0, "output": why, "stdout_visibility": "hidden", "tests": []}}, open(results, "w"), indent=2)
PY
fi
rm -f "$errors"
exit 0
"""


def _toml_string(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(text)


def bundle_rubric(rubric: Rubric, goldens: dict[Path, str]) -> str:
    """The grading file as the bundle holds it: the same checks, each golden named by its path in
    the bundle (``goldens``: the teacher's path -> the bundle's)."""
    lines = ["# glsandbox gradescope: the assignment's checks, hidden ones included; goldens in goldens/"]
    if rubric.timeout is not None:
        lines.append(f"timeout = {rubric.timeout!r}")
    if rubric.memory is not None:
        lines.append(f"memory = {rubric.memory}")
    if rubric.entry is not None:
        lines.append(f"entry = {_toml_string(rubric.entry)}")
    for check in rubric.checks:
        if check.kind == "exercise":  # no golden: the exercise's own cases, its points per case group
            groups = ", ".join(f"{_toml_string(g)} = {p!r}" for g, p in check.group_points)
            lines += ["", "[[check]]", f"kind = {_toml_string(check.kind)}", f"name = {_toml_string(check.name)}",
                      f"exercise = {_toml_string(check.exercise)}", f"points = {{ {groups} }}",
                      f"hidden = {'true' if check.hidden else 'false'}"]
            continue
        lines += ["", "[[check]]", f"kind = {_toml_string(check.kind)}", f"name = {_toml_string(check.name)}",
                  f"golden = {_toml_string(goldens[check.golden])}", f"points = {check.points!r}",
                  f"hidden = {'true' if check.hidden else 'false'}"]
        if check.settings:
            lines.append(f"set = [{', '.join(_toml_string(s) for s in check.settings)}]")
        if check.size is not None:
            lines.append(f"size = \"{check.size[0]}x{check.size[1]}\"")
        if check.samples:
            lines.append(f"samples = {check.samples}")
        if check.tolerances:
            lines.append("tolerance = { " + ", ".join(f"{k} = {v!r}" for k, v in check.tolerances.items()) + " }")
    return "\n".join(lines) + "\n"


def _golden_names(checks: tuple[Check, ...]) -> dict[Path, str]:
    """Each golden's name in the bundle: ``goldens/<n>-<stem>.png`` (two checks may share one)."""
    names: dict[Path, str] = {}
    for check in checks:
        if check.kind == "exercise":
            continue
        if check.golden not in names:
            stem = "".join(c if c.isalnum() or c in "._-" else "_" for c in check.golden.stem)[:60] or "golden"
            names[check.golden] = f"goldens/{len(names) + 1}-{stem}.png"
    return names


def _project_root() -> Path | None:
    """The checkout this glsandbox runs from (a ``pyproject.toml`` naming glsandbox beside the package)."""
    root = Path(__file__).resolve().parents[2]
    try:
        text = (root / "pyproject.toml").read_text(encoding="utf-8")
    except OSError:
        return None
    return root if 'name = "glsandbox"' in text else None


def _installed_editable(dist: importlib.metadata.Distribution) -> bool:
    try:
        info = json.loads(dist.read_text("direct_url.json") or "{}")
    except ValueError:
        return False
    return bool(info.get("dir_info", {}).get("editable"))


def _build_from_checkout(root: Path, folder: Path) -> Path:
    """``uv build --wheel`` (or ``pip wheel``) of the checkout into ``folder``."""
    uv = shutil.which("uv") or (os.environ.get("UV") if os.path.isfile(os.environ.get("UV", "")) else None)
    commands = ([[uv, "build", "--wheel", "--out-dir", str(folder), str(root)]] if uv else []) + \
        [[sys.executable, "-m", "pip", "wheel", "--no-deps", "--wheel-dir", str(folder), str(root)]]
    reasons = []
    for command in commands:
        done = subprocess.run(command, capture_output=True, text=True)
        built = sorted(folder.glob("glsandbox-*.whl"))
        if done.returncode == 0 and built:
            return built[-1]
        reasons.append((done.stderr.strip().splitlines() or ["no wheel"])[-1])
    raise SandboxError(f"gradescope: cannot build glsandbox's wheel from {root} ({'; '.join(reasons)}); "
                       "give one with --wheel FILE")


def _record_hash(data: bytes) -> str:
    return "sha256=" + base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode("ascii")


def _wheel_from_installed(dist: importlib.metadata.Distribution, folder: Path) -> Path:
    """A wheel of the installed distribution's own files (its package and ``.dist-info``), RECORD rebuilt."""
    version = dist.version
    info = f"glsandbox-{version}.dist-info"
    target = folder / f"glsandbox-{version}-py3-none-any.whl"
    record = io.StringIO()
    writer = csv.writer(record, lineterminator="\n")
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as wheel:
        for entry in dist.files or []:
            name = entry.as_posix()
            if name.startswith(("..", "/")) or "__pycache__" in name or name.endswith((".pyc", "/RECORD", "INSTALLER",
                                                                                 "direct_url.json")):
                continue
            data = Path(dist.locate_file(entry)).read_bytes()
            wheel.writestr(name, data)
            writer.writerow([name, _record_hash(data), len(data)])
        writer.writerow([f"{info}/RECORD", "", ""])
        wheel.writestr(f"{info}/RECORD", record.getvalue())
    return target


def glsandbox_wheel(folder: Path, given: Path | None = None) -> Path:
    """The wheel of the glsandbox that is running: ``given``, else built from its checkout, else
    packed from the installed distribution's files."""
    if given is not None:
        if not given.is_file() or not given.name.startswith("glsandbox-") or given.suffix != ".whl":
            raise SandboxError(f"--wheel {given}: expected a glsandbox-VERSION-...whl file")
        return given
    try:
        dist = importlib.metadata.distribution("glsandbox")
    except importlib.metadata.PackageNotFoundError:
        dist = None
    root = _project_root()
    if root is not None and (dist is None or _installed_editable(dist)):
        return _build_from_checkout(root, folder)
    if dist is None:
        raise SandboxError("gradescope: glsandbox is neither installed nor a checkout; give its wheel with --wheel FILE")
    return _wheel_from_installed(dist, folder)


def _check_out(out: Path) -> None:
    if out.suffix.lower() != ".zip":
        raise SandboxError(f"--out {out}: expected a .zip file name (Gradescope uploads a zip)")
    if out.is_dir():
        raise SandboxError(f"--out {out}: is a folder, expected a .zip file name")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise SandboxError(f"--out {out}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise SandboxError(f"--out {out}: not writable")


def build_bundle(assignment: Path, out: Path, wheel: Path | None = None) -> list[str]:
    """Write the autograder zip for ``assignment`` (a grading file) to ``out``, atomically;
    the names it holds come back. Every golden must exist and be a PNG (one line if not)."""
    if not assignment.name.endswith(".toml"):
        raise SandboxError(f"{assignment}: expected a grading file (NAME.grading.toml; see glsandbox new --assignment)")
    _check_out(out)
    rubric = load_rubric(assignment)
    read_references([c for c in rubric.checks if c.kind != "exercise"])  # each golden a PNG, before any writing
    goldens = _golden_names(rubric.checks)
    with tempfile.TemporaryDirectory(prefix="glsandbox-gradescope-") as scratch:
        built = glsandbox_wheel(Path(scratch), wheel)
        entries: list[tuple[str, bytes, int]] = [
            ("setup.sh", SETUP_SH.encode(), 0o755), ("run_autograder", RUN_AUTOGRADER.encode(), 0o755),
            (RUBRIC_NAME, bundle_rubric(rubric, goldens).encode(), 0o644)]
        entries += [(name, files.read_user_file(path, "reference", "a .png file"), 0o644)
                    for path, name in goldens.items()]
        # each golden's margin beside it, under the bundle's name (glsandbox.measure.margin)
        entries += [(str(margin_path(name)), files.read_user_file(margin_path(path), "margin", "a .png file"), 0o644)
                    for path, name in goldens.items() if margin_path(path).exists()]
        entries.append((built.name, built.read_bytes(), 0o644))

        def write(handle) -> None:
            with zipfile.ZipFile(handle, "w", zipfile.ZIP_DEFLATED) as bundle:
                for name, data, mode in entries:
                    info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
                    info.external_attr = (0o100000 | mode) << 16  # a regular file and its mode, for unzip
                    info.compress_type = zipfile.ZIP_DEFLATED
                    bundle.writestr(info, data)

        try:
            files.atomic_write(out, write)
        except OSError as exc:
            raise SandboxError(f"--out {out}: cannot write ({exc.strerror or exc})") from None
    return [name for name, _, _ in entries]
