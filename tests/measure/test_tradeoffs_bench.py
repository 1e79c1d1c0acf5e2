"""``glsandbox tradeoffs``, ``glsandbox bench`` and ``--set effects=all``.

The two commands' measuring runs are in subprocesses (a second GL context must not be
opened in the test process); their content is checked, never their timings. Their
refusals, made before any context opens, run in this process.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import REPO_ROOT as REPO
from support import run_cli

from glsandbox.frame import LazyRenderer
from glsandbox.lesson import all_lessons
from glsandbox.measure.render_context import downsample
from glsandbox.measure.tradeoffs_report import CSV_COLUMNS
from glsandbox.plan import plan



def _run(*args: str, timeout: int = 240) -> subprocess.CompletedProcess:
    env = {**os.environ, "GLSANDBOX_BACKEND": os.environ.get("GLSANDBOX_BACKEND", "egl")}
    return subprocess.run([sys.executable, "-m", "glsandbox.cli", *args], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout, env=env)


# --- supersampling -------------------------------------------------------------------


def test_downsample_averages_each_block() -> None:
    big = np.zeros((4, 6, 4), dtype=np.uint8)
    big[:2, :2] = 255          # one full block
    big[2:, 4:] = [100, 0, 0, 255]
    big[2, 4] = [104, 0, 0, 255]  # (104 + 3*100) / 4 = 101
    small = downsample(big, 2)
    assert small.shape == (2, 3, 4) and small.dtype == np.uint8
    assert small[0, 0].tolist() == [255, 255, 255, 255]
    assert small[1, 2].tolist() == [101, 0, 0, 255]
    assert small[0, 1].tolist() == [0, 0, 0, 0]
    assert np.array_equal(downsample(big, 1), big)


# --- effects=all ----------------------------------------------------------------------


@pytest.mark.parametrize("cls", all_lessons(), ids=lambda c: c.name)
def test_effects_all_plan_is_a_superset(cls) -> None:
    needed, forced = plan(cls().scene()), plan(cls(effects="all").scene())
    assert forced.buffers.depth >= needed.buffers.depth and forced.buffers.stencil
    assert forced.buffers.depth or not cls().scene().depth_test
    assert forced.buffers.samples == needed.buffers.samples  # MSAA would change the picture
    assert set(needed.programs) <= set(forced.programs)
    assert len(forced.passes) >= len(needed.passes)
    for step in needed.passes:  # every needed pass is there, with at least the same buffers and tests
        twins = [p for p in forced.passes if (p.kind, p.viewport, p.draws) == (step.kind, step.viewport, step.draws)]
        assert twins, step.describe()
        twin = twins[0]
        assert twin.clear_depth >= step.clear_depth and twin.clear_stencil >= step.clear_stencil
        assert twin.depth_test >= step.depth_test
    assert all(p.clear_stencil for p in forced.passes if p.kind == "clear")


@pytest.mark.parametrize("cls", all_lessons(), ids=lambda c: c.name)
def test_effects_all_renders_the_same_picture(gl, cls) -> None:
    for time in (0.0, 0.7):
        needed = gl.render(cls(time=time), (96, 72)).image.copy()
        forced_frame = gl.render(cls(time=time, effects="all"), (96, 72))
        assert forced_frame.plan.buffers.stencil
        assert np.array_equal(needed, forced_frame.image), f"{cls.name} at time {time}"
        # Opaque (tests/gl/test_target.py): alpha 255 everywhere, as the window shows the frame.
        assert (needed[..., 3] == 255).all(), f"{cls.name} at time {time}: alpha below 255"


def test_effects_is_a_parameter_of_every_lesson() -> None:
    proc = run_cli("plan", "indexed_cube", "--set", "effects=all")
    assert proc.returncode == 0, proc.stderr
    assert "stencil 8" in proc.stdout
    proc = run_cli("plan", "indexed_cube", "--set", "effects=some")
    assert proc.returncode == 2 and proc.stderr.startswith("error: --set effects=some: expected one of needed, all")


# --- glsandbox tradeoffs --quick --------------------------------------------------------


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("tradeoffs")
    proc = _run("tradeoffs", "--quick", "--passes", "2", "--out", str(out))  # two: the least, to keep it short
    assert proc.returncode == 0, proc.stderr
    assert "[1/" in proc.stderr and "timing pass 2/2" in proc.stderr and "load average" in proc.stderr
    return out


def _rows(out: Path) -> list[dict[str, str]]:
    with open(out / "tradeoffs.csv", newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.mark.slow
def test_tradeoffs_writes_every_file(quick_report: Path) -> None:
    for name in ("report.md", "tradeoffs.csv", "tradeoffs.png"):
        assert (quick_report / name).is_file(), name
    assert (quick_report / "tradeoffs.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = _rows(quick_report)
    assert tuple(rows[0].keys()) == CSV_COLUMNS
    for row in rows:
        assert (quick_report / row["error_map"]).is_file() and (quick_report / row["image"]).is_file()
        assert int(row["runs"]) >= 5
        assert 0 < float(row["time_min_ms"]) <= float(row["time_median_ms"]) <= float(row["time_max_ms"])


@pytest.mark.slow
def test_tradeoffs_report_has_a_table_per_knob(quick_report: Path) -> None:
    report = (quick_report / "report.md").read_text(encoding="utf-8")
    header = "| setting | time (ms) | runs min-max (ms) | RMSE | PSNR (dB) | FLIP | error map |"
    assert report.count(header) == 4  # the knobs without a pixel count
    assert report.count("| setting | time (ms) | runs min-max (ms) | z-fighting px | share of shadow px | "
                        "RMSE | PSNR (dB) | FLIP | error map |") == 1
    for title in ("## Anti-aliasing (`antialiasing`)", "## Lighting model (`lighting`)",
                  "## Texture filtering (`texture_filter`)"):
        assert title in report
    assert "| SSAA 8x (reference) | " in report
    assert "Load average (1, 5, 15 min) on " in report and " before, " in report
    for row in _rows(quick_report):  # two passes each; a figure or "too noisy", as the passes agree
        assert int(row["passes"]) == 2 and len(row["pass_medians_ms"].split()) == 2
        assert row["trusted"] == str(int(float(row["run_spread"]) <= 0.2 and not row["busy"]))
    assert "Reference: the float64 numpy ray tracer" in report  # lighting's reference
    assert "## Ray tracer engine (`ray_engine`)" in report
    rows = _rows(quick_report)
    knobs = {row["knob"] for row in rows}
    assert knobs == {"antialiasing", "lighting", "ray_engine", "texture_filter", "depth", "shadows_mirror",
                     "shadow_map", "shadow_offset", "shadow_epsilon", "triangle_test", "sphere_test", "depth_format"}
    for knob in knobs:  # one reference per knob, at zero error
        refs = [r for r in rows if r["knob"] == knob and r["reference"] == "1"]
        assert len(refs) == 1 and float(refs[0]["rmse"]) == 0.0 and refs[0]["psnr_db"] == "inf"
        assert float(refs[0]["flip"]) == 0.0


@pytest.mark.slow
def test_tradeoffs_errors_fall_where_they_must(quick_report: Path) -> None:
    rows = {(r["knob"], r["setting"]): r for r in _rows(quick_report)}

    def err(knob: str, setting: str, metric: str = "rmse") -> float:
        return float(rows[(knob, setting)][metric])

    for metric in ("rmse", "flip"):
        chain = [err("antialiasing", s, metric) for s in ("none", "SSAA 2x", "SSAA 4x")]
        assert chain[0] > chain[1] > chain[2] > 0, (metric, chain)  # supersampling error shrinks with factor
        assert err("antialiasing", "MSAA 4x", metric) < err("antialiasing", "none", metric)
        assert err("texture_filter", "mipmapped (trilinear)", metric) < err("texture_filter", "nearest", metric)
    assert err("texture_filter", "anisotropic 16x") < err("texture_filter", "mipmapped (trilinear)")
    assert err("lighting", "per-pixel Phong") < err("lighting", "per-vertex (Gouraud)")
    psnr = [float(rows[("antialiasing", s)]["psnr_db"]) for s in ("none", "SSAA 2x", "SSAA 4x")]
    assert psnr[0] < psnr[1] < psnr[2]
    report = (quick_report / "report.md").read_text(encoding="utf-8")
    assert "DOES NOT HOLD" not in report and report.count("(RMSE): holds") == 3  # + depth_format's


@pytest.mark.slow
def test_depth_knob_counts_z_fighting_pixels(quick_report: Path) -> None:
    # Seen from 90 units (tests/lessons/test_mirror.py pins it): a 24-bit buffer with no polygon offset
    # fights with or without the course's lift, and so does reverse-Z without any lift; each
    # remedy alone (nearer plane, reverse-Z with the lift, polygon offset) has no fighting pixel.
    rows = {r["setting"]: r for r in _rows(quick_report) if r["knob"] == "depth"}
    reference = rows["default: reverse-Z float, lift 0.005, polygon offset"]
    assert reference["reference"] == "1" and reference["count_px"] == "0"
    shadow = int(reference["count_of_px"])
    assert shadow > 50  # the shadow is in the frame
    for label in ("standard 24-bit, lift 0, no offset", "standard 24-bit, lift 0.005, no offset",
                  "reverse-Z float, lift 0, no offset"):
        fighting = int(rows[label]["count_px"])
        assert fighting > 0.15 * shadow, (label, fighting, shadow)
        assert float(rows[label]["count_share"]) == pytest.approx(fighting / int(rows[label]["count_of_px"]))
        assert float(rows[label]["rmse"]) > 0.0
    for label in ("standard 24-bit, lift 0.005, near 0.1", "standard 24-bit, lift 0.005, polygon offset",
                  "reverse-Z float, lift 0.005, no offset"):
        assert rows[label]["count_px"] == "0", label
    uncounted = {"antialiasing", "lighting", "texture_filter", "shadows_mirror"}
    others = [r for r in _rows(quick_report) if r["knob"] in uncounted]
    assert others and all(r["count_px"] == "" for r in others)  # the picture-only knobs count nothing
    assert all(r["count_px"] != "" for r in _rows(quick_report) if r["knob"] not in uncounted and r["reference"] == "0")
    report = (quick_report / "report.md").read_text(encoding="utf-8")
    assert "## Depth precision (`depth`)" in report
    fights = int(rows["standard 24-bit, lift 0, no offset"]["count_px"])
    assert "| standard 24-bit, lift 0, no offset | " in report and f" | {fights} | " in report
    assert "| default: reverse-Z float, lift 0.005, polygon offset (reference) | " in report


@pytest.mark.slow
def test_precision_knobs_in_the_quick_report(quick_report: Path) -> None:
    # What precision costs: each new knob's counts in the report order as the numerics say.
    rows = {(r["knob"], r["setting"]): r for r in _rows(quick_report)}

    def count(knob: str, setting: str) -> int:
        return int(rows[(knob, setting)]["count_px"])

    assert count("triangle_test", "Möller–Trumbore float64, at 0") > 0
    assert count("triangle_test", "Möller–Trumbore float32, at 0") > 0
    assert count("triangle_test", "watertight float64, at 100000") == 0
    assert count("triangle_test", "watertight float64, at 0") == 0
    far = rows[("sphere_test", "geometric, at 1e+08")]
    assert int(far["count_px"]) > 0.2 * int(far["count_of_px"])
    assert count("sphere_test", "stable, at 1e+08") == count("sphere_test", "geometric, at 10000") == 0
    assert float(far["rmse"]) > float(rows[("sphere_test", "stable, at 1e+08")]["rmse"])
    depth = {s: count("depth_format", s) for k, s in rows if k == "depth_format"}
    assert depth["16-bit, near 1 (far/near 1e+03)"] > 0 and depth["24-bit, near 0.01 (far/near 1e+05)"] > 0
    assert depth["reverse-Z float, near 0.01 (far/near 1e+05)"] == 0
    assert count("shadow_epsilon", "no offset, at 1") > count("shadow_epsilon", "error bound, at 100000") == 0
    assert count("shadow_epsilon", "2^-16*|P|, at 100000") > 0
    assert count("ray_engine", "gpu world-space float32, at 1e5") > count("ray_engine", "gpu, at 1e5")
    report = (quick_report / "report.md").read_text(encoding="utf-8")
    for title in ("(`triangle_test`)", "(`sphere_test`)", "(`depth_format`)", "(`shadow_epsilon`)"):
        assert title in report
    assert "| no offset, at 1 | " in report and "| 2^-16*\\|P\\|, at 100000 | " in report  # a '|' kept in its cell


@pytest.mark.slow
def test_shadows_mirror_knob_against_the_ray_tracer(quick_report: Path) -> None:
    rows = {r["setting"]: r for r in _rows(quick_report) if r["knob"] == "shadows_mirror"}
    reference = rows["ray tracer, numpy (float64)"]
    assert reference["reference"] == "1" and float(reference["rmse"]) == 0.0 and reference["psnr_db"] == "inf"
    raster = float(rows["raster: stencil mirror + planar shadow"]["rmse"])
    assert 0.0 < raster < float(rows["raster: opaque glass, planar shadow"]["rmse"])  # the reflection is most of it
    assert float(rows["raster: stencil mirror, no shadow"]["flip"]) > float(
        rows["raster: stencil mirror + planar shadow"]["flip"])  # the planar shadow brings it closer
    assert float(rows["ray tracer, gpu (GLSL, float32)"]["rmse"]) < 0.25 * raster  # float32 only
    report = (quick_report / "report.md").read_text(encoding="utf-8")
    assert "## Planar shadow and stencil mirror vs the ray tracer (`shadows_mirror`)" in report
    assert "| ray tracer, numpy (float64) (reference) | " in report
    assert "The two renderers model different things" in report  # the honest notes


@pytest.mark.slow
def test_tradeoffs_lists_what_is_not_measured_yet(quick_report: Path) -> None:
    from glsandbox.measure.knob import all_knobs

    report = (quick_report / "report.md").read_text(encoding="utf-8")
    measured = {k.name for k in all_knobs()}
    assert "## Not measured yet" not in report  # every knob of the issue is measured now
    assert {"depth", "shadows_mirror"} <= measured


def test_a_knob_that_cannot_run_is_listed_as_not_measured_yet(tmp_path: Path) -> None:
    from glsandbox.measure.tradeoffs_report import write_report

    info = {"renderer": "llvmpipe", "backend": "egl", "size": "128x96", "runs": "5", "quick": "yes"}
    write_report([], info, tmp_path / "report.md", {"embree": "embreex is not installed"})
    report = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "## Not measured yet\n\n- `embree`: embreex is not installed\n" in report


def test_tradeoffs_without_matplotlib_is_one_line(tmp_path: Path, monkeypatch, capsys) -> None:
    from glsandbox.cli import main

    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if not installed: importing it raises ImportError
    out = tmp_path / "tradeoffs"
    assert main(["tradeoffs", "--quick", "--out", str(out)]) == 2
    assert capsys.readouterr().err == ("error: glsandbox tradeoffs needs matplotlib (the 'measure' extra, with "
                                       "flip-evaluator): uv run --extra measure glsandbox tradeoffs\n")
    assert not out.exists()  # refused before anything was written


def test_tradeoffs_without_flip_says_so_in_one_line_and_measures_the_rest(tmp_path: Path, monkeypatch, capsys,
                                                                         gl) -> None:
    """flip-evaluator has no wheel for some systems and Pythons: the FLIP column and error maps
    are left out, RMSE and PSNR and the times are measured, the plot shows RMSE."""
    import csv

    from glsandbox.cli import main
    from glsandbox.measure.extra import FLIP_MISSING

    monkeypatch.setitem(sys.modules, "flip_evaluator", None)  # here, where the pictures are compared
    out = tmp_path / "tradeoffs"
    assert main(["tradeoffs", "--quick", "--knob", "antialiasing", "--passes", "2", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count(FLIP_MISSING) == 1 and "FLIP column" in FLIP_MISSING
    rows = list(csv.DictReader((out / "tradeoffs.csv").open(encoding="utf-8")))
    assert len(rows) >= 3 and all(r["flip"] == "" and r["error_map"] == "" for r in rows)
    assert all(float(r["rmse"]) >= 0 for r in rows) and any(float(r["rmse"]) > 0 for r in rows)
    report = (out / "report.md").read_text(encoding="utf-8")
    table = [line for line in report.splitlines() if line.startswith("| ") and "setting" not in line]
    assert table and all(line.endswith("| - | - |") for line in table)  # FLIP and error map left out
    assert not list((out / "error_maps").glob("*.png")) and (out / "tradeoffs.png").is_file()


def test_the_measure_extra_is_imported_only_by_tradeoffs_at_work() -> None:
    code = ("import sys, glsandbox.cli, glsandbox.measure.tradeoffs, glsandbox.measure.bench, "
            "glsandbox.measure.compare, glsandbox.measure.golden; from glsandbox.measure.knob import all_knobs; "
            "all_knobs(); print(sorted(m for m in ('flip_evaluator', 'matplotlib') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_the_commands_passes_default_is_the_measuring_wings() -> None:
    from glsandbox.cli import build_parser
    from glsandbox.measure.tradeoffs import PASSES

    assert build_parser("tradeoffs").parse_args(["tradeoffs"]).passes == PASSES >= 3


def test_tradeoffs_bad_passes_is_one_line() -> None:
    proc = run_cli("tradeoffs", "--quick", "--passes", "1", "--out", "/nonexistent/x")
    assert proc.returncode == 2
    assert proc.stderr.strip() == "error: --passes 1: a run-to-run spread needs at least 2 passes"


def test_tradeoffs_bad_runs_is_one_line() -> None:
    proc = run_cli("tradeoffs", "--quick", "--runs", "3", "--out", "/nonexistent/x")
    assert proc.returncode == 2 and proc.stderr.strip() == "error: --runs 3: the timing needs at least 5 runs"


# --- glsandbox bench -----------------------------------------------------------------------


@pytest.mark.slow
def test_bench_prints_one_table_and_writes_json(tmp_path: Path) -> None:
    out = tmp_path / "bench.json"
    proc = _run("bench", "--quick", "--only", "clear_and_swap", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("glsandbox bench: 2 cases")
    assert lines[1].split()[:3] == ["benchmark", "baseline", "subject"]
    assert any(line.startswith("frame vs raw ModernGL: clear_and_swap") and "identical" in line for line in lines)
    assert any(line.startswith("on-demand vs effects=all: clear_and_swap") and "identical" in line
               for line in lines)
    assert "embreex" not in proc.stdout  # the ray tracer's cases were not asked for, nor is their note
    data = json.loads(out.read_text(encoding="utf-8"))
    assert {c["group"] for c in data["cases"]} == {"frame vs raw ModernGL", "on-demand vs effects=all"}
    for case in data["cases"]:
        assert case["same_picture"] == "identical" and case["ratio"] > 0
        assert case["baseline_time"]["min"] <= case["baseline_time"]["median"] <= case["baseline_time"]["max"]


def test_bench_unknown_case_is_one_line() -> None:
    proc = run_cli("bench", "--quick", "--only", "no_such_benchmark")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "error: --only no_such_benchmark: no benchmark case matched (see glsandbox bench)"]  # no progress first


# --- the raw-ModernGL baselines (benchmarks/lesson_frames.py) --------------------------------

RAW_BASELINE_LESSONS = ("clear_and_swap", "triangle", "phong", "texture", "transform_order", "mirror", "shadow_map")


def test_every_raw_baseline_is_checked_here() -> None:
    assert tuple(_benchmark_module("lesson_frames.py").RAW_BASELINES) == RAW_BASELINE_LESSONS


@pytest.mark.parametrize("name", RAW_BASELINE_LESSONS)
def test_raw_baseline_draws_the_lessons_picture(gl, name: str) -> None:
    """The bench's "same picture" column, at a small size: the hand-written frame equals
    glsandbox's pixel for pixel at the lesson's defaults, at several moments, and leaves the
    shared context's state as it found it (the bench alternates the two on one context)."""
    from glsandbox.lesson import find_lesson

    def state() -> dict[str, object]:
        # moderngl's Framebuffer.use() sets the depth write mask from the framebuffer (off for a
        # colour-only one) and every frame starts with one, glsandbox's too: that one is not compared.
        return {key: value for key, value in gl.host.raw.state_snapshot().items() if key != "depth_writemask"}

    size = (160, 120)
    module = _benchmark_module("lesson_frames.py")
    raw = module.RAW_BASELINES[name](gl.host.ctx, size)
    lesson = find_lesson(name)(**module.RAW_SETTINGS.get(name, {}))
    for k in (0, 37, 150):
        expected = gl.render(lesson.at(0.01 * k), size).image.copy()
        before = state()
        drawn = np.array(raw.frame(k))
        assert state() == before, f"{name}: the raw frame left GL state changed"
        assert np.array_equal(drawn, expected), f"{name} at time {0.01 * k}"


def test_raw_cube_draws_the_indexed_cube_lessons_picture(gl) -> None:
    """The indexed cube's raw frame (benchmarks/cube_frame.py) equals glsandbox's pixel for pixel
    at several moments, and leaves the shared context's state as it found it."""
    from glsandbox.lesson import find_lesson

    def state() -> dict[str, object]:
        return {key: value for key, value in gl.host.raw.state_snapshot().items() if key != "depth_writemask"}

    size = (160, 120)
    raw = _benchmark_module("cube_frame.py").RawCube(gl.host.ctx, size)
    lesson = find_lesson("indexed_cube")()
    for t in (0.3, 0.67, 1.8):
        expected = gl.render(lesson.at(t), size).image.copy()
        before = state()
        drawn = np.array(raw.frame(t))
        assert state() == before, "the raw cube frame left GL state changed"
        assert np.array_equal(drawn, expected), f"indexed_cube at time {t}"


# --- the ray tracer's benchmark cases (benchmarks/raytrace.py) ------------------------------


def _benchmark_module(file_name: str):
    from glsandbox.measure.bench import benchmarks_dir, load_modules

    return next(m for m in load_modules(benchmarks_dir()) if m.__file__.endswith(file_name))


def _raytrace_module():
    return _benchmark_module("raytrace.py")


def test_raytrace_cases_without_embree_say_so(gl, monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv, measure

    module = _raytrace_module()
    monkeypatch.setattr(module, "embree_available", lambda: False)
    env = BenchEnv(quick=True, size=(48, 36))
    env.gl = LazyRenderer(renderer=gl)  # the session's context: never a second one in this process
    found = module.cases(env)
    assert env.notes == [module.EMBREE_MISSING] and "skipped: embreex not installed" in env.notes[0]
    assert [c.group for c in found] == ["ray tracer engines"] * 2
    assert [c.name for c in found] == ["phong, primary", "phong, shadow+bounce"]
    results = measure(found, rounds=1)
    for result in results:
        assert result.ratio is not None and result.ratio > 0
        assert result.same.endswith("rays each")
    assert results[0].same == f"{48 * 36:,} rays each"  # primary: one ray per pixel


def test_embree_casts_the_engines_rays() -> None:
    pytest.importorskip("embreex")
    module = _raytrace_module()
    from glsandbox.lesson import find_lesson
    from glsandbox.raytrace import RenderStats, render

    scene = find_lesson("ray_phong")(renderer="raster").scene()
    for mode, options in module.MODES.items():
        stats = RenderStats()
        render(scene, (40, 30), stats=stats, **options)
        cast = module.EmbreeCaster(scene, (40, 30), options["shadows"], options["max_depth"]).cast()
        assert abs(cast - stats.rays) <= 0.02 * stats.rays, mode  # spheres are meshes for Embree


# --- the ray tracer on models (benchmarks/models.py) -----------------------------------------


def _models_module():
    return _benchmark_module("models.py")


def test_model_cases_without_embree_say_so(monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv

    module = _models_module()
    monkeypatch.setattr(module, "embree_available", lambda: False)
    env = BenchEnv(quick=True)
    assert module.cases(env) == []
    assert len(env.notes) == 1 and "skipped: embreex not installed" in env.notes[0]


def test_model_cases_cover_every_size_mode_and_engine(monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv

    module = _models_module()
    monkeypatch.setattr(module, "embree_available", lambda: True)
    monkeypatch.setattr(module, "bunny_path", lambda: None)
    monkeypatch.setattr(module, "mitsuba_missing", lambda: "mitsuba not installed")
    found = module.cases(BenchEnv())  # nothing is built until a case runs
    assert found[0].name == "BVH build, 1,000,000 tris"
    assert [c.name for c in found[1:7]] == ["1,000 tris, primary, numpy", "1,000 tris, primary, gpu",
                                           "1,000 tris, primary, gpu wide BVH", "1,000 tris, shadow+bounce, numpy",
                                           "1,000 tris, shadow+bounce, gpu", "1,000 tris, shadow+bounce, gpu wide BVH"]
    assert len(found) == 1 + 6 * len(module.SIZES)
    assert {c.goal for c in found[1:] if "wide" not in c.name} == {1.0, 5.0}  # the start-up and frame-time goals
    # The gpu engine's two BVH shapes timed against each other, their pictures compared.
    wide = [c for c in found if c.name.endswith("gpu wide BVH")]
    assert len(wide) == 2 * len(module.SIZES) and {c.goal for c in wide} == {None}
    assert {(c.baseline.label, c.subject.label) for c in wide} == {("gpu engine, binary BVH", "gpu engine, 4-wide BVH")}
    image = np.zeros((3, 4, 4), dtype=np.uint8)
    assert wide[0].compare(image, image.copy()) == "pixels: identical to the binary BVH's"
    other = image.copy()
    other[1, 2, 0] = 9
    assert wide[0].compare(image, other) == "pixels: 1 of 12 differ"


def test_model_cases_without_mitsuba_leave_its_rows_out_and_say_why(monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv

    module = _models_module()
    monkeypatch.setattr(module, "embree_available", lambda: True)
    monkeypatch.setattr(module, "bunny_path", lambda: None)
    monkeypatch.setitem(sys.modules, "mitsuba", None)  # `import mitsuba` fails, installed or not
    why = module.mitsuba_missing.__wrapped__()  # not the cached answer for this machine
    assert why == "mitsuba not installed (uv run --group bench --group mitsuba glsandbox bench)"
    monkeypatch.setattr(module, "mitsuba_missing", lambda: why)
    env = BenchEnv(quick=True)
    found = module.cases(env)
    assert not [c for c in found if "mitsuba" in c.name]
    assert f"{module.GROUP}: the Mitsuba rows skipped: {why}" in env.notes


def test_model_cases_with_mitsuba_add_a_row_beside_each_gpu_row(monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv

    module = _models_module()
    monkeypatch.setattr(module, "embree_available", lambda: True)
    monkeypatch.setattr(module, "bunny_path", lambda: None)
    monkeypatch.setattr(module, "mitsuba_missing", lambda: None)
    found = module.cases(BenchEnv())  # nothing is built (nor mitsuba imported) until a case runs
    assert [c.name for c in found[1:9]] == [
        "1,000 tris, primary, numpy", "1,000 tris, primary, gpu", "1,000 tris, primary, gpu wide BVH",
        "1,000 tris, primary, mitsuba", "1,000 tris, shadow+bounce, numpy", "1,000 tris, shadow+bounce, gpu",
        "1,000 tris, shadow+bounce, gpu wide BVH", "1,000 tris, shadow+bounce, mitsuba"]
    mitsuba = [c for c in found if c.name.endswith("mitsuba")]
    assert len(mitsuba) == 2 * len(module.SIZES)
    assert {c.baseline.label for c in mitsuba} == {"Embree (embreex)"}
    assert {c.subject.label for c in mitsuba} == {"Mitsuba 3 (llvm_ad_rgb)"}
    assert {c.goal for c in mitsuba} == {None} and "compiled at the warm-up, not timed" in mitsuba[0].note


def test_model_summary_gives_the_time_exponent_and_the_mode_ratio() -> None:
    """The exponent is fitted from the 10k and 1M rows' medians; the mode ratio is
    (shadow+bounce engine/Embree) over (primary engine/Embree), per model."""
    from glsandbox.measure.bench import Case, Result, Side

    module = _models_module()
    small, large = (module.terrain_triangles(n) for n in module.SIZES[1::2])
    growth = (large / small) ** 0.25  # time x growth for 100x the triangles: exponent 0.25

    def result(name: str, subject: float, embree: float) -> Result:
        side = Side("x", lambda k: None)
        return Result(Case(module.GROUP, name, side, side), [embree, embree * 2, embree / 2],
                      [subject, subject * 3, subject / 3])

    results = [result("10,000 tris, primary, gpu", 1.0, 0.5),
               result("1,000,000 tris, primary, gpu", growth, 0.5),
               result("10,000 tris, shadow+bounce, gpu", 3.0, 0.5)]
    lines = module.summarize(results)
    assert lines[0].startswith(f"{module.GROUP}: gpu engine, primary: time exponent 0.25 from 10,000 tris")
    assert "Embree's in the same rows: 0.00" in lines[0]
    assert lines[1] == f"{module.GROUP}: gpu engine, shadow+bounce ratio / primary ratio: 10,000 tris 3.00x (goal: within 2x)"
    assert len(lines) == 2  # numpy rows were not measured: no lines for them


def test_model_summary_puts_the_gpu_engine_beside_mitsuba() -> None:
    """gpu / Mitsuba is the ratio of their two ratios to Embree, each measured beside Embree."""
    from glsandbox.measure.bench import Case, Result, Side

    module = _models_module()
    side = Side("x", lambda k: None)
    results = [Result(Case(module.GROUP, f"bunny, primary, {kind}", side, side), [1.0, 1.0, 1.0], [t, t, t])
               for kind, t in (("gpu", 2.4), ("mitsuba", 0.2))]
    assert module.summarize(results) == [
        f"{module.GROUP}: gpu engine time / Mitsuba time (each ratio to Embree in its own rows): bunny primary 12.0x"]


def test_near_edge_tells_grazing_rays_from_clear_ones() -> None:
    from glsandbox.raytrace.bvh import bvh_for_triangles

    module = _models_module()
    bvh = bvh_for_triangles([[-1.0, -1.0, -5.0]], [[1.0, -1.0, -5.0]], [[0.0, 1.0, -5.0]])
    dirs = np.array([[0.0, 0.0, -5.0],   # the middle: a hit whichever way it turns
                     [0.3, -1.0, -5.0],  # exactly on the bottom edge
                     [0.5, 0.0, -5.0],   # exactly on the right edge
                     [0.3, -1.0 - 1e-4, -5.0],  # below the edge by far more than float32
                     [4.0, 4.0, -5.0]])  # a clear miss
    assert module.near_edge(bvh, np.zeros(3), dirs).tolist() == [False, True, True, False, False]


def test_hit_miss_against_embree_counts_the_differing_pixels() -> None:
    pytest.importorskip("embreex")  # the bench group, not the dev group
    from glsandbox.raytrace import render

    module = _models_module()
    size = (40, 30)
    reference = module.HitMiss("1000", size)
    image = render(module.model_scene("1000"), size, max_depth=0, shadows=False)
    assert reference.compare(image).startswith("hit/miss: identical to Embree")
    hit = reference.embree_hit.reshape(size[1], size[0])
    # A hit pixel whose 8 neighbours also hit: far from any silhouette edge.
    inner = hit[1:-1, 1:-1] & hit[:-2, 1:-1] & hit[2:, 1:-1] & hit[1:-1, :-2] & hit[1:-1, 2:]
    row, col = (int(v) + 1 for v in np.argwhere(inner)[0])
    holed = image.copy()
    holed[row, col, :3] = np.round(np.asarray(module.BACKGROUND[:3]) * 255)
    assert reference.compare(holed) == f"hit/miss: 1 of {40 * 30:,} px differ from Embree, 0 at an edge"


# --- Mitsuba 3 beside the model rows (benchmarks/_mitsuba.py; the optional mitsuba group) ------------


def _mitsuba_or_skip():
    """The models module, when Mitsuba's LLVM variant runs here and embreex is installed."""
    pytest.importorskip("embreex")  # the bench group
    pytest.importorskip("mitsuba")  # the mitsuba group: never in the dev group
    module = _models_module()
    why = module.mitsuba_missing()
    if why is not None:
        pytest.skip(why)
    return module


def test_mitsuba_casts_embrees_rays_and_compiles_once() -> None:
    module = _mitsuba_or_skip()
    import drjit as dr
    from _mitsuba import MitsubaCaster
    from raytrace import EmbreeCaster

    size = (40, 30)
    reference = module.HitMiss("1000", size)
    for mode, options in module.MODES.items():
        scene = module.model_scene("1000")
        caster = MitsubaCaster(scene, size, options["shadows"], options["max_depth"])
        caster.cast()  # traces and compiles the kernel
        with dr.scoped_set_flag(dr.JitFlag.KernelHistory):
            caster.cast()
            history = dr.kernel_history([dr.KernelType.JIT])
        assert history and all(run["cache_hit"] for run in history), mode  # the timed casts compile nothing
        assert caster.ray_count() == EmbreeCaster(scene, size, options["shadows"], options["max_depth"]).cast()
        assert reference.compare(caster.image(module.BACKGROUND)).startswith("hit/miss: identical to Embree")


def test_mitsuba_row_times_a_positive_ratio_to_embree() -> None:
    module = _mitsuba_or_skip()
    from _mitsuba import mitsuba_side
    from raytrace import embree_side

    from glsandbox.measure.bench import Case, measure

    size = (40, 30)
    case = Case(module.GROUP, "1,000 tris, shadow+bounce, mitsuba",
                embree_side(lambda: module.model_scene("1000"), size, "shadow+bounce"),
                mitsuba_side(lambda: module.model_scene("1000"), size, "shadow+bounce", module.BACKGROUND),
                repeat=1, unit="s", compare=lambda _rays, image: module.HitMiss("1000", size).compare(image))
    (result,) = measure([case], rounds=2)
    assert min(result.subject_s) > 0 and result.ratio is not None and result.ratio > 0
    assert result.same.startswith("hit/miss: identical to Embree")


@pytest.mark.slow
def test_mitsuba_without_libllvm_says_what_it_needs() -> None:
    _mitsuba_or_skip()
    code = "import sys; sys.path.insert(0, 'benchmarks'); from _mitsuba import mitsuba_missing; print(mitsuba_missing())"
    env = {**os.environ, "DRJIT_LIBLLVM_PATH": "/nonexistent/libLLVM.so"}
    proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr
    line = proc.stdout.strip()
    assert line.startswith("mitsuba's llvm_ad_rgb cannot run: ") and "libLLVM" in line


# --- a 1M-triangle frame's memory (benchmarks/frame_memory.py, benchmarks/_memory.py) ---------------


def test_frame_memory_row_compares_the_gpu_engine_with_embree_in_mib(monkeypatch) -> None:
    from glsandbox.measure.bench import BenchEnv

    module = _benchmark_module("frame_memory.py")
    monkeypatch.setattr(module, "embree_available", lambda: True)
    (case,) = module.cases(BenchEnv())  # nothing runs until measured
    assert case.name == "1,000,000 tris, shadow+bounce, gpu" and case.unit == "MiB" and case.goal == 3.0
    assert case.baseline.label.startswith("Embree") and case.subject.label.startswith("gpu engine")
    assert "models vs Embree" in case.group  # --only "models vs Embree" selects it with the model rows
    quick = BenchEnv(quick=True)
    assert module.cases(quick) == [] and "skipped under --quick" in quick.notes[0]
    monkeypatch.setattr(module, "embree_available", lambda: False)
    missing = BenchEnv()
    assert module.cases(missing) == [] and "skipped: embreex not installed" in missing.notes[0]


def test_frame_memory_reads_the_childs_last_line() -> None:
    module = _benchmark_module("frame_memory.py")
    out = "a warning from the driver\n" + module.child_line("gpu", 3 * 2 ** 20 + 2 ** 19) + "\n"
    assert module.parse_child(out, "gpu") == 3.5
    with pytest.raises(ValueError, match="asked for embree"):
        module.parse_child(out, "embree")
    with pytest.raises(ValueError, match="printed nothing"):
        module.parse_child("\n", "gpu")


@pytest.mark.slow  # a fresh process: its peak before the step is small on every platform
def test_peak_growth_sees_an_allocation_in_a_fresh_process() -> None:
    code = ("import sys; sys.path.insert(0, 'benchmarks'); import numpy as np; from _memory import peak_growth, "
            "peak_start\nstart = peak_start(); a = np.ones(96 * 2 ** 20 // 8); del a\nprint(peak_growth(start))")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert 90 * 2 ** 20 <= int(done.stdout) <= 200 * 2 ** 20  # 96 MiB touched, then freed: still the peak


def test_embree_of_model_casts_the_time_rows_rays() -> None:
    pytest.importorskip("embreex")  # the bench group
    models, module = _models_module(), _raytrace_module()
    size = (40, 30)
    scene = models.model_scene("1000")
    for mode, options in module.MODES.items():
        full = module.EmbreeCaster(scene, size, options["shadows"], options["max_depth"])
        lean = module.EmbreeCaster.of_model(scene, size, options["shadows"], options["max_depth"])
        assert lean.cast() == full.cast() > size[0] * size[1] * (mode != "primary"), mode
        ours, theirs = (c.scene.run(c.origins, c.directions, output=1)["primID"] for c in (lean, full))
        assert np.array_equal(ours, theirs), mode  # the same triangles, numbered alike


# --- loading model files (benchmarks/model_load.py) ---------------------------------------------


def test_model_load_memory_line_puts_trimeshs_parse_beside_glsandboxs_part(monkeypatch) -> None:
    """The memory line under the table: the peak against the goal, trimesh's own load of the file alone,
    and, traced, trimesh's parse and glsandbox's own part after it, each judged against the goal."""
    from glsandbox.measure.bench import Case, Result, Side

    module = _benchmark_module("model_load.py")
    figures = {"triangles": 56_172, "peak": 626.4, "trimesh": 610.0, "trimesh_traced": 572.2, "parse": 572.4,
               "own": 157.3, "held": 36.0, "arrays": 36.0}
    monkeypatch.setattr(module, "peak_bytes_per_triangle", lambda path: figures)
    side = Side("x", lambda k: None)
    results = [Result(Case(module.GROUP, "load + first frame, bunny", side, side), [0.3], [0.4])]
    assert module.summarize(results) == [
        f"{module.GROUP}: peak memory of load + first frame, bunny (56,172 triangles): 626 bytes per triangle "
        "(goal: at most 250: NOT met); trimesh's own load_scene of the file alone: 610 (572 traced); numpy and "
        "Python allocations: trimesh's parse 572 at its peak, glsandbox's own part after it 157 at its peak (met), "
        "36 held after; the loaded model's arrays: 36"]


@pytest.mark.slow
def test_model_load_memory_is_measured_in_fresh_processes(gl, tmp_path: Path) -> None:
    """A small OBJ measured as the bench does: trimesh alone and glsandbox in their own processes; the
    OBJ's text parse is trimesh's (glsandbox's parse peak is trimesh's own, within a few percent)."""
    import trimesh

    module = _benchmark_module("model_load.py")
    path = tmp_path / "sphere.obj"
    trimesh.creation.icosphere(4).export(path, include_normals=False)
    m = module.peak_bytes_per_triangle(path)
    assert m["triangles"] == 5_120
    # Resident growth can be zero for a model this small (memory the warm-up freed is reused); the
    # traced figures cannot.
    assert m["peak"] >= 0 and m["trimesh"] >= 0 and m["arrays"] > 0 and m["held"] >= m["arrays"]
    assert m["trimesh_traced"] <= m["parse"] <= 1.05 * m["trimesh_traced"]
    assert m["own"] > m["held"]
