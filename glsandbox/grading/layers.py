"""The process-wide layers around a graded submission (Linux): its environment, its user, its network.

:mod:`glsandbox.grading.sandbox` confines what a submission's process may
read, write and signal; this module gives that process nothing of the
teacher's to start with:

- **environment**: the zygote every renderer is forked from is a fresh
  program started with :func:`minimal_environment` (only what rendering and
  the locale read), so the ``/proc/self/environ`` of every fork holds nothing
  else: a cleared ``os.environ`` would still leave the first one there;
- **user**: when the grader runs as root (Gradescope, CI containers), the
  renderer becomes a user with no account (:func:`submission_ids`) before the
  submission's code runs; its copy of the submission is owned by that user.
  Where the Python installation is readable only by root, the renderer keeps
  one capability, reading any file (``CAP_DAC_READ_SEARCH``), and only where
  Landlock bounds those reads; it never keeps the power to write or signal;
- **network**: a network namespace of its own with no interface up
  (:func:`close_network`: every family but local Unix sockets), Landlock's TCP
  rules (ABI 4 and later, in :mod:`~glsandbox.grading.sandbox`) and a seccomp
  filter that refuses every socket but a Unix one (:func:`install_seccomp`).

:func:`describe` is the one line ``glsandbox check`` starts with: which of
them this machine has.
"""

from __future__ import annotations

import ctypes
import os
import struct
import sys

__all__ = ["minimal_environment", "renderer_environment", "submission_ids", "hand_over", "reading_kept",
           "drop_privileges", "close_network", "install_seccomp", "describe"]

#: The environment a renderer keeps (by prefix): the drivers', the locale's and glsandbox's own.
ENV_KEPT = ("PATH", "HOME", "LANG", "LC_", "TZ", "DISPLAY", "WAYLAND_", "XDG_", "MESA_", "LIBGL_", "GALLIUM_",
            "LP_", "EGL_", "__EGL_", "__GLX_", "GLCONTEXT_", "PYOPENGL_", "GLSANDBOX_", "PYTHONHASHSEED", "CI")

#: The first of the user ids a submission runs as when the grader is root: ids no account has
#: (one per supervisor, so two submissions graded at once are two users).
NO_ACCOUNT_BASE, NO_ACCOUNT_COUNT = 1_870_000_000, 1 << 20

_CLONE_NEWUSER, _CLONE_NEWNET = 0x10000000, 0x40000000
_PR_SET_KEEPCAPS, _PR_SET_NO_NEW_PRIVS, _PR_SET_SECCOMP, _PR_CAP_AMBIENT = 8, 38, 22, 47
_PR_CAP_AMBIENT_RAISE = 2
_CAP_DAC_READ_SEARCH = 2
_CAPABILITY_VERSION_3 = 0x20080522


def minimal_environment(environ: dict[str, str] | os._Environ | None = None) -> dict[str, str]:
    """Of ``environ`` (the grader's), only the variables rendering and the locale read (:data:`ENV_KEPT`)."""
    source = os.environ if environ is None else environ
    return {key: value for key, value in source.items() if key.startswith(ENV_KEPT)}


#: What a renderer's environment sets besides what it keeps: numpy's BLAS on one thread. Its
#: threads would only spin (a renderer's arrays are a few matrices and its pixels; the job slots
#: are the parallelism), about 0.1 s of a core each time numpy is imported, on a machine whose
#: cores the renderers want.
RENDERER_SETS = {"OPENBLAS_NUM_THREADS": "1"}


def renderer_environment(environ: dict[str, str] | os._Environ | None = None) -> dict[str, str]:
    """The environment a renderer's program starts with (the zygote's, which every renderer it
    forks keeps, or a fresh Python's on the portable path): :func:`minimal_environment` of
    ``environ`` and :data:`RENDERER_SETS`."""
    return {**minimal_environment(environ), **RENDERER_SETS}


def _libc() -> ctypes.CDLL | None:
    if sys.platform != "linux":
        return None
    return ctypes.CDLL(None, use_errno=True)


def submission_ids(seed: int) -> tuple[int, int] | None:
    """The (uid, gid) a submission runs as when this process is root: an id no account has,
    from ``seed`` (``nobody``'s 65534 where that id has one); None when not root."""
    if sys.platform != "linux" or os.geteuid() != 0:  # setresuid and these ids: Linux's
        return None
    import pwd

    uid = NO_ACCOUNT_BASE + seed % NO_ACCOUNT_COUNT
    try:
        pwd.getpwuid(uid)
    except KeyError:
        return uid, uid
    return 65534, 65534


def python_readable_by_others() -> bool:
    """Whether a user with no account can read the Python installation (every folder above
    the standard library searchable by others, the library readable)."""
    import sysconfig

    stdlib = os.path.realpath(sysconfig.get_paths()["stdlib"])
    path = stdlib
    while True:
        try:
            mode = os.stat(path).st_mode
        except OSError:
            return False
        if not mode & 0o001:
            return False
        parent = os.path.dirname(path)
        if parent == path:
            break
        path = parent
    return bool(os.stat(stdlib).st_mode & 0o004)


def _capset(effective: int, permitted: int, inheritable: int = 0) -> bool:
    libc = _libc()
    if libc is None:
        return False
    header = struct.pack("II", _CAPABILITY_VERSION_3, 0)
    data = struct.pack("IIIIII", effective & 0xFFFFFFFF, permitted & 0xFFFFFFFF, inheritable & 0xFFFFFFFF,
                       effective >> 32, permitted >> 32, inheritable >> 32)
    return libc.capset(ctypes.c_char_p(header), ctypes.c_char_p(data)) == 0


def hand_over(work: str, folders: list[str], ids: tuple[int, int]) -> None:
    """Make ``folders`` (and all in them) ``ids``'s; ``work`` above them only passable by others."""
    uid, gid = ids
    os.chmod(work, 0o711)
    for folder in folders:
        os.lchown(folder, uid, gid)
        for base, dirs, names in os.walk(folder):
            for name in dirs + names:
                os.lchown(os.path.join(base, name), uid, gid)


def reading_kept() -> bool:
    """Whether a submission's user keeps the capability to read any file: only where the Python
    installation is readable by root alone (it could not run else) and Landlock bounds the reads."""
    from glsandbox.grading.sandbox import landlock_abi

    return not python_readable_by_others() and landlock_abi() >= 1


def drop_privileges(ids: tuple[int, int], keep_reading: bool, across_exec: bool = False) -> str:
    """Become ``ids`` for good (no way back); ``keep_reading`` keeps only the capability to read
    any file (for a Python only root may read; call it only where Landlock will bound the reads),
    and ``across_exec`` keeps it through the ``execve`` of a fresh interpreter too (an ambient
    capability: the exercises' process). Returns what was done, for the layers line."""
    libc = _libc()
    uid, gid = ids
    if keep_reading and libc is not None:
        libc.prctl(_PR_SET_KEEPCAPS, 1, 0, 0, 0)
    os.setgroups([])
    os.setresgid(gid, gid, gid)
    os.setresuid(uid, uid, uid)
    if keep_reading and libc is not None:
        bit = 1 << _CAP_DAC_READ_SEARCH
        if _capset(bit, bit, bit if across_exec else 0):
            if across_exec:
                libc.prctl(_PR_CAP_AMBIENT, _PR_CAP_AMBIENT_RAISE, _CAP_DAC_READ_SEARCH, 0, 0)
            return f"uid {uid}, reading as root does"
    return f"uid {uid}"


def drop_reading() -> None:
    """Give up the capability :func:`drop_privileges` may have kept (Landlock was not there after all)."""
    _capset(0, 0)


def close_network() -> bool:
    """A network namespace of this process's own (no interface up: nothing reaches the host's
    loopback or any other machine); True when the kernel allowed it. As root directly, else
    inside a user namespace of its own, which needs a single-threaded process (call it before a
    GL context starts threads)."""
    libc = _libc()
    if libc is None:
        return False
    if os.geteuid() == 0 and libc.unshare(_CLONE_NEWNET) == 0:
        return True
    return libc.unshare(_CLONE_NEWUSER | _CLONE_NEWNET) == 0


# --- seccomp: refuse every socket but a Unix one, and opening files by handle ---------------------------

_ARCHES = {  # machine -> (AUDIT_ARCH_*, socket, io_uring_setup, open_by_handle_at)
    "x86_64": (0xC000003E, 41, 425, 304),
    "aarch64": (0xC00000B7, 198, 425, 265),
}
_SECCOMP_RET_ALLOW, _SECCOMP_RET_ERRNO = 0x7FFF0000, 0x00050000
_EPERM, _EAFNOSUPPORT, _AF_UNIX = 1, 97, 1
_LD_W_ABS, _JEQ_K, _JGE_K, _RET_K = 0x20, 0x15, 0x35, 0x06


class _SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]


def _filter_program(arch: int, socket_nr: int, uring_nr: int, handle_nr: int) -> bytes:
    """The BPF program: on another architecture or the x32 numbers, refuse; ``socket`` of any
    family but ``AF_UNIX``: EAFNOSUPPORT; ``io_uring_setup`` (sockets around this filter) and
    ``open_by_handle_at`` (files around Landlock's paths): EPERM; everything else allowed.
    Offsets into ``struct seccomp_data``: nr 0, arch 4, args[0] 16 (its low half on little-endian)."""
    def op(code: int, jt: int, jf: int, k: int) -> bytes:
        return struct.pack("HBBI", code, jt, jf, k)

    deny, refuse_family = _SECCOMP_RET_ERRNO | _EPERM, _SECCOMP_RET_ERRNO | _EAFNOSUPPORT
    return b"".join([
        op(_LD_W_ABS, 0, 0, 4),                 # 0 arch
        op(_JEQ_K, 1, 0, arch),                 # 1 -> 3
        op(_RET_K, 0, 0, deny),                 # 2
        op(_LD_W_ABS, 0, 0, 0),                 # 3 nr
        op(_JGE_K, 0, 1, 0x40000000),           # 4 x32 numbers -> 5, else 6
        op(_RET_K, 0, 0, deny),                 # 5
        op(_JEQ_K, 4, 0, socket_nr),            # 6 -> 11
        op(_JEQ_K, 1, 0, uring_nr),             # 7 -> 9
        op(_JEQ_K, 0, 1, handle_nr),            # 8 -> 9, else 10
        op(_RET_K, 0, 0, deny),                 # 9
        op(_RET_K, 0, 0, _SECCOMP_RET_ALLOW),   # 10
        op(_LD_W_ABS, 0, 0, 16),                # 11 the family
        op(_JEQ_K, 0, 1, _AF_UNIX),             # 12 -> 13, else 14
        op(_RET_K, 0, 0, _SECCOMP_RET_ALLOW),   # 13
        op(_RET_K, 0, 0, refuse_family),        # 14
    ])


def install_seccomp() -> bool:
    """Install the filter of :func:`_filter_program` on this thread and what it starts; False
    where the system has no seccomp (or another architecture)."""
    libc = _libc()
    numbers = _ARCHES.get(os.uname().machine) if libc is not None else None
    if numbers is None:
        return False
    program = _filter_program(*numbers)
    buffer = ctypes.create_string_buffer(program, len(program))
    prog = _SockFprog(len(program) // 8, ctypes.cast(buffer, ctypes.c_void_p))
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        return False
    return libc.prctl(_PR_SET_SECCOMP, 2, ctypes.byref(prog), 0, 0) == 0


# --- the line ``check`` starts with ---------------------------------------------------------------------


def _probe() -> tuple[bool, bool]:
    """(a network namespace, seccomp) tried in a throw-away child: nothing here changes."""
    if not hasattr(os, "fork") or sys.platform != "linux":
        return False, False
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:
        try:
            os.close(read_end)
            os.write(write_end, bytes([close_network(), install_seccomp()]))
        finally:
            os._exit(0)
    os.close(write_end)
    answer = os.read(read_end, 2)
    os.close(read_end)
    os.waitpid(pid, 0)
    return (len(answer) == 2 and bool(answer[0])), (len(answer) == 2 and bool(answer[1]))


def describe() -> str:
    """One line: which layers confine a submission on this machine."""
    from glsandbox.grading.sandbox import landlock_abi

    if sys.platform != "linux":
        return "isolation: a process per submission with time and memory limits (Landlock, namespaces and seccomp are Linux's)"
    abi = landlock_abi()
    netns, seccomp = _probe()
    ids = submission_ids(os.getpid())
    network = [name for name, on in (("a network namespace", netns), ("Landlock TCP", abi >= 4),
                                     ("seccomp sockets", seccomp)) if on]
    if ids is None:
        user = "the teacher's user (not root)"
    elif python_readable_by_others():
        user = "a user with no account"
    elif abi >= 1:
        user = "a user with no account, reading as root does (Python is readable only by root; Landlock bounds it)"
    else:
        user = "root (Python is readable only by root and no Landlock bounds the reads)"
    files = f"Landlock ABI {abi}" if abi else "no Landlock (Python's audit hook only)"
    procs = "own entries only" if abi else "the audit hook only"
    return (f"isolation: fresh environment; user: {user}; files: {files}; /proc: {procs}; "
            f"network: {', '.join(network) if network else 'open (the kernel closes none)'}")
