"""The layers around a graded submission (glsandbox.grading.layers): nothing of the teacher's reaches it.

A spy lesson reads every place the teacher's environment and other processes
could show (``/proc/self/environ``, ``/proc/1/environ``, its parent's
``environ`` and ``cmdline``, from Python and from ctypes) and tries the
network; the grader runs with a secret in its environment, and the secret
must be in no report, no printed line, no output kept.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import textwrap
import time
import uuid
from pathlib import Path

import pytest
from support import REPO_ROOT

from glsandbox.grading import layers
from glsandbox.grading.sandbox import landlock_abi

RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'

SPY = '''
import ctypes, os, socket
from pathlib import Path
from glsandbox import Lesson
from glsandbox.scene_file import load_scene

PORT = {port}
libc = ctypes.CDLL(None, use_errno=True)


def by_python(path):
    try:
        return Path(path).read_bytes()
    except OSError:
        return None


def by_ctypes(path):
    fd = libc.open(os.fsencode(path), 0)
    if fd < 0:
        return None
    buffer = ctypes.create_string_buffer(1 << 16)
    count = libc.read(fd, buffer, 1 << 16)
    libc.close(fd)
    return buffer.raw[:max(count, 0)]


class Spy(Lesson):
    def build(self):
        parent = os.getppid()
        paths = ("/proc/self/environ", "/proc/1/environ", "/proc/1/cmdline", f"/proc/{{parent}}/environ",
                 f"/proc/{{parent}}/cmdline", f"/proc/{{parent}}/stat", "/proc/cpuinfo")
        found = []  # the teacher's secret, wherever it shows: printed, so a leak reaches the report
        for name, read in (("P", by_python), ("C", by_ctypes)):
            texts = [read(path) for path in paths]
            print(name, "".join("-" if t is None else "r" for t in texts), flush=True)
            found += [t[t.find(b"tok-"):][:40] for t in texts if t and b"tok-" in t]
        found += [v[:40] for v in os.environ.values() if "tok-" in v]
        print("LEAK", found, flush=True)
        own = (by_python("/proc/self/environ") or b"").split(b"\\0")
        print("E", ",".join(e.split(b"=")[0].decode() for e in own if e)[:150], flush=True)
        try:
            listing = "r" if os.listdir("/proc") else "r"
        except OSError:
            listing = "-"
        try:
            with socket.create_connection(("127.0.0.1", PORT), timeout=3):
                tcp = "connected"
        except OSError as exc:
            tcp = f"refused:{{exc.errno}}"
        try:
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM).sendto(b"x", ("127.0.0.1", PORT))
            udp = "sent"
        except OSError as exc:
            udp = f"refused:{{exc.errno}}"
        print("N", listing, tcp, udp, os.getuid(), os.stat(__file__).st_uid, flush=True)
        print("S", "r" if by_ctypes("/etc/shadow") is not None else "-", flush=True)
        here = Path("scene.toml")
        here.write_text({scene!r})
        return load_scene(here)
'''

PATHS = ("/proc/self/environ", "/proc/1/environ", "/proc/1/cmdline", "/proc/PARENT/environ",
         "/proc/PARENT/cmdline", "/proc/PARENT/stat", "/proc/cpuinfo")


def network_closable() -> bool:
    """Whether this kernel lets the grader close a submission's network (a namespace or Landlock TCP)."""
    netns, _seccomp = layers._probe()
    return netns or landlock_abi() >= 4


def grade(tmp_path: Path, env: dict[str, str]) -> tuple[subprocess.CompletedProcess, dict, dict[str, str]]:
    """The spy (and a right submission) graded with every report; (process, what the spy saw, reports' text)."""
    ref = tmp_path / "ref.png"
    (tmp_path / "model.toml").write_text(RIGHT)
    run = [sys.executable, "-m", "glsandbox", "check"]  # the command as the console script runs it (glsandbox.launch)
    made = subprocess.run([*run, str(tmp_path / "model.toml"), "--golden", str(ref), "--update", "--size", "64x48"],
                          capture_output=True, text=True, env=env, cwd=REPO_ROOT, timeout=300)
    assert made.returncode == 0, made.stderr
    listener = socket.create_server(("127.0.0.1", 0))
    listener.settimeout(0.5)
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "a_right.toml").write_text(RIGHT)
    (subs / "spy.py").write_text(SPY.format(port=listener.getsockname()[1], scene=RIGHT))
    out = tmp_path / "out"
    reports = {kind: out / f"r.{kind}" for kind in ("csv", "json", "html", "junit", "gradescope")}
    proc = subprocess.run([*run, str(subs), "--golden", str(ref), *[f"--{k}={p}" for k, p in reports.items()]],
                          capture_output=True, text=True, env=env, cwd=REPO_ROOT, timeout=300)
    try:
        connection, _ = listener.accept()
        connection.close()
        reached = True
    except TimeoutError:
        reached = False
    listener.close()
    assert proc.returncode == 0, proc.stdout + proc.stderr
    spy = next(s for s in json.loads(reports["json"].read_text())["submissions"] if s["name"] == "spy")
    assert spy["status"] == "PASS", spy
    seen = {line.split(" ", 1)[0]: line.split(" ", 1)[1] for line in spy["output"] if " " in line}
    seen["reached"] = reached
    return proc, seen, {kind: path.read_text() for kind, path in reports.items()}


@pytest.mark.slow
def test_nothing_of_the_teachers_reaches_a_submission(tmp_path: Path, gl) -> None:
    secret = "tok-" + uuid.uuid4().hex
    env = {**os.environ, "TEACHERS_CLOUD_KEY": secret, "AWS_SECRET_ACCESS_KEY": secret}
    proc, seen, reports = grade(tmp_path, env)
    for text in (proc.stdout, proc.stderr, *reports.values()):
        assert secret not in text and secret.encode().hex() not in text
    assert proc.stdout.startswith("isolation: fresh environment;")
    assert seen["LEAK"] == "[]"  # the spy found nothing of the teacher's to print


@pytest.mark.slow
def test_the_submission_sees_no_other_process_and_no_network(tmp_path: Path, gl) -> None:
    """What the spy saw: only its own /proc entries, a closed network, its own user when the grader is root."""
    _proc, seen, _reports = grade(tmp_path, dict(os.environ))
    keys = seen["E"].split(",")
    assert keys and all(key.startswith(layers.ENV_KEPT) for key in keys[:-1]), keys
    python, c = dict(zip(PATHS, seen["P"])), dict(zip(PATHS, seen["C"]))
    assert python["/proc/self/environ"] == "r" and c["/proc/cpuinfo"] == "r"  # its own, and the machine's
    for path in PATHS[1:-1]:
        assert python[path] == "-", path  # the audit hook, everywhere
        if landlock_abi() >= 1:
            assert c[path] == "-", path  # the kernel, around Python
    listing, tcp, udp, uid, owner = seen["N"].split()
    if landlock_abi() >= 1:
        assert listing == "-"
    if network_closable() or os.environ.get("CI"):
        assert seen["reached"] is False and tcp.startswith("refused"), tcp
    if layers._probe()[0]:
        assert udp.startswith("refused"), udp
    if os.path.exists("/etc/shadow") and not os.stat("/etc/shadow").st_mode & 0o004:
        assert seen["S"] == "-"  # a root-only file: even where reading as root does is kept
    if os.geteuid() == 0:
        assert int(uid) != 0 and int(owner) == int(uid)  # a user with no account, owning its own copy
    else:
        assert int(uid) in (os.geteuid(), 65534)  # itself, or as its own user namespace shows it


def test_the_zygote_starts_from_a_minimal_environment() -> None:
    kept = layers.minimal_environment({"PATH": "/bin", "LANG": "C", "MESA_DEBUG": "1", "AWS_SECRET_ACCESS_KEY": "k",
                                       "PWD": "/home/teacher/course", "GITHUB_TOKEN": "t", "LC_ALL": "C"})
    assert kept == {"PATH": "/bin", "LANG": "C", "MESA_DEBUG": "1", "LC_ALL": "C"}


def test_a_renderer_starts_with_blas_on_one_thread_and_the_zygote_with_that_environment() -> None:
    import shutil

    from glsandbox.grading.zygote import Zygote

    assert layers.renderer_environment({"PATH": "/bin", "GITHUB_TOKEN": "t", "OPENBLAS_NUM_THREADS": "8"}) == \
        {"PATH": "/bin", "OPENBLAS_NUM_THREADS": "1"}
    zygote = Zygote()
    try:
        # Popen returns once the exec closed its error pipe, a moment before the kernel records
        # where the new program's environment lies: until then the file reads empty
        deadline = time.monotonic() + 10
        while not (raw := Path(f"/proc/{zygote.process.pid}/environ").read_bytes()) and time.monotonic() < deadline:
            time.sleep(0.01)
        environ = raw.split(b"\0")
    finally:
        zygote.close()
        shutil.rmtree(zygote.folder, ignore_errors=True)
    assert b"OPENBLAS_NUM_THREADS=1" in environ
    assert sorted(e for e in environ if e) == sorted(f"{k}={v}".encode() for k, v in layers.renderer_environment().items())


SECCOMP = """
import errno, socket, sys
from glsandbox.grading import layers
installed = layers.install_seccomp()
print(installed)
for family, kind in ((socket.AF_INET, socket.SOCK_STREAM), (socket.AF_INET6, socket.SOCK_DGRAM),
                     (socket.AF_PACKET, socket.SOCK_RAW), (socket.AF_UNIX, socket.SOCK_STREAM)):
    try:
        socket.socket(family, kind).close()
        print("made")
    except OSError as exc:
        print(errno.errorcode[exc.errno])
"""


def test_the_seccomp_filter_refuses_every_socket_but_a_unix_one() -> None:
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(SECCOMP)], capture_output=True, text=True,
                          timeout=60, cwd=REPO_ROOT)
    assert proc.returncode == 0, proc.stderr
    installed, *results = proc.stdout.split()
    if installed == "False":
        assert not (sys.platform == "linux" and os.uname().machine in ("x86_64", "aarch64") and os.environ.get("CI"))
        pytest.skip("no seccomp here")
    assert results == ["EAFNOSUPPORT", "EAFNOSUPPORT", "EAFNOSUPPORT", "made"]


def test_the_layers_line_says_what_this_machine_has() -> None:
    line = layers.describe()
    assert line.startswith("isolation: fresh environment; user: ")
    assert (f"Landlock ABI {landlock_abi()}" in line) == (landlock_abi() >= 1)
    assert ("Landlock TCP" in line) == (landlock_abi() >= 4)
    if os.geteuid() == 0:
        assert "a user with no account" in line
