"""The course's first half: a ray tracer from scratch, in numpy float64 (and in GLSL, float32).

Public API, in the course's words (``tests/raytrace/test_worked_examples.py``
checks that these reproduce every worked example of the notes):

- Vektörel işlemler: :func:`normalize`, :func:`dot`, :func:`cross`, :func:`length`;
- Bakış noktası, görüntü düzlemi GD(x,y): :func:`course_image_plane`, the
  notes' pixel-to-image-plane mapping;
- the ray ``R = R0 + t·Rd``: :class:`Ray`;
- shapes, each with ``intersect(ray) -> t | None`` (nearest ``t > 0``),
  ``normal_at(point)`` and vectorized ``intersect_many(origins, directions)``:
  :class:`Plane` (``N·P + D = 0``), :class:`Triangle` (six tests by name, see
  :data:`INSIDE_TESTS`), :class:`Sphere` (geometric and stable), :class:`AABB`;
  :class:`TriangleBatch` and :func:`moller_trumbore_many` for many triangles;
- the nearest hit (``tDistances``/``min_indis``): :func:`nearest_hit`,
  :func:`first_hit` (a :class:`Hit` record), :func:`nearest_hit_many`;
- Yansıma vektörü :func:`reflect`, Phong boyama modeli :func:`phong`;
- Gölge testi: :func:`in_shadow` (and :func:`shadow_ray`);
- the whole picture: :func:`render` traces a :class:`glsandbox.scene.Scene`,
  the same one the rasterizer draws, with the float64 ``"numpy"`` engine or
  the GLSL ``"gpu"`` engine (one of :data:`ENGINES`); :class:`RenderStats`
  counts what a numpy render did;
- Hızlandırma beyond the course's AABB: :func:`bvh_for_mesh`, a mesh's
  :class:`BVH` (binned SAH, cached by content), the numpy engine's
  ``bvh=True`` traversal.

The modules, each importing only those above it: ``raytrace_error``, ``vec``, ``ray``,
``shape_protocol``, then the shapes (``plane``, ``triangle``, ``sphere``, ``aabb``) and
what uses them (``trace``, ``shading``); ``constants`` (the numbers both
engines share); ``world`` (a Scene as the engines trace it, and the primary
rays); the engines, ``numpy_engine`` and ``gpu`` (GLSL, ``shaders/raytrace.glsl``);
``render``, the front door that picks one.

Conventions: right-handed, float64 throughout; ``t`` is in units of the ray's
direction as given; misses are ``None`` (scalar) or ``inf`` (vectorized).
"""

from __future__ import annotations

from glsandbox.raytrace.aabb import AABB
from glsandbox.raytrace.bvh import BVH, bvh_for_mesh
from glsandbox.raytrace.plane import Plane
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.raytrace_error import RayTraceError
from glsandbox.raytrace.render import ENGINES, RenderStats, render
from glsandbox.raytrace.shading import diffuse_factor, phong, reflect, specular_factor
from glsandbox.raytrace.shape_protocol import Shape
from glsandbox.raytrace.sphere import SPHERE_METHODS, Sphere
from glsandbox.raytrace.trace import (
    SHADOW_EPSILON,
    Hit,
    first_hit,
    in_shadow,
    nearest_hit,
    nearest_hit_many,
    shadow_ray,
)
from glsandbox.raytrace.triangle import (
    DEFAULT_METHOD,
    INSIDE_TESTS,
    POINT_IN_TRIANGLE,
    Triangle,
    TriangleBatch,
    moller_trumbore_many,
)
from glsandbox.raytrace.vec import cross, dot, length, normalize
from glsandbox.raytrace.watertight import aimed_rays, nearest_by
from glsandbox.raytrace.world import camera_rays, course_image_plane

__all__ = [
    "AABB",
    "BVH",
    "DEFAULT_METHOD",
    "ENGINES",
    "INSIDE_TESTS",
    "POINT_IN_TRIANGLE",
    "SHADOW_EPSILON",
    "SPHERE_METHODS",
    "Hit",
    "Plane",
    "Ray",
    "RayTraceError",
    "RenderStats",
    "Shape",
    "Sphere",
    "Triangle",
    "TriangleBatch",
    "aimed_rays",
    "bvh_for_mesh",
    "camera_rays",
    "course_image_plane",
    "cross",
    "diffuse_factor",
    "dot",
    "first_hit",
    "in_shadow",
    "length",
    "moller_trumbore_many",
    "nearest_by",
    "nearest_hit",
    "nearest_hit_many",
    "normalize",
    "phong",
    "reflect",
    "render",
    "shadow_ray",
    "specular_factor",
]
