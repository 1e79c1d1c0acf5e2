"""The one user-facing error type and the checks that make its one-line messages."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.errors import NUMBER_LIMIT, SandboxError, check_number, check_numbers, parse_size_text, plain


def test_a_sandbox_error_is_one_printable_line() -> None:
    error = SandboxError("line one\nline two\r\nthree\tfour\x1efive ")
    assert str(error) == "line one line two three four\\x1efive"
    assert str(error).splitlines() == [str(error)]


def test_plain_shows_numpy_values_as_plain_numbers_and_cuts_long_or_deep_ones() -> None:
    assert plain(np.float64(1.5)) == "1.5"
    assert plain(np.arange(3)) == "[0, 1, 2]"
    assert plain(tuple(range(12))) == "(0, 1, 2, 3, 4, 5, 6, 7, 8, ...)"
    assert plain([[[[[1]]]]]) == "[[[[[...]]]]]"
    assert plain({"a": 1}) == "{...}" and plain({}) == "{}"
    text = plain("x" * 200, limit=20)
    assert len(text) == 20 and text.endswith("...")


@pytest.mark.parametrize(("value", "message"), [
    ("1", "must be a number, got '1'"),
    (True, "must be a number, got True"),
    (float("nan"), "must be a finite number, got nan"),
    (2 * NUMBER_LIMIT, "must lie within -1e+06..1e+06, got 2000000.0"),
])
def test_check_number_names_what_and_the_value(value: object, message: str) -> None:
    with pytest.raises(SandboxError) as caught:
        check_number(value, "radius")
    assert str(caught.value) == f"radius {message}"


def test_check_number_and_check_numbers_accept_numpy_and_return_floats() -> None:
    assert check_number(np.int32(3), "n") == 3.0 and type(check_number(np.int32(3), "n")) is float
    assert check_numbers(np.array([1, 2, 3]), "eye") == (1.0, 2.0, 3.0)
    assert check_numbers((1.0, 2.0, 3.0, 4.0), "color", counts=(3, 4)) == (1.0, 2.0, 3.0, 4.0)


@pytest.mark.parametrize(("value", "message"), [
    ((1.0, 2.0), "eye must be 3 numbers, got (1.0, 2.0)"),
    ("abc", "eye must be 3 numbers, got 'abc'"),
    (5, "eye must be 3 numbers, got 5"),
    ((1, "2", 3), "eye must be 3 numbers, got (1, '2', 3)"),
    ((1.0, float("inf"), 3.0), "eye must be finite, got (1.0, inf, 3.0)"),
    ((0.0, 0.0, 1e9), "eye must lie within -1e+06..1e+06, got (0.0, 0.0, 1000000000.0)"),
])
def test_check_numbers_refuses_in_one_line(value: object, message: str) -> None:
    with pytest.raises(SandboxError) as caught:
        check_numbers(value, "eye")
    assert str(caught.value) == message


def test_parse_size_text() -> None:
    assert parse_size_text("640x480", "--size") == (640, 480)
    assert parse_size_text("64X48", "--size") == (64, 48)
    for bad in ("640", "0x480", "-1x2", "axb", "20000x10"):
        with pytest.raises(SandboxError, match=r"^--size '.*': expected WIDTHxHEIGHT"):
            parse_size_text(bad, "--size")
