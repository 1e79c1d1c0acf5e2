"""What a confined process may read, write and signal (glsandbox.grading.sandbox), and the file root."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from glsandbox.errors import SandboxError
from glsandbox.files import read_user_file, set_sandbox_root
from glsandbox.grading.sandbox import landlock_abi, read_roots


def test_user_files_outside_the_root_are_refused_only_while_grading(tmp_path: Path) -> None:
    inside, outside = tmp_path / "sub" / "a.txt", tmp_path / "secret.txt"
    inside.parent.mkdir()
    inside.write_text("mine")
    outside.write_text("secret")
    (tmp_path / "sub" / "link.txt").symlink_to(outside)
    assert read_user_file(outside, "texture file", "x") == b"secret"  # outside grading: any path
    set_sandbox_root(tmp_path / "sub")
    try:
        assert read_user_file(inside, "texture file", "x") == b"mine"
        for path in (outside, tmp_path / "sub" / ".." / "secret.txt", tmp_path / "sub" / "link.txt"):
            with pytest.raises(SandboxError, match=f"^texture file {path} is outside the submission"):
                read_user_file(path, "texture file", "x")
    finally:
        set_sandbox_root(None)
    assert read_user_file(outside, "texture file", "x") == b"secret"


CONFINED = """
import ctypes, os, sys
from glsandbox.grading.sandbox import confine
root, private, outside = sys.argv[1:4]
kernel = confine(root, [private])
libc = ctypes.CDLL(None, use_errno=True)
def python(call):
    try:
        call()
        return "allowed"
    except PermissionError:
        return "refused"
def c_open(path, flags):
    fd = libc.open(os.fsencode(path), flags)
    return "allowed" if fd >= 0 else "refused"
print(kernel)
print(python(lambda: open(os.path.join(root, "a.txt")).read()), python(lambda: open(outside).read()),
      python(lambda: open(os.path.join(private, "w.txt"), "w").write("x")), python(lambda: open(outside, "a")),
      python(lambda: os.remove(outside)), python(lambda: os.kill(os.getppid(), 0)),
      python(lambda: __import__("subprocess").run(["true"])))
print(c_open(os.path.join(root, "a.txt"), 0), c_open(outside, 0), c_open(outside, os.O_WRONLY))
print("signal", "refused" if libc.kill(os.getppid(), 0) != 0 else "allowed")
"""


def test_a_confined_process_reads_its_own_files_only(tmp_path: Path) -> None:
    root, private, outside = tmp_path / "sub", tmp_path / "private", tmp_path / "ref.png"
    root.mkdir()
    private.mkdir()
    (root / "a.txt").write_text("mine")
    outside.write_bytes(b"reference")
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(CONFINED), str(root), str(private), str(outside)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    kernel, python, c_calls, signal = proc.stdout.splitlines()
    assert python.split() == ["allowed", "refused", "allowed", "refused", "refused", "refused", "refused"]
    assert outside.read_bytes() == b"reference" and (private / "w.txt").read_text() == "x"
    abi = landlock_abi()
    assert kernel == str(abi >= 1)
    # around Python (ctypes): the kernel refuses where Landlock exists, and only there
    expected = ["allowed", "refused", "refused"] if abi >= 1 else ["allowed", "allowed", "allowed"]
    assert c_calls.split() == expected
    assert signal == ("signal refused" if abi >= 6 else "signal allowed")


def test_the_read_roots_hold_python_and_glsandbox_not_the_working_folder(tmp_path: Path) -> None:
    roots = read_roots([tmp_path])
    assert str(tmp_path.resolve()) in roots and "/usr" in roots
    assert str(Path(__file__).resolve().parents[2] / "glsandbox") in roots
    assert not any(root in ("/", "/tmp", str(Path.home())) for root in roots)
