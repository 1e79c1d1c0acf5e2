"""The processes below the grader: the zygote, a supervisor per submission and its renderer.

See :mod:`glsandbox.grading.isolate` for the tree and what each may do. This
module runs only in those processes; the grader starts the zygote with
:func:`zygote_main` and never imports the rest.
"""

from __future__ import annotations

import ctypes
import functools
import gc
import json
import os
import select
import shutil
import signal
import struct
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from glsandbox.grading import layers
from glsandbox.grading.isolate import (BROKEN, CRASHED, OOM, STORY_LIMIT, TAIL_LINES, TAIL_WIDTH, TIMEOUT, Job, Picture,
                                       Reader, job_from, send, story_of, wide_pipe)
from glsandbox.grading.processes import kill_tree, killpg, set_subreaper, wait_briefly
from glsandbox.grading.warm import quiet

__all__ = ["PRELOAD", "zygote_main"]

#: What the zygote imports once, so each submission starts warm (and no module
#: opens a GL context at import).
PRELOAD = ["glsandbox.grading.worker", "glsandbox.frame", "glsandbox.lesson",
           "glsandbox.scene_file", "glsandbox.grading.sandbox", "glsandbox.gl.context", "glsandbox.gl.shaders",
           "numpy", "moderngl", "glcontext", "glcontext.egl", "PIL.Image", "glsandbox.lessons"]



# --- the renderer (grandchild) ---------------------------------------------------------------


def _limit(job: Job, cpu: tuple[int, int] | None = None) -> None:
    """Address space (--memory), CPU seconds (--timeout for each picture, plus start-up; or
    ``cpu``, soft and hard), no core files, and files no larger than 256 MB."""
    import resource  # POSIX only, as the whole of this module's running side

    memory = job.memory_mb * 1024 * 1024
    soft, hard = cpu if cpu is not None else (cpu_budget(job), cpu_budget(job) + 1)
    for limit, value, top in ((resource.RLIMIT_AS, memory, memory), (resource.RLIMIT_CPU, soft, hard),
                              (resource.RLIMIT_CORE, 0, 0), (resource.RLIMIT_FSIZE, 256 << 20, 256 << 20)):
        try:
            resource.setrlimit(limit, (value, top))
        except (ValueError, OSError):
            pass


def cpu_budget(job: Job) -> int:
    """The CPU seconds one job may use: its pictures' time limits and 10 s of start-up."""
    return int(job.timeout * len(job.renders)) + 10


def _renderer(job: Job, root: str, target: str, work: str, out: int, ids: tuple[int, int] | None) -> None:
    """The renderer's whole life; it never returns (``os._exit``). ``ids``: the user it becomes
    before the submission's code runs (the grader is root)."""
    code = 0
    try:
        cwd = os.path.join(work, "cwd")
        renderer = enter_renderer(job, root, root if job.copy else cwd, [root if job.copy else cwd, cwd], work, out,
                                  ids)
        if renderer is not None:
            render_job(job, renderer, root, target, 3)
    except BaseException:  # noqa: BLE001 - the pipe closed, or worse: the supervisor reports it
        code = 3
    finally:
        flush_output()
        os._exit(code)  # no atexit handler, no thread, no finaliser of the submission runs


def enter_renderer(job: Job, root: str, here: str, writable: list[str], work: str, out: int,
                   ids: tuple[int, int] | None, keep: int | None = None, cpu: tuple[int, int] | None = None):
    """A renderer's start, before any submission is read: its own session, stdin /dev/null,
    stdout and stderr into ``work``'s ``output.txt``, the result pipe ``out`` as descriptor 3
    (``keep``, a pipe of commands, as 4; every other one closed), its own network, working in
    ``here``, limited (``cpu``: soft and hard CPU seconds, else :func:`cpu_budget`'s), its GL
    context (or the warm template's copy), then the user ``ids``, confined to reading ``root``
    and writing ``writable`` (:func:`~glsandbox.grading.sandbox.confine`), and seccomp's filter.
    The renderer, or None when no GL context opened (the supervisor was told)."""
    from glsandbox.errors import SandboxError
    from glsandbox.frame import HeadlessRenderer
    from glsandbox.grading.sandbox import confine, landlock_abi

    os.setsid()
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    log = os.open(os.path.join(work, "output.txt"), os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    os.dup2(log, 1)
    os.dup2(log, 2)
    os.close(null)
    os.close(log)
    os.dup2(out, 3)  # the result pipe; every other descriptor (the supervisor's, the zygote's) is closed
    if keep is not None:
        os.dup2(keep, 4)
    os.closerange(5 if keep is not None else 4, os.sysconf("SC_OPEN_MAX"))
    sys.stdin = open(os.devnull)  # noqa: SIM115 - the submission's, for its life
    sys.argv = ["submission"]
    layers.close_network()  # before a context starts threads: a user namespace needs a single thread
    os.chdir(here)
    _limit(job, cpu)
    try:  # forked from a warm template: its context, copied (see glsandbox.grading.warm)
        renderer = _template if _template is not None else HeadlessRenderer(job.backend)
    except SandboxError as exc:
        send(3, {"kind": "nogl", "error": str(exc)})
        return None
    kept_reading = False
    if ids is not None:  # Python only root may read: reading kept, bounded by Landlock below
        kept_reading = not _python_readable() and landlock_abi() >= 1
        layers.drop_privileges(ids, keep_reading=kept_reading)
    if not confine(root, writable, cache_writable=job.writes_cache, others_only=kept_reading) and kept_reading:
        layers.drop_reading()
    layers.install_seccomp()
    return renderer


def flush_output() -> None:
    """Write out what the process printed so far (its output file is read as soon as its last
    picture arrives, while it may still be ending)."""
    for stream in (sys.__stdout__, sys.__stderr__):
        try:
            stream.flush()
        except BaseException:  # noqa: BLE001 - replaced or closed by the submission
            pass  # no atexit handler, no thread, no finaliser of the submission runs


def _flushed_send(out: int, header: dict, payload: bytes | np.ndarray = b"") -> None:
    """:func:`send` once what the submission printed is written out: the supervisor reads the
    output file as soon as the last picture's message (an image, or why there is none) arrives."""
    flush_output()
    send(out, header, payload)


def render_job(job: Job, renderer, root: str, target: str, out: int,
               own_process: Callable[[Path], bool] | None = None) -> bool:
    """Load the submission's lesson (``target`` in ``root``, or a built-in lesson's name) and send
    each of the job's pictures on ``out`` as it is drawn, or the error that stopped it: the
    renderer's work once confined, on either path (this one and :mod:`glsandbox.grading.portable`).
    ``own_process``: whether the lesson file must be rendered in a process of its own (a resident
    renderer's question, :mod:`glsandbox.grading.resident`); then only ``own`` is sent. False
    when drawing a picture raised (the renderer may hold a half-made frame), else True."""
    from glsandbox.errors import SandboxError
    from glsandbox.lesson import find_lesson, submission_lesson, user_code_error

    if own_process is not None and own_process(Path(root) / target):
        _flushed_send(out, {"kind": "own"})
        return True
    try:
        cls = find_lesson(target) if job.source is None else submission_lesson(Path(root) / target, job.entry)
    except MemoryError as exc:
        _flushed_send(out, {"kind": "oom", "index": 0, "error": str(user_code_error(exc)), "all": True})
        return True
    except SandboxError as exc:
        _flushed_send(out, {"kind": "broken", "index": 0, "error": str(exc), "all": True})
        return True
    except BaseException as exc:  # noqa: BLE001 - anything the submission raised while loading
        _flushed_send(out, {"kind": "broken", "index": 0, "error": str(user_code_error(exc)), "all": True})
        return True
    if job.describe:  # the tour's card: read from the class now, sent as text
        try:
            from glsandbox.lesson import lesson_description

            _flushed_send(out, {"kind": "meta", "title": str(cls.title)[:500],
                                "course_section": str(cls.course_section)[:500],
                                "description": str(lesson_description(cls))[:2000]})
        except BaseException:  # noqa: BLE001 - a class whose attributes raise: its card says less
            pass
    clean = True
    for index, render in enumerate(job.renders):
        started = time.perf_counter()
        try:
            if render.nudge:  # a model answer's picture for its margin
                from glsandbox.measure.margin import nudged_image

                frame = None
                image = nudged_image(renderer, cls.from_settings(render.settings), render.size, render.samples,
                                     render.nudge)
            else:
                frame = renderer.render(cls.from_settings(render.settings), render.size, render.samples)
                image = frame.image
            image = np.ascontiguousarray(image, dtype=np.uint8)
            header = {"kind": "image", "index": index, "shape": list(image.shape),
                      "seconds": time.perf_counter() - started}
            if job.describe and frame is not None:
                header["info"] = {"plan": frame.plan.to_dict(), "plan_text": frame.plan.describe()}
            if render.explain is not None:
                header["story"] = _story(cls, render, renderer)
            _flushed_send(out, header, image)
        except MemoryError as exc:
            clean = False
            _flushed_send(out, {"kind": "oom", "index": index, "error": str(user_code_error(exc))})
        except SandboxError as exc:
            clean = False
            _flushed_send(out, {"kind": "broken", "index": index, "error": str(exc)})
        except BaseException as exc:  # noqa: BLE001 - KeyboardInterrupt, SystemExit, its own kinds
            clean = False
            _flushed_send(out, {"kind": "broken", "index": index, "error": str(user_code_error(exc))})
    return clean


def _story(cls, render, renderer) -> str:  # noqa: ANN001 - the submission's class, a Render, its renderer
    """The story of ``render.explain``'s pixel in the submission's own frame (``glsandbox explain``),
    or the line saying why there is none; told here, in the confined renderer."""
    from glsandbox.frame import with_samples
    from glsandbox.story import pixel_story

    try:
        scene = with_samples(cls.from_settings(render.settings).scene(), render.samples)
        story = pixel_story(scene, tuple(render.size), tuple(render.explain), cls.name, lambda: renderer)
        return story.text[:STORY_LIMIT]
    except BaseException as exc:  # noqa: BLE001 - the submission's scene may raise anything
        return f"(no story: {str(exc)[:300]})"


# --- the supervisor (child) ------------------------------------------------------------------


def _copy_submission(source: Path, into: Path) -> Path:
    """A private copy of a submission's file or folder; symbolic links are copied as links
    (one that points outside is refused when read, never followed while copying)."""
    if source.is_dir():
        shutil.copytree(source, into, symlinks=True)
    else:
        into.mkdir()
        shutil.copy2(source, into / source.name, follow_symlinks=False)
    return into


@functools.cache
def _python_readable() -> bool:
    from glsandbox.grading.layers import python_readable_by_others

    return python_readable_by_others()


def _exit_reason(status: int, job: Job) -> tuple[str, str]:
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        if number == signal.SIGXCPU:
            return TIMEOUT, f"timed out: the CPU time limit ({cpu_budget(job)} s) reached"
        name = signal.Signals(number).name if number in signal.Signals._value2member_map_ else str(number)
        return CRASHED, f"killed by signal {name}"
    return CRASHED, f"exited with code {os.WEXITSTATUS(status)} before its picture was sent"


def _collect(job: Job, pid: int, fd: int, meta: dict | None = None, reader: Reader | None = None) -> list[Picture]:
    """Each picture as it arrives, against the clock: ``job.timeout`` seconds for each. ``reader``:
    the pipe's, kept by a caller that reads on after the last picture (a resident renderer's)."""
    pictures: list[Picture] = [Picture() for _ in job.renders]
    limit = max(w * h * 4 for w, h in (r.size for r in job.renders))
    reader = reader if reader is not None else Reader(fd)
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
            pictures[current].seconds = time.monotonic() - started  # the limit it ran into, not 0
            return finish(TIMEOUT, f"timed out after {job.timeout:g} s")
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
                if kind == "own":
                    raise OwnProcess()
                if kind == "meta" and meta is not None and not meta:
                    meta.update({k: str(header.get(k, ""))[:2000] for k in ("title", "course_section", "description")})
                    continue
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
                    if job.describe and isinstance(header.get("info"), dict):
                        picture.info = header["info"]
                    picture.info = {**picture.info, **story_of(header)}
                else:
                    picture.status = OOM if kind == "oom" else BROKEN
                    picture.error = str(header.get("error", ""))[:500]
                    if header.get("all"):  # the lesson did not load: no picture of it can be made
                        return finish(picture.status, picture.error)
                current, started = current + 1, time.monotonic()
                if current == len(pictures):  # what follows is the caller's (a resident renderer's "served")
                    break
        except (ValueError, KeyError, TypeError) as exc:
            return finish(CRASHED, f"sent {exc}")
        if status is not None and (reader.closed or not select.select([fd], [], [], 0)[0]) and current < len(pictures):
            return finish(*_exit_reason(status, job))
    return pictures


class _NoGL(Exception):
    """The renderer could not open a GL context: the machine's problem, not the submission's."""


class OwnProcess(Exception):
    """A resident renderer's answer: this submission is rendered in a process of its own."""


def _tail(path: str) -> list[str]:
    try:
        with open(path, "rb") as handle:
            handle.seek(max(0, os.fstat(handle.fileno()).st_size - 64 * 1024))
            lines = handle.read().decode("utf-8", "backslashreplace").splitlines()
    except OSError:
        return []
    return [line[:TAIL_WIDTH] for line in lines[-TAIL_LINES:]]


def _supervise(job: Job, out: int) -> None:
    """One submission, start to end, its result framed on ``out`` (runs in a process the zygote forked)."""
    os.setsid()
    set_subreaper()
    send(out, {"kind": "pid", "pid": os.getpid()})
    work = tempfile.mkdtemp(prefix="glsandbox-grade-")
    result: dict = {"kind": "result", "pictures": None, "output": [], "no_gl": "", "root": "", "meta": {}}
    pictures: list[Picture] | None = None
    cleaned = sent = False
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
        ids = layers.submission_ids(os.getpid()) if job.copy else None
        if ids is not None:  # its own copy and working folder, owned by the user it runs as
            layers.hand_over(work, [root, os.path.join(work, "cwd")], ids)
        read_end, write_end = os.pipe()
        wide_pipe(write_end)
        pid = os.fork()
        if pid == 0:  # the renderer: no GL context here, or the warm template's, checked safe to fork
            os.close(read_end)
            _renderer(job, root, target, work, write_end, ids)
        os.close(write_end)
        try:
            pictures = _collect(job, pid, read_end, result["meta"])
        except _NoGL as exc:
            result["no_gl"] = str(exc)
        if pictures is not None and not any(p.status in (TIMEOUT, CRASHED, OOM) for p in pictures):
            # Every picture came, each after the renderer flushed its output: the grader hears now
            # and starts the next submission while this one's processes and folder are cleaned up
            # (the grader waits for this pipe to close before its run ends: nothing left behind).
            result["output"] = _tail(os.path.join(work, "output.txt"))
            _send_result(out, result, pictures)
            sent = True
        else:
            wait_briefly(pid)  # a renderer that ended by itself: then one look finds nothing left
        killpg(pid)  # the renderer's session (all there is to kill where /proc is missing)
        kill_tree(os.getpid())
        cleaned = True
        os.close(read_end)
        if not sent:
            result["output"] = _tail(os.path.join(work, "output.txt"))
    finally:
        if not cleaned:
            kill_tree(os.getpid())
        shutil.rmtree(work, ignore_errors=True)
        if not sent:
            _send_result(out, result, pictures)


def _send_result(out: int, result: dict, pictures: list[Picture] | None) -> None:
    """The supervisor's one result message: ``result`` with each picture's outcome, and the pixels."""
    payload: list[np.ndarray] = []
    if pictures is not None:
        result["pictures"] = []
        for picture in pictures:
            image = picture.image
            result["pictures"].append({"status": picture.status, "error": picture.error,
                                       "seconds": picture.seconds, "info": picture.info,
                                       "shape": None if image is None else list(image.shape)})
            if image is not None:
                payload.append(np.ascontiguousarray(image, dtype=np.uint8))
    send(out, result, payload)


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


def zygote_main(channel_fd: int, folder: str | None = None,
                serve_slot: Callable[[int, int], None] | None = None) -> None:
    """The zygote process: import :data:`PRELOAD` and the GL libraries once, then :func:`zygote`.
    ``folder``: where every supervisor makes its private folder (the grader removes it at the end);
    ``serve_slot``: a job slot's supervisor (:func:`glsandbox.grading.resident.serve_slot`)."""
    import importlib

    if folder is not None:
        tempfile.tempdir = folder

    for module in PRELOAD:
        try:
            importlib.import_module(module)
        except ImportError:  # e.g. no lessons package beside an installed glsandbox
            pass
    preload_gl_libraries()
    prepare_confinement()
    # Every object so far into the permanent generation: a fork's collector never walks them, so
    # never writes their headers and copies their pages (a collection in a renderer touched the
    # whole inherited heap: about 10 ms of one renderer's 60 in one profile here).
    gc.freeze()
    zygote(channel_fd, serve_slot)


def prepare_confinement() -> None:
    """Work out once, before any fork, what every renderer's :func:`~glsandbox.grading.sandbox.confine`
    reads of the file system, so each inherits the answers: the folders a submission may read, and
    where the grader is root and a renderer keeps reading as root does, the parts of ``/etc`` a user
    with no account may read (a walk of ``/etc``: 30 to 40 ms that each renderer paid before)."""
    from glsandbox.grading.sandbox import landlock_abi, others_may_read, read_roots

    read_roots()
    if layers.submission_ids(os.getpid()) is not None and not _python_readable() and landlock_abi() >= 1:
        others_may_read("/etc")


def zygote(channel_fd: int, serve_slot: Callable[[int, int], None] | None = None) -> None:
    """Serve the grader on ``channel_fd`` (one end of a socket pair): each message is a job and
    the pipe its result goes to; fork a supervisor for it, or hand the job to the warm template
    of its backend (:func:`_template_for`), which forks it from a context already drawn with.
    Ends when the grader closes its end.

    A socket pair has no name in the file system, so no submission can find it
    and ask for a process (multiprocessing's forkserver listens on a named socket).
    """
    import socket

    channel = socket.socket(fileno=channel_fd)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the grader decides when a run stops
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # supervisors are reaped by the kernel
    templates: dict[str | None, socket.socket | None] = {}
    while True:
        size_bytes = _recv_exact(channel, 4)
        if size_bytes is None:
            break
        (size,) = struct.unpack("!I", size_bytes)
        first, fds, _, _ = socket.recv_fds(channel, min(size, 1 << 16), 2)
        data = first + (_recv_exact(channel, size - len(first)) or b"")
        if not fds:
            continue
        request = json.loads(data)
        if request.get("slot"):  # a job slot for data-only submissions (glsandbox.grading.resident)
            _fork_slot(channel, templates, fds, serve_slot)
            continue
        job = job_from(request)
        if _template is None and not job.writes_cache:  # the model answer's renderer fills Mesa's cache: cold
            warm = _template_for(job, templates, channel, fds)
            if warm is not None:
                try:
                    warm.sendall(size_bytes)
                    socket.send_fds(warm, [data], fds)
                    os.close(fds[0])
                    continue
                except OSError:  # the template is gone: cold forks for this backend from now on
                    templates[job.backend] = None
        if _template is not None:
            quiet()  # Mesa's cache thread holds no lock the copy could need
        _fork_serving(channel, templates, fds, lambda: _supervise(job, fds[0]))
    os._exit(0)


def _fork_serving(channel, templates: dict, fds: list[int], serve: Callable[[], None]) -> None:  # noqa: ANN001
    """Fork a supervisor that runs ``serve`` and ends (its child reaped by itself, none of the
    zygote's sockets kept); here, ``fds`` (now the supervisor's) are closed."""
    pid = os.fork()
    if pid == 0:
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)  # the supervisor waits for its renderer
        channel.close()
        for other in templates.values():
            if other is not None:
                other.close()
        code = 0
        try:
            serve()
        except BaseException:  # noqa: BLE001 - the grader sees the pipe close without a result
            code = 1
        os._exit(code)
    for fd in fds:
        os.close(fd)


def _fork_slot(channel, templates: dict, fds: list[int],  # noqa: ANN001 - the grader's socket
               serve_slot: Callable[[int, int], None] | None) -> None:
    """Fork a slot supervisor (``serve_slot``: :func:`glsandbox.grading.resident.serve_slot`) on
    ``fds``: the read end of its jobs' pipe and the write end of its results'. Cold: a resident
    renderer opens a context of its own, kept for all its submissions. None (a template's
    zygote, which is never asked): the request is dropped, the grader sees its pipe close."""
    if len(fds) != 2 or serve_slot is None:
        for fd in fds:
            os.close(fd)
        return
    _fork_serving(channel, templates, fds, lambda: serve_slot(fds[0], fds[1]))


def _template_for(job: Job, templates: dict, channel, fds: list[int]) -> object | None:
    """The zygote's end of the warm template for ``job.backend``, started on first use (a forked
    child that opens and warms a context, says whether it is safe to fork, then serves as a
    zygote); None where it is not (:func:`glsandbox.grading.warm.open_template`)."""
    import socket

    if job.backend in templates:
        return templates[job.backend]
    ours, theirs = socket.socketpair()
    pid = os.fork()
    if pid == 0:
        global _template
        ours.close()
        channel.close()
        for fd in fds:  # this job's result pipe: the template passes it on, it never keeps it
            os.close(fd)
        for other in templates.values():
            if other is not None:
                other.close()
        from glsandbox.grading.warm import open_template

        _template = open_template(job.backend, {r.size for r in job.renders})
        gc.freeze()  # the warm-up's objects too
        try:
            theirs.sendall(b"1" if _template is not None else b"0")
            if _template is not None:
                zygote(theirs.detach())
        except BaseException:  # noqa: BLE001 - the zygote sees the socket close
            pass
        os._exit(0)
    theirs.close()
    ours.settimeout(30)
    try:
        ready = ours.recv(1) == b"1"
    except OSError:
        ready = False
    ours.settimeout(None)
    if not ready:  # unsafe, or no answer in time: it goes, and this backend's renderers start cold
        ours.close()
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    templates[job.backend] = ours if ready else None
    return templates[job.backend]


#: In the warm template and the renderers forked from it: the renderer on its warmed context.
_template = None


def _recv_exact(channel, size: int) -> bytes | None:
    data = b""
    while len(data) < size:
        chunk = channel.recv(size - len(data))
        if not chunk:
            return None
        data += chunk
    return data
