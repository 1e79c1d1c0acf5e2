"""The student's process: load one file, call one function on the inputs it is sent.

Run as a script by :mod:`glsandbox.exercises.isolation` (``python -I -S -B
student_process.py CONFIG``); it imports the standard library only, so
nothing of glsandbox (least of all the reference implementations) is ever
loaded here (glsandbox imports it for :func:`_encode` alone, so the grader
reads values as the student's process writes them). Its import path is set from the
config (the standard library and the third-party packages, without
glsandbox); the parent has already put the process in its own session,
under limits and, on Linux, under a Landlock rule set that cannot read
glsandbox's files. This script adds a Python audit hook with the same file
rules (for systems without Landlock), then loads the submission.

Protocol, JSON lines: requests on file descriptor ``requests`` (``{"id": i,
"args": [...]}`` or ``{"id": i, "batch": [[...], ...], "shared": {position: value},
"arity": n}``, a batch's arguments common to every call sent once), answers on
descriptor ``answers`` (``{"id": i, "value": v}``, ``{"id": i, "error": "..."}``,
``{"id": i, "values": [...], "errors": {...}}``). The answers never hold
anything but what the student's function returned.
"""

import io
import json
import os
import signal
import sys
import traceback

_PROC_SELF = ("/proc/self", "/proc/thread-self", "/proc/cpuinfo", "/proc/meminfo", "/proc/stat")


def _inside(path, root):
    return path == root or path.startswith(root.rstrip("/") + "/")


def _audit(denied, writable, me):
    """Refuse reading the denied folders, writing outside ``writable``, starting programs and
    signalling other processes (PEP 578 hook: it cannot be removed once added)."""
    own = (f"/proc/{me}",) + _PROC_SELF

    def real(path):
        if isinstance(path, int) or path is None:
            return None
        try:
            return os.path.realpath(os.fsdecode(path))
        except (TypeError, ValueError):
            return None

    def readable(path):
        if path.startswith("/proc/") and path.split("/")[2].isdigit():
            return any(_inside(path, p) for p in own)
        return not any(_inside(path, d) for d in denied)

    def hook(event, args):
        if event == "open":
            path = real(args[0])
            if path is None:
                return
            mode = args[1] if isinstance(args[1], str) else "r"
            flags = args[2] if len(args) > 2 and isinstance(args[2], int) else 0
            writing = any(c in mode for c in "wax+") or flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT)
            if writing and not (any(_inside(path, w) for w in writable) or path == os.devnull):
                raise PermissionError(f"writing {path}: an exercise's function may not write files")
            if not readable(path):
                raise PermissionError(f"reading {path}: not allowed from an exercise's function")
        elif event in ("os.listdir", "os.scandir"):
            path = real(args[0] if args[0] is not None else ".")
            if path is not None and not readable(path):
                raise PermissionError(f"listing {path}: not allowed from an exercise's function")
        elif event in ("os.system", "os.exec", "os.posix_spawn", "os.spawn", "subprocess.Popen", "pty.spawn",
                       "os.fork", "os.forkpty"):
            raise PermissionError(f"{event}: an exercise's function may not start processes")
        elif event in ("os.kill", "os.killpg", "signal.pthread_kill"):
            if event != "signal.pthread_kill" and args[0] != me:
                raise PermissionError(f"{event}: an exercise's function may signal only itself")
        elif event in ("socket.connect", "socket.bind", "socket.sendto"):
            raise PermissionError(f"{event}: an exercise's function may not use the network")

    sys.addaudithook(hook)


class _Bounded(io.TextIOBase):
    """What the function prints: kept up to ``limit`` characters; past that, the case fails."""

    def __init__(self, limit):
        self.limit, self.size = limit, 0

    def writable(self):
        return True

    def write(self, text):
        text = str(text)
        self.size += len(text)
        if self.size > self.limit:
            raise _TooMuchOutput(f"printed more than {self.limit // 1024} KiB")
        return len(text)


class _TooMuchOutput(BaseException):
    """Raised inside the function's ``print``: a BaseException, so a bare ``except Exception`` in
    the student's code does not swallow it."""


def _encode(value, depth=0):
    """The function's answer as JSON-able data: numbers, None, bools, lists; numpy values by
    ``tolist``; anything else as its type's name."""
    if value is None or isinstance(value, (bool, int, float)):
        if type(value) not in (bool, int, float, type(None)):  # a subclass (numpy's float64): the plain value
            return bool(value) if isinstance(value, bool) else float(value) if isinstance(value, float) else int(value)
        return value
    if depth > 3:
        return {"__type__": type(value).__name__, "repr": "nested too deep"}
    tolist = getattr(type(value), "tolist", None)
    if tolist is not None and type(value).__module__.startswith("numpy"):
        return _encode(value.tolist(), depth + 1)
    if isinstance(value, (list, tuple)) and len(value) <= 64:
        return [_encode(v, depth + 1) for v in value]
    return {"__type__": type(value).__name__, "repr": ""}


def _error_line(exc, path):
    """``ZeroDivisionError: float division by zero (line 12)``: the last line of the
    traceback that is in the submission's file."""
    line = ""
    for frame in traceback.extract_tb(exc.__traceback__):
        if os.path.realpath(frame.filename) == path:
            line = f" (line {frame.lineno})"
    text = str(exc).splitlines()[0][:200] if str(exc) else ""
    return f"{type(exc).__name__}{': ' + text if text else ''}{line}"


def _call(function, args, limit):
    printed = _Bounded(limit)
    sys.stdout = sys.stderr = printed
    try:
        value = function(*args)
        return {"value": _encode(value)}
    except _TooMuchOutput as exc:
        return {"error": str(exc), "kind": "output"}
    except RecursionError as exc:
        return {"error": _error_line(exc, _PATH[0])}
    except BaseException as exc:  # noqa: BLE001 - SystemExit, KeyboardInterrupt: the case's, not the run's
        return {"error": _error_line(exc, _PATH[0])}
    finally:
        sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__


_PATH = [""]
#: A batch whose first this many calls all raise is not run further.
_STOP_AFTER = 256


def _batch(function, request, limit):
    """A batch's calls, each as :func:`_call` makes it (its printing bounded on its own, its
    error its own) at less cost a call: one output guard reused, the arguments every input
    shares (``shared``, by position) put in one template that each input's own fill."""
    shared = {int(k): v for k, v in request.get("shared", {}).items()}
    arity = int(request.get("arity", 0))
    template = [shared.get(k) for k in range(arity)]
    slots = [k for k in range(arity) if k not in shared]  # where each input's own arguments go
    printed = _Bounded(limit)
    values, errors, stopped = [], {}, None
    try:
        for i, varying in enumerate(request["batch"]):
            if shared:
                args = template.copy()
                for k, v in zip(slots, varying):
                    args[k] = v
            else:
                args = varying
            printed.size = 0
            sys.stdout = sys.stderr = printed  # again each call: the function may have replaced them
            try:
                values.append(_encode(function(*args)))
                continue
            except _TooMuchOutput as exc:
                error = str(exc)
            except BaseException as exc:  # noqa: BLE001 - SystemExit, KeyboardInterrupt: the case's
                error = _error_line(exc, _PATH[0])
            values.append(None)
            errors[str(i)] = error if len(errors) < 20 else ""
            if i == _STOP_AFTER - 1 and len(errors) == _STOP_AFTER:
                stopped = i + 1  # every call so far raised: the rest would too (a starter)
                break
    finally:
        sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__
    return {"values": values, "errors": errors, "stopped": stopped}


def main():
    with open(sys.argv[1], encoding="utf-8") as handle:
        config = json.load(handle)
    os.unlink(sys.argv[1])
    sys.path[:] = [config["folder"], *config["path"]]
    requests = os.fdopen(config["requests"], "r", encoding="utf-8", buffering=1 << 20)
    answers = os.fdopen(config["answers"], "w", encoding="utf-8")
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a file grown past its limit: an error, not a kill
    limit = int(config["output_limit"])
    _PATH[0] = os.path.realpath(config["file"])
    _audit([os.path.realpath(p) for p in config["denied"]], [os.path.realpath(config["work"])], os.getpid())

    def answer(message):
        answers.write(json.dumps(message, separators=(",", ":")) + "\n")
        answers.flush()

    namespace = {"__name__": "submission", "__file__": _PATH[0]}
    try:
        with open(_PATH[0], encoding="utf-8") as handle:
            source = handle.read()
        printed = _Bounded(limit)
        sys.stdout = sys.stderr = printed
        try:
            exec(compile(source, _PATH[0], "exec"), namespace)  # noqa: S102 - the submission, confined
        finally:
            sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__
        function = namespace.get(config["function"])
        if not callable(function):
            answer({"load_error": f"the file defines no function {config['function']}()"})
            return
    except BaseException as exc:  # noqa: BLE001 - whatever the file raised while loading
        answer({"load_error": _error_line(exc, _PATH[0])})
        return
    answer({"ready": True})
    for line in requests:
        request = json.loads(line)
        if "batch" in request:
            answer({"id": request["id"], **_batch(function, request, limit)})
        else:
            answer({"id": request["id"], **_call(function, request["args"], limit)})


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
