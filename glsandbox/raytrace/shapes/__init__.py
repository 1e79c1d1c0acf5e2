"""The analytic shape kinds: one module per kind, for both engines.

A kind is the exact unit shape under a node's model matrix, traced instead
of the triangles that tessellate it (course section "Işın-Küre kesim testi"
for the sphere). Each module ``shapes/<kind>.py`` holds one :class:`ShapeKind`
record (:class:`~glsandbox.raytrace.shape_kind.ShapeKind`), ``SHAPE``, with everything the engines need:

- ``hit``: the numpy engine's test in the kind's own space;
- ``own_box``: its bounds there (``build_world`` maps them to a world box,
  course "Hızlandırma: AABB");
- ``surface``: the own-space normal and uv at a hit;
- ``holds``: whether a mesh's vertices lie on the shape (then the mesh is
  traced as the kind);
- ``record``: the node-record fields its GLSL reads (``gpu_records.NODE``);
- ``mesh``: the raster mesh the rasterizer draws for it (in ``geometry``);
- ``shaders/shapes/<kind>.glsl``: the gpu engine's ``<kind>_t`` and
  ``<kind>_surface``, included by ``shaders/raytrace.glsl``.

:data:`KINDS` is the registry; :class:`glsandbox.raytrace.world.NodeKind`
is built from it, and :func:`glsl_dispatch` writes the shader's per-kind
cases from it.
"""

from __future__ import annotations

from glsandbox.raytrace.shape_kind import ShapeKind, glsl_path
from glsandbox.raytrace.shapes import cylinder, sphere

__all__ = ["KINDS", "ShapeKind", "by_name", "glsl_dispatch", "glsl_path"]


#: Every analytic kind, in the order of their node-kind codes (after the mesh kind's 0).
KINDS: tuple[ShapeKind, ...] = (sphere.SHAPE, cylinder.SHAPE)


def by_name(name: str) -> ShapeKind:
    """The registered kind called ``name``; a KeyError naming the known ones otherwise."""
    for kind in KINDS:
        if kind.name == name:
            return kind
    raise KeyError(f"no shape kind {name!r}; known: {', '.join(k.name for k in KINDS)}")


def glsl_dispatch(names: frozenset[str] | set[str]) -> tuple[tuple[str, str], ...]:
    """The shader's per-kind cases for the kinds ``names`` a scene holds, as two defines:
    ``SHAPE_T_CASES`` (``if (kind == KIND_X) return x_t(o, d, cull);`` per kind) and
    ``SHAPE_SURFACE_CASES`` (``if (kind == KIND_X) { x_surface(q, n, uv); return; }``).
    A kind without its GLSL functions fails the compile, naming them; a kind code with no
    case falls to the end of the dispatch, which flags the pixel (``g_bad_kind``)."""
    held = [kind for kind in KINDS if kind.name in names]
    t_cases = " ".join(f"if (kind == KIND_{k.name.upper()}) return {k.name}_t(o, d, cull);" for k in held)
    surface_cases = " ".join(f"if (kind == KIND_{k.name.upper()}) {{ {k.name}_surface(q, n, uv); return; }}"
                             for k in held)
    return ("SHAPE_T_CASES", t_cases), ("SHAPE_SURFACE_CASES", surface_cases)
