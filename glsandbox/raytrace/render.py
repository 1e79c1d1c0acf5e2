"""``render(scene, size, engine=...)``: ray-trace the Scene the rasterizer draws.

This module is the front door: it checks the options, traces each viewport
with the engine asked for and lays the tiles out in one image. Two engines,
one algorithm:

- ``"numpy"``: the float64 reference, vectorized over rays
  (:mod:`glsandbox.raytrace.numpy_engine`);
- ``"gpu"``: a GLSL fragment shader on a ModernGL context, float32
  (:mod:`glsandbox.raytrace.gpu`, ``shaders/raytrace.glsl``).

Each offers ``render_viewport(scene, size, viewport, **options)``, an
``(H, W, 4)`` uint8 image of one viewport. Both trace a
:class:`~glsandbox.raytrace.world.World` (:mod:`glsandbox.raytrace.world`)
and read the numbers they share from :mod:`glsandbox.raytrace.constants`.

The algorithm, in the course's order (first half of the notes):

1. **Primary rays** through the image plane (:func:`~glsandbox.raytrace.world.camera_rays`).
2. **Nearest hit** (``tDistances``/``min_indis``): for each node, the AABB
   slab test first (course "Hızlandırma: AABB"; ``aabb=False`` skips it),
   then the watertight triangle test (Woop, Benthin & Wald; the course's
   Işın-Üçgen kesim testi ends with it) against its triangles, or an analytic
   node's own test in its own space (the exact sphere, the capped cylinder:
   the node table, :class:`~glsandbox.raytrace.world.NodeKind`): a ray
   through a shared edge or vertex never slips through, in either engine, on
   any path.
   The numpy engine's ``bvh=True`` (the default) traces each mesh node's rays
   through a BVH over its triangles instead (:mod:`glsandbox.raytrace.bvh`,
   built once per mesh and cached), with the watertight triangle test
   (:mod:`glsandbox.raytrace.watertight`: a ray through a shared edge or
   vertex hits one of its triangles, never none); analytic nodes stay exact, and
   shadow rays stop at their first occluder. ``bvh=False`` is the per-node
   scan above (what ``ray_acceleration`` compares it with). The gpu engine
   decides by itself (:mod:`glsandbox.raytrace.gpu`: a scan for small
   meshes, BVHs for large ones, both with the watertight test) and ignores
   the option.
   **Backface culling** (course "Hızlandırma: backface culling"): a node the
   rasterizer culls (``cull_back_faces``) is one-sided for *every* ray, as
   the front faces only (``N·d < 0``); ``cull_backfaces=True``/``False``
   overrides all nodes.
3. **Shading**, the rasterizer's formula (``shaders/common/lighting.glsl``,
   course "Lighting"), so the two renderers differ only where the raster
   approximates: per light, ``min(ka·mesh + kd·max(N·L,0)·mesh·light +
   ks·max(R·E,0)^n·light, 1)``, summed; ``R`` the light direction mirrored
   about ``N`` (Blinn–Phong: ``N·H``). The course's first-half form with
   ``ka + kd + ks = 1`` is :func:`glsandbox.raytrace.phong`; the exam scenes
   use coefficients that sum to 1. Gouraud and naive normals are raster
   approximations: the ray tracer always shades per pixel with the normal
   matrix. ``solid`` and ``vertex_color`` surfaces are unlit (their colour,
   barycentric-interpolated vertex colours). Textures are sampled bilinearly
   in their base level at the barycentric uv ``t(u,v) = V0 + u(V1−V0) +
   v(V2−V0)`` (no mipmaps: a ray has no footprint).
4. **Shadow rays** (course "Gölge testi"): a light counts for a lit point only
   if nothing lies between: the ray ``P' + s·(L − P')``, ``0 < s < 1``, hits
   nothing (``s = 1`` is the light itself, so an occluder beyond it never
   counts). ``P'`` is ``P`` moved off its surface, towards the light's side,
   along the geometric normal by a bound on ``P``'s rounding error (pbrt-v4;
   the bounds are in :mod:`glsandbox.raytrace.constants`): a contact shadow
   survives at the origin and at 1e6 alike. In shadow, only the ambient term stays.
   A light's lamp (an unlit node whose box holds it) casts no shadow for it.
5. **Reflection** (course "Yansıma vektörü"): a surface with
   ``material.reflectivity = r > 0`` shows ``(1 − r)·local + r·reflected``,
   the reflected ray ``R = Rd − 2(Rd·N)N`` traced again, up to
   ``max_depth`` bounces (at the last one the local colour stands in).
   A ray that hits nothing shows the viewport's clear colour.

Colours are clamped to 0..1 and rounded to 8 bits as GL does (``⌊255c + ½⌋``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial

import numpy as np
from numpy.typing import NDArray

from glsandbox.raytrace import numpy_engine
from glsandbox.raytrace.constants import OFFSETS
from glsandbox.raytrace.numpy_engine import RenderStats
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.scene import Scene

__all__ = ["ENGINES", "RenderStats", "render"]

#: The two engines.
ENGINES = ("numpy", "gpu")


def _check(size: tuple[int, int], engine: str, max_depth: int, offset: str = "bound") -> None:
    if offset not in OFFSETS:
        raise RayTraceError(f"unknown shadow-ray offset {offset!r}; use one of {', '.join(OFFSETS)}")
    if engine not in ENGINES:
        raise RayTraceError(f"unknown ray tracing engine {engine!r}; use one of {', '.join(ENGINES)}")
    if len(size) != 2 or any(int(s) != s or s <= 0 or s > 16384 for s in size):
        raise RayTraceError(f"image size must be two positive integers, got {size!r}")
    if int(max_depth) != max_depth or not 0 <= max_depth <= 16:
        raise RayTraceError(f"max_depth must be an integer in 0..16, got {max_depth!r}")


def render(scene: Scene, size: tuple[int, int], engine: str = "numpy", *, ctx: object | None = None,
           max_depth: int = 2, shadows: bool = True, cull_backfaces: bool | None = None, aabb: bool = True,
           bvh: bool = True, analytic_spheres: bool = True, offset: str = "bound",
           stats: RenderStats | None = None) -> NDArray[np.uint8]:
    """Ray-trace ``scene`` at ``size = (width, height)``: an ``(H, W, 4)`` uint8 image, top row first.

    Every viewport is traced in its rectangle with its camera and clear
    colour, as the rasterizer lays them out; overlays are not drawn (they
    are the rasterizer's). ``engine="gpu"`` needs ``ctx``, a ModernGL
    context (the GLSL engine renders on it). Options: ``max_depth``
    reflection bounces, ``shadows``, ``cull_backfaces`` (None: per node, as
    the rasterizer), ``aabb`` culling, ``bvh`` (numpy engine: mesh nodes
    through their BVH; ``False``: every triangle of each node the box test
    lets through), ``analytic_spheres`` (every analytic kind, spheres and cylinders,
    exact; ``False``: their triangles; see :mod:`glsandbox.raytrace.world`),
    ``offset`` (how secondary rays leave a surface: ``"bound"``, by the hit
    point's rounding-error bound; ``"simple"``, the teaching variant
    :data:`~glsandbox.raytrace.constants.SIMPLE_OFFSET` times ``max(1, max|P|)`` of the
    *world* position ``P`` in both engines: the gpu engine, whose points are relative to
    its anchor, adds the anchor back first).
    ``stats`` (numpy engine) counts the rays and the box and shape tests.
    """
    _check(size, engine, max_depth, offset)
    width, height = int(size[0]), int(size[1])
    start = time.perf_counter()
    frame = np.zeros((height, width, 4), dtype=np.uint8)
    options = dict(max_depth=int(max_depth), shadows=shadows, cull_backfaces=cull_backfaces, aabb=aabb,
                   analytic_spheres=analytic_spheres, offset=offset)
    # tracer(size, viewport): one viewport's image, from either engine.
    tracer: Callable[[tuple[int, int], int], NDArray[np.uint8]]
    if engine == "gpu":
        if ctx is None:
            raise RayTraceError("engine='gpu' needs a ModernGL context: render(..., ctx=renderer.host.ctx)")
        # Imported here, not at the top: a numpy render never loads moderngl or the shaders.
        from glsandbox.raytrace.gpu import gpu_tracer

        tracer = partial(gpu_tracer(ctx).render_viewport, scene, **options)
    else:
        tracer = partial(numpy_engine.render_viewport, scene, stats=stats, bvh=bool(bvh), **options)
    for index, vp in enumerate(scene.viewports):
        x, y, w, h = vp.pixels(width, height)
        if w <= 0 or h <= 0:
            continue
        top = height - y - h  # viewports count from the bottom, images from the top
        frame[top:top + h, x:x + w] = tracer((w, h), index)
    if stats is not None:
        stats.seconds += time.perf_counter() - start
    return frame
