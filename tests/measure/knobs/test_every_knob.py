"""Every knob module of ``glsandbox tradeoffs`` (glsandbox/measure/knobs/), one parametrised test
each: it registers one well-formed knob, and measured at ``--quick``'s size (one timing round) its
reference is exact, every picture has the frame's size and errors do not grow along its order.

A knob module is one entry (a :class:`~glsandbox.measure.knob.Knob` and the scene it renders),
so this file is their test file: ``tests/test_suite.py`` counts a module of the folder as
tested when it is listed in :data:`MODULES` (or has its own ``test_<knob>.py`` here as well,
for what only that knob measures), and the first test fails when a new module is not listed."""

from __future__ import annotations

import importlib
import pkgutil

import pytest

from glsandbox.files import load_png
from glsandbox.frame import LazyRenderer
from glsandbox.measure import knobs
from glsandbox.measure.knob import all_knobs
from glsandbox.measure.render_context import RenderContext
from glsandbox.measure.tradeoffs import QUICK_SIZE, measure_knob

#: Every knob module of glsandbox/measure/knobs/ (``_far``, shared scenes, has test_far.py).
MODULES = ("antialiasing", "depth", "depth_format", "lighting", "ray_engine", "shadow_epsilon", "shadow_map",
           "shadow_offset", "shadows_mirror", "sphere_test", "texture_filter", "triangle_test")
#: The size of ``tradeoffs --quick``: the orders a knob claims hold from there up.
SIZE = QUICK_SIZE


def test_every_knob_module_is_listed() -> None:
    found = sorted(m.name for m in pkgutil.iter_modules(knobs.__path__) if not m.name.startswith("_"))
    assert sorted(MODULES) == found, "list the knob module in MODULES (and give it its checks)"


@pytest.mark.parametrize("name", MODULES)
def test_the_module_registers_one_well_formed_knob(name: str) -> None:
    knob = importlib.import_module(f"glsandbox.measure.knobs.{name}").KNOB
    assert [k for k in all_knobs() if k.name == knob.name] == [knob]
    labels = [s.label for s in knob.settings]
    assert len(set(labels)) == len(labels) >= 2 and knob.reference.label not in labels
    assert set(knob.quick) <= set(labels) and set(knob.monotone) <= set(labels)
    assert knob.title and knob.scene and knob.reference_note
    counted = [s.count is not None for s in knob.settings]
    assert all(counted) if knob.count_label else not any(counted), "a counted knob counts every setting"


@pytest.mark.parametrize("name", MODULES)
def test_measured_quick_the_reference_is_exact_and_errors_fall_along_the_order(gl, tmp_path, name: str) -> None:
    knob = importlib.import_module(f"glsandbox.measure.knobs.{name}").KNOB
    if knob.unavailable():
        pytest.skip(f"{name}: {knob.unavailable()}")
    context = RenderContext(SIZE)
    context.gl = LazyRenderer(renderer=gl)  # the session's renderer: never a second context here
    result = measure_knob(knob, context, tmp_path, quick=True, runs=1, passes=1, flip=False)
    assert [r.setting for r in result.rows] == [s.label for s in knob.chosen(True)] + [knob.reference.label]
    reference = result.rows[-1]
    assert reference.reference and reference.rmse == 0.0
    for row in result.rows:
        assert load_png(tmp_path / row.image).shape[:2] == (SIZE[1], SIZE[0]), row.setting
        assert (row.count is not None) == bool(knob.count_label) or row.reference
    assert result.monotone_ok() is not False, [(r.setting, r.rmse) for r in result.rows]
