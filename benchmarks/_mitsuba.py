"""Mitsuba 3 (its ``llvm_ad_rgb`` variant) casting the rays the engines cast, for the model rows.

Optional, like Embree: ``uv run --group bench --group mitsuba glsandbox bench``. Mitsuba's
LLVM variants compile their kernels with Dr.Jit at run time and need ``libLLVM`` 15 or newer
for that (Debian/Ubuntu: ``libllvm15``, which Debian 12's Mesa installs for llvmpipe; elsewhere Dr.Jit
reads its path from ``DRJIT_LIBLLVM_PATH``). Without either, :func:`mitsuba_missing` says why.

:class:`MitsubaCaster` casts exactly the rays :class:`raytrace.EmbreeCaster` casts (the same
float32 triangle soup, the same camera rays, the same shadow-ray and bounce origins), as one
Dr.Jit wavefront: every ray of a depth is a lane, rays that do not exist (a miss, an unlit
node, a material that does not reflect) are masked lanes, and Mitsuba traces each depth's
rays with ``ray_intersect`` / ``ray_test`` inside the compiled kernel (Embree underneath).
Dr.Jit only computes what is evaluated, so each cast evaluates a per-pixel Lambert shade
(``max(0, n·l)`` per unshadowed hit, weighted by the reflectivity along the bounce path) and
the pixel's ray count: every ray cast feeds them. The first cast traces and compiles the
kernel (the bench's warm-up); later casts replay the same trace and reuse the compiled
kernel, so the timed casts exclude JIT compilation as the other rows exclude their warm-ups.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np
from raytrace import MODES

from glsandbox.raytrace.constants import SIMPLE_OFFSET
from glsandbox.raytrace.world import build_world, camera_rays

VARIANT = "llvm_ad_rgb"
#: What to run for the Mitsuba rows.
INSTALL = "uv run --group bench --group mitsuba glsandbox bench"


@cache
def mitsuba_missing() -> str | None:
    """None when Mitsuba's :data:`VARIANT` can compile and run a kernel here, else why not
    (one line: not installed, or its LLVM backend found no ``libLLVM``)."""
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError:
        return f"mitsuba not installed ({INSTALL})"
    try:
        mi.set_variant(VARIANT)
        if int(dr.sum(dr.arange(mi.UInt32, 4))[0]) != 6:  # compiles and runs one kernel
            return f"mitsuba's {VARIANT} computed a wrong sum"
    except Exception as error:  # Dr.Jit raises RuntimeError/ImportError kinds that vary by version
        first = (str(error).strip().splitlines() or [type(error).__name__])[0]
        return (f"mitsuba's {VARIANT} cannot run: {first} (it needs libLLVM 15 or newer: Debian/"
                "Ubuntu `apt-get install libllvm15`, or DRJIT_LIBLLVM_PATH)")
    return None


def _mesh_scene(mi: Any, triangles: np.ndarray) -> Any:
    """A Mitsuba scene of one mesh holding ``triangles`` ((N, 3, 3) float32), built from the
    arrays (no file): vertex ``3k + j`` is corner ``j`` of triangle ``k``, as Embree gets them."""
    count = triangles.shape[0]
    mesh = mi.Mesh("model", vertex_count=3 * count, face_count=count,
                   has_vertex_normals=False, has_vertex_texcoords=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(np.ascontiguousarray(triangles, dtype=np.float32).reshape(-1))
    params["faces"] = mi.UInt32(np.arange(3 * count, dtype=np.uint32))
    params.update()
    return mi.load_dict({"type": "scene", "model": mesh})


def _larger(a: Any, b: Any) -> Any:
    """max(a, b) lane by lane."""
    import drjit as dr

    return dr.select(a > b, a, b)


class MitsubaCaster:
    """Mitsuba's ``llvm_ad_rgb`` casting one scene's rays: primary rays, a shadow ray per
    light at every lit hit (the light's lamp left out, as the engines do) and reflection
    bounces up to ``max_depth`` where a material reflects (:mod:`benchmarks._mitsuba`)."""

    def __init__(self, scene: object, size: tuple[int, int], shadows: bool, max_depth: int) -> None:
        import drjit as dr
        import mitsuba as mi

        mi.set_variant(VARIANT)
        self.mi, self.dr = mi, dr
        world = build_world(scene, analytic_spheres=False)
        triangles = np.stack([world.v0, world.v1, world.v2], axis=1).astype(np.float32)
        self.scene = _mesh_scene(mi, triangles)
        # Per triangle: its node's reflectivity and whether it is lit (gathered by prim_index).
        reflectivity = np.array([n.reflectivity for n in world.nodes], dtype=np.float32)[world.tri_node]
        lit = np.array([n.lit for n in world.nodes], dtype=bool)[world.tri_node]
        self.reflectivity, self.lit = mi.Float(reflectivity), mi.Bool(lit)
        self.lights = []  # (position, the scene its shadow rays test: without that light's lamp)
        for index, light in enumerate(world.light_positions if shadows else ()):
            keep = np.array([not world.nodes[k].lamp_of >> index & 1 for k in world.tri_node], dtype=bool)
            occluders = self.scene if keep.all() else _mesh_scene(mi, triangles[keep]) if keep.any() else None
            position = mi.Point3f(*(float(np.float32(c)) for c in light))
            dr.make_opaque(position)  # a literal would make the second cast's kernel differ from the first's
            self.lights.append((position, occluders))
        self.max_depth = max_depth
        eye, dirs = camera_rays(scene.viewports[0].camera or scene.camera, *size)  # type: ignore[attr-defined]
        dirs = np.ascontiguousarray(dirs, dtype=np.float32)
        self.eye = [float(np.float32(c)) for c in eye]
        self.directions = mi.Vector3f(dirs[:, 0], dirs[:, 1], dirs[:, 2])
        dr.eval(self.directions)
        self.size = size
        self.last: tuple[Any, Any] | None = None

    def cast(self) -> None:
        """Cast every ray once: one kernel (compiled at the first cast), waited for."""
        mi, dr = self.mi, self.dr
        count = dr.width(self.directions)
        o = mi.Point3f(*(dr.full(mi.Float, c, count) for c in self.eye))  # the eye, in every lane
        d = mi.Vector3f(self.directions)
        active = dr.full(mi.Bool, True, count)
        weight = dr.full(mi.Float, 1.0, count)
        shade = dr.full(mi.Float, -1.0, count)  # -1: the primary ray missed
        rays = dr.zeros(mi.UInt32, count)
        for depth in range(self.max_depth + 1):
            rays += dr.select(active, 1, 0)
            # Minimal: t, the hit point and the geometric normal (what Embree's side gets: tfar, Ng);
            # coherent: the primary rays leave one eye in pixel order.
            si = self.scene.ray_intersect(mi.Ray3f(o, d), ray_flags=mi.RayFlags.Minimal, coherent=depth == 0,
                                          active=active)
            active &= si.is_valid()
            if depth == 0:
                shade = dr.select(active, 0.0, shade)
            point = o + si.t * d  # as Embree's side computes it: origin + tfar·direction
            normal = si.n
            # The engines' simple offset (constants.SIMPLE_OFFSET·max(1, max|P_i|)) along ±n.
            # (dr.select, not dr.maximum: libLLVM 15 aborts the process on Dr.Jit's llvm.maximum on x86,
            # "Cannot select fmaximum"; Mitsuba's own integrators hit the same with fminimum there.)
            largest = _larger(_larger(dr.abs(point.x), dr.abs(point.y)), dr.abs(point.z))
            scale = SIMPLE_OFFSET * _larger(largest, 1.0)
            lit = active & dr.gather(mi.Bool, self.lit, si.prim_index, active)
            for light, occluders in self.lights:
                towards = light - point
                start = point + dr.select(dr.dot(normal, towards) < 0.0, -scale, scale) * normal
                rays += dr.select(lit, 1, 0)
                blocked = mi.Bool(False) if occluders is None else \
                    occluders.ray_test(mi.Ray3f(mi.Ray3f(start, light - start), 1.0), lit)
                lambert = _larger(dr.dot(normal, dr.normalize(towards)), 0.0)
                shade += dr.select(lit & ~blocked, weight * lambert, 0.0)
            if depth == self.max_depth:
                break
            reflect = dr.gather(mi.Float, self.reflectivity, si.prim_index, active)
            active &= reflect > 0.0
            weight *= reflect
            d_next = d - 2.0 * dr.dot(d, normal) * normal
            o = dr.select(active, point + dr.select(dr.dot(normal, -d) < 0.0, -scale, scale) * normal, o)
            d = dr.select(active, d_next, d)
        dr.eval(shade, rays)
        dr.sync_thread()
        self.last = (shade, rays)

    def ray_count(self) -> int:
        """How many rays the last :meth:`cast` cast."""
        assert self.last is not None
        return int(self.dr.sum(self.last[1])[0])

    def image(self, background: tuple[float, ...]) -> np.ndarray:
        """The last cast as an (H, W, 4) uint8 picture: grey shades where the primary ray hit,
        ``background`` where it missed (rows as :func:`camera_rays` orders its rays)."""
        assert self.last is not None
        width, height = self.size
        shade = np.asarray(self.last[0]).reshape(height, width)
        grey = np.clip(0.15 + 0.85 * np.maximum(shade, 0.0), 0.0, 1.0)  # never the magenta background
        rgb = np.where((shade < 0.0)[..., None], np.asarray(background[:3]), grey[..., None])
        alpha = np.ones((height, width, 1))
        return np.round(np.concatenate([rgb, alpha], axis=-1) * 255.0).astype(np.uint8)


def mitsuba_side(make_scene: Callable[[], object], size: tuple[int, int], mode: str,
                 background: tuple[float, ...]) -> object:
    """A bench :class:`~glsandbox.measure.bench.Side`: Mitsuba casting a scene's rays in ``mode``
    (:data:`raytrace.MODES`). The first call (the bench's warm-up) builds the scene, casts once
    (tracing and compiling the kernel) and returns the picture for the hit/miss check; every
    later call casts with the compiled kernel and returns None."""
    from glsandbox.measure.bench import Side

    caster: list[MitsubaCaster] = []

    def run(_: int) -> np.ndarray | None:
        if caster:
            caster[0].cast()
            return None
        options = MODES[mode]
        caster.append(MitsubaCaster(make_scene(), size, options["shadows"], options["max_depth"]))
        caster[0].cast()
        return caster[0].image(background)

    return Side(f"Mitsuba 3 ({VARIANT})", run)
