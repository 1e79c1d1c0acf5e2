"""A renderer kept for many data-only submissions: one per job slot, confined as a one-shot renderer is.

A scene file (``.toml``) is data: no code of the student's runs while it
is read and drawn. Starting a process, a context and the confinement for
each such submission is most of what grading one costs, so the grader
(:mod:`glsandbox.grading.slots`) asks the zygote for one *slot supervisor*
per job slot and hands it scene file after scene file::

    zygote
     └─ slot supervisor (own session, child subreaper; the grader's jobs on a pipe)
         └─ resident renderer (own session, network and user; limits; one GL context;
            confined to reading its inbox and writing its working folder)

For each submission the supervisor copies its files into a fresh folder
of the inbox (``in/<n>``: a new path each time, so a cache keyed by a
path never answers for another submission), owned by the submission's
user, and removes it when the pictures are in; the renderer can read the
inbox and nothing of any other submission: at any time the inbox holds
only the submission being drawn. The renderer, told the folder and the
job on its command pipe, starts each submission afresh
(:func:`start_afresh`: its frame renderer keeps only glsandbox's own
compiled programs; the model, BVH and warning caches emptied), narrows
glsandbox's file checks to that folder, and renders as a one-shot
renderer does (:func:`~glsandbox.grading.worker.render_job`).

Limits: the supervisor holds each picture to ``--timeout`` by the clock
(as for every renderer); a CPU-time limit is set before each job to what
the renderer used so far plus the job's budget (the one-shot renderer's,
so a CPU-bound TIMEOUT reads the same), under a hard limit for
:data:`RETIRE_AFTER` jobs, after which a fresh renderer takes over. After
a TIMEOUT, crash, OUT OF MEMORY or a picture that raised while drawing,
the renderer's whole tree is killed and the next submission gets a fresh
one. A scene file naming a shader of its own (GLSL: code, compiled and run
by the driver) is answered ``own`` and graded the one-process-each way.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from glsandbox.grading import layers
from glsandbox.grading.isolate import BROKEN, CRASHED, OOM, TIMEOUT, Job, Picture, Reader, _job_data, job_from, send
from glsandbox.grading.processes import kill_tree, killpg, set_subreaper
from glsandbox.grading.worker import (OwnProcess, _collect, _copy_submission, _NoGL, _send_result, _tail,
                                      cpu_budget, enter_renderer, flush_output, render_job, wide_pipe)

__all__ = ["zygote_main", "serve_slot", "start_afresh", "names_own_shader", "RETIRE_AFTER"]

#: Submissions one resident renderer draws before a fresh one replaces it (its CPU limit's horizon).
RETIRE_AFTER = 200
#: How long the supervisor waits for a renderer's ``served`` line after its last picture (seconds).
SERVED_WAIT = 5.0


def names_own_shader(path: Path) -> bool:
    """Whether the scene file at ``path`` gives a node a shader file of its own (``shader =``):
    GLSL, code the driver compiles and runs, rendered in a process of its own. A file that
    cannot be read or parsed (or is too big to be) says no: loading it reports that, as it
    would in a process of its own. Only a file holding the word, or an escape that could spell
    it in a quoted key, is parsed here."""
    import tomllib

    try:
        raw = path.read_bytes()
        if b"shader" not in raw and b"\\u" not in raw and b"\\U" not in raw:
            return False
        data = tomllib.loads(raw.decode("utf-8"))
    except Exception:  # noqa: BLE001 - unreadable, not UTF-8, not TOML, out of memory: its load tells
        return False
    nodes = data.get("nodes")
    return isinstance(nodes, list) and any(isinstance(n, dict) and "shader" in n for n in nodes)


def start_afresh(renderer) -> None:  # noqa: ANN001 - a HeadlessRenderer
    """Nothing of the last submission left in this process's drawing: the frame renderer
    :meth:`~glsandbox.frame.FrameRenderer.forget`\\ s all but the built-in programs, and the
    caches of what files held (models, BVHs) and the warnings printed once are emptied. The
    caches left are pure functions of numbers and names (built-in meshes, matrices), whose
    answers are read-only: they cannot carry one submission's picture into another's."""
    import sys

    renderer.forget()
    # A module not imported yet holds nothing (and importing it here, under the audit hook, costs)
    for name, clear in (("glsandbox.mesh.load", "clear_cache"), ("glsandbox.raytrace.bvh", "clear_cache"),
                        ("glsandbox.raytrace.gpu", "clear_warnings")):
        module = sys.modules.get(name)
        if module is not None:
            getattr(module, clear)()


def zygote_main(channel_fd: int, folder: str) -> None:
    """The zygote's program (:func:`glsandbox.grading.worker.zygote_main`), which forks a slot
    supervisor (:func:`serve_slot`) for each slot the grader asks for."""
    from glsandbox.grading import worker

    worker.zygote_main(channel_fd, folder, serve_slot)


# --- the resident renderer (grandchild) --------------------------------------------------------


def _resident(job: Job, work: str, inbox: str, cwd: str, out: int, commands: int,
              ids: tuple[int, int] | None) -> None:
    """The resident renderer's whole life; it never returns (``os._exit``)."""
    from glsandbox import files
    from glsandbox.gl.shaders import shader_roots

    code = 0
    try:
        # The warm template's drawing (glsandbox.grading.warm): no rasterizer threads and no
        # on-disk shader cache, so no thread at all: the context opens before confinement, and
        # Landlock and seccomp bind only the thread that enters them and those it starts later
        # (Mesa's cache thread, started with the context, could write the cache). And so a
        # resident renderer's address space (what --memory bounds) is that of the renderers
        # forked from the template, and an OUT OF MEMORY the same verdict.
        os.environ["LP_NUM_THREADS"] = "0"
        os.environ["MESA_SHADER_CACHE_DISABLE"] = "true"
        budget = cpu_budget(job)
        renderer = enter_renderer(job, inbox, cwd, [cwd], work, out, ids, keep=commands,
                                  cpu=(budget, budget * (RETIRE_AFTER + 1)))
        reader = Reader(4)
        also = (cwd, *shader_roots())  # the folders glsandbox's own file checks allow besides a submission's
        while renderer is not None:
            command = _next(reader)
            if command is None:  # the supervisor is done with it
                break
            job = job_from(command["job"])
            root = os.path.join(inbox, str(command["folder"]))
            start_afresh(renderer)
            files.set_sandbox_root(root, also=also)
            os.chdir(root)
            _cpu_limit(cpu_budget(job))
            clean = render_job(job, renderer, root, job.target, 3, own_process=names_own_shader)
            flush_output()
            send(3, {"kind": "served", "clean": clean})
    except BaseException:  # noqa: BLE001 - a pipe closed, or worse: the supervisor reports it
        code = 3
    finally:
        flush_output()
        os._exit(code)


def _next(reader: Reader) -> dict | None:
    """The next command on the renderer's pipe, waiting for it; None when the pipe closed."""
    while True:
        for header, _ in reader.messages(0):
            return header
        if reader.closed:
            return None
        reader.pump(3600.0)


def _cpu_limit(budget: int) -> None:
    """The soft CPU-time limit: what this process used so far and ``budget`` more seconds (the
    hard limit, set at the start, stays: a renderer past it is killed, and is replaced anyway
    after :data:`RETIRE_AFTER` jobs)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_SELF)
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    soft = int(usage.ru_utime + usage.ru_stime) + 1 + budget
    try:
        resource.setrlimit(resource.RLIMIT_CPU, (min(soft, hard), hard))
    except (ValueError, OSError):
        pass


# --- the slot supervisor (child) ---------------------------------------------------------------


class _Renderer:
    """The supervisor's handle on its resident renderer."""

    def __init__(self, pid: int, commands: int, results: int, key: tuple) -> None:
        self.pid, self.commands, self.results, self.key = pid, commands, results, key
        self.reader = Reader(results)
        self.served = 0

    def stop(self) -> None:
        """Kill its whole tree and close its pipes."""
        os.close(self.commands)
        killpg(self.pid)
        kill_tree(os.getpid())
        os.close(self.results)


def serve_slot(jobs: int, out: int) -> None:
    """A slot supervisor's whole life (a process the zygote forked): each job read from ``jobs``
    drawn by the resident renderer, its result framed on ``out``, until ``jobs`` closes."""
    os.setsid()
    set_subreaper()
    send(out, {"kind": "pid", "pid": os.getpid()})
    work = tempfile.mkdtemp(prefix="glsandbox-grade-")
    inbox, cwd = os.path.join(work, "in"), os.path.join(work, "cwd")
    renderer: _Renderer | None = None
    try:
        os.mkdir(inbox, 0o711)  # the renderer may open what it is told of, not list the folder
        os.mkdir(cwd)
        os.close(os.open(os.path.join(work, "output.txt"), os.O_WRONLY | os.O_CREAT, 0o600))  # each job truncates it
        ids = layers.submission_ids(os.getpid())
        if ids is not None:
            layers.hand_over(work, [cwd], ids)
        reader = Reader(jobs)
        number = 0
        while (command := _next(reader)) is not None:
            number += 1
            renderer = _serve(job_from(command), number, work, renderer, ids, out)
    finally:
        if renderer is not None:
            renderer.stop()
        kill_tree(os.getpid())
        shutil.rmtree(work, ignore_errors=True)


def _serve(job: Job, number: int, work: str, renderer: _Renderer | None, ids: tuple[int, int] | None,
           out: int) -> _Renderer | None:
    """One submission through the resident renderer (started first where there is none, or a
    fresh one where it served its share or has other limits), its result sent on ``out`` as soon
    as its pictures are in; the renderer the next submission gets (None: a fresh one)."""
    result: dict = {"kind": "result", "pictures": None, "output": [], "no_gl": "", "root": "", "meta": {}}
    root = os.path.join(work, "in", str(number))
    try:
        _copy_submission(Path(job.source or ""), Path(root))
    except (OSError, shutil.Error) as exc:
        shutil.rmtree(root, ignore_errors=True)
        reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0][:200]
        _send_result(out, result, [Picture(status=BROKEN, error=f"{job.source}: cannot be copied for grading "
                                                                f"({reason})") for _ in job.renders])
        return renderer
    result["root"] = root
    key = (job.backend, job.memory_mb, job.timeout, len(job.renders))
    try:
        if ids is not None:
            layers.hand_over(work, [root], ids)
        if renderer is not None and (renderer.key != key or renderer.served >= RETIRE_AFTER):
            renderer.stop()
            renderer = None
        renderer = renderer or _start(job, work, ids, key)
        output = os.path.join(work, "output.txt")
        os.truncate(output, 0)  # the renderer appends: this submission's lines only
        pictures = _draw(job, number, renderer, result)
        renderer.served += 1
        result["output"] = _tail(output)  # (flushed before its last picture was sent)
        failed = bool(result["no_gl"]) or any(p.status in (TIMEOUT, CRASHED, OOM) for p in pictures or ())
        if not failed:  # the grader hears now; the renderer's "served" line and the clean-up follow
            _send_result(out, result, pictures)
        if failed or not _served(renderer):
            renderer.stop()
            renderer = None
        if failed:
            _send_result(out, result, pictures)
        return renderer
    finally:
        shutil.rmtree(root, ignore_errors=True)
        _empty(os.path.join(work, "cwd"))


def _empty(folder: str) -> None:
    """Remove what is in ``folder`` (the renderer's working folder: a scene file writes nothing
    there, and whatever was written is gone before the next submission)."""
    for entry in os.scandir(folder):
        try:
            shutil.rmtree(entry.path) if entry.is_dir(follow_symlinks=False) else os.unlink(entry.path)
        except OSError:
            pass


def _draw(job: Job, number: int, renderer: _Renderer, result: dict) -> list[Picture] | None:
    """Tell the renderer of the job and collect its pictures (None: no GL, or the job is handed
    back for a process of its own, said in ``result``)."""
    try:
        send(renderer.commands, {"job": _job_data(job), "folder": number})
    except OSError:  # it ended while idle: the clock and its exit status tell below
        pass
    try:
        return _collect(job, renderer.pid, renderer.results, result["meta"], renderer.reader)
    except _NoGL as exc:
        result["no_gl"] = str(exc)
    except OwnProcess:
        result["own_process"] = True
    return None


def _served(renderer: _Renderer) -> bool:
    """The renderer's ``served`` line after a job: whether it stayed clean (False: none came)."""
    import time

    deadline = time.monotonic() + SERVED_WAIT
    while time.monotonic() < deadline:
        try:
            for header, _ in renderer.reader.messages(0):
                return header.get("kind") == "served" and header.get("clean") is True
        except ValueError:
            return False
        if renderer.reader.closed:
            return False
        renderer.reader.pump(deadline - time.monotonic())
    return False


def _start(job: Job, work: str, ids: tuple[int, int] | None, key: tuple) -> _Renderer:
    """Fork a resident renderer for jobs like ``job``."""
    commands_read, commands_write = os.pipe()
    results_read, results_write = os.pipe()
    wide_pipe(results_write)
    pid = os.fork()
    if pid == 0:
        os.close(commands_write)
        os.close(results_read)
        _resident(job, work, os.path.join(work, "in"), os.path.join(work, "cwd"), results_write, commands_read, ids)
    os.close(commands_read)
    os.close(results_write)
    return _Renderer(pid, commands_write, results_read, key)
