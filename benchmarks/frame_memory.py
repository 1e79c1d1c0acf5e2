"""Benchmark: the memory a 1M-triangle ray traced frame adds, the gpu engine against Embree.

The goal: a 1M-triangle frame of the gpu engine takes at most 3x the
memory of Embree's. One row, in a group of its own that ``--only "models vs
Embree"`` also selects: each sample is a fresh child process per side that
builds :mod:`models`' 1,000,000-triangle terrain scene (the loaded model),
renders one frame of it in ``shadow+bounce`` mode at 800x600 (the warm-up:
imports, the EGL context, the compiled program variant, Embree's device),
lets it go (the gpu tracer forgets its upload; freed heap handed back with
``malloc_trim``), and then measures a second, cold frame: how far the peak
resident size rises above the resident size just before it (:mod:`_memory`:
``VmHWM`` reset through ``/proc``; ``ru_maxrss`` where there is no ``/proc``).

What each side's frame is:

- **gpu engine** (subject): :meth:`~glsandbox.raytrace.gpu.GpuTracer.render_viewport`
  with no upload kept: ``build_world`` (glsandbox's float64 triangles), the BVH
  build, the packed records and textures (llvmpipe keeps textures in host
  memory, so they are in the resident size), the draw and the read-back; its
  render target is kept between frames, as in the window.
- **Embree** (baseline): :meth:`raytrace.EmbreeCaster.of_model`: the mesh's own
  vertices (float32) and indices handed to ``embreex``, Embree's BVH built at
  the first query, and the same rays as the time rows cast (primary, a shadow
  ray at every hit, one bounce), hits only, no shading. Not the time rows'
  caster, which first builds glsandbox's float64 World (about 72 bytes a
  triangle more, plus the unrolled float32 triangles: glsandbox's cost, not
  Embree's; the by-hand measure with it was about 357 MiB).

The ratio column is the gpu frame's peak over Embree's (MiB, medians of the
rounds); the extra CPU column is the gpu child's CPU time over Embree's (two
frames each, and the model's build in both). Without ``embreex`` the row is
left out and said so; ``--quick`` leaves it out (a 1M-triangle model).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from raytrace import embree_available

GROUP = "ray tracer on models vs Embree: frame memory"
#: The goal: the gpu engine's 1M-triangle frame at most this many times Embree's memory.
GOAL = 3.0
LABEL = "1000000"
MODE = "shadow+bounce"
MIB = 2.0 ** 20
ENGINE_LABELS = {"embree": "Embree (embreex), from the mesh", "gpu": "gpu engine (GLSL float32)"}
NOTE = ("ratio = peak MiB a cold frame adds over the loaded model, gpu / Embree, fresh process each "
        "(gpu: World, BVH, textures, draw; Embree: its scene and BVH from the mesh, the same rays)")


def frame_peak(engine: str, label: str = LABEL, mode: str = MODE, size: tuple[int, int] = (800, 600)) -> int:
    """In this process (meant to be a fresh one): the bytes one cold ``mode`` frame of the model
    ``label`` adds to the peak resident size, after one frame as a warm-up."""
    import gc

    from _memory import peak_growth, peak_start
    from models import model_scene
    from raytrace import MODES, EmbreeCaster

    from glsandbox.raytrace.gpu import _return_freed_memory

    scene = model_scene(label)
    options = MODES[mode]
    if engine == "gpu":
        from glsandbox.measure.bench import BenchEnv
        from glsandbox.raytrace.gpu import GpuTracer

        tracer = GpuTracer(BenchEnv().renderer.host.ctx)

        def frame() -> None:
            tracer.render_viewport(scene, size, **options)
            tracer.forget_scenes()  # the next frame uploads again: what a new model's frame costs
    elif engine == "embree":
        def frame() -> None:
            EmbreeCaster.of_model(scene, size, options["shadows"], options["max_depth"]).cast()
    else:
        raise ValueError(f"engine: gpu or embree, got {engine!r}")
    frame()  # warm-up: imports, context, program variant, Embree's device
    gc.collect()
    _return_freed_memory()
    start = peak_start()
    frame()
    return peak_growth(start)


def child_line(engine: str, grown: int) -> str:
    """What a child prints last: one JSON object."""
    return json.dumps({"engine": engine, "peak_bytes": grown})


def parse_child(stdout: str, engine: str) -> float:
    """The MiB a child measured, from its last line (:func:`child_line`)."""
    lines = stdout.strip().splitlines()
    if not lines:
        raise ValueError(f"frame memory, {engine}: the child printed nothing")
    found = json.loads(lines[-1])
    if found.get("engine") != engine:
        raise ValueError(f"frame memory: asked for {engine}, the child measured {found.get('engine')!r}")
    return int(found["peak_bytes"]) / MIB


def measure_in_child(engine: str) -> float:
    """:func:`frame_peak` in a fresh Python process, in MiB."""
    folder = str(Path(__file__).resolve().parent)
    code = (f"import sys; sys.path.insert(0, {folder!r}); import frame_memory as m; "
            f"print(m.child_line({engine!r}, m.frame_peak({engine!r})))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()
        raise RuntimeError(f"frame memory, {engine}: the child failed: {tail[-1] if tail else done.returncode}")
    return parse_child(done.stdout, engine)


def cases(env: Any) -> list:
    """One row: the gpu engine's 1M-triangle frame memory against Embree's (nothing runs until measured)."""
    from glsandbox.measure.bench import Case, Side

    if not embree_available():
        env.note(f"{GROUP}: skipped: embreex not installed (uv run --group bench glsandbox bench)")
        return []
    if env.quick:
        env.note(f"{GROUP}: skipped under --quick (a 1M-triangle model)")
        return []
    return [Case(GROUP, f"{int(LABEL):,} tris, {MODE}, gpu",
                 Side(ENGINE_LABELS["embree"], lambda _: measure_in_child("embree")),
                 Side(ENGINE_LABELS["gpu"], lambda _: measure_in_child("gpu")),
                 repeat=1, unit="MiB", goal=GOAL, note=NOTE)]
