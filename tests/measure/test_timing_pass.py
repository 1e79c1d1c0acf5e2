"""A tradeoffs timing pass in a process of its own (glsandbox/measure/timing_pass.py): the child
finds the knobs by name, times every setting asked for over the rounds, reports each timed render
as it goes, and a failing child ends the run with one line."""

from __future__ import annotations

import os

import pytest

from glsandbox.errors import SandboxError
from glsandbox.measure import tradeoffs
from glsandbox.measure.knob import all_knobs
from glsandbox.measure.timing_pass import time_in_process

SIZE = (32, 24)


def _cheap_entries() -> list[tuple[str, str]]:
    """Two settings of the depth_format knob (a plain raster frame each) and its reference."""
    knob = next(k for k in all_knobs() if k.name == "depth_format")
    return [(knob.name, s.label) for s in (*knob.chosen(True)[:2], knob.reference)]


def test_a_pass_in_a_child_times_every_setting_over_the_rounds(gl) -> None:
    entries = _cheap_entries()
    steps: list[int] = []
    times = time_in_process(entries, SIZE, gl.host.backend, True, 5, steps.append)
    assert len(times) == len(entries)
    assert all(len(taken) >= 5 and all(t > 0 for t in taken) for taken in times)
    assert steps == [1] * (5 * len(entries))  # one step per timed render of the rounds, not the repeats


def test_the_processes_timer_hands_each_pass_to_a_child(gl, monkeypatch) -> None:
    """The timer ``run`` uses takes no context: it sends the entries' names to a child per pass."""
    seen: list[int] = []
    real = tradeoffs.time_in_process

    def spy(entries, size, backend, quick, rounds, advance):
        seen.append(os.getpid())
        return real(entries, size, backend, quick, rounds, advance)

    monkeypatch.setattr(tradeoffs, "time_in_process", spy)
    knob = next(k for k in all_knobs() if k.name == "depth_format")
    timer = tradeoffs.processes_timer(SIZE, gl.host.backend, True)
    entries = [(knob, knob.reference)]
    times = timer(entries, 5, lambda n: None)
    assert seen == [os.getpid()] and len(times) == 1 and len(times[0]) >= 5


@pytest.mark.parametrize(("entries", "message"), [
    ([("no_such_knob", "x")], "tradeoffs: a timing pass failed: unknown knob 'no_such_knob'"),
    ([("depth_format", "no such setting")],
     "tradeoffs: a timing pass failed: knob 'depth_format' has no setting 'no such setting'"),
])
def test_a_failing_child_is_one_line(entries, message) -> None:
    with pytest.raises(SandboxError) as caught:
        time_in_process(entries, SIZE, None, True, 5)
    assert str(caught.value) == message
