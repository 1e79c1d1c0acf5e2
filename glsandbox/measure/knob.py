"""Accuracy knobs: what ``glsandbox tradeoffs`` measures, and their registry.

A :class:`Knob` is data: the scene it looks at, its :class:`Setting` values,
the reference they are compared with, and what the report says about them.
A setting is a label and a function from a
:class:`~glsandbox.measure.render_context.RenderContext` (the GL renderer and
the frame size) to an RGBA ``uint8`` picture, so a rasterised setting and a
ray-traced reference plug in the same way.

The built-in knobs are the modules of :mod:`glsandbox.measure.knobs`, one
knob each, found the way lessons are: every module of that package not
starting with ``_`` is imported and registers its knob with
:func:`register_knob`. :func:`all_knobs` lists them by ``order``.
"""

from __future__ import annotations

import importlib
import math
import pkgutil
import statistics
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from glsandbox.scene import Scene

if TYPE_CHECKING:
    from glsandbox.measure.render_context import RenderContext

__all__ = ["BUSY_LOAD_PER_CPU", "FRAME_NOISE_MS", "Knob", "KnobResult", "PixelCount", "RUN_DRIFT", "Row", "Setting",
           "WIDE_SPREAD", "all_knobs",
           "lesson_scene", "machine_busy", "median_spread", "register_knob", "run_spread"]


@dataclass(frozen=True)
class PixelCount:
    """An error counted in pixels: ``pixels`` bad ones out of ``of`` that matter
    (for the depth knob: z-fighting pixels out of the shadow's pixels)."""

    pixels: int
    of: int

    @property
    def share(self) -> float:
        """``pixels / of`` (0 when ``of`` is 0)."""
        return self.pixels / self.of if self.of else 0.0


@dataclass(frozen=True)
class Setting:
    """One value of a knob: a label and how to render the knob's scene with it.

    ``count`` (knobs with a ``count_label``) counts the setting's bad pixels,
    the knob's own error measure; it is computed once, outside the timing.
    """

    label: str
    render: Callable[[RenderContext], np.ndarray]
    note: str = ""
    count: Callable[[RenderContext], PixelCount] | None = None


@dataclass(frozen=True)
class Knob:
    """An accuracy knob: settings, the reference they are measured against, and checks.

    ``monotone`` lists setting labels whose error must not grow along the
    list (checked in the report and by the tests); ``quick`` the labels kept
    by ``--quick``; ``unavailable`` returns why the knob cannot be measured
    here (None: it can), and such a knob is listed in the report under "Not
    measured yet". ``count_label`` names an error counted in pixels by
    each setting's ``count`` (e.g. "z-fighting px"), reported before RMSE,
    PSNR and FLIP and plotted instead of FLIP; ``notes`` are printed under
    the knob's table (what the reference models differently, say).
    ``order`` places the knob in the run and the report (the built-in ones
    use 10 to 60; ties keep registration order).
    """

    name: str
    title: str
    scene: str
    settings: tuple[Setting, ...]
    reference: Setting
    reference_note: str
    quick: tuple[str, ...] = ()
    monotone: tuple[str, ...] = ()
    unavailable: Callable[[], str | None] = field(default=lambda: None)
    count_label: str = ""
    count_of: str = ""
    notes: tuple[str, ...] = ()
    order: int = 100

    def chosen(self, quick: bool) -> tuple[Setting, ...]:
        """The settings a run measures: all of them, or with ``quick`` the ``quick`` ones."""
        if not quick or not self.quick:
            return self.settings
        return tuple(s for s in self.settings if s.label in self.quick)


_KNOBS: dict[str, Knob] = {}


def register_knob(knob: Knob) -> Knob:
    """Add (or replace) a knob by its name."""
    _KNOBS[knob.name] = knob
    return knob


def all_knobs() -> list[Knob]:
    """Every knob: the modules of :mod:`glsandbox.measure.knobs` imported, then all by ``order``."""
    from glsandbox.measure import knobs

    for module in pkgutil.iter_modules(knobs.__path__):
        if not module.name.startswith("_"):
            importlib.import_module(f"{knobs.__name__}.{module.name}")
    return sorted(_KNOBS.values(), key=lambda k: k.order)


def lesson_scene(name: str, **values: Any) -> Scene:
    """The scene of lesson ``name`` at the given parameter values (what a knob usually renders)."""
    from glsandbox.lesson import find_lesson

    return find_lesson(name)(**values).scene()


# --- what measuring a knob gives (glsandbox.measure.tradeoffs) --------------------


@dataclass
class Row:
    """The figures of one setting."""

    knob: str
    setting: str
    reference: bool
    times_ms: list[float]
    rmse: float
    psnr: float
    #: Mean FLIP error; None where flip-evaluator is not installed.
    flip: float | None
    image: str = ""
    error_map: str = ""
    count: PixelCount | None = None
    #: The median of each independent pass of timing rounds (:mod:`glsandbox.measure.tradeoffs`).
    pass_medians: list[float] = field(default_factory=list)
    #: Why the machine was too busy for any time to be a figure (:func:`machine_busy`), else None.
    busy: str | None = None

    @property
    def median_ms(self) -> float:
        return statistics.median(self.times_ms)

    @property
    def spread_ms(self) -> tuple[float, float]:
        return min(self.times_ms), max(self.times_ms)

    @property
    def median_spread(self) -> float:
        """How far the median can be trusted: the medians of the odd and the even
        runs apart, as a share of the median of all (:func:`median_spread`)."""
        return median_spread(self.times_ms)

    @property
    def run_spread(self) -> float:
        """How far apart independent passes put the median: ``(max − min) / median`` of the
        pass medians (:func:`run_spread`; inf with fewer than two passes)."""
        return run_spread(self.pass_medians)

    @property
    def stated_spread(self) -> float:
        """The share either side of the median the report states: the passes' whole spread, but
        never less than whole runs move together (:data:`RUN_DRIFT`) nor than a frame's timer
        noise (:data:`FRAME_NOISE_MS`)."""
        middle = self.median_ms
        return max(self.run_spread, RUN_DRIFT, FRAME_NOISE_MS / middle if middle > 0 else 0.0)

    @property
    def trusted(self) -> bool:
        """Whether the passes agree within :data:`WIDE_SPREAD` on a machine that was not too
        busy (:func:`machine_busy`): else the report gives no figure."""
        return self.run_spread <= WIDE_SPREAD and self.busy is None


#: Pass medians further apart than this share of their median: the time is noise, not a figure.
WIDE_SPREAD = 0.2
#: How far whole runs of the command move together, beyond what their own passes show: three
#: quick runs back to back on a 2-CPU machine at a load under 1 put every CPU-bound figure of
#: one run 6-10% above the others' (numpy engine 18.9, 18.6, then 20.2 ms) while each run's
#: passes agreed within 1-4%. Fresh processes do not sample it: it is the machine's state over
#: the run's half minute (other tenants, clocks). A stated spread is never narrower.
RUN_DRIFT = 0.10
#: The least a frame's median moves between runs however steady its passes: the 16-bit depth
#: frame at 128x96 measured 0.23, 0.18 and 0.19 ms in those runs, each run's passes within 0.02.
FRAME_NOISE_MS = 0.05


#: A 1-minute load average above this many runnable threads per CPU: the machine was too busy.
#: The run itself adds up to one thread per CPU (llvmpipe's) and its own, so an idle machine
#: stays under 2 per CPU; above it other work shares the cores with every frame, and passes
#: that agree within one run still disagree with the next run (three quick runs at a load of
#: 12 on 2 CPUs: SSAA 4x timed 36.6 ms ±1%, then 5.8 ms ±3%, then 82 ms).
BUSY_LOAD_PER_CPU = 2.0


def machine_busy(loads: list[float], cpus: int) -> str | None:
    """Why no time measured at these 1-minute load averages (one per pass) on ``cpus`` CPUs is
    a figure, or None: the highest above :data:`BUSY_LOAD_PER_CPU` per CPU."""
    if not loads or max(loads) <= BUSY_LOAD_PER_CPU * cpus:
        return None
    return f"machine busy: load {max(loads):.1f} on {cpus} CPU{'s' if cpus != 1 else ''}"


def run_spread(medians: list[float]) -> float:
    """``(max − min) / median`` of independent passes' medians (inf with fewer than two):
    the run-to-run spread a figure is given with. Two passes timed at different moments
    of one run disagree as two runs of the command do when the machine's load changes."""
    if len(medians) < 2:
        return math.inf
    middle = statistics.median(medians)
    return (max(medians) - min(medians)) / middle if middle > 0 else 0.0


def median_spread(times: list[float]) -> float:
    """``|median(odd runs) − median(even runs)| / median(all)``: two independent
    halves of the runs agreeing on the median is what "stable" means here."""
    if len(times) < 2:
        return math.inf
    whole = statistics.median(times)
    return abs(statistics.median(times[0::2]) - statistics.median(times[1::2])) / whole if whole > 0 else 0.0


@dataclass
class KnobResult:
    """One knob measured: a :class:`Row` per setting, the reference last."""

    knob: Knob
    rows: list[Row]

    def row(self, label: str) -> Row:
        return next(r for r in self.rows if r.setting == label)

    def monotone_ok(self) -> bool | None:
        """Whether errors do not grow along ``knob.monotone`` (None: nothing to check)."""
        labels = [label for label in self.knob.monotone if any(r.setting == label for r in self.rows)]
        if len(labels) < 2:
            return None
        errors = [self.row(label).rmse for label in labels]
        return all(later <= earlier for earlier, later in zip(errors, errors[1:]))
