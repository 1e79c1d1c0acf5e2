"""The student's process (glsandbox/exercises/student_process.py), its pure parts in this process: answers
encoded as plain data whatever the function returned, an error told by the submission's own line,
and printing bounded. (The process itself, confined: test_isolation.py.)"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from glsandbox.exercises import student_process


def test_answers_are_plain_data_whatever_was_returned() -> None:
    assert student_process._encode(np.float64(35.0)) == 35.0 and type(student_process._encode(np.float64(35.0))) is float
    assert student_process._encode(np.array([[1, 2], [3, 4]])) == [[1, 2], [3, 4]]
    assert student_process._encode((True, None, 2)) == [True, None, 2] and type(student_process._encode(np.bool_(True))) is bool
    assert student_process._encode(object()) == {"__type__": "object", "repr": ""}  # never its repr: the student's text
    assert student_process._encode(list(range(65))) == {"__type__": "list", "repr": ""}
    assert student_process._encode([[[[[1]]]]]) == [[[[{"__type__": "list", "repr": "nested too deep"}]]]]


def _raise_in(path: Path, source: str) -> BaseException:
    namespace: dict = {}
    exec(compile(source, str(path), "exec"), namespace)  # noqa: S102 - the test's own text
    try:
        namespace["f"]()
    except BaseException as exc:  # noqa: BLE001
        return exc
    raise AssertionError("f() did not raise")


def test_an_error_names_its_line_in_the_submission(tmp_path: Path) -> None:
    path = tmp_path / "mine.py"
    exc = _raise_in(path, "def f():\n    x = 1\n    return x / 0\n")
    assert student_process._error_line(exc, str(path.resolve())) == "ZeroDivisionError: division by zero (line 3)"
    assert student_process._error_line(exc, "/elsewhere.py") == "ZeroDivisionError: division by zero"
    assert student_process._error_line(ValueError(), "/x.py") == "ValueError"


def test_a_call_keeps_its_printing_bounded_and_its_exit_to_itself(monkeypatch) -> None:
    monkeypatch.setattr(sys, "stdout", sys.stdout)  # _call puts back sys.__stdout__: the test's own restored after
    monkeypatch.setattr(sys, "stderr", sys.stderr)
    assert student_process._call(lambda: print("hi") or 2.5, (), 1024) == {"value": 2.5}
    assert student_process._call(lambda: print("x" * 2000), (), 1024) == {"error": "printed more than 1 KiB", "kind": "output"}
    assert student_process._call(lambda: sys.exit(3), (), 1024) == {"error": "SystemExit: 3"}

    def swallows():
        try:
            print("y" * 5000)
        except Exception:  # noqa: BLE001 - a student's bare except does not hide the limit
            return 1.0

    assert student_process._call(swallows, (), 1024)["kind"] == "output"


def test_a_batch_puts_the_shared_arguments_back_and_bounds_each_call_alone(monkeypatch) -> None:
    monkeypatch.setattr(sys, "stdout", sys.stdout)
    monkeypatch.setattr(sys, "stderr", sys.stderr)

    def f(a, b, c):
        print("z" * int(a))  # 600 characters a call: within 1 KiB each, past it together
        if a == 700.0:
            raise ValueError("seven hundred")
        return a + 10 * b + 100 * c

    request = {"batch": [[600.0, 1.0], [600.0, 2.0], [700.0, 0.0], [2000.0, 0.0]], "shared": {"1": 3.0}, "arity": 3}
    answer = student_process._batch(f, request, 1024)
    assert answer["values"] == [600.0 + 30.0 + 100.0, 600.0 + 30.0 + 200.0, None, None]
    assert answer["errors"] == {"2": "ValueError: seven hundred", "3": "printed more than 1 KiB"}
    assert answer["stopped"] is None and sys.stdout is sys.__stdout__


def test_a_batch_that_raises_on_every_call_is_stopped_early() -> None:
    answer = student_process._batch(lambda x: 1 / 0, {"batch": [[i] for i in range(1000)], "shared": {}, "arity": 1}, 1024)
    assert answer["stopped"] == student_process._STOP_AFTER == len(answer["values"])
    assert len(answer["errors"]) == student_process._STOP_AFTER and answer["errors"]["0"].startswith("ZeroDivisionError")
