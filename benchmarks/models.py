"""Benchmark: the ray tracer on models of about 1k, 10k, 100k and 1M triangles.

Per model and mode, each engine is timed against Embree (``embreex``, Intel's
CPU ray tracer) casting the same rays in the same run, ratio = engine time /
Embree time (the goals, printed in the goal column: the gpu engine at
most 1x, the numpy engine at most 5x):

- the models are generated terrains (:func:`glsandbox.mesh.generate.terrain`: no
  download, the same every run), and the Stanford bunny (56,172 triangles)
  when ``pymeshlab`` is installed (the ``bench`` group: it ships the bunny
  inside its wheel);
- ``primary``: one ray a pixel at 800x600; ``shadow+bounce``: a shadow ray
  to the light at every hit and one reflection bounce (the model reflects
  30%);
- the engines render with their shading, the numpy engine through
  :func:`glsandbox.raytrace.render` (it keeps the Scene's World and BVHs), the
  gpu engine on the bench's EGL context with one tracer per model (its upload
  and BVH kept between frames, as in the window; the first call, a warm-up,
  builds them); Embree only finds hits (no shading), so its time is a lower bound
  for the same work, and builds its own BVH at its first query (the
  warm-up).

The "same picture" column compares hit/miss per pixel with Embree's
primary rays (the model's colour never equals the magenta background). A
pixel that differs is counted "at an edge" when the float64 reference
(:func:`glsandbox.raytrace.bvh_traverse.closest_hit`) itself changes its
answer when the ray turns by a few float32 steps (:data:`EDGE_TURN`): there,
float32 and float64 may rightly disagree. Any other differing pixel is a
wrong hit or a hole.

Beside the gpu engine's rows, a ``gpu wide BVH`` row per model and mode times the gpu
engine's two BVH shapes against each other on the same frames: its binary tree
(baseline) and the same tree collapsed to 4 children a node
(:mod:`glsandbox.raytrace.bvh_wide`, subject; ``GpuTracer(ctx, wide_bvh=True)``), one
tracer each; its last column compares their pictures pixel for pixel (any channel).

Beside the gpu engine's rows, when Mitsuba 3 is installed and its LLVM variant
runs (the ``mitsuba`` group, which needs libLLVM: :mod:`benchmarks._mitsuba`), a
``mitsuba`` row per model and mode: Mitsuba's ``llvm_ad_rgb`` casting exactly
Embree's rays as one Dr.Jit wavefront, against Embree in the same run. Its first
cast (the warm-up) compiles the kernel; the timed casts reuse it. Without it the
rows are left out and a line under the table says why.

A first row times building the BVH of the largest model (the goal: under
2 s for 1M triangles) beside Embree building its own for the same triangles.

Under the table (:func:`summarize`): the build time against its goal, each engine's time exponent from 10k to
1M triangles, ``log(t_1M / t_10k) / log(1M / 10k)`` (the goal: at most
0.25), and how the shadow+bounce ratios compare with the primary ones
(goal: within 2x). Without ``embreex`` the module adds no rows and says so.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from functools import cache
from typing import Any

import numpy as np

from _bunny import bunny_path
from _mitsuba import mitsuba_missing, mitsuba_side
from raytrace import EMBREE_MISSING, MODES, embree_available, embree_side

from glsandbox import Camera, Light, Material, Mesh, Node, Scene, load_model, meshgen
from glsandbox.raytrace import render
from glsandbox.raytrace.bvh import build_bvh, bvh_for_triangles
from glsandbox.raytrace.bvh_traverse import closest_hit
from glsandbox.raytrace.world import build_world, camera_rays

GROUP = "ray tracer on models vs Embree"
#: Triangle counts of the generated terrains (``--quick``: the first two).
SIZES = (1_000, 10_000, 100_000, 1_000_000)
#: The goals as time ratios against Embree.
GOALS = {"gpu": 1.0, "numpy": 5.0}
ENGINE_LABELS = {"gpu": "gpu engine (GLSL float32)", "numpy": "numpy engine (float64)"}
#: The gpu engine's two BVH shapes, timed against each other (``gpu.BVH_WIDE``).
WIDE_LABELS = {False: "gpu engine, binary BVH", True: "gpu engine, 4-wide BVH"}
MITSUBA_NOTE = ("ratio = Mitsuba time / Embree time for the same rays; kernel compiled at the warm-up, "
                "not timed; Dr.Jit on all cores, the CPU column counts its main thread only")
BACKGROUND = (1.0, 0.0, 1.0, 1.0)  # magenta: no shade of the grey model
#: How far a ray is turned to test whether it lies within float32 of an edge:
#: 8 float32 steps at 1 (2^-21 relative), in 8 directions around it.
EDGE_TURN = 8.0 * 2.0 ** -24
#: The goal for building the BVH of 1M triangles, in seconds.
BUILD_GOAL_S = 2.0
#: At most this many differing pixels are examined for the edge count.
EDGE_SAMPLE = 400


@cache
def model_scene(label: str) -> Scene:
    """The scene for one model: the mesh lit by one light, seen from above and in front."""
    if label == "bunny":
        path = bunny_path()
        assert path is not None
        mesh: Mesh = load_model(path, fit=True).mesh
        camera = Camera(eye=(0.0, 0.8, 4.0))
    else:
        mesh = meshgen.terrain(meshgen.terrain_cells_for(int(label)))
        camera = Camera(eye=(0.0, 1.2, 2.2))
    material = Material(color=(0.7, 0.7, 0.7, 1.0), shading="phong", reflectivity=0.3)
    return Scene(f"model {label}", nodes=(Node("model", mesh, material=material),), camera=camera,
                 lights=(Light((1.0, 3.0, 1.5)),), clear_color=BACKGROUND)


def terrain_triangles(size: int) -> int:
    """The triangle count of the terrain built for ``size`` (``2·cells²``)."""
    return 2 * meshgen.terrain_cells_for(size) ** 2


def near_edge(bvh: Any, eye: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Whether each ray's float64 hit/miss changes when it turns by :data:`EDGE_TURN`
    in any of 8 directions around it: a ray that close to a triangle's edge may rightly
    hit in float32 and miss in float64, or the other way."""
    d = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    # Two unit vectors across each ray.
    helper = np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    p = np.cross(d, helper)
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    q = np.cross(d, p)
    hit = closest_hit(bvh, eye, d).hit
    changed = np.zeros(d.shape[0], dtype=bool)
    for angle in np.arange(8) * (math.pi / 4.0):
        turned = d + EDGE_TURN * (math.cos(angle) * p + math.sin(angle) * q)
        changed |= closest_hit(bvh, eye, turned).hit != hit
    return changed


class HitMiss:
    """Embree's primary hits for one model, and the float64 reference for the edge test."""

    def __init__(self, label: str, size: tuple[int, int]) -> None:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        scene = model_scene(label)
        world = build_world(scene, 0, analytic_spheres=False)
        self.bvh = bvh_for_triangles(world.v0, world.v1, world.v2)
        self.eye, self.dirs = camera_rays(scene.camera, *size)
        self.size = size
        embree = rtcore_scene.EmbreeScene()
        TriangleMesh(embree, np.stack([world.v0, world.v1, world.v2], axis=1).astype(np.float32))
        origins = np.ascontiguousarray(np.broadcast_to(self.eye, self.dirs.shape), dtype=np.float32)
        hits = embree.run(origins, np.ascontiguousarray(self.dirs, dtype=np.float32), output=1)
        self.embree_hit = np.asarray(hits["primID"]) >= 0

    def compare(self, image: np.ndarray) -> str:
        """``hit/miss: N of M px differ, K at an edge`` for an engine's picture."""
        background = np.round(np.asarray(BACKGROUND[:3]) * 255.0).astype(np.uint8)
        engine_hit = np.any(np.asarray(image)[..., :3] != background, axis=-1).reshape(-1)
        differ = np.flatnonzero(engine_hit != self.embree_hit)
        if differ.size == 0:
            return f"hit/miss: identical to Embree ({engine_hit.mean():.1%} hit)"
        sample = differ if differ.size <= EDGE_SAMPLE else \
            np.random.default_rng(0).choice(differ, EDGE_SAMPLE, replace=False)
        at_edge = near_edge(self.bvh, self.eye, self.dirs[sample])
        share = f"{int(at_edge.sum())}" if sample.size == differ.size else \
            f"~{round(at_edge.mean() * differ.size):,} (of {sample.size} examined)"
        return f"hit/miss: {differ.size:,} of {engine_hit.size:,} px differ from Embree, {share} at an edge"


def same_pixels(binary: np.ndarray, wide: np.ndarray) -> str:
    """``pixels: identical`` or how many of the two BVHs' pictures differ (any channel)."""
    differ = int(np.count_nonzero(np.any(np.asarray(binary) != np.asarray(wide), axis=-1)))
    total = int(np.asarray(binary).shape[0] * np.asarray(binary).shape[1])
    return "pixels: identical to the binary BVH's" if differ == 0 else f"pixels: {differ:,} of {total:,} differ"


def cases(env: Any) -> list:
    """``glsandbox bench`` cases: per model, mode and engine, the engine against Embree.

    Everything is built on first use, so listing the cases costs nothing."""
    from glsandbox.measure.bench import Case, Side

    if not embree_available():
        env.note(EMBREE_MISSING.replace("ray tracer vs Embree", GROUP).split(";")[0])
        return []
    size: tuple[int, int] = env.size
    labels = [str(n) for n in (SIZES[:2] if env.quick else SIZES)]
    if bunny_path() is not None and not env.quick:
        labels.insert(2, "bunny")
    elif bunny_path() is None:
        env.note(f"{GROUP}: the bunny skipped: pymeshlab not installed (uv run --group bench glsandbox bench)")
    mitsuba_why = mitsuba_missing()
    if mitsuba_why is not None:
        env.note(f"{GROUP}: the Mitsuba rows skipped: {mitsuba_why}")
    references: dict[str, HitMiss] = {}

    def reference(label: str) -> HitMiss:
        if label not in references:
            references[label] = HitMiss(label, size)
        return references[label]

    tracers: dict[tuple[str, bool | None], Any] = {}

    def engine(label: str, mode: str, kind: str, wide: bool | None = None) -> Side:
        def run(_: int) -> np.ndarray:
            scene = model_scene(label)
            if kind == "numpy":
                return render(scene, size, **MODES[mode])
            # One tracer per model, as Embree keeps one scene per case: the context's own
            # tracer keeps only its last few uploads, and five models would evict each other.
            # ``wide``: the BVH's shape (None: the engine's default, gpu.BVH_WIDE).
            if (label, wide) not in tracers:
                from glsandbox.raytrace.gpu import GpuTracer

                tracers[label, wide] = GpuTracer(env.renderer.host.ctx, wide_bvh=wide)
            return tracers[label, wide].render_viewport(scene, size, **MODES[mode])

        label_of = ENGINE_LABELS[kind] if wide is None else WIDE_LABELS[wide]
        return Side(label_of, run)

    def embree(label: str, mode: str) -> Side:
        return embree_side(lambda: model_scene(label), size, mode)

    def hit_miss(label: str) -> Callable[[Any, Any], str]:
        return lambda _rays, image: reference(label).compare(image)

    @cache
    def triangles(label: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        world = build_world(model_scene(label), 0)  # made at the warm-up, not timed after it
        return world.v0, world.v1, world.v2

    def build(label: str) -> Side:
        def run(_: int) -> float:
            return build_bvh(*triangles(label)).build_seconds  # build_bvh: never the cached one

        return Side("build_bvh (binned SAH, numpy, threads on idle CPUs)", run)

    def embree_build(label: str) -> Side:
        def run(_: int) -> None:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh

            scene = rtcore_scene.EmbreeScene()
            TriangleMesh(scene, np.stack(triangles(label), axis=1).astype(np.float32))
            one = np.zeros((1, 3), dtype=np.float32)
            scene.run(one, one + np.float32(1.0), output=1)  # Embree builds at its first query

        return Side("Embree (embreex)", run)

    largest = labels[-1]
    found = [Case(GROUP, f"BVH build, {int(largest):,} tris", embree_build(largest), build(largest), repeat=1,
                  unit="s", note=f"goal: under {BUILD_GOAL_S:g} s for 1M triangles (both sides from the "
                                 "same float64 world triangles, made once)")]
    for label in labels:
        name = "bunny" if label == "bunny" else f"{int(label):,} tris"
        for mode in MODES:
            for kind in ("numpy", "gpu"):
                found.append(Case(GROUP, f"{name}, {mode}, {kind}", embree(label, mode), engine(label, mode, kind),
                                  repeat=1, unit="s", goal=GOALS[kind], compare=hit_miss(label),
                                  note="ratio = engine time / Embree time for the same rays"))
            found.append(Case(GROUP, f"{name}, {mode}, gpu wide BVH", engine(label, mode, "gpu", False),
                              engine(label, mode, "gpu", True), repeat=1, unit="s", compare=same_pixels,
                              note="ratio = 4-wide BVH time / binary BVH time, the gpu engine, the same frames"))
            if mitsuba_why is None:
                found.append(Case(GROUP, f"{name}, {mode}, mitsuba", embree(label, mode),
                                  mitsuba_side(lambda label=label: model_scene(label), size, mode, BACKGROUND),
                                  repeat=1, unit="s", compare=hit_miss(label), note=MITSUBA_NOTE))
    return found


def summarize(results: Sequence[Any]) -> list[str]:
    """Lines under the table: time exponents from 10k to 1M triangles, and the
    shadow+bounce ratios against the primary ones."""
    times: dict[tuple[str, str, str], float] = {}
    ratios: dict[tuple[str, str, str], float] = {}
    for result in results:
        if result.case.group != GROUP or not result.subject_s:
            continue
        if result.case.name.startswith("BVH build"):
            continue
        model, mode, kind = result.case.name.split(", ")
        times[model, mode, kind] = statistics.median(result.subject_s)
        if result.ratio is not None:
            ratios[model, mode, kind] = result.ratio
    lines = []
    for result in results:
        if result.case.group == GROUP and result.case.name.startswith("BVH build") and result.subject_s:
            built = statistics.median(result.subject_s)
            verdict = ("met" if built < BUILD_GOAL_S else "NOT met") if f"{SIZES[-1]:,}" in result.case.name \
                else "not judged: a smaller model"
            lines.append(f"{GROUP}: {result.case.name}: {built:.2f} s "
                         f"(goal: under {BUILD_GOAL_S:g} s for 1M triangles: {verdict})")
    small, large = f"{SIZES[1]:,} tris", f"{SIZES[-1]:,} tris"
    counts = {small: terrain_triangles(SIZES[1]), large: terrain_triangles(SIZES[-1])}
    for mode in MODES:
        for kind in ("numpy", "gpu"):
            if (small, mode, kind) in times and (large, mode, kind) in times:
                exponent = math.log(times[large, mode, kind] / times[small, mode, kind]) / \
                    math.log(counts[large] / counts[small])
                embree = [times.get((m, mode, kind), 0.0) / ratios[m, mode, kind]
                          for m in (small, large) if (m, mode, kind) in ratios]
                embree_exponent = math.log(embree[1] / embree[0]) / math.log(counts[large] / counts[small]) \
                    if len(embree) == 2 else float("nan")
                lines.append(f"{GROUP}: {kind} engine, {mode}: time exponent {exponent:.2f} from {small} to "
                             f"{large} (goal <= 0.25; Embree's in the same rows: {embree_exponent:.2f})")
    for kind in ("numpy", "gpu"):
        pairs = [(model, ratios[model, "shadow+bounce", kind] / ratios[model, "primary", kind])
                 for model, mode, k in ratios if k == kind and mode == "primary"
                 and (model, "shadow+bounce", kind) in ratios]
        if pairs:
            text = ", ".join(f"{model} {factor:.2f}x" for model, factor in pairs)
            lines.append(f"{GROUP}: {kind} engine, shadow+bounce ratio / primary ratio: {text} (goal: within 2x)")
    # The gpu engine against Mitsuba: their two ratios to Embree, each measured side by side with it.
    versus = [f"{model} {mode} {ratios[model, mode, 'gpu'] / ratios[model, mode, 'mitsuba']:.1f}x"
              for model, mode, kind in ratios if kind == "mitsuba" and (model, mode, "gpu") in ratios]
    if versus:
        lines.append(f"{GROUP}: gpu engine time / Mitsuba time (each ratio to Embree in its own rows): "
                     + ", ".join(versus))
    return lines

