"""Confining a graded submission's process to its own files (Linux), in three layers.

A submission runs as the teacher's own user, so nothing in the operating
system stops it, by default, from reading the reference, editing a
neighbour's file or signalling the grader. :func:`confine` closes those doors
in the child that renders it, after the GL context is open and before any
of the submission's code runs:

1. glsandbox's own reads of user files (scene files, textures, models,
   shaders, lesson files) refuse a path that resolves outside the submission
   (:func:`glsandbox.files.set_sandbox_root`): a one-line error naming the path.
2. A Python audit hook (PEP 578) refuses, from then on, opening a file for
   reading outside the allowed folders, any write, rename or removal outside
   the submission's private folders, starting programs, and signals to
   processes other than the child and its own children.
3. Landlock (Linux 5.13 and later, where enabled) makes the kernel enforce
   the same file rules, and from kernel 6.12 (Landlock ABI 6) the signal
   rule, against code that bypasses Python (``ctypes`` calling the C
   library), and from ABI 4 refuses every TCP bind and connect. Of ``/proc``
   it may read only its own entries (and the machine's ``cpuinfo``,
   ``meminfo``, ...), so no other process's environment or command line.
   Where Landlock is missing, layers 1 and 2 remain; the time,
   memory and process limits (:mod:`glsandbox.grading.isolate`) hold always.

The user, environment and network around the process are :mod:`glsandbox.grading.layers`'.

The folders a submission may read: its own copy, its private working folder,
the Python installation and its packages, glsandbox's own files, and the
system's (``/usr``, ``/lib``, ``/etc``, ``/dev``, ``/sys``, and of ``/proc`` its own entries).
"""

from __future__ import annotations

import ctypes
import functools
import os
import sys
import sysconfig
from collections.abc import Iterable, Sequence
from pathlib import Path

from glsandbox import files

__all__ = ["confine", "read_roots", "landlock_abi", "others_may_read"]

#: System folders every process reads (shared libraries, fonts, locale, devices).
SYSTEM_READ = ("/usr", "/lib", "/lib32", "/lib64", "/etc", "/dev", "/proc", "/sys", "/opt")

#: Audit events that start another program: refused outright.
_EXEC_EVENTS = frozenset({"os.system", "os.exec", "os.posix_spawn", "os.spawn", "subprocess.Popen",
                          "os.startfile", "pty.spawn"})
#: Audit events that change the file system at their first argument.
_WRITE_EVENTS = frozenset({"os.remove", "os.rmdir", "os.mkdir", "os.chmod", "os.chown", "os.truncate",
                           "os.utime", "os.chflags", "os.lchflags", "os.setxattr", "os.removexattr",
                           "shutil.rmtree", "os.mkfifo", "os.mknod"})
#: Audit events that change the file system at their first two arguments.
_TWO_PATH_EVENTS = frozenset({"os.rename", "os.link", "os.symlink", "shutil.copyfile", "shutil.move"})


def read_roots(extra: Iterable[str | os.PathLike[str]] = ()) -> list[str]:
    """The folders a confined submission may read: Python's, glsandbox's, the system's and ``extra``."""
    return sorted({*_base_roots(), *(os.path.realpath(p) for p in extra if os.path.isdir(p))})


@functools.lru_cache(maxsize=1)
def _base_roots() -> tuple[str, ...]:
    """:func:`read_roots` without the extra folders: the same for every submission of a run, so
    worked out once (in the zygote, before it forks)."""

    roots = {sys.prefix, sys.base_prefix, sys.exec_prefix, *SYSTEM_READ,
             str(Path(__file__).resolve().parents[1])}  # the glsandbox package
    for key in ("stdlib", "platstdlib", "purelib", "platlib"):
        path = sysconfig.get_paths().get(key)
        if path:
            roots.add(path)
    roots.update(p for p in sys.path if p.endswith(("site-packages", "dist-packages")))
    from glsandbox.course_lessons import BUILTIN_LESSONS

    roots.add(str(BUILTIN_LESSONS))  # the course's lessons, which a submission may subclass
    from glsandbox.gl.shaders import shader_roots

    roots.update(str(p) for p in shader_roots())  # glsandbox's shaders, and GLSANDBOX_SHADER_DIR's
    return tuple(sorted({os.path.realpath(r) for r in roots if os.path.isdir(r)}))


@functools.lru_cache(maxsize=None)
def others_may_read(root: str) -> tuple[str, ...]:
    """The parts of ``root`` (a small folder: ``/etc``) a user with no account may read: the whole
    folder where all in it is readable by others, else its entries so, recursively (a link by
    what it points to). With the capability of reading any file kept, Landlock granting these
    instead of ``root`` keeps a root-only file (``/etc/shadow``, a private key) unreadable."""
    import stat

    try:
        mode = os.stat(root).st_mode
    except OSError:
        return ()
    if not stat.S_ISDIR(mode):
        return (root,) if mode & 0o004 else ()
    if mode & 0o005 != 0o005 or os.path.islink(root):  # a link to a folder: not followed
        return ()
    try:
        names = sorted(os.listdir(root))
    except OSError:
        return ()
    parts = [(os.path.join(root, n), others_may_read(os.path.join(root, n))) for n in names]
    if all(found == (path,) for path, found in parts):
        return (root,)
    return tuple(p for _, found in parts for p in found)


def shader_cache_dirs() -> list[str]:
    """Mesa's on-disk shader cache folders that exist (compiled shaders: a warm cache saves
    a fresh process 0.2 to 0.4 s of compiling on llvmpipe)."""
    home = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidates = [os.environ.get("MESA_SHADER_CACHE_DIR"), os.environ.get("MESA_GLSL_CACHE_DIR"),
                  os.path.join(home, "mesa_shader_cache"), os.path.join(home, "mesa_shader_cache_db")]
    return [os.path.realpath(c) for c in candidates if c and os.path.isdir(c)]


def _inside(path: str, roots: Sequence[str]) -> bool:
    return any(files.inside(path, root) for root in roots)


def _resolved(path: object) -> str | None:
    """An audit event's path argument as a real absolute path (None: a file descriptor or unknown)."""
    if isinstance(path, int) or path is None:
        return None
    try:
        raw = os.fsdecode(path)
    except TypeError:
        return None
    return os.path.realpath(raw)


def _descendant(pid: int, ancestor: int) -> bool:
    """Whether ``pid`` is ``ancestor`` or one of its descendants (by /proc's parent links)."""
    seen = 0
    while pid > 1 and seen < 4096:
        if pid == ancestor:
            return True
        try:
            with open(f"/proc/{pid}/stat", "rb") as handle:  # before the hook: opened by us, allowed
                fields = handle.read().rsplit(b")", 1)[1].split()
        except OSError:
            return False
        pid, seen = int(fields[1]), seen + 1
    return False


def _install_audit_hook(reads: Sequence[str], writes: Sequence[str]) -> None:
    me = os.getpid()
    proc_self = (f"/proc/{me}", "/proc/self", "/proc/thread-self", "/proc/cpuinfo", "/proc/meminfo")

    def refuse(what: str, path: str) -> None:
        raise PermissionError(f"{what} {path}: outside the submission (a graded submission may use only its own files)")

    def readable(path: str) -> bool:
        parts = path.split("/")
        if path.startswith("/proc/") and parts[2].isdigit():  # only its own process, not the grader's
            return _inside(path, proc_self)
        return _inside(path, reads) or _inside(path, writes)

    def hook(event: str, args: tuple) -> None:
        if event == "open":
            path = _resolved(args[0])
            if path is None:
                return
            mode = args[1] if isinstance(args[1], str) else "r"
            flags = args[2] if len(args) > 2 and isinstance(args[2], int) else 0
            writing = any(c in mode for c in "wax+") or flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC)
            if writing and not (_inside(path, writes) or path == os.devnull):
                refuse("writing", path)
            if not writing and not readable(path):
                refuse("reading", path)
        elif event in ("os.listdir", "os.scandir"):
            path = _resolved(args[0] if args[0] is not None else ".")
            if path is not None and not readable(path):
                refuse("listing", path)
        elif event in _WRITE_EVENTS or event in _TWO_PATH_EVENTS:
            for arg in args[:2 if event in _TWO_PATH_EVENTS else 1]:
                path = _resolved(arg)
                if path is not None and not _inside(path, writes):
                    refuse("changing", path)
        elif event in _EXEC_EVENTS:
            raise PermissionError(f"{event}: a graded submission may not start programs")
        elif event in ("os.kill", "os.killpg", "signal.pthread_kill"):
            target = args[0]
            if event == "os.killpg" or not isinstance(target, int) or target <= 0 or not _descendant(target, me):
                raise PermissionError(f"{event}({target}): a graded submission may signal only its own processes")

    sys.addaudithook(hook)


# --- Landlock (linux/landlock.h), through the raw system calls --------------------------

_SYS_CREATE, _SYS_ADD_RULE, _SYS_RESTRICT = 444, 445, 446  # the same numbers on x86-64 and arm64
_PR_SET_NO_NEW_PRIVS = 38
#: Access rights by ABI version: files (v1), refer (v2), truncate (v3), device ioctl (v5).
_FS_V1 = (1 << 13) - 1
_FS_BY_ABI = {1: _FS_V1, 2: _FS_V1 | 1 << 13, 3: _FS_V1 | 1 << 13 | 1 << 14, 4: _FS_V1 | 1 << 13 | 1 << 14}
_READ = 1 | 4 | 8  # EXECUTE, READ_FILE, READ_DIR
_SCOPE_SIGNAL, _SCOPE_UNIX = 2, 1
_NET_BIND_TCP, _NET_CONNECT_TCP = 1, 2
#: What of /proc a confined process may read besides its own /proc/<pid>: no other process's entries.
PROC_READ = ("/proc/cpuinfo", "/proc/meminfo", "/proc/stat", "/proc/version", "/proc/sys/kernel")


class _RulesetAttr(ctypes.Structure):
    _fields_ = [("handled_access_fs", ctypes.c_uint64), ("handled_access_net", ctypes.c_uint64),
                ("scoped", ctypes.c_uint64)]


class _PathBeneath(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _libc() -> ctypes.CDLL | None:
    if sys.platform != "linux" or os.uname().machine not in ("x86_64", "aarch64"):
        return None
    return ctypes.CDLL(None, use_errno=True)


def landlock_abi() -> int:
    """The kernel's Landlock ABI version (0: not available)."""
    libc = _libc()
    if libc is None:
        return 0
    version = libc.syscall(_SYS_CREATE, None, ctypes.c_size_t(0), ctypes.c_uint32(1))
    return max(int(version), 0)


def _landlock(reads: Sequence[str], writes: Sequence[str]) -> bool:
    """Restrict this process (and every process it starts) to ``reads`` and ``writes``; False when unavailable."""
    abi = landlock_abi()
    libc = _libc()
    if abi < 1 or libc is None:
        return False
    fs = _FS_BY_ABI.get(abi, _FS_BY_ABI[4] | 1 << 15)
    # ABI 4: TCP bind and connect are handled, and no rule allows any port: both refused.
    attr = _RulesetAttr(fs, _NET_BIND_TCP | _NET_CONNECT_TCP if abi >= 4 else 0,
                        _SCOPE_SIGNAL | _SCOPE_UNIX if abi >= 6 else 0)
    size = 24 if abi >= 6 else 16 if abi >= 4 else 8
    ruleset = libc.syscall(_SYS_CREATE, ctypes.byref(attr), ctypes.c_size_t(size), ctypes.c_uint32(0))
    if ruleset < 0:
        return False
    try:
        for roots, access in ((reads, _READ), (writes, fs)):
            for root in roots:
                try:
                    fd = os.open(root, os.O_PATH | os.O_CLOEXEC)
                except OSError:
                    continue
                try:
                    rule = _PathBeneath(access if os.path.isdir(root) else access & (1 | 2 | 4 | 1 << 14), fd)
                    libc.syscall(_SYS_ADD_RULE, ruleset, 1, ctypes.byref(rule), ctypes.c_uint32(0))
                finally:
                    os.close(fd)
        if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
            return False
        return libc.syscall(_SYS_RESTRICT, ruleset, ctypes.c_uint32(0)) == 0
    finally:
        os.close(ruleset)


def confine(submission: str | os.PathLike[str], private: Sequence[str | os.PathLike[str]],
            cache_writable: bool = False, others_only: bool = False) -> bool:
    """Confine this process to reading ``submission`` (and :func:`read_roots`) and writing only ``private``.

    Mesa's shader cache is read, and written only with ``cache_writable``
    (the model answer, rendered by ``--update``): a submission that could
    write it could plant compiled code that its neighbours' renderers load.
    ``others_only``: the process kept the capability of reading any file
    (:func:`glsandbox.grading.layers.drop_privileges`), so of ``/etc`` only
    what any user may read is granted (:func:`others_may_read`).
    Irreversible: call it in the child that renders a submission, never in
    the grader. Returns whether the kernel enforces it too (Landlock).
    """
    root = os.path.realpath(submission)
    cache = shader_cache_dirs()
    writes = [os.path.realpath(p) for p in private] + (cache if cache_writable else [])
    # /proc: its own entries only (/proc/self resolves to them), never another process's
    own_proc = [f"/proc/{os.getpid()}", *(p for p in PROC_READ if os.path.exists(p))]
    reads = [r for r in read_roots([root, *cache]) if r != "/proc"] + own_proc
    if others_only:  # reading as root does: no root-only file of /etc (shadow, private keys)
        reads = [r for r in reads if r != "/etc"] + list(others_may_read("/etc"))
    from glsandbox.gl.shaders import shader_roots

    files.set_sandbox_root(root, also=(*writes, *shader_roots()))
    enforced = _landlock(reads, [*writes, "/dev/null"])
    _install_audit_hook(reads, writes)
    return enforced
