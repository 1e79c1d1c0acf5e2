"""Benchmark: rays per second of the two ray tracing engines, and Embree, at 800x600.

Run: ``uv run python benchmarks/raytrace.py [--rounds R] [--size WxH]``; with
Embree: ``uv run --with embreex python benchmarks/raytrace.py`` (``embreex``
is optional: without it the Embree column says so and is skipped).

For each scene (lesson scenes, rendered by :func:`glsandbox.raytrace.render`):

- ``primary``: one ray per pixel, no shadow rays, no bounces
  (``shadows=False, max_depth=0``);
- ``shadow+bounce``: primary, a shadow ray per light at every lit hit, and one
  reflection bounce (``max_depth=1``) where the material reflects.

The ray count comes from the numpy engine's :class:`RenderStats` (the gpu
engine casts the same rays); rays/s is that count over the median time of
``--rounds`` renders, the engines measured alternately in one process so
machine noise hits both alike. The gpu time includes uploading the scene and
reading the image back. Embree (``embreex``, Intel's CPU ray tracer) casts the
same primary rays against the same world triangles (spheres as their mesh,
which it needs) with ``scene.run(origins, directions)``: closest hit only, no
shading, so its figure is an upper bound for the same work. Goals (issue 6):
gpu >= 1.0x Embree's primary rate, numpy >= 0.1x.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable

import numpy as np

from glsandbox.app import HeadlessRenderer, parse_size
from glsandbox.lesson import find_lesson
from glsandbox.raytrace import RenderStats, render
from glsandbox.raytrace.world import build_world, camera_rays

SCENES = ("indexed_cube", "phong", "ray_phong", "ray_acceleration")
MODES = {"primary": dict(shadows=False, max_depth=0), "shadow+bounce": dict(shadows=True, max_depth=1)}


def median_seconds(run: Callable[[], object], rounds: int) -> float:
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def embree_primary(scene, size: tuple[int, int]) -> Callable[[], object] | None:
    """A closure casting the scene's primary rays with Embree, or None without ``embreex``."""
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        return None
    world = build_world(scene, analytic_spheres=False)
    triangles = np.stack([world.v0, world.v1, world.v2], axis=1).astype(np.float32)
    embree = rtcore_scene.EmbreeScene()
    TriangleMesh(embree, triangles)
    eye, dirs = camera_rays(scene.viewports[0].camera or scene.camera, *size)
    origins = np.ascontiguousarray(np.broadcast_to(eye, dirs.shape), dtype=np.float32)
    directions = np.ascontiguousarray(dirs, dtype=np.float32)
    return lambda: embree.run(origins, directions, output=1)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--size", default="800x600")
    parser.add_argument("--scenes", default=",".join(SCENES))
    args = parser.parse_args(argv)
    size = parse_size(args.size)
    has_embree = embree_primary(find_lesson("indexed_cube")().scene(), (2, 2)) is not None
    if not has_embree:
        print("embree: skipped (embreex is not installed; run `uv run --with embreex python benchmarks/raytrace.py`)")
    header = f"{'scene':<17} {'mode':<14} {'rays':>10} {'numpy Mrays/s':>14} {'gpu Mrays/s':>12} " \
             f"{'embree Mrays/s':>15} {'gpu/embree':>10} {'numpy/embree':>12}"
    with HeadlessRenderer() as renderer:
        ctx = renderer.host.ctx
        print(f"{size[0]}x{size[1]}, median of {args.rounds} rounds, {renderer.host.renderer}")
        print(header)
        for name in args.scenes.split(","):
            scene = find_lesson(name)(renderer="raster").scene()
            embree = embree_primary(scene, size) if has_embree else None
            for mode, options in MODES.items():
                stats = RenderStats()
                render(scene, size, stats=stats, **options)
                render(scene, size, "gpu", ctx=ctx, **options)  # compile the program variant
                t_numpy = median_seconds(lambda: render(scene, size, **options), args.rounds)
                t_gpu = median_seconds(lambda: render(scene, size, "gpu", ctx=ctx, **options), args.rounds)
                numpy_rate = stats.rays / t_numpy / 1e6
                gpu_rate = stats.rays / t_gpu / 1e6
                cells = [f"{name:<17}", f"{mode:<14}", f"{stats.rays:>10,}", f"{numpy_rate:>14.2f}", f"{gpu_rate:>12.2f}"]
                if embree is not None and mode == "primary":
                    t_embree = median_seconds(embree, args.rounds)
                    embree_rate = stats.primary / t_embree / 1e6
                    cells += [f"{embree_rate:>15.2f}", f"{gpu_rate / embree_rate:>9.2f}x",
                              f"{numpy_rate / embree_rate:>11.3f}x"]
                else:
                    cells += [f"{'-':>15}", f"{'-':>10}", f"{'-':>12}"]
                print(" ".join(cells), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
