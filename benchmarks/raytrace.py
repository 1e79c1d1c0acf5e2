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
machine noise hits both alike. Two gpu figures: ``cold`` forgets the
uploaded scene before each render, so its time includes building the World,
packing and uploading it, drawing and reading the image back; ``warm`` renders
the same scene again (what the interactive tracer does every frame): the
upload is kept, so it is drawing plus readback (and setting uniforms). Both
use an already compiled program variant (compiled once per variant and
context). The numpy time includes building the World. Embree (``embreex``, Intel's CPU ray tracer) casts the
same primary rays against the same world triangles (spheres as their mesh,
which it needs) with ``scene.run(origins, directions)``: closest hit only, no
shading, so its figure is an upper bound for the same work. Goals:
gpu >= 1.0x Embree's primary rate, numpy >= 0.1x.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable

import numpy as np

from glsandbox.cli import parse_size
from glsandbox.frame import HeadlessRenderer
from glsandbox.lesson import find_lesson
from glsandbox.raytrace import RenderStats, render
from glsandbox.raytrace.constants import SIMPLE_OFFSET
from glsandbox.raytrace.gpu import gpu_tracer
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


# --- glsandbox bench: the ray tracer's engines against Embree, one table ------------

#: The scenes ``glsandbox bench`` traces (``--quick``: the first only).
BENCH_SCENES = ("phong", "ray_phong")
#: The goals as time ratios against Embree: gpu >= 1.0x Embree's ray rate, numpy >= 0.1x.
GOALS = {"gpu": 1.0, "numpy": 10.0}
EMBREE_MISSING = ("ray tracer vs Embree: skipped: embreex not installed "
                  "(uv run --group bench glsandbox bench); rows show the gpu engine against the numpy engine")


def embree_available() -> bool:
    """Whether ``embreex`` (Embree's Python binding) can be imported."""
    try:
        from embreex import rtcore_scene  # noqa: F401
        from embreex.mesh_construction import TriangleMesh  # noqa: F401
    except ImportError:
        return False
    return True


class EmbreeCaster:
    """Embree casting the rays the engines cast for one scene: primary rays,
    a shadow ray per light at every lit hit (``OCCLUDED`` queries, the
    light's lamp left out as the engines do), and reflection bounces up to
    ``max_depth`` where a material reflects. Closest hit and occlusion
    only, no shading: an upper bound for the same ray work. Spheres are
    their triangle mesh (Embree needs triangles)."""

    def __init__(self, scene: object, size: tuple[int, int], shadows: bool, max_depth: int) -> None:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        world = build_world(scene, analytic_spheres=False)
        triangles = np.empty((world.v0.shape[0], 3, 3), dtype=np.float32)  # no float64 copy on the way
        for corner, v in enumerate((world.v0, world.v1, world.v2)):
            triangles[:, corner] = v
        self.scene = rtcore_scene.EmbreeScene()
        TriangleMesh(self.scene, triangles)
        self.shadow_scenes = []  # one per light, without that light's lamp
        for index in range(len(world.light_positions) if shadows else 0):
            keep = np.array([not world.nodes[k].lamp_of >> index & 1 for k in world.tri_node], dtype=bool)
            if keep.all():  # no lamp: the shadow rays query the same scene
                self.shadow_scenes.append(self.scene)
                continue
            occluders = rtcore_scene.EmbreeScene()
            if keep.any():
                TriangleMesh(occluders, np.ascontiguousarray(triangles[keep]))
            self.shadow_scenes.append(occluders if keep.any() else None)
        self.lights = world.light_positions.astype(np.float32)
        self.tri_node = world.tri_node
        self.lit = np.array([n.lit for n in world.nodes], dtype=bool)
        self.reflectivity = np.array([n.reflectivity for n in world.nodes])
        self.max_depth = max_depth
        self._rays(scene, size)

    def _rays(self, scene: object, size: tuple[int, int]) -> None:
        eye, dirs = camera_rays(scene.viewports[0].camera or scene.camera, *size)
        self.origins = np.ascontiguousarray(np.broadcast_to(eye, dirs.shape), dtype=np.float32)
        self.directions = np.ascontiguousarray(dirs, dtype=np.float32)

    @classmethod
    def of_model(cls, scene: object, size: tuple[int, int], shadows: bool, max_depth: int) -> EmbreeCaster:
        """The same rays for a scene of one lit mesh node and no lamp (``models.py``'s scenes), Embree
        given the mesh's own vertices and indices as a renderer built on it would take them: no
        World (glsandbox's float64 arrays a triangle), and the shadow rays query the same scene."""
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        from glsandbox.transforms import transform_points

        (node,) = scene.nodes
        assert node.mesh.mode == "triangles" and node.material.lit, "one lit triangle mesh"
        self = cls.__new__(cls)
        self.scene = rtcore_scene.EmbreeScene()
        vertices = transform_points(np.asarray(node.model, dtype=np.float64), np.asarray(node.mesh.positions))
        indices = np.asarray(node.mesh.indices).reshape(-1, 3)
        TriangleMesh(self.scene, vertices.astype(np.float32), indices)
        self.shadow_scenes = [self.scene] * (len(scene.lights) if shadows else 0)
        self.lights = np.array([light.position for light in scene.lights], dtype=np.float32).reshape(-1, 3)
        self.tri_node = np.broadcast_to(np.intp(0), (indices.shape[0],))  # every triangle is node 0's
        self.lit = np.array([True])
        self.reflectivity = np.array([node.material.reflectivity])
        self.max_depth = max_depth
        self._rays(scene, size)
        return self

    def cast(self) -> int:
        """Cast every ray once; returns how many were cast."""
        o, d, cast = self.origins, self.directions, 0
        for depth in range(self.max_depth + 1):
            hits = self.scene.run(o, d, output=1)
            cast += d.shape[0]
            hit = hits["primID"] >= 0
            if not hit.any():
                break
            nodes = self.tri_node[hits["primID"][hit]]
            dh = d[hit]
            point = o[hit] + hits["tfar"][hit, None] * dh
            normal = hits["Ng"][hit]
            normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-30)
            scale = (SIMPLE_OFFSET * np.maximum(1.0, np.abs(point).max(axis=1)))[:, None]
            lit = self.lit[nodes]
            for light, occluders in zip(self.lights, self.shadow_scenes):
                p, n = point[lit], normal[lit]
                towards = light - p
                side = np.where(np.einsum("ij,ij->i", n, towards) < 0.0, -1.0, 1.0)[:, None]
                start = np.ascontiguousarray(p + scale[lit] * side * n, dtype=np.float32)
                cast += start.shape[0]
                if occluders is not None and start.shape[0]:
                    occluders.run(start, np.ascontiguousarray(light - start, dtype=np.float32),
                                  dists=np.ones(start.shape[0], dtype=np.float32), query="OCCLUDED")
            bounce = self.reflectivity[nodes] > 0.0
            if depth == self.max_depth or not bounce.any():
                break
            db, nb = dh[bounce], normal[bounce]
            d = np.ascontiguousarray(db - 2.0 * np.einsum("ij,ij->i", db, nb)[:, None] * nb, dtype=np.float32)
            side = np.where(np.einsum("ij,ij->i", nb, -db) < 0.0, -1.0, 1.0)[:, None]
            o = np.ascontiguousarray(point[bounce] + scale[bounce] * side * nb, dtype=np.float32)
        return cast


def embree_side(make_scene: Callable[[], object], size: tuple[int, int], mode: str) -> object:
    """A bench :class:`~glsandbox.measure.bench.Side`: Embree casting a scene's rays in ``mode``
    (:data:`MODES`), its scene built at the first call (the warm-up) and kept; returns the ray count."""
    from glsandbox.measure.bench import Side

    caster: list[EmbreeCaster] = []

    def run(_: int) -> int:
        if not caster:
            options = MODES[mode]
            caster.append(EmbreeCaster(make_scene(), size, options["shadows"], options["max_depth"]))
        return caster[0].cast()

    return Side("Embree (embreex)", run)


def cases(env: object) -> list:
    """``glsandbox bench`` cases: per scene and mode (primary; shadow+bounce: the
    secondary rays), the numpy and gpu engines against Embree casting the same
    rays, ratio = engine time / Embree time; without ``embreex``, the gpu
    engine against the numpy engine, and a note saying Embree was skipped.
    Everything is built on first use, so listing the cases costs nothing."""
    from glsandbox.measure.bench import Case, Side

    size: tuple[int, int] = env.size  # type: ignore[attr-defined]
    has_embree = embree_available()
    if not has_embree:
        env.note(EMBREE_MISSING)  # type: ignore[attr-defined]
    counts: dict[tuple[str, str], int] = {}

    def scene_of(name: str) -> object:
        return find_lesson(name)(renderer="raster").scene()

    def rays(name: str, mode: str) -> int:
        """The engines' ray count (numpy's RenderStats; the gpu engine casts the same rays)."""
        if (name, mode) not in counts:
            stats = RenderStats()
            render(scene_of(name), size, stats=stats, **MODES[mode])
            counts[(name, mode)] = stats.rays
        return counts[(name, mode)]

    def engine(name: str, mode: str, kind: str) -> Side:
        scene = scene_of(name)
        options = MODES[mode]

        def run(_: int) -> int:
            if kind == "gpu":
                render(scene, size, "gpu", ctx=env.renderer.host.ctx, **options)  # type: ignore[attr-defined]
                return rays(name, mode)
            stats = RenderStats()
            render(scene, size, stats=stats, **options)
            counts[(name, mode)] = stats.rays
            return stats.rays

        return Side("gpu engine (GLSL float32)" if kind == "gpu" else "numpy engine (float64)", run)

    def embree(name: str, mode: str) -> Side:
        return embree_side(lambda: scene_of(name), size, mode)

    def same_rays(baseline: int, subject: int) -> str:
        return f"{subject:,} rays each" if baseline == subject else f"rays: {subject:,}, Embree {baseline:,}"

    found = []
    for name in BENCH_SCENES[:1] if env.quick else BENCH_SCENES:  # type: ignore[attr-defined]
        for mode in MODES:
            if has_embree:
                for kind in ("numpy", "gpu"):
                    found.append(Case("ray tracer vs Embree", f"{name}, {mode}, {kind}", embree(name, mode),
                                      engine(name, mode, kind), repeat=1, goal=GOALS[kind], compare=same_rays,
                                      note="ratio = engine time / Embree time for the same rays"))
            else:
                found.append(Case("ray tracer engines", f"{name}, {mode}", engine(name, mode, "numpy"),
                                  engine(name, mode, "gpu"), repeat=1, compare=same_rays))
    return found


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
    header = f"{'scene':<17} {'mode':<14} {'rays':>10} {'numpy Mrays/s':>14} {'gpu cold':>9} {'gpu warm':>9} " \
             f"{'embree Mrays/s':>15} {'cold/embree':>11} {'warm/embree':>11} {'numpy/embree':>12}"
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
                tracer = gpu_tracer(ctx)

                def cold() -> None:
                    tracer.forget_scenes()
                    render(scene, size, "gpu", ctx=ctx, **options)

                t_numpy = median_seconds(lambda: render(scene, size, **options), args.rounds)
                t_cold = median_seconds(cold, args.rounds)
                render(scene, size, "gpu", ctx=ctx, **options)  # upload once
                t_warm = median_seconds(lambda: render(scene, size, "gpu", ctx=ctx, **options), args.rounds)
                numpy_rate = stats.rays / t_numpy / 1e6
                cold_rate = stats.rays / t_cold / 1e6
                warm_rate = stats.rays / t_warm / 1e6
                cells = [f"{name:<17}", f"{mode:<14}", f"{stats.rays:>10,}", f"{numpy_rate:>14.2f}",
                         f"{cold_rate:>9.2f}", f"{warm_rate:>9.2f}"]
                if embree is not None and mode == "primary":
                    t_embree = median_seconds(embree, args.rounds)
                    embree_rate = stats.primary / t_embree / 1e6
                    cells += [f"{embree_rate:>15.2f}", f"{cold_rate / embree_rate:>10.2f}x",
                              f"{warm_rate / embree_rate:>10.2f}x", f"{numpy_rate / embree_rate:>11.3f}x"]
                else:
                    cells += [f"{'-':>15}", f"{'-':>11}", f"{'-':>11}", f"{'-':>12}"]
                print(" ".join(cells), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
