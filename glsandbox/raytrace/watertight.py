"""The watertight ray-triangle test for many (ray, triangle) pairs at once.

Woop, Benthin & Wald (2013), "Watertight Ray/Triangle Intersection", the
test the course's Işın-Üçgen kesim testi ends with (the scalar version, with
its derivation, is ``_watertight`` in :mod:`glsandbox.raytrace.triangle`).
This module runs the *same arithmetic* on numpy arrays: for every pair the
same float64 operations in the same order, so a pair's ``t`` is bit for bit
the scalar test's ``t``. The steps, per ray:

1. **Permute** the axes so the direction's largest component is ``z``
   (``kz``), keeping the winding (``kx, ky`` swapped when ``d[kz] < 0``);
2. **shear** with ``sx = dx/dz, sy = dy/dz, sz = 1/dz``: after
   ``x − sx·z, y − sy·z`` the ray is the ``+z`` axis through ``(0, 0)``;

and per pair:

3. move the vertices so the ray starts at the origin, shear them, and form
   the 2D edge functions ``U = E(C, B)``, ``V = E(A, C)``, ``W = E(B, A)``
   with ``E(p, q) = px·qy − py·qx`` (the scaled barycentrics of ``V0, V1,
   V2``). Two triangles sharing an edge compute *the same products* for it,
   subtracted in the opposite order, so a ray can never slip between them;
4. inside when ``U, V, W`` share a sign (zeros count on both sides;
   backface culling keeps only ``U, V, W >= 0``, the front faces, ``N·d <
   0``); ``det = U + V + W = 0`` is a triangle seen edge-on;
5. ``t = (U·z_A + V·z_B + W·z_C)/det`` with the sheared ``z = sz·z``;
6. a hit counts only for ``t`` above pbrt-v4's bound on its rounding error
   (:func:`~glsandbox.raytrace.triangle.watertight_t_bound`), so a secondary
   ray that leaves its surface by the hit point's error bound never meets it.

When an edge function rounds to exactly 0, its sign is not trustworthy. The
scalar test recomputes it in exact rational arithmetic; here the same
number comes from an error-free transformation instead: ``fl(p1 − p2) = 0``
means the two rounded products are equal, so the exact value
``(p1 + e1) − (p2 + e2)`` is ``e1 − e2``, where ``e = a·b − fl(a·b)`` is
exact (Dekker's product with Veltkamp's split), and ``fl(e1 − e2)`` is the
correctly rounded exact value: what ``float(Fraction(...))`` gives. (Both
differ only where the products underflow, below about 1e-290.)

The test itself knows nothing about degenerate (zero-area) triangles: like
the scalar one it leaves that to the caller (the BVH excludes them at build
time with the course's :data:`~glsandbox.raytrace.triangle.DEGENERATE_SIN`
rule, see :func:`nondegenerate`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from glsandbox.raytrace.shape_protocol import broadcast_rays
from glsandbox.raytrace.triangle import DEGENERATE_SIN, watertight_t_bound

__all__ = ["RaySetup", "aimed_rays", "nearest_by", "nearest_watertight", "nondegenerate", "ray_setup",
           "watertight_pairs"]

#: Veltkamp's splitting constant for float64: 2^27 + 1 cuts a double into two
#: halves of 26 bits whose pairwise products are exact.
_SPLITTER = 134217729.0


@dataclass(frozen=True)
class RaySetup:
    """The per-ray constants of the watertight test, ``(N,)`` each.

    ``kx, ky, kz`` are the permuted axes, ``sx, sy, sz`` the shear, and
    ``ox, oy, oz`` the origin's components on the permuted axes. They are rows
    of two stacked arrays, ``k = [kx, ky, kz]`` ``(3, N)`` and ``s = [sx, sy,
    sz, ox, oy, oz]`` ``(6, N)``, so a batch of pairs gathers its rays' constants
    in two calls.
    """

    k: NDArray[np.intp]
    s: NDArray[np.float64]

    kx = property(lambda self: self.k[0])
    ky = property(lambda self: self.k[1])
    kz = property(lambda self: self.k[2])
    sx = property(lambda self: self.s[0])
    sy = property(lambda self: self.s[1])
    sz = property(lambda self: self.s[2])
    ox = property(lambda self: self.s[3])
    oy = property(lambda self: self.s[4])
    oz = property(lambda self: self.s[5])

    def __len__(self) -> int:
        return int(self.k.shape[1])


def ray_setup(origins: ArrayLike, directions: ArrayLike) -> RaySetup:
    """Steps 1 and 2 for ``N`` rays (``origins`` may be one shared ``(3,)`` point)."""
    o, d = broadcast_rays(origins, directions)
    n = d.shape[0]
    rows = np.arange(n)
    a = np.abs(d)
    if np.isnan(a).any():  # argmax's rule for NaN (the first NaN is the largest); such a ray misses anyway
        kz = np.argmax(a, axis=1)
    else:  # the first largest component, as np.argmax in the scalar test, without a per-row reduction
        ax, ay, az = a.T
        kz = np.where((ax >= ay) & (ax >= az), 0, np.where(ay >= az, 1, 2))
    k = np.empty((3, n), dtype=np.intp)
    kx = (kz + 1) % 3
    ky = (kx + 1) % 3
    flip = d[rows, kz] < 0.0  # keep the winding: swap kx and ky
    k[0] = np.where(flip, ky, kx)
    k[1] = np.where(flip, kx, ky)
    k[2] = kz
    s = np.empty((6, n))
    dz = d[rows, kz]
    with np.errstate(divide="ignore", invalid="ignore"):  # a zero direction: NaN, and it misses
        np.divide(d[rows, k[0]], dz, out=s[0])
        np.divide(d[rows, k[1]], dz, out=s[1])
        np.divide(1.0, dz, out=s[2])
    if n and o.strides[0] == 0:  # one shared origin: its (3,) row permuted
        s[3:] = o[0][k]
    else:
        s[3], s[4], s[5] = o[rows, k[0]], o[rows, k[1]], o[rows, kz]
    return RaySetup(k, s)


def nondegenerate(v0: NDArray[np.float64], v1: NDArray[np.float64], v2: NDArray[np.float64]) -> NDArray[np.bool_]:
    """``(M,)``: the triangles with area, ``|e1 × e2| > DEGENERATE_SIN·|e1|·|e2|``
    (exactly the rule of :class:`~glsandbox.raytrace.triangle.TriangleBatch`)."""
    # The same float64 steps as ``length(cross(e1, e2)) > DEGENERATE_SIN * length(e1) * length(e2)``
    # (so the same triangles), on one contiguous row per component and reused buffers: the
    # BVH build runs this over a million triangles.
    e1 = np.asarray(np.subtract(v1, v0), dtype=np.float64).T.copy()  # (3, M)
    e2 = np.asarray(np.subtract(v2, v0), dtype=np.float64).T.copy()
    t = np.empty_like(e1[0])
    cx = np.multiply(e1[1], e2[2])  # R1y·R2z − R1z·R2y, then the other two components (vec.cross)
    cx -= np.multiply(e1[2], e2[1], out=t)
    cy = np.multiply(e1[2], e2[0])
    cy -= np.multiply(e1[0], e2[2], out=t)
    cz = np.multiply(e1[0], e2[1])
    cz -= np.multiply(e1[1], e2[0], out=t)

    def norm(x: NDArray[np.float64], y: NDArray[np.float64], z: NDArray[np.float64],
             out: NDArray[np.float64]) -> NDArray[np.float64]:  # sqrt(x² + y² + z²) into out, as vec.length
        np.multiply(x, x, out=out)
        out += np.multiply(y, y, out=t)
        out += np.multiply(z, z, out=t)
        return np.sqrt(out, out=out)

    area = norm(cx, cy, cz, cx)  # |e1 × e2| (cx is read before it is overwritten)
    bound = norm(e1[0], e1[1], e1[2], cy)
    bound *= DEGENERATE_SIN
    bound *= norm(e2[0], e2[1], e2[2], cz)
    result: NDArray[np.bool_] = area > bound
    return result


def _product_error(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a·b − fl(a·b)``, exactly (Dekker's two-product with Veltkamp's split)."""
    p = a * b
    ca = _SPLITTER * a
    a_hi = ca - (ca - a)
    a_lo = a - a_hi
    cb = _SPLITTER * b
    b_hi = cb - (cb - b)
    b_lo = b - b_hi
    result: NDArray[np.float64] = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
    return result


def _edge(px: NDArray[np.float64], py: NDArray[np.float64], qx: NDArray[np.float64],
          qy: NDArray[np.float64]) -> NDArray[np.float64]:
    """``E(p, q) = px·qy − py·qx``; where it rounds to 0, the correctly rounded exact value."""
    e = px * qy - py * qx
    zero = np.flatnonzero(e == 0.0)
    if zero.size:
        pxz, pyz, qxz, qyz = px[zero], py[zero], qx[zero], qy[zero]
        e[zero] = _product_error(pxz, qyz) - _product_error(pyz, qxz)
    return e


def watertight_pairs(setup: RaySetup, rays: NDArray[np.intp], v0: NDArray[np.float64], v1: NDArray[np.float64],
                     v2: NDArray[np.float64], tris: NDArray[np.intp], cull_backfaces: bool = False,
                     barycentrics: bool = True, relative: bool = False
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """Ray ``rays[i]`` against triangle ``tris[i]`` for every ``i``: ``(t, u, v)``, ``(P,)`` each.

    ``t`` is ``inf`` for a miss (outside, edge-on, culled, or ``t <= 0``);
    ``(u, v)`` are the hit's barycentrics in the course's form
    ``P = V0 + u·(V1 − V0) + v·(V2 − V0)`` (meaningless for a miss; None
    when ``barycentrics`` is False: a traversal needs ``t`` alone).
    ``v0, v1, v2`` are ``(M, 3)`` float64 arrays; ``relative``: they are already
    ``V − O`` for the one origin every ray shares (the same numbers step 3 forms).
    """
    # Each pair's flat vertex rows: component k of triangle j is [3j + k] (kx, ky, kz rows).
    index = setup.k.take(rays, axis=1)
    index += tris * 3
    s = (setup.s[:3] if relative else setup.s).take(rays, axis=1)  # sx, sy, sz(, ox, oy, oz)
    sx, sy, sz = s[0], s[1], s[2]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        coords = []
        for vertex in (v0, v1, v2):
            # Step 3: relative to the origin (the scalar's V − O), then sheared: x − sx·z, y − sy·z.
            p = vertex.reshape(-1).take(index)
            if not relative:
                p -= s[3:]
            p[:2] -= s[:2] * p[2]
            coords.append(p)
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = coords
        u = _edge(cx, cy, bx, by)  # edge V1-V2: the weight of V0
        v = _edge(ax, ay, cx, cy)  # edge V2-V0: the weight of V1
        w = _edge(bx, by, ax, ay)  # edge V0-V1: the weight of V2
        # Step 4: all signs alike (zeros on both sides): the smallest >= 0 or the largest <= 0;
        # culling keeps the front faces only (the smallest >= 0). A NaN edge (coordinates
        # that overflow) is neither: a miss, as its NaN t would be.
        low = np.minimum(u, v)
        np.minimum(low, w, out=low)
        inside = low >= 0.0
        if not cull_backfaces:
            high = np.maximum(u, v, out=low)
            np.maximum(high, w, out=high)
            inside |= high <= 0.0
        det = u + v
        det += w
        inside &= det != 0.0
        t = np.full(rays.shape[0], np.inf)
        near = np.flatnonzero(inside)  # most pairs a traversal tests are outside: the rest for these only
        if near.size:
            zn = sz[near]
            z = zn * az[near], zn * bz[near], zn * cz[near]
            e = u[near], v[near], w[near]
            dn = det[near]
            # Step 5: the sheared z interpolated with the scaled barycentrics is t along d.
            tn = (e[0] * z[0] + e[1] * z[1] + e[2] * z[2]) / dn
            # Step 6: only a t above its rounding-error bound counts (pbrt-v4), as in the scalar test;
            # formed for the pairs that could hit only.
            front = np.flatnonzero(tn > 0.0)
            if front.size:
                bound = watertight_t_bound((ax[near[front]], bx[near[front]], cx[near[front]]),
                                           (ay[near[front]], by[near[front]], cy[near[front]]),
                                           (z[0][front], z[1][front], z[2][front]),
                                           (e[0][front], e[1][front], e[2][front]), dn[front])
                keep = front[tn[front] > bound]
                t[near[keep]] = tn[keep]
        if not barycentrics:
            return t, None, None
        return t, v / det, w / det


def nearest_watertight(v0: NDArray[np.float64], v1: NDArray[np.float64], v2: NDArray[np.float64],
                       origins: ArrayLike, directions: ArrayLike, cull_backfaces: bool = False,
                       chunk_pairs: int = 1 << 14, accept: Callable[..., NDArray[np.bool_]] | None = None,
                       tested: list[int] | None = None) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Nearest hit of each ray over *every* triangle (no BVH): ``(t, index)``, ``(inf, −1)``
    for a miss, the lower index winning a tie (the course's ``min_indis``). The
    numpy engine's per-node scan (``bvh=False``): the watertight test, so a ray
    through a shared edge or vertex never slips through. Triangles without area
    (:func:`nondegenerate`) are never hit, as in the BVH. Pairs are tested a
    block of rays at a time, about ``chunk_pairs`` pairs a block.

    ``accept(rays, triangles, t)``: which hits count (the any-hit filter of
    :func:`~glsandbox.raytrace.bvh_traverse.any_hit`); the nearest of those wins.

    ``cull_backfaces`` (course "Hızlandırma 1: Backface Culling"): a pair whose
    triangle faces away from the ray, ``d·N > 0`` with ``N = (V1−V0)×(V2−V0)``,
    is skipped after that one dot product and never reaches the test (which
    would cull it: front faces have ``d·N < 0``; edge-on pairs are left to it).
    ``tested``: the number of ray-triangle tests actually run is appended."""
    o, d = broadcast_rays(origins, directions)
    n, m = d.shape[0], v0.shape[0]
    best_t = np.full(n, np.inf)
    best_i = np.full(n, -1, dtype=np.intp)
    keep = np.flatnonzero(nondegenerate(v0, v1, v2))
    if n == 0 or keep.size == 0:
        return best_t, best_i
    normals = np.cross(v1[keep] - v0[keep], v2[keep] - v0[keep]) if cull_backfaces else None
    if normals is not None and (o.shape[0] == 1 or not (o != o[0]).any()):
        # One origin for every ray (primary rays): a hit P = O + t·d (t > 0) on the plane has
        # d·N = (P − O)·N / t = (V0 − O)·N / t, so the triangle faces every ray that can hit it
        # alike: a triangle facing away from O is dropped for the whole block at once.
        keep = keep[np.einsum("ij,ij->i", v0[keep] - o[0], normals) <= 0.0]
        normals = None
        if keep.size == 0:
            if tested is not None:
                tested.append(0)
            return best_t, best_i
    setup = ray_setup(o, d)
    step = max(1, chunk_pairs // keep.size)
    done = 0
    for lo in range(0, n, step):
        rays = np.arange(lo, min(n, lo + step))
        pair_rays, pair_tris = np.repeat(rays, keep.size), np.tile(keep, rays.size)
        if normals is None:
            t, _, _ = watertight_pairs(setup, pair_rays, v0, v1, v2, pair_tris, cull_backfaces, barycentrics=False)
        else:  # the facing test first: only pairs that may face the ray are tested
            facing = np.flatnonzero((d[rays] @ normals.T).reshape(-1) <= 0.0)
            t = np.full(pair_rays.shape[0], np.inf)
            t[facing], _, _ = watertight_pairs(setup, pair_rays[facing], v0, v1, v2, pair_tris[facing], True,
                                               barycentrics=False)
            done += facing.size
        if accept is not None:
            hit = np.flatnonzero(np.isfinite(t))
            if hit.size:
                refused = hit[~accept(np.repeat(rays, keep.size)[hit], np.tile(keep, rays.size)[hit], t[hit])]
                t[refused] = np.inf
        t = t.reshape(rays.size, keep.size)
        j = np.argmin(t, axis=1)  # the first minimum: the lowest index on a tie
        best_t[rays] = t[np.arange(rays.size), j]
        best_i[rays] = np.where(np.isfinite(best_t[rays]), keep[j], -1)
    if tested is not None:
        tested.append(done if normals is not None else n * int(keep.size))
    return best_t, best_i


# --- the probe of a closed mesh: rays aimed at its vertices and edges -------------------------

#: Where each edge is aimed at, as a share of the way along it (0.5: the midpoint).
EDGE_POINTS = (0.3, 0.5, 0.71)
#: The way the probe's mesh is moved from the origin (``at`` times this).
AWAY = (0.99, 0.7, -0.4)

Triangles = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


@functools.lru_cache(maxsize=8)
def aimed_rays(size: tuple[int, int], at: float = 0.0) -> tuple[Triangles, NDArray[np.float64], NDArray[np.float64]]:
    """A closed mesh's world triangles and ``width·height`` rays ``(origins, directions)`` (float64)
    that must all hit it: the icosphere subdivided once (80 triangles, radius 2, turned so
    no edge lies along an axis), moved by ``at·AWAY``; each ray from one of a few eyes inside
    it (within 0.4 of its centre, the same eyes at every offset) to a vertex or a point of an
    edge, every vertex and edge point in turn, ``t = 1`` there. A ray that finds no triangle
    slipped through a crack: what the watertight test never lets happen. The rays the
    ``triangle_test`` row of ``glsandbox tradeoffs`` and ``ray_triangle --set timing=on`` time."""
    from glsandbox import transforms
    from glsandbox.mesh import generate as meshgen

    mesh = meshgen.icosphere(1)
    model = transforms.translate(*(at * np.array(AWAY))) @ transforms.rotate_y(0.3) @ transforms.scale(2.0, 2.0, 2.0)
    world = transforms.transform_points(model, np.asarray(mesh.positions, dtype=np.float64))
    tris = np.asarray(mesh.indices, dtype=np.intp).reshape(-1, 3)
    edges = np.array(sorted({tuple(sorted((int(t[k]), int(t[(k + 1) % 3])))) for t in tris for k in range(3)}))
    targets = np.concatenate([world] + [world[edges[:, 0]] + f * (world[edges[:, 1]] - world[edges[:, 0]])
                                        for f in EDGE_POINTS])
    count = size[0] * size[1]
    eyes = at * np.array(AWAY) + np.random.default_rng(21).uniform(-0.4, 0.4, (math.ceil(count / len(targets)), 3))
    origins = np.repeat(eyes, len(targets), axis=0)[:count]
    directions = np.tile(targets, (len(eyes), 1))[:count] - origins
    return (world[tris[:, 0]], world[tris[:, 1]], world[tris[:, 2]]), origins, directions


def nearest_by(test: str, tris: Triangles, origins: NDArray[np.float64],
               directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """The nearest ``t`` of each ray over every triangle (``inf``: none), by ``test``: ``"watertight"``
    (:func:`nearest_watertight`) or ``"mt64"`` (Möller–Trumbore in float64,
    :meth:`~glsandbox.raytrace.triangle.TriangleBatch.nearest_many`): the vectorised scans
    the numpy engine runs, every pair tested."""
    if test == "watertight":
        return nearest_watertight(*tris, origins, directions)[0]
    if test == "mt64":
        from glsandbox.raytrace.triangle import TriangleBatch

        return TriangleBatch(*tris).nearest_many(origins, directions)[0]
    raise ValueError(f"unknown triangle test {test!r}; use watertight or mt64")
