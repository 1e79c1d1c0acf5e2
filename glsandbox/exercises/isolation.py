"""Calling a student's function in a process of its own: only inputs go in, only answers come out.

The seam between the exercises and the grader's isolation. A
:class:`Isolated` function is the submission's file, copied into a private
folder and loaded by :mod:`glsandbox.exercises.student_process` (standard library
only) in a fresh interpreter (``python -I -S -B``, a clean environment)
that:

- is its own session (its whole tree is killed when a call times out),
  under an address-space, CPU-time, file-size and core-file limit;
- imports from the standard library and the third-party packages only:
  glsandbox is not on its path;
- cannot read glsandbox's files: on Linux the kernel enforces it (Landlock,
  set in the child before the interpreter starts, with the rule set of
  :func:`glsandbox.grading.sandbox` which reads only the allowed folders and
  none of glsandbox's), and a Python audit hook refuses it too (where
  Landlock is missing), with writes outside the private folder, starting
  programs and signalling others;
- has no network: the grader's layers (:mod:`glsandbox.grading.layers`) give it
  a network namespace of its own and a seccomp filter refusing sockets but
  local Unix ones, where the system has them;
- when the grader is root (Gradescope, CI), runs as a user with no account,
  exactly as a picture submission's renderer does
  (:func:`~glsandbox.grading.layers.submission_ids`,
  :func:`~glsandbox.grading.layers.drop_privileges`): its private folder is
  that user's. Where the Python installation is readable by root alone, the
  user keeps the one capability of reading any file, through the ``execve``,
  and only where Landlock bounds those reads
  (:func:`~glsandbox.grading.layers.reading_kept`); where neither, the
  process stays root (the layers line says so).

Each call has its own deadline. A call that does not answer in time is
TIMEOUT and the process is killed (the next call starts a fresh one); one
that ends the process (``os._exit``, a signal, memory) is CRASHED; an
exception is ERROR with its line. After :attr:`Limits.restarts` such
endings the remaining calls are not run. The expected answers and the
references stay in the caller's process: the student's process is sent arguments.

:class:`InProcess` is the same interface for a function object in the
caller's own process (a notebook: the student's own kernel).
"""

from __future__ import annotations

import atexit
import itertools
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from glsandbox.exercises import student_process
from glsandbox.grading.processes import kill_tree, killpg

__all__ = ["Answer", "InProcess", "Isolated", "Limits", "VALUE", "ERROR", "TIMEOUT", "CRASHED"]

VALUE, ERROR, TIMEOUT, CRASHED = "value", "error", "timeout", "crashed"

#: A number per process this grader starts: two students' functions graded at once are two users.
_SEEDS = itertools.count(1)

#: System folders the student's interpreter reads (shared libraries, locale, devices).
_SYSTEM = ("/usr", "/lib", "/lib32", "/lib64", "/etc", "/dev", "/proc", "/sys", "/opt")


@dataclass(frozen=True)
class Limits:
    """The limits of one student's process: seconds per call and per batch, memory, output."""

    call_seconds: float = 2.0
    batch_seconds: float = 30.0
    start_seconds: float = 15.0
    memory_mb: int = 2048
    cpu_seconds: int = 300
    output_limit: int = 1 << 20
    restarts: int = 3


@dataclass
class Answer:
    """One call's outcome: ``status`` is :data:`VALUE` (``value`` is the answer, plain JSON data),
    :data:`ERROR`, :data:`TIMEOUT` or :data:`CRASHED` (``error`` says what happened)."""

    status: str
    value: Any = None
    error: str = ""


def _package_dir() -> Path:
    return Path(__file__).resolve().parents[1]


def denied_paths() -> list[str]:
    """What the student's process may not read: glsandbox's package, the course's lessons and,
    for a source checkout, the project's whole folder (its tests and benchmarks too)."""
    import importlib.util

    package = _package_dir()
    denied = {str(package)}
    root = package.parent
    if (root / "pyproject.toml").is_file():  # a checkout: all of it but the folder of the interpreter (.venv)
        keep = [os.path.realpath(p) for p in (sys.prefix, *sys.path) if p]
        denied.update(str(root / e) for e in os.listdir(root)
                      if not any(_inside(k, os.path.realpath(root / e)) for k in keep))
    spec = importlib.util.find_spec("lessons")
    if spec is not None and spec.submodule_search_locations:
        denied.update(str(Path(p).resolve()) for p in spec.submodule_search_locations)
    site = [p for p in sys.path if p.endswith(("site-packages", "dist-packages")) and os.path.isdir(p)]
    for folder in site:  # an installed glsandbox (a wheel, or an editable install's hooks)
        for entry in os.listdir(folder):
            if entry.lower().startswith(("glsandbox", "_glsandbox", "__editable__", "_editable_impl_glsandbox",
                                         "lessons")):
                denied.add(os.path.realpath(os.path.join(folder, entry)))
    return sorted(denied)


def _inside(path: str, root: str) -> bool:
    return path == root or path.startswith(root.rstrip("/") + "/")


def import_path(denied: Sequence[str], site: str | os.PathLike[str]) -> list[str]:
    """The student's import path: this interpreter's standard library, then ``site``, a folder
    made of links to the entries of its site-packages, less glsandbox's.

    A folder of links, because the kernel's rules grant whole folders: site-packages itself
    cannot be listed (it holds glsandbox's entries), and Python's importer lists a folder
    on the path before it finds anything in it."""
    site = Path(site)
    site.mkdir(exist_ok=True)
    folder = str(site)
    linked = set(os.listdir(folder))
    path: list[str] = []
    package_root = str(_package_dir().parent)
    exact, below = set(denied), tuple(d.rstrip("/") + "/" for d in denied)  # _inside of any, in C
    for entry in sys.path:
        real = os.path.realpath(entry) if entry else ""
        if not real or not os.path.isdir(real) or real == package_root or real in exact or real.startswith(below):
            continue
        if real.endswith(("site-packages", "dist-packages")):
            for name in os.listdir(real):
                target = os.path.join(real, name)
                if not name.endswith(".pth") and name not in linked and target not in exact \
                        and not target.startswith(below):
                    os.symlink(target, os.path.join(folder, name))
                    linked.add(name)
            if folder not in path:
                path.append(folder)
        else:
            path.append(real)
    return path


_SHARED_LOCK = threading.Lock()
_SHARED: dict[tuple, Any] = {}


def _shared_import_path(denied: Sequence[str]) -> list[str]:
    """:func:`import_path` made once per grader process, its folder of links shared by every
    student's process (the grader's, root's where the grader is root, readable by all and
    writable by none of them; removed when the grader ends): a class's hundred processes
    then make and remove no hundred folders of links."""
    key = ("path", tuple(denied))
    with _SHARED_LOCK:
        if key not in _SHARED:
            folder = tempfile.mkdtemp(prefix="glsandbox-exercise-site-")
            os.chmod(folder, 0o755)
            atexit.register(shutil.rmtree, folder, ignore_errors=True)
            _SHARED[key] = import_path(denied, Path(folder) / "site")
            os.chmod(Path(folder) / "site", 0o755)
        return list(_SHARED[key])


def _shared_roots(allowed: Sequence[str], denied: Sequence[str]) -> list[str]:
    """:func:`readable_roots`, worked out once per grader process for the same folders."""
    key = ("roots", tuple(allowed), tuple(denied))
    with _SHARED_LOCK:
        if key not in _SHARED:
            _SHARED[key] = readable_roots(allowed, denied)
        return list(_SHARED[key])


def readable_roots(allowed: Sequence[str], denied: Sequence[str]) -> list[str]:
    """``allowed``, with every folder that holds a denied path replaced by its other entries
    (recursively): Landlock grants folders, it cannot grant a folder but one of its entries."""
    out: list[str] = []
    for root in sorted({os.path.realpath(r) for r in allowed if os.path.exists(r)}):
        if any(_inside(root, d) for d in denied):
            continue
        if not any(_inside(d, root) for d in denied):
            out.append(root)
            continue
        try:
            entries = [os.path.join(root, e) for e in os.listdir(root)]
        except OSError:
            continue
        out.extend(readable_roots(entries, denied))
    return out


def _user(seed: int) -> tuple[tuple[int, int] | None, bool]:
    """The user a student's process runs as (None: this one's, not root) and whether it keeps
    reading as root does: the picture renderer's rule (:mod:`glsandbox.grading.layers`), save
    that a fresh interpreter must be able to start, so without either way it stays this user."""
    from glsandbox.grading.layers import python_readable_by_others, reading_kept, submission_ids

    ids = submission_ids(os.getpid() * 4099 + seed)
    if ids is None:
        return None, False
    keep = reading_kept()
    if not keep and not python_readable_by_others():
        return None, False
    return ids, keep


def _restrict(reads: list[str], writes: list[str], limits: Limits, ids: tuple[int, int] | None = None,
              keep_reading: bool = False) -> Callable[[], None]:
    """What the child does after fork and before the interpreter starts: its session, limits, no
    network, ``ids``'s user (the grader is root), the kernel's file rules and the socket filter."""
    import resource

    from glsandbox.grading.layers import close_network, drop_privileges, install_seccomp
    from glsandbox.grading.sandbox import _landlock  # the grader's kernel rules, shared (one place)

    def setup() -> None:
        os.setsid()
        memory = limits.memory_mb * 1024 * 1024
        for limit, value in ((resource.RLIMIT_AS, memory), (resource.RLIMIT_CPU, limits.cpu_seconds),
                             (resource.RLIMIT_CORE, 0), (resource.RLIMIT_FSIZE, 16 * 1024 * 1024)):
            try:
                resource.setrlimit(limit, (value, value))
            except (ValueError, OSError):
                pass
        close_network()  # a network namespace with nothing up, where the system lets us (as root: first)
        if ids is not None:
            drop_privileges(ids, keep_reading, across_exec=True)
        _landlock(reads, writes)
        install_seccomp()  # no socket but a local Unix one

    return setup


#: The pipes' size asked for (Linux; 64 KiB otherwise): a probe's batch of 1-2 MB then goes
#: in a few writes, not thirty turns of each process waiting for the other.
PIPE_BYTES = 1 << 20


def _widen(fd: int) -> None:
    """Ask for a pipe of :data:`PIPE_BYTES` (as much as the system allows unprivileged; no error)."""
    try:
        import fcntl
    except ImportError:  # not a Unix
        return
    size = getattr(fcntl, "F_SETPIPE_SZ", None)
    if size is None:
        return
    try:
        with open("/proc/sys/fs/pipe-max-size", encoding="ascii") as handle:
            most = int(handle.read())
    except (OSError, ValueError):
        most = PIPE_BYTES
    try:
        fcntl.fcntl(fd, size, min(PIPE_BYTES, most))
    except OSError:
        pass


def _broken(message: dict) -> bool:
    """Whether an answers-pipe reading is the pipe's end or garbage rather than an answer."""
    return bool(message.get("closed") or message.get("garbled"))


class Isolated:
    """The function ``function`` of the file ``path``, called in its own confined process.

    Use as a context manager; :meth:`call` and :meth:`batch` start the process
    when needed. A file that does not load (it raises, or defines no such
    function) makes every call an :data:`ERROR` with that line.
    """

    def __init__(self, path: str | os.PathLike[str], function: str, limits: Limits = Limits()) -> None:
        self.path, self.function, self.limits = Path(path), function, limits
        self.work = tempfile.mkdtemp(prefix="glsandbox-exercise-")
        self.process: subprocess.Popen[bytes] | None = None
        self.requests = self.answers = -1
        self.buffer = b""
        self.endings = 0
        self.load_error = ""
        self.next_id = 0
        self.ready_by: float | None = None  # started, its ready line not read yet: by when it must come
        self.denied = denied_paths()
        folder = Path(self.work) / "submission"
        folder.mkdir()
        self.copy = folder / self.path.name
        shutil.copyfile(self.path, self.copy)
        shutil.copyfile(student_process.__file__, Path(self.work) / "student_process.py")
        self.path_list = _shared_import_path(self.denied)
        self.site_roots = [os.path.realpath(p) for p in sys.path if p.endswith(("site-packages", "dist-packages"))]
        self.ids, self.keep_reading = _user(next(_SEEDS))

    def __enter__(self) -> Isolated:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the process ---------------------------------------------------------------------

    def start(self) -> None:
        """Start the student's process now and go on (the first call waits for it to be ready):
        a checker with work of its own first (the probe's field) overlaps the interpreter's start."""
        if self.process is None and not self.load_error and self.endings < self.limits.restarts:
            self._spawn()

    def _start(self) -> None:
        self._spawn()
        self._await_ready()

    def _spawn(self) -> None:
        requests_read, self.requests = os.pipe()
        os.set_blocking(self.requests, False)  # our end only: the child's end is another open file
        self.answers, answers_write = os.pipe()
        _widen(self.requests)
        _widen(self.answers)
        config = {"file": str(self.copy), "function": self.function, "folder": str(self.copy.parent),
                  "path": self.path_list, "denied": self.denied, "work": self.work,
                  "requests": requests_read, "answers": answers_write, "output_limit": self.limits.output_limit}
        fd, config_path = tempfile.mkstemp(dir=self.work, suffix=".json")
        with os.fdopen(fd, "w") as handle:
            json.dump(config, handle)
        if self.ids is not None:  # its private folder (copy, script, config), owned by the user it runs as
            from glsandbox.grading.layers import hand_over

            hand_over(self.work, [self.work], self.ids)
        executable = getattr(sys, "_base_executable", None) or sys.executable
        system: tuple[str, ...] = _SYSTEM
        if self.keep_reading:  # reading as root does: of /etc only what others may read (no /etc/shadow)
            from glsandbox.grading.sandbox import others_may_read

            system = tuple(p for p in _SYSTEM if p != "/etc") + others_may_read("/etc")
        reads = _shared_roots([sys.base_prefix, sys.prefix, sys.exec_prefix, *system, *config["path"], *self.site_roots,
                                os.path.dirname(os.path.realpath(executable))], self.denied)
        env = {"PATH": "/usr/bin:/bin", "LANG": "C.UTF-8", "PYTHONHASHSEED": "0", "OPENBLAS_NUM_THREADS": "1",
               "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "HOME": self.work}
        log = open(os.path.join(self.work, "output.txt"), "ab")  # noqa: SIM115 - closed below
        try:
            self.process = subprocess.Popen(
                [executable, "-I", "-S", "-B", os.path.join(self.work, "student_process.py"), config_path],
                stdin=subprocess.DEVNULL, stdout=log, stderr=log, cwd=self.work, env=env,
                pass_fds=(requests_read, answers_write),
                preexec_fn=_restrict(reads, [self.work, "/dev/null"], self.limits, self.ids, self.keep_reading))  # noqa: PLW1509
        finally:
            log.close()
            os.close(requests_read)
            os.close(answers_write)
        self.buffer = b""
        self.ready_by = time.monotonic() + self.limits.start_seconds

    def _await_ready(self) -> None:
        """The started process's first line: ready, or why its file did not load."""
        message = self._read(self.ready_by - time.monotonic())
        self.ready_by = None
        if message is None or "ready" not in message:
            message = None if message is None or _broken(message) else message
            reason = (message or {}).get("load_error") or self._ending()
            self._stop()
            self.load_error = str(reason) or "the submission did not start"

    def _stop(self) -> None:
        if self.process is not None:
            killpg(self.process.pid)
            kill_tree(self.process.pid)
            try:
                self.process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                pass
            self.process = None
        self.ready_by = None
        for fd in (self.requests, self.answers):
            if fd >= 0:
                os.close(fd)
        self.requests = self.answers = -1

    def close(self) -> None:
        """Kill the process (if any) and remove the private folder."""
        self._stop()
        shutil.rmtree(self.work, ignore_errors=True)

    def _ending(self) -> str:
        """Why the process ended, in words (after its answers pipe closed)."""
        if self.process is None:
            return ""
        try:
            code = self.process.wait(timeout=2)
        except subprocess.TimeoutExpired:
            return "it closed its answers and went on running"
        if code < 0:
            name = signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else str(-code)
            more = " (CPU time limit)" if -code == signal.SIGXCPU else ""
            return f"its process was killed by {name}{more}"
        return f"its process ended with exit code {code} (os._exit or sys.exit outside a call?)"

    def _read(self, seconds: float) -> dict | None:
        """The next answer line within ``seconds`` (None: none came, or the process ended)."""
        deadline = time.monotonic() + seconds
        first = True
        while b"\n" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0 and not first:  # a line already waiting is read even past the time (one look)
                return None
            first = False
            ready, _, _ = select.select([self.answers], [], [], max(left, 0.0))
            if not ready:
                return None
            chunk = os.read(self.answers, 1 << 20)
            if not chunk:
                return {"closed": True}
            self.buffer += chunk
            if len(self.buffer) > 256 << 20:
                return None
        line, self.buffer = self.buffer.split(b"\n", 1)
        try:
            message = json.loads(line)
        except ValueError:
            return {"garbled": True}
        return message if isinstance(message, dict) else {"garbled": True}

    def _write(self, data: bytes, deadline: float) -> bool:
        """Write a request by the answer's deadline (False: not all of it went in time). The pipe is
        non-blocking on this side: a process that stops reading (it stopped itself) cannot hang
        the grader in a write of a big batch."""
        view = memoryview(data)
        while view:
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            _, ready, _ = select.select([], [self.requests], [], left)
            if not ready:
                return False
            try:
                view = view[os.write(self.requests, view[:PIPE_BYTES]):]
            except BlockingIOError:
                continue
            except OSError:
                return True  # the process has gone: its reading end says why
        return True

    def _send(self, payload: dict, seconds: float) -> float | Answer:
        """Send one request; its answer's deadline (``seconds`` from now), or the :class:`Answer`
        when it could not be asked (the file did not load, too many endings, the write timed out)."""
        if self.load_error:
            return Answer(ERROR, error=self.load_error)
        if self.endings >= self.limits.restarts:
            return Answer(TIMEOUT, error=f"not run: the function's process ended {self.endings} times already")
        if self.process is None:
            self._spawn()
        if self.ready_by is not None:
            self._await_ready()
            if self.load_error:
                return Answer(ERROR, error=self.load_error)
        self.next_id += 1
        deadline = time.monotonic() + seconds
        if not self._write(_line({"id": self.next_id, **payload}), deadline):
            return self._ended(None, seconds)
        return deadline

    def _receive(self, deadline: float, seconds: float) -> dict | Answer:
        """The answer to the request last sent, by ``deadline``."""
        message = self._read(deadline - time.monotonic())
        while message is not None and message.get("id") != self.next_id and not _broken(message):
            message = self._read(deadline - time.monotonic())  # something the function wrote on the answers pipe
        if message is not None and not _broken(message):
            return message
        return self._ended(message, seconds)

    def _ended(self, message: dict | None, seconds: float) -> Answer:
        """A request with no answer: the process is stopped and the ending counted."""
        reason = self._ending() if message is not None and message.get("closed") else ""
        self._stop()
        self.endings += 1
        if message is None:
            return Answer(TIMEOUT, error=f"no answer within {seconds:g} s (an endless loop, or a sleep?)")
        if message.get("garbled"):
            return Answer(CRASHED, error="the function's process sent something that is not an answer")
        return Answer(CRASHED, error=reason)

    def _request(self, payload: dict, seconds: float) -> dict | Answer:
        deadline = self._send(payload, seconds)
        return deadline if isinstance(deadline, Answer) else self._receive(deadline, seconds)

    # --- calls -------------------------------------------------------------------------

    def call(self, args: Sequence[Any]) -> Answer:
        """One call with ``args`` (plain JSON data), within :attr:`Limits.call_seconds`."""
        message = self._request({"args": list(args)}, self.limits.call_seconds)
        if isinstance(message, Answer):
            return message
        if "error" in message:
            return Answer(ERROR, error=str(message["error"]))
        return Answer(VALUE, value=message.get("value"))

    def batch(self, inputs: Sequence[Sequence[Any]]) -> tuple[list[Any], dict[int, str]] | Answer:
        """Many calls at once (a probe picture's field): the values, and the errors by index;
        an :class:`Answer` when the whole batch failed (timed out, crashed)."""
        return self.begin_batch(inputs)()

    def begin_batch(self, inputs: Sequence[Sequence[Any]]
                    ) -> Callable[[], tuple[list[Any], dict[int, str]] | Answer]:
        """:meth:`batch` in two halves: the inputs are sent now; the returned function waits for
        the answers (what :meth:`batch` returns). Between the two the grader works on (the
        reference's values) while the student's process runs the calls; no other call may be
        made before the answers are taken. The batch's time runs from now."""
        seconds = self.limits.batch_seconds
        deadline = self._send(_batch_request(inputs), seconds)

        def answers() -> tuple[list[Any], dict[int, str]] | Answer:
            message = deadline if isinstance(deadline, Answer) else self._receive(deadline, seconds)
            return _batch_answers(message, len(inputs))

        return answers


def _batch_answers(message: dict | Answer, count: int) -> tuple[list[Any], dict[int, str]] | Answer:
    """A batch's answer message as the values and the errors by index (or the failure)."""
    if isinstance(message, Answer):
        return message
    values, stopped = message.get("values"), message.get("stopped")
    errors = message.get("errors") if isinstance(message.get("errors"), dict) else {}
    if isinstance(stopped, int) and isinstance(values, list) and len(values) == stopped < count:
        first = str(errors.get("0", "it raised"))
        errors.update({str(i): first for i in range(stopped, count)})
        values = values + [None] * (count - stopped)
    if not isinstance(values, list) or len(values) != count:
        return Answer(CRASHED, error="the function's process sent a batch of the wrong length")
    try:
        return values, {int(k): str(v) for k, v in errors.items()}
    except ValueError:
        return Answer(CRASHED, error="the function's process sent something that is not an answer")


def _line(message: dict) -> bytes:
    """A request as its JSON line, without the spaces after separators (a probe's batch is
    megabytes of numbers: a fifth less to write and for the student's process to read)."""
    return (json.dumps(message, separators=(",", ":")) + "\n").encode()


def _batch_request(inputs: Sequence[Sequence[Any]]) -> dict:
    """A batch as sent: the arguments every input shares (the same object in each: a probe's
    scene) once, under ``shared``, and only the others per input."""
    if not inputs:
        return {"batch": [], "shared": {}, "arity": 0}
    columns = list(zip(*inputs, strict=True))
    # list.count compares by identity first: a column of one shared object counts in C
    shared = [k for k, column in enumerate(columns) if column.count(column[0]) == len(column)
              and all(column[i] is column[0] for i in (0, len(column) // 2, -1))]
    varying = [column for k, column in enumerate(columns) if k not in shared]
    return {"batch": list(zip(*varying, strict=True)) if varying else [[] for _ in inputs],
            "shared": {str(k): columns[k][0] for k in shared}, "arity": len(columns)}


class InProcess:
    """The same calls as :class:`Isolated` on a function object in this process (no limits):
    for a notebook, where the function is the student's own, in their own kernel."""

    def __init__(self, function: Callable[..., Any]) -> None:
        self.function = function
        self.load_error = ""

    def __enter__(self) -> InProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def close(self) -> None:
        return None

    def call(self, args: Sequence[Any]) -> Answer:
        try:
            return Answer(VALUE, value=student_process._encode(self.function(*args)))
        except Exception as exc:  # noqa: BLE001 - the student's
            return Answer(ERROR, error=f"{type(exc).__name__}: {exc}"[:300])

    def begin_batch(self, inputs: Sequence[Sequence[Any]]) -> Callable[[], tuple[list[Any], dict[int, str]]]:
        """:meth:`batch` run now, its answers given by the returned function (as Isolated's)."""
        answers = self.batch(inputs)
        return lambda: answers

    def batch(self, inputs: Sequence[Sequence[Any]]) -> tuple[list[Any], dict[int, str]]:
        values, errors = [], {}
        for i, args in enumerate(inputs):
            answer = self.call(args)
            values.append(answer.value)
            if answer.status != VALUE and len(errors) < 20:
                errors[i] = answer.error
        return values, errors
