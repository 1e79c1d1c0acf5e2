"""glsandbox.measure.bench: the extra main-thread CPU column and its goal."""

from __future__ import annotations

import re
import sys
import time

import pytest

from glsandbox.measure.bench import Case, Result, Side, format_table, measure, run_process


def spin(seconds: float) -> None:
    """Busy main-thread CPU for ``seconds``."""
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


def test_measure_records_the_main_threads_cpu_of_each_side() -> None:
    case = Case("g", "busy vs idle", Side("idle", lambda k: time.sleep(0.002)), Side("busy", lambda k: spin(0.002)),
                repeat=2)
    (result,) = measure([case], rounds=2)
    assert len(result.baseline_cpu_s) == len(result.subject_cpu_s) == 2
    # Sleeping takes wall time but no CPU; spinning takes both.
    assert max(result.baseline_cpu_s) < 0.001 <= min(result.subject_cpu_s)
    assert result.extra_cpu_us is not None and result.extra_cpu_us >= 1000


def test_the_table_prints_the_extra_cpu_and_its_goal() -> None:
    case = Case("frame vs raw ModernGL", "phong", Side("raw", print), Side("glsandbox", print), goal=1.05,
                cpu_goal_us=50.0)
    met = Result(case, [0.010], [0.0104], "identical", baseline_cpu_s=[0.001], subject_cpu_s=[0.00103])
    missed = Result(case, [0.010], [0.011], "identical", baseline_cpu_s=[0.001], subject_cpu_s=[0.0012])
    header, _, first, second = format_table([met, missed]).splitlines()
    assert "extra CPU" in header and "CPU goal" in header
    assert "+30 us" in first and "<=50 us met" in first and "<=1.05x met" in first
    assert "+200 us" in second and "<=50 us NOT met" in second and "<=1.05x NOT met" in second
    assert met.to_dict()["extra_cpu_us"] == 30.0 and met.to_dict()["cpu_goal_met"] is True


def test_a_case_without_a_baseline_has_no_cpu_difference() -> None:
    case = Case("g", "alone", None, Side("one", lambda k: None))
    (result,) = measure([case], rounds=1)
    assert result.extra_cpu_us is None
    assert result.to_dict()["extra_cpu_us"] is None


@pytest.mark.slow  # starts processes
def test_a_process_sides_cpu_is_the_processs_own() -> None:
    # The cold-start row's column: the child's CPU (all of it), not the parent's waiting.
    idle = [sys.executable, "-c", "import time; time.sleep(0.1)"]
    busy = [sys.executable, "-c", "import time\nend = time.process_time() + 0.2\nwhile time.process_time() < end: pass"]
    case = Case("startup", "idle vs busy", Side("idle", run_process(idle)), Side("busy", run_process(busy)),
                repeat=1, unit="s")
    (result,) = measure([case], rounds=2)
    assert min(result.subject_cpu_s) >= 0.2 > max(result.baseline_cpu_s)
    assert result.extra_cpu_us is not None and result.extra_cpu_us >= 150_000
    assert re.search(r"  \+0\.[12]\d\d s  ", format_table([result]))  # the column, in seconds


def test_a_quantity_case_records_what_its_sides_return() -> None:
    # A memory row: each call returns its figure (MiB), which is the sample in place of the time.
    calls: list[str] = []

    def side(label: str, figures: list[float]) -> Side:
        return Side(label, lambda k: calls.append(label) or figures[k])

    case = Case("memory", "frame", side("small", [100.0, 120.0, 110.0]), side("big", [300.0, 330.0, 360.0]),
                repeat=1, unit="MiB", goal=3.0)
    (result,) = measure([case], rounds=3)
    assert calls.count("small") == calls.count("big") == 3  # no warm-up call: each one measures anew
    assert result.baseline_s == [100.0, 120.0, 110.0] and sorted(result.subject_s) == [300.0, 330.0, 360.0]
    assert result.ratio == pytest.approx(330.0 / 110.0)
    row = format_table([result]).splitlines()[2]
    assert "110.000 MiB (100.000-120.000)" in row and "330.000 MiB (300.000-360.000)" in row
    assert "3.00x" in row and "<=3.00x met" in row
    assert result.to_dict()["subject_time"] == {"median": 330.0, "min": 300.0, "max": 360.0}


#: A bench whose process side is interrupted: the side's process cleans up on its own SIGINT
#: (a marker file), as a glsandbox command removes its temporary folders.
INTERRUPTED_SIDE = """
import signal, sys
from glsandbox.measure.bench import run_process
signal.signal(signal.SIGINT, signal.default_int_handler)  # a foreground command's (a background job's is ignored)
child = ("import signal, sys, time\\n"
         "def cleaned(*_):\\n"
         "    open(sys.argv[1], 'w').write('cleaned up')\\n"
         "    sys.exit(130)\\n"
         "signal.signal(signal.SIGINT, cleaned)\\n"
         "print('started', flush=True)\\n"
         "time.sleep(60)\\n")
print("running", flush=True)
try:
    run_process([sys.executable, "-c", child, sys.argv[1]])(0)
except KeyboardInterrupt:
    sys.exit(130)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a process is POSIX")
def test_ctrl_c_reaches_a_process_side_which_cleans_up_before_the_bench_ends(tmp_path) -> None:
    """Ctrl-C to the bench alone (not its group): the side's process gets the interrupt too and
    ends on its own (its clean-up runs) instead of being killed with its temporary files left."""
    import signal
    import subprocess

    marker = tmp_path / "cleaned.txt"
    proc = subprocess.Popen([sys.executable, "-c", INTERRUPTED_SIDE, str(marker)], stdout=subprocess.PIPE,
                            text=True, start_new_session=True)
    assert proc.stdout is not None and proc.stdout.readline().strip() == "running"
    time.sleep(1.0)  # the side's child has started its sleep (its own start takes a few ms)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=10) == 130
    assert marker.read_text() == "cleaned up"
