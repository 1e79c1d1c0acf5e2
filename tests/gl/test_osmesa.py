"""The OSMesa backend (glsandbox/gl/osmesa.py): which library it loads, each way of not finding one
as one reason naming it, and a context that is current and answers moderngl's loader.
(The command line's side of it: tests/cli/test_bad_input.py; every lesson on it: test_context.py.)"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import subprocess
import sys
from pathlib import Path

import pytest
from support import backend_available, need

from glsandbox.errors import SandboxError
from glsandbox.gl import osmesa


def _refused(monkeypatch, value: str) -> str:
    monkeypatch.setenv("GLSANDBOX_OSMESA", value)
    with pytest.raises(SandboxError) as caught:
        osmesa._load_library()
    message = str(caught.value)
    assert message.startswith("OSMesa backend unavailable: ") and "\n" not in message
    return message


def test_a_path_that_is_not_a_library_file_is_refused_before_loading(monkeypatch, tmp_path: Path) -> None:
    assert "No such file or directory" in _refused(monkeypatch, str(tmp_path / "missing.so"))
    assert _refused(monkeypatch, str(tmp_path)).endswith("is not a regular file")
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "pipe.so")  # the dynamic loader would block reading it
        assert _refused(monkeypatch, str(tmp_path / "pipe.so")).endswith("is not a regular file")
    (tmp_path / "text.so").write_text("not a library\n")
    assert f"cannot load GLSANDBOX_OSMESA={tmp_path / 'text.so'} (" in _refused(monkeypatch, str(tmp_path / "text.so"))


def test_a_library_without_the_osmesa_entry_points_is_named(monkeypatch) -> None:
    libc = ctypes.util.find_library("c")
    if not libc:
        assert not (sys.platform == "linux" and os.environ.get("CI")), "CI's Linux has a C library ctypes finds"
        pytest.skip("no C library found by name here")
    assert osmesa._missing_symbol(ctypes.CDLL(libc)) == "OSMesaCreateContextAttribs"
    assert _refused(monkeypatch, libc).endswith(
        f"GLSANDBOX_OSMESA={libc} is not an OSMesa library (it has no OSMesaCreateContextAttribs)")


def test_no_system_library_says_how_to_install_one(monkeypatch) -> None:
    monkeypatch.delenv("GLSANDBOX_OSMESA", raising=False)
    tried = []
    monkeypatch.setattr(osmesa.ctypes.util, "find_library", lambda name: None)

    def cdll(name: str):
        tried.append(name)
        raise OSError(f"{name}: cannot open shared object file")

    monkeypatch.setattr(osmesa.ctypes, "CDLL", cdll)
    with pytest.raises(SandboxError, match=f"libOSMesa not found; {osmesa.INSTALL_HINT}$"):
        osmesa._load_library()
    assert tried == ["libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"]


CONTEXT = """
import ctypes
from glsandbox.gl.osmesa import OSMesaContext
context = OSMesaContext((8, 8))
get_string = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_uint)(context.load("glGetString"))
print(get_string(0x1F02).decode())  # GL_VERSION
assert context.make_current()
context.release()
context.release()  # twice: nothing left to destroy
"""


def test_a_context_is_current_and_answers_the_loader() -> None:
    reason = backend_available("osmesa")
    if reason:
        need("the osmesa backend", reason)
    # In a child: OSMesa and EGL must not share one process, and this one holds the EGL context.
    proc = subprocess.run([sys.executable, "-c", CONTEXT], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    major, minor = (int(part) for part in proc.stdout.split()[0].split(".")[:2])
    assert (major, minor) >= (3, 3), proc.stdout  # the core profile asked for
