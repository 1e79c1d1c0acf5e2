"""The student's function in its own process: hostile functions cost their own case, never the
run, and nothing of glsandbox (the references, the hidden answers) can be reached from there."""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import pytest

from glsandbox.exercises import get
from glsandbox.exercises.check import BROKEN, FAIL, PASS, TIMEOUT_STATUS, check_file
from glsandbox.exercises.isolation import CRASHED, ERROR, TIMEOUT, VALUE, Isolated, Limits, readable_roots

PACKAGE = Path(__file__).resolve().parents[2] / "glsandbox"

HOSTILE = f'''
import math, os, sys, time

def f(mode):
    if mode == "ok":
        return 2.0
    if mode == "loop":
        while True:
            pass
    if mode == "sleep":
        time.sleep(60)
    if mode == "raise":
        return 1 / 0
    if mode == "nan":
        return float("nan")
    if mode == "type":
        return "thirty-five"
    if mode == "print":
        print("x" * 5_000_000)
        return 2.0
    if mode == "exit":
        os._exit(3)
    if mode == "sysexit":
        sys.exit(0)
    if mode == "read":
        return open({str(PACKAGE / "raytrace" / "sphere.py")!r}).read()[:20]
    if mode == "walk":
        return sorted(os.listdir({str(PACKAGE)!r}))
    if mode == "import":
        import glsandbox.raytrace.sphere
        return 1.0
    if mode == "ctypes":
        import ctypes
        return ctypes.CDLL(None).open({str(PACKAGE / "raytrace" / "sphere.py").encode()!r}, 0)
    if mode == "numpy":
        import numpy as np
        return np.float64(2.0)
    if mode == "spawn":
        import subprocess
        return subprocess.run(["true"]).returncode
    if mode == "memory":
        return len(bytearray(8 << 30))
    if mode == "network":
        import socket
        socket.create_connection(("127.0.0.1", 9), timeout=0.2)
        return 1.0
    if mode == "parent":
        return open(f"/proc/{{os.getppid()}}/environ").read()[:20]
'''


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    path = tmp_path_factory.mktemp("hostile") / "hostile.py"
    path.write_text(HOSTILE)
    with Isolated(path, "f", Limits(call_seconds=1.0, memory_mb=1024, restarts=20)) as caller:
        yield caller


@pytest.mark.parametrize(("mode", "status", "fragment"), [
    ("ok", VALUE, ""),
    ("raise", ERROR, "ZeroDivisionError: division by zero (line 13)"),
    ("print", ERROR, "printed more than"),
    ("sysexit", ERROR, "SystemExit"),
    ("read", ERROR, "PermissionError: reading"),
    ("walk", ERROR, "PermissionError: listing"),
    ("import", ERROR, "No module named 'glsandbox'"),
    ("spawn", ERROR, "may not start processes"),
    ("memory", ERROR, "MemoryError"),
    ("parent", ERROR, "PermissionError: reading /proc/"),
    ("network", ERROR, "Error"),
    ("exit", CRASHED, "exit code 3"),
    ("loop", TIMEOUT, "no answer within 1 s"),
    ("sleep", TIMEOUT, "no answer within 1 s"),
])
def test_each_hostile_call_is_its_own_outcome_and_the_next_call_still_answers(hostile, mode, status,
                                                                              fragment) -> None:
    answer = hostile.call([mode])
    assert answer.status == status, answer
    assert fragment in answer.error
    assert hostile.call(["ok"]).value == 2.0


def test_values_come_back_as_plain_data(hostile) -> None:
    assert hostile.call(["numpy"]).value == 2.0
    nan = hostile.call(["nan"])
    assert nan.status == VALUE and nan.value != nan.value
    assert hostile.call(["type"]).value == {"__type__": "str", "repr": ""}  # only its type's name comes back


def test_the_kernel_refuses_reading_the_reference_even_past_python(hostile) -> None:
    from glsandbox.grading.sandbox import landlock_abi

    if landlock_abi() < 1:
        assert not (sys.platform == "linux" and os.environ.get("CI")), "CI's Linux has Landlock: it must close this"
        pytest.skip("no Landlock in this kernel: the audit hook alone refuses the read")
    answer = hostile.call(["ctypes"])
    assert answer.status == VALUE and answer.value == -1  # open(2) failed: EACCES


def test_no_glsandbox_folder_is_readable_and_site_packages_is_given_by_entries(tmp_path) -> None:
    site = tmp_path / "site"
    (site / "glsandbox").mkdir(parents=True)
    (site / "numpy").mkdir()
    (site / "other.py").write_text("")
    roots = readable_roots([str(tmp_path)], [str(site / "glsandbox")])
    assert sorted(roots) == sorted([str(site / "numpy"), str(site / "other.py")])


def test_a_function_that_always_loops_is_given_up_after_the_restarts(tmp_path) -> None:
    path = tmp_path / "loop.py"
    path.write_text("def f(x):\n    while True:\n        pass\n")
    with Isolated(path, "f", Limits(call_seconds=0.3, restarts=2)) as caller:
        started = time.monotonic()
        answers = [caller.call([i]) for i in range(6)]
        assert time.monotonic() - started < 5.0
    assert [a.status for a in answers] == [TIMEOUT] * 6
    assert "not run" in answers[-1].error


def _submission(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "mine.py"
    path.write_text(body)
    return path


@pytest.mark.parametrize(("body", "status"), [
    ("def intersect_sphere(o, d, c, r):\n    while True:\n        pass\n", TIMEOUT_STATUS),
    ("def intersect_sphere(o, d, c, r):\n    raise ValueError('no')\n", BROKEN),
    ("def intersect_sphere(o, d, c, r):\n    return float('nan')\n", FAIL),
    ("def intersect_sphere(o, d, c, r):\n    return 'hit'\n", FAIL),
    ("def intersect_sphere(o, d, c, r):\n    print('.' * 3_000_000)\n    return 35.0\n", BROKEN),
    ("import time\ndef intersect_sphere(o, d, c, r):\n    time.sleep(30)\n", TIMEOUT_STATUS),
    ("import os\ndef intersect_sphere(o, d, c, r):\n    os._exit(1)\n", BROKEN),
])
def test_hostile_submissions_get_the_right_outcome_per_case(tmp_path, body, status) -> None:
    result = check_file(get("ray_sphere"), _submission(tmp_path, body), probe=False,
                        limits=Limits(call_seconds=0.5, restarts=2))
    assert result.cases[0].status == status
    assert not result.visible_passed
    json.dumps(result.to_dict())


def test_a_submission_that_hunts_for_the_reference_does_not_pass(tmp_path) -> None:
    body = f'''
import importlib, os, sys
def intersect_sphere(origin, direction, center, radius):
    for name in ("glsandbox.raytrace.sphere", "glsandbox.exercises.catalogue.ray_sphere"):
        try:
            module = importlib.import_module(name)
            return module.Sphere(center, radius).intersect(module.Ray(origin, direction))
        except Exception:
            pass
    sys.path.append({str(PACKAGE.parent)!r})
    for root, dirs, files in os.walk({str(PACKAGE)!r}):
        if "sphere.py" in files:
            return 35.0
    for module in list(sys.modules.values()):
        if "glsandbox" in getattr(module, "__name__", ""):
            return 35.0
    return None
'''
    result = check_file(get("ray_sphere"), _submission(tmp_path, body), probe=False)
    assert [c.status for c in result.cases] == [FAIL] * len(result.cases)


def test_a_correct_submission_passes_in_isolation(tmp_path) -> None:
    body = '''
import math
def intersect_sphere(origin, direction, center, radius):
    a = sum(d * d for d in direction)
    l = [o - c for o, c in zip(origin, center)]
    b = sum(x * d for x, d in zip(l, direction))
    c = sum(x * x for x in l) - radius * radius
    disc = b * b - a * c
    if disc < 0:
        return None
    for t in sorted(((-b - math.sqrt(disc)) / a, (-b + math.sqrt(disc)) / a)):
        if t > 0:
            return t
    return None
'''
    result = check_file(get("ray_sphere"), _submission(tmp_path, body), hidden=True, probe_size=64)
    assert all(c.status == PASS for c in result.cases), [c for c in result.cases if c.status != PASS]
    assert result.probe.agrees


WHO = '''
import os

def f(path):
    try:
        with open(path, "rb") as handle:
            read = len(handle.read())
    except OSError as exc:
        read = -exc.errno
    status = open("/proc/self/status").read()
    effective = int(status.split("CapEff:")[1].split()[0], 16)
    return [os.getuid(), os.geteuid(), os.getgid(), os.stat(__file__).st_uid, read, effective]
'''


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="the grader is root only under root")
def test_under_a_root_grader_the_function_runs_as_a_user_with_no_account(tmp_path) -> None:
    """As a picture submission's renderer: a uid no account has, owning its own copy, with at most
    the one capability of reading (where Python is root's alone), bounded so that a root-only
    file, beside the submission or in /etc, stays unreadable."""
    from glsandbox.grading.layers import reading_kept

    secret = tmp_path / "teacher_only.txt"
    secret.write_text("the hidden cases")
    secret.chmod(0o600)
    os.chown(secret, 0, 0)
    path = tmp_path / "who.py"
    path.write_text(WHO)
    with Isolated(path, "f") as caller:
        answer = caller.call([str(secret)])
        shadow = caller.call(["/etc/shadow"]) if os.path.exists("/etc/shadow") else None
        other = Isolated(path, "f")
        try:
            second = other.call(["/dev/null"])
        finally:
            other.close()
    assert answer.status == VALUE, answer
    uid, euid, gid, owner, read, effective = answer.value
    assert uid != 0 and euid == uid and gid != 0 and owner == uid
    assert read < 0  # refused: EACCES
    assert effective == (1 << 2 if reading_kept() else 0)  # CAP_DAC_READ_SEARCH at most, no other power
    if shadow is not None and not os.stat("/etc/shadow").st_mode & 0o004:
        assert shadow.status == VALUE and shadow.value[4] < 0, shadow
    assert second.status == VALUE and second.value[0] not in (0, uid)  # two processes: two users


def test_a_process_that_stops_itself_cannot_hang_the_grader_in_a_big_batch(tmp_path) -> None:
    # The submission stops its own process (SIGSTOP, the one signal it may send) soon after it
    # loads: a batch of some megabytes then no longer fits the pipe, and its write must end by
    # the batch's deadline, as a TIMEOUT, rather than block the grader for ever.
    path = tmp_path / "stops.py"
    path.write_text("import os, signal, threading\n"
                    "threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGSTOP)).start()\n"
                    "def f(x):\n    return 1.0\n")
    with Isolated(path, "f", Limits(batch_seconds=1.5, restarts=1)) as caller:
        assert caller.call([0.0]).status == VALUE
        time.sleep(0.8)
        started = time.monotonic()
        answer = caller.batch([[float(i) * 1.000001] for i in range(300_000)])
        assert time.monotonic() - started < 6.0
    assert answer.status == TIMEOUT


def test_a_batch_begun_comes_back_whole_while_the_grader_works_meanwhile(tmp_path) -> None:
    path = tmp_path / "double.py"
    path.write_text("def f(x, k):\n    if x == 3:\n        raise ValueError('three')\n    return k * x\n")
    inputs = [(float(i), 2.0) for i in range(5)]
    with Isolated(path, "f") as caller:
        answers = caller.begin_batch(inputs)
        time.sleep(0.2)  # the grader's own work, while the process answers
        values, errors = answers()
        assert caller.call([1.0, 3.0]).value == 3.0  # the next request after it is answered as usual
    assert values == [0.0, 2.0, 4.0, None, 8.0]
    assert list(errors) == [3] and errors[3].startswith("ValueError: three")


def test_a_process_started_ahead_answers_its_first_call_or_says_why_it_did_not_load(tmp_path) -> None:
    good, bad = tmp_path / "good.py", tmp_path / "bad.py"
    good.write_text("def f(x):\n    return 2 * x\n")
    bad.write_text("raise RuntimeError('not today')\ndef f(x):\n    return x\n")
    with Isolated(good, "f") as caller:
        caller.start()
        assert caller.process is not None
        time.sleep(0.3)  # the checker's own work meanwhile
        assert caller.call([2.5]).value == 5.0
    with Isolated(bad, "f") as caller:
        caller.start()
        answer = caller.call([1.0])
        assert answer.status == ERROR and "RuntimeError: not today" in answer.error
        assert caller.load_error and caller.call([1.0]).status == ERROR
