"""Rendering each graded submission in a process of its own, under limits, and getting back only pixels.

The process tree of one grading run::

    grader (never opens a GL context; reads the reference, compares, writes every report)
     └─ zygote (imported glsandbox, numpy and moderngl once; forks on the grader's word)
         └─ supervisor, one per submission (own session; a "child subreaper": every process
            │  the submission leaves behind is re-parented to it, and it kills them all)
            └─ renderer (own session; stdin /dev/null, stdout and stderr into a file;
               address-space, CPU-time and file-size limits; working folder a private
               copy of the submission; confined by :mod:`glsandbox.measure.sandbox`)

The renderer opens its GL context (a fork of a process that had opened one
would deadlock on llvmpipe's threads, so nothing above it ever does), then
loads the submission and renders each requested picture, writing each as a
framed message on a pipe: raw RGBA pixels, or an error line. It knows no
reference. The supervisor reads the pipe against the clock, kills the
renderer's whole tree when it is done, times out or dies, and sends the
grader one plain result per picture (JSON and raw pixels on a pipe of its
own: the grader never unpickles what a child sends). The zygote is
Python's "forkserver" idea without its named socket: the grader talks to it
over a socket pair no other process can find. Nothing the submission does in its
own process (``os._exit``, a signal, ``atexit``, threads, ``fork``,
replacing ``sys.stdout`` or glsandbox's functions) reaches the grader: the
worst it can do is lose its own pictures.
"""

from __future__ import annotations

import ctypes
import json
import os
import select
import shutil
import signal
import struct
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Render", "Job", "Picture", "JobResult", "run_jobs", "PRELOAD"]

#: What the zygote imports once, so each submission starts warm (and no module
#: opens a GL context at import).
PRELOAD = ["glsandbox.measure.isolate", "glsandbox.frame", "glsandbox.lesson", "glsandbox.scene_file",
           "glsandbox.measure.sandbox", "glsandbox.gl.context", "glsandbox.gl.shaders", "numpy", "moderngl",
           "glcontext", "glcontext.egl", "PIL.Image", "lessons"]

#: Outcomes of one picture, besides the grader's PASS and FAIL.
BROKEN, TIMEOUT, CRASHED, OOM = "BROKEN", "TIMEOUT", "CRASHED", "OUT OF MEMORY"
#: The renderer's output kept for the report: its last lines, each cut.
TAIL_LINES, TAIL_WIDTH = 8, 200

#: The environment a renderer keeps (by prefix): the drivers', the locale's and glsandbox's own.
_ENV_KEPT = ("PATH", "HOME", "LANG", "LC_", "TZ", "DISPLAY", "WAYLAND_", "XDG_", "MESA_", "LIBGL_", "GALLIUM_",
             "LP_", "EGL_", "__EGL_", "__GLX_", "GLCONTEXT_", "PYOPENGL_", "GLSANDBOX_", "PYTHONHASHSEED", "CI")
_MAGIC = b"GLSB"
_HEADER = struct.Struct("!4sIQ")  # magic, JSON header length, payload length
_PR_SET_CHILD_SUBREAPER = 36


@dataclass(frozen=True)
class Render:
    """One picture to render: the lesson's ``--set`` values, the size and MSAA samples."""

    settings: tuple[str, ...]
    size: tuple[int, int]
    samples: int = 0


@dataclass(frozen=True)
class Job:
    """One submission: where it is, what to render, and the limits.

    ``source`` is the submission's file or folder, copied into the private
    folder (``copy=True``, grading) or read where it is (``copy=False``: one
    lesson checked by its author, whose folder is its root); ``target`` is
    the lesson file to load inside it (relative), or a built-in lesson's
    name when ``source`` is None.
    """

    index: int
    source: str | None
    target: str
    renders: tuple[Render, ...]
    backend: str | None = None
    timeout: float = 30.0
    memory_mb: int = 2048
    copy: bool = True
    #: The model answer (``--update``): its compiled shaders may go into Mesa's cache for the submissions.
    writes_cache: bool = False


@dataclass
class Picture:
    """What came back for one :class:`Render`: the pixels, or an outcome and its line."""

    image: np.ndarray | None = None
    status: str = ""
    error: str = ""
    seconds: float = 0.0


@dataclass
class JobResult:
    """Every picture of one job, the renderer's last output lines, and whether GL was there at all."""

    job: Job
    pictures: list[Picture]
    output: list[str] = field(default_factory=list)
    no_gl: str = ""


# --- the renderer (grandchild) ---------------------------------------------------------------


def _send(fd: int, header: dict, payload: bytes = b"") -> None:
    data = json.dumps(header).encode()
    message = _HEADER.pack(_MAGIC, len(data), len(payload)) + data + payload
    view = memoryview(message)
    while view:
        view = view[os.write(fd, view):]


def _limit(job: Job) -> None:
    """Address space (--memory), CPU seconds (--timeout for each picture, plus start-up), no core
    files, and files no larger than 256 MB."""
    import resource  # POSIX only, as the whole of this module's running side

    memory = job.memory_mb * 1024 * 1024
    cpu = int(job.timeout * len(job.renders)) + 10
    for limit, value in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, cpu), (resource.RLIMIT_CORE, 0),
                         (resource.RLIMIT_FSIZE, 256 * 1024 * 1024)):
        try:
            resource.setrlimit(limit, (value, value + 1 if limit == resource.RLIMIT_CPU else value))
        except (ValueError, OSError):
            pass


def _renderer(job: Job, root: str, target: str, work: str, out: int) -> None:
    """The renderer's whole life; it never returns (``os._exit``)."""
    from glsandbox.errors import SandboxError
    from glsandbox.frame import HeadlessRenderer
    from glsandbox.lesson import find_lesson, submission_lesson, user_code_error
    from glsandbox.measure.sandbox import confine

    os.setsid()
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    log = os.open(os.path.join(work, "output.txt"), os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    os.dup2(log, 1)
    os.dup2(log, 2)
    os.close(null)
    os.close(log)
    os.dup2(out, 3)  # the result pipe; every other descriptor (the supervisor's, the zygote's) is closed
    out = 3
    os.closerange(4, os.sysconf("SC_OPEN_MAX"))
    sys.stdin = open(os.devnull)  # noqa: SIM115 - the submission's, for its life
    sys.argv = ["submission"]
    for key in list(os.environ):  # only what rendering reads: no path of the teacher's (PWD, OLDPWD, ...)
        if not key.startswith(_ENV_KEPT):
            del os.environ[key]
    cwd = os.path.join(work, "cwd")
    os.chdir(root if job.copy else cwd)
    _limit(job)
    code = 0
    try:
        try:
            renderer = HeadlessRenderer(job.backend)
        except SandboxError as exc:
            _send(out, {"kind": "nogl", "error": str(exc)})
            return
        confine(root, [root if job.copy else cwd, cwd], cache_writable=job.writes_cache)
        try:
            cls = find_lesson(target) if job.source is None else submission_lesson(Path(root) / target)
        except MemoryError as exc:
            _send(out, {"kind": "oom", "index": 0, "error": str(user_code_error(exc)), "all": True})
            return
        except SandboxError as exc:
            _send(out, {"kind": "broken", "index": 0, "error": str(exc), "all": True})
            return
        except BaseException as exc:  # noqa: BLE001 - anything the submission raised while loading
            _send(out, {"kind": "broken", "index": 0, "error": str(user_code_error(exc)), "all": True})
            return
        for index, render in enumerate(job.renders):
            started = time.perf_counter()
            try:
                image = renderer.render(cls.from_settings(render.settings), render.size, render.samples).image
                image = np.ascontiguousarray(image, dtype=np.uint8)
                header = {"kind": "image", "index": index, "shape": list(image.shape),
                          "seconds": time.perf_counter() - started}
                _send(out, header, image.tobytes())
            except MemoryError as exc:
                _send(out, {"kind": "oom", "index": index, "error": str(user_code_error(exc))})
            except SandboxError as exc:
                _send(out, {"kind": "broken", "index": index, "error": str(exc)})
            except BaseException as exc:  # noqa: BLE001 - KeyboardInterrupt, SystemExit, its own kinds
                _send(out, {"kind": "broken", "index": index, "error": str(user_code_error(exc))})
    except BaseException:  # noqa: BLE001 - the pipe closed, or worse: the supervisor reports it
        code = 3
    finally:
        for stream in (sys.__stdout__, sys.__stderr__):
            try:
                stream.flush()
            except BaseException:  # noqa: BLE001 - replaced or closed by the submission
                pass
        os._exit(code)  # no atexit handler, no thread, no finaliser of the submission runs


# --- the supervisor (child) ------------------------------------------------------------------


def _children_map() -> dict[int, list[int]]:
    """Every live process's children, from /proc."""
    children: dict[int, list[int]] = {}
    if not os.path.isdir("/proc"):  # not Linux: only the renderer's own session is killed (see _supervise)
        return children
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                fields = handle.read().rsplit(b")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != b"Z":
            children.setdefault(int(fields[1]), []).append(int(entry))
    return children


def descendants(pid: int) -> list[int]:
    """The live (not zombie) descendants of ``pid``."""
    children = _children_map()
    found, queue = [], deque(children.get(pid, []))
    while queue:
        child = queue.popleft()
        found.append(child)
        queue.extend(children.get(child, []))
    return found


def _reap() -> None:
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def kill_tree(pid: int, keep: Sequence[int] = ()) -> None:
    """SIGKILL every descendant of ``pid`` (except ``keep`` and theirs) until none is left.

    A process that forks while we look is found on the next pass; orphans come
    back to us as long as we are a subreaper. Reaps our own children.
    """
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        excluded = set(keep)
        for kept in keep:
            excluded.update(descendants(kept))
        alive = [p for p in descendants(pid) if p not in excluded]
        if not alive:
            break
        for victim in alive:
            try:
                os.kill(victim, signal.SIGKILL)
            except OSError:
                pass
        _reap() if pid == os.getpid() else None
        time.sleep(0.005)
    if pid == os.getpid():
        _reap()


def _wait_briefly(pid: int, seconds: float = 0.05) -> None:
    """Reap ``pid`` if it ends within ``seconds``."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            done, _ = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            return
        if done:
            return
        time.sleep(0.001)


def _copy_submission(source: Path, into: Path) -> Path:
    """A private copy of a submission's file or folder; symbolic links are copied as links
    (one that points outside is refused when read, never followed while copying)."""
    if source.is_dir():
        shutil.copytree(source, into, symlinks=True)
    else:
        into.mkdir()
        shutil.copy2(source, into / source.name, follow_symlinks=False)
    return into


class _Reader:
    """The framed messages of the renderer's pipe, read as they arrive."""

    def __init__(self, fd: int) -> None:
        self.fd, self.buffer, self.closed = fd, bytearray(), False

    def pump(self, timeout: float) -> None:
        ready, _, _ = select.select([self.fd], [], [], max(timeout, 0.0))
        if ready:
            chunk = os.read(self.fd, 1 << 20)
            self.closed = not chunk
            self.buffer += chunk

    def messages(self, limit: int) -> Iterator[tuple[dict, bytes]]:
        while len(self.buffer) >= _HEADER.size:
            magic, head, size = _HEADER.unpack_from(self.buffer)
            if magic != _MAGIC or head > 1 << 16 or size > limit:
                raise ValueError("a malformed message on the result pipe")
            end = _HEADER.size + head + size
            if len(self.buffer) < end:
                return
            header = json.loads(bytes(self.buffer[_HEADER.size:_HEADER.size + head]))
            payload = bytes(self.buffer[_HEADER.size + head:end])
            del self.buffer[:end]
            yield header, payload


def _exit_reason(status: int, job: Job) -> tuple[str, str]:
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        if number == signal.SIGXCPU:
            return TIMEOUT, f"CPU time limit ({int(job.timeout * len(job.renders)) + 10} s) reached"
        name = signal.Signals(number).name if number in signal.Signals._value2member_map_ else str(number)
        return CRASHED, f"killed by signal {name}"
    return CRASHED, f"exited with code {os.WEXITSTATUS(status)} before its picture was sent"


def _collect(job: Job, pid: int, fd: int) -> list[Picture]:
    """Each picture as it arrives, against the clock: ``job.timeout`` seconds for each."""
    pictures: list[Picture] = [Picture() for _ in job.renders]
    limit = max(w * h * 4 for w, h in (r.size for r in job.renders))
    reader = _Reader(fd)
    status: int | None = None
    current, started = 0, time.monotonic()

    def finish(kind: str, error: str) -> list[Picture]:
        for picture in pictures[current:]:
            if not picture.status:
                picture.status, picture.error = kind, error
        return pictures

    while current < len(pictures):
        remaining = started + job.timeout - time.monotonic()
        if remaining <= 0:
            return finish(TIMEOUT, f"after {job.timeout:g} s")
        if status is None:
            done, status_now = os.waitpid(pid, os.WNOHANG)
            status = status_now if done else None
        if not reader.closed:
            reader.pump(0.0 if status is not None else min(remaining, 0.05))
        elif status is None:  # it closed the pipe but lives on: wait for its end or the clock
            time.sleep(0.01)
        try:
            for header, payload in reader.messages(limit):
                kind = header.get("kind")
                if kind == "nogl":
                    raise _NoGL(str(header.get("error", "")))
                index = int(header.get("index", -1))
                if index != current:
                    raise ValueError("a message out of order on the result pipe")
                picture = pictures[index]
                if kind == "image":
                    shape = tuple(header.get("shape", ()))
                    w, h = job.renders[index].size
                    if shape != (h, w, 4) or len(payload) != w * h * 4:
                        raise ValueError(f"a picture of shape {shape} for a {w}x{h} render")
                    picture.image = np.frombuffer(payload, dtype=np.uint8).reshape(h, w, 4)
                    picture.seconds = float(header.get("seconds", 0.0))
                else:
                    picture.status = OOM if kind == "oom" else BROKEN
                    picture.error = str(header.get("error", ""))[:500]
                    if header.get("all"):  # the lesson did not load: no picture of it can be made
                        return finish(picture.status, picture.error)
                current, started = current + 1, time.monotonic()
        except (ValueError, KeyError, TypeError) as exc:
            return finish(CRASHED, f"sent {exc}")
        if status is not None and (reader.closed or not select.select([fd], [], [], 0)[0]) and current < len(pictures):
            return finish(*_exit_reason(status, job))
    return pictures


class _NoGL(Exception):
    """The renderer could not open a GL context: the machine's problem, not the submission's."""


def _tail(path: str) -> list[str]:
    try:
        with open(path, "rb") as handle:
            handle.seek(max(0, os.fstat(handle.fileno()).st_size - 64 * 1024))
            lines = handle.read().decode("utf-8", "backslashreplace").splitlines()
    except OSError:
        return []
    return [line[:TAIL_WIDTH] for line in lines[-TAIL_LINES:]]


def _job_from(data: dict) -> Job:
    renders = tuple(Render(tuple(r["settings"]), tuple(r["size"]), r["samples"]) for r in data.pop("renders"))
    return Job(renders=renders, **data)


def _job_data(job: Job) -> dict:
    return {"index": job.index, "source": job.source, "target": job.target, "backend": job.backend,
            "timeout": job.timeout, "memory_mb": job.memory_mb, "copy": job.copy, "writes_cache": job.writes_cache,
            "renders": [{"settings": list(r.settings), "size": list(r.size), "samples": r.samples}
                        for r in job.renders]}


def _supervise(job: Job, out: int) -> None:
    """One submission, start to end, its result framed on ``out`` (runs in a process the zygote forked)."""
    os.setsid()
    _set_subreaper()
    _send(out, {"kind": "pid", "pid": os.getpid()})
    work = tempfile.mkdtemp(prefix="glsandbox-grade-")
    result: dict = {"kind": "result", "pictures": None, "output": [], "no_gl": "", "root": ""}
    pictures: list[Picture] | None = None
    cleaned = False
    try:
        os.mkdir(os.path.join(work, "cwd"))
        if job.source is None:
            root, target = os.path.join(work, "cwd"), job.target
        elif job.copy:
            try:
                root = str(_copy_submission(Path(job.source), Path(work) / "submission"))
            except (OSError, shutil.Error) as exc:
                reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0][:200]
                pictures = [Picture(status=BROKEN, error=f"{job.source}: cannot be copied for grading ({reason})")
                            for _ in job.renders]
                return
            target = job.target
            result["root"] = root
        else:
            root, target = str(Path(job.source).parent), job.target
        read_end, write_end = os.pipe()
        pid = os.fork()
        if pid == 0:  # the renderer: no GL context exists in this process yet, so forking is safe
            os.close(read_end)
            _renderer(job, root, target, work, write_end)
        os.close(write_end)
        try:
            pictures = _collect(job, pid, read_end)
        except _NoGL as exc:
            result["no_gl"] = str(exc)
        _wait_briefly(pid)  # after its last picture it ends by itself: then one look finds nothing left
        _killpg(pid)  # the renderer's session (all there is to kill where /proc is missing)
        kill_tree(os.getpid())
        cleaned = True
        os.close(read_end)
        result["output"] = _tail(os.path.join(work, "output.txt"))
    finally:
        if not cleaned:
            kill_tree(os.getpid())
        shutil.rmtree(work, ignore_errors=True)
        payload = b""
        if pictures is not None:
            result["pictures"] = []
            for picture in pictures:
                image = picture.image
                result["pictures"].append({"status": picture.status, "error": picture.error,
                                           "seconds": picture.seconds,
                                           "shape": None if image is None else list(image.shape)})
                payload += b"" if image is None else image.tobytes()
        _send(out, result, payload)


# --- the zygote: a warm process that forks a supervisor per job -------------------------------


def preload_gl_libraries() -> None:
    """Load (never initialise) the EGL and Mesa driver libraries, so every fork has them mapped and
    relocated: about 0.05 to 0.1 s off each renderer's first context. Loading starts no thread;
    a context would (llvmpipe's), which is why none is opened here."""
    import ctypes.util
    import functools
    import glob

    # glcontext looks its libraries up on every context (ctypes.util.find_library runs ldconfig,
    # 20 to 40 ms): remembered once here, for every renderer forked from this process.
    ctypes.util.find_library = functools.lru_cache(maxsize=None)(ctypes.util.find_library)
    for name in ("GL", "EGL", "OSMesa"):
        ctypes.util.find_library(name)
    folders = [p for p in os.environ.get("LIBGL_DRIVERS_PATH", "").split(":") if p]
    folders += ["/usr/lib/x86_64-linux-gnu/dri", "/usr/lib/aarch64-linux-gnu/dri", "/usr/lib64/dri", "/usr/lib/dri"]
    libraries = ["libEGL.so.1", "libEGL_mesa.so.0", "libglapi.so.0", "libgbm.so.1"]
    libraries += [path for folder in folders for path in glob.glob(os.path.join(folder, "swrast_dri.so"))][:1]
    libraries += sorted(glob.glob("/usr/lib*/*/libgallium*.so") + glob.glob("/usr/lib64/libgallium*.so"))[:1]
    for library in libraries:
        try:
            ctypes.CDLL(library, mode=os.RTLD_NOW | os.RTLD_GLOBAL)
        except OSError:
            pass


def zygote_main(channel_fd: int) -> None:
    """The zygote process: import :data:`PRELOAD` and the GL libraries once, then :func:`zygote`."""
    import importlib

    for module in PRELOAD:
        try:
            importlib.import_module(module)
        except ImportError:  # e.g. no lessons package beside an installed glsandbox
            pass
    preload_gl_libraries()
    from glsandbox.measure.sandbox import read_roots

    read_roots()  # worked out once, for every renderer
    zygote(channel_fd)


def zygote(channel_fd: int) -> None:
    """Serve the grader on ``channel_fd`` (one end of a socket pair): each message is a job and
    the pipe its result goes to; fork a supervisor for it. Ends when the grader closes its end.

    A socket pair has no name in the file system, so no submission can find it
    and ask for a process (multiprocessing's forkserver listens on a named socket).
    """
    import socket

    channel = socket.socket(fileno=channel_fd)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the grader decides when a run stops
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # supervisors are reaped by the kernel
    while True:
        size_bytes = _recv_exact(channel, 4)
        if size_bytes is None:
            break
        (size,) = struct.unpack("!I", size_bytes)
        first, fds, _, _ = socket.recv_fds(channel, min(size, 1 << 16), 1)
        data = first + (_recv_exact(channel, size - len(first)) or b"")
        if not fds:
            continue
        pid = os.fork()
        if pid == 0:
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)  # the supervisor waits for its renderer
            channel.close()
            code = 0
            try:
                _supervise(_job_from(json.loads(data)), fds[0])
            except BaseException:  # noqa: BLE001 - the grader sees the pipe close without a result
                code = 1
            os._exit(code)
        os.close(fds[0])
    os._exit(0)


def _recv_exact(channel, size: int) -> bytes | None:
    data = b""
    while len(data) < size:
        chunk = channel.recv(size - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def _set_subreaper(on: bool = True) -> None:
    if sys.platform == "linux":
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0)


# --- the grader's side -----------------------------------------------------------------------


class _Zygote:
    """The zygote process and the grader's end of its socket pair."""

    def __init__(self) -> None:
        import socket
        import subprocess

        self.channel, theirs = socket.socketpair()
        code = "import sys; from glsandbox.measure.isolate import zygote_main; zygote_main(int(sys.argv[1]))"
        self.process = subprocess.Popen([sys.executable, "-c", code, str(theirs.fileno())], pass_fds=[theirs.fileno()],
                                        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)  # never the grader's stdout
        theirs.close()

    def start(self, job: Job) -> int:
        """Ask for a supervisor for ``job``; the read end of its result pipe."""
        import socket

        read_end, write_end = os.pipe()
        data = json.dumps(_job_data(job)).encode()
        try:
            self.channel.sendall(struct.pack("!I", len(data)))
            socket.send_fds(self.channel, [data], [write_end])
        finally:
            os.close(write_end)
        return read_end

    def close(self) -> None:
        self.channel.close()
        try:
            self.process.wait(timeout=10)
        except Exception:  # noqa: BLE001 - it is killed with the rest of the run
            pass


@dataclass
class _Running:
    job: Job
    reader: _Reader
    deadline: float
    pid: int = 0


def run_jobs(jobs: Sequence[Job], workers: int, done: Callable[[JobResult], None]) -> list[JobResult]:
    """Run every job, ``workers`` at once; ``done`` is called as each finishes; results in job order.

    The grader becomes a subreaper for the run, so a process a submission
    leaves behind whose supervisor was killed still comes back here, and is
    killed at the end with everything else the run started.
    """
    if not hasattr(os, "fork"):
        from glsandbox.errors import SandboxError

        raise SandboxError("glsandbox check runs each submission in a process of its own, which needs a POSIX "
                           "system (Linux, macOS); on Windows run it in WSL or a container")
    before = set(descendants(os.getpid()))
    _set_subreaper()
    pending = deque(jobs)
    running: dict[int, _Running] = {}
    results: dict[int, JobResult] = {}
    retried: set[int] = set()
    zygote_process = _Zygote()
    try:
        while pending or running:
            while pending and len(running) < max(1, workers):
                job = pending.popleft()
                try:
                    fd = zygote_process.start(job)
                except OSError:  # the zygote is gone (it should not be): a fresh one, once
                    zygote_process.close()
                    zygote_process = _Zygote()
                    fd = zygote_process.start(job)
                # a supervisor that hangs (it should not) is given up after every picture's time and a margin
                running[fd] = _Running(job, _Reader(fd), time.monotonic() + job.timeout * len(job.renders) + 60)
            ready, _, _ = select.select(list(running), [], [], 1.0)
            for fd in list(running):
                entry = running[fd]
                if fd in ready:
                    entry.reader.pump(0.0)
                message = None
                try:
                    for header, payload in entry.reader.messages(1 << 34):
                        if header.get("kind") == "pid":
                            entry.pid = int(header["pid"])
                        elif header.get("kind") == "result":
                            message = (header, payload)
                except (ValueError, KeyError, TypeError):
                    entry.reader.closed = True
                late = time.monotonic() > entry.deadline
                if message is None and not entry.reader.closed and not late:
                    continue
                if entry.pid and message is None:
                    kill_tree(entry.pid)
                    _killpg(entry.pid)
                del running[fd]
                os.close(fd)
                result = _result(entry.job, message)
                if result.no_gl and entry.job.index not in retried:  # once more: a driver can fail now and then
                    retried.add(entry.job.index)
                    pending.appendleft(entry.job)
                    continue
                results[entry.job.index] = result
                if result.no_gl:
                    return [results[j.index] for j in jobs if j.index in results]
                done(result)
    finally:
        for fd, entry in running.items():
            if entry.pid:
                _killpg(entry.pid)
            os.close(fd)
        zygote_process.close()
        kill_tree(os.getpid(), keep=sorted(before))
        _set_subreaper(False)
    return [results[j.index] for j in jobs]


def _killpg(group: int) -> None:
    try:
        os.killpg(group, signal.SIGKILL)
    except OSError:
        pass


def _result(job: Job, message: tuple[dict, bytes] | None) -> JobResult:
    if message is None or (message[0].get("pictures") is None and not message[0].get("no_gl")):
        pictures = [Picture(status=CRASHED, error="its grading process ended without a result") for _ in job.renders]
        return JobResult(job, pictures)
    header, payload = message
    if header.get("no_gl"):
        return JobResult(job, [], no_gl=str(header["no_gl"]))
    pictures, offset = [], 0
    for entry in header["pictures"]:
        image = None
        if entry.get("shape"):
            h, w, c = entry["shape"]
            image = np.frombuffer(payload, dtype=np.uint8, count=h * w * c, offset=offset).reshape(h, w, c)
            offset += h * w * c
        pictures.append(Picture(image, str(entry.get("status", "")), str(entry.get("error", "")),
                                float(entry.get("seconds", 0.0))))
    output = [str(line) for line in header.get("output", [])]
    root = str(header.get("root") or "")
    if root and job.source:  # the private copy's path, said as the submission's own
        original = job.source if Path(job.source).is_dir() else str(Path(job.source).parent)
        for picture in pictures:
            picture.error = picture.error.replace(root, original)
        output = [line.replace(root, original) for line in output]
    return JobResult(job, pictures, output)
