"""Benchmark: the BVH at 1k, 10k, 100k and 1M triangles.

Run: ``uv run python benchmarks/bvh.py [--sizes 1000,10000] [--model terrain|rock] [--rounds R]``;
with Embree: ``uv run --group bench python benchmarks/bvh.py``.

Per model size (a generated model, :mod:`glsandbox.mesh.generate`: no download):

- **build**: :func:`~glsandbox.raytrace.bvh.build_bvh` (binned SAH), wall and
  CPU seconds (the CPU figure is steadier on a shared machine);
- **numpy**: :func:`~glsandbox.raytrace.bvh_traverse.closest_hit`, float64,
  the 800x600 primary rays of a perspective camera looking at the model;
- **brute force**: the numpy engine's per-node test (``TriangleBatch.nearest_many``,
  Möller-Trumbore against every triangle) on a slice of the same rays, scaled
  to all of them (marked ``~``), where it takes under a minute;
- **GLSL**: :class:`~glsandbox.raytrace.gpu_bvh.GpuBVH` (``shaders/common/bvh.glsl``,
  float32, one fragment per pixel making its primary ray as ``shaders/raytrace.glsl``
  does, on the default headless context: llvmpipe here), including the read-back
  of the results (two RGBA32F targets);
- **Embree** (``embreex``): the same rays against the same triangles, closest hit
  (its own BVH build, done at the first query, not counted).

Times are the median of ``--rounds`` (the 1M model: at most 2).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

from glsandbox import meshgen
from glsandbox.geometry import Mesh
from glsandbox.raytrace.bvh import build_bvh, mesh_world_triangles
from glsandbox.raytrace.bvh_traverse import closest_hit
from glsandbox.raytrace.triangle import TriangleBatch
from glsandbox.raytrace.world import camera_rays
from glsandbox.scene import Camera

CAMERAS = {"terrain": Camera(eye=(0.0, 1.2, 2.2)), "rock": Camera(eye=(0.0, 0.8, 3.0))}


def model(kind: str, triangles: int) -> Mesh:
    if kind == "terrain":
        return meshgen.terrain(meshgen.terrain_cells_for(triangles))
    subdivisions = max(0, round(np.log(triangles / 20.0) / np.log(4.0)))  # 20·4^s triangles
    return meshgen.rock(int(subdivisions))


def timed(run: Callable[[], object], rounds: int) -> tuple[float, float, object]:
    """``(median wall s, median CPU s, last result)``."""
    walls, cpus = [], []
    result: object = None
    for _ in range(rounds):
        w, c = time.perf_counter(), time.process_time()
        result = run()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return statistics.median(walls), statistics.median(cpus), result


def embree_closure(a: np.ndarray, b: np.ndarray, c: np.ndarray, eye: np.ndarray,
                   dirs: np.ndarray) -> Callable[[], object] | None:
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        return None
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, np.stack([a, b, c], axis=1).astype(np.float32))
    origins = np.ascontiguousarray(np.broadcast_to(eye, dirs.shape), dtype=np.float32)
    directions = np.ascontiguousarray(dirs, dtype=np.float32)
    return lambda: scene.run(origins, directions, output=1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1000,10000,100000,1000000")
    parser.add_argument("--model", choices=sorted(CAMERAS), default="terrain")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--size", default="800x600")
    parser.add_argument("--no-gpu", action="store_true")
    args = parser.parse_args()
    width, height = (int(x) for x in args.size.split("x"))
    camera = CAMERAS[args.model]
    eye, dirs = camera_rays(camera, width, height)
    rays = dirs.shape[0]
    host = None
    if not args.no_gpu:
        from glsandbox.errors import SandboxError
        from glsandbox.gl.context import open_context

        try:
            host = open_context()
        except SandboxError as exc:
            print(f"GLSL column skipped: {exc}")
    print(f"{args.model} models, {width}x{height} primary rays ({rays:,}); seconds (Mrays/s)")
    print(f"{'triangles':>10} {'build wall':>10} {'build cpu':>9} {'nodes':>8} {'depth':>5} "
          f"{'numpy':>14} {'brute force':>16} {'GLSL':>14} {'Embree':>14} {'hits':>6}")
    for target in (int(s) for s in args.sizes.split(",")):
        mesh = model(args.model, target)
        a, b, c = mesh_world_triangles(mesh)
        rounds = min(args.rounds, 2) if len(a) > 300_000 else args.rounds
        build_wall, build_cpu, bvh = timed(lambda: build_bvh(a, b, c), rounds)
        numpy_wall, _, hits = timed(lambda: closest_hit(bvh, eye, dirs), rounds)

        def rate(seconds: float) -> str:
            return f"{seconds:7.3f} ({rays / seconds / 1e6:4.2f})"

        # Brute force on a slice of about 2e7 ray-triangle pairs, scaled to all rays.
        part = max(64, int(rays * min(1.0, 2e7 / (len(a) * rays))))
        batch = TriangleBatch(a, b, c)
        wall, _, _ = timed(lambda: batch.nearest_many(eye, dirs[:part]), 1)
        brute = ("~" if part < rays else " ") + rate(wall * rays / part)
        glsl = "-"
        if host is not None:
            from glsandbox.raytrace.gpu_bvh import GpuBVH

            gpu = GpuBVH(host.ctx, bvh)
            gpu.trace_camera(camera, 16, 16)  # compile
            wall, _, got = timed(lambda: gpu.trace_camera(camera, width, height, strict=False), rounds)
            overflow = int(np.count_nonzero(got.overflow))
            glsl = rate(wall) + (f" {overflow} cut off" if overflow else "")
            gpu.release()
        embree = "-"
        run = embree_closure(a, b, c, eye, dirs)
        if run is not None:
            run()  # Embree builds its BVH at the first query: not counted
            embree = rate(timed(run, rounds)[0])
        print(f"{len(a):>10,} {build_wall:>10.3f} {build_cpu:>9.3f} {bvh.node_total:>8,} {bvh.depth:>5} "
              f"{rate(numpy_wall):>14} {brute:>16} {glsl:>14} {embree:>14} {hits.hit.mean():>6.1%}")
    if host is not None:
        host.release()


if __name__ == "__main__":
    main()
