"""Planar effects a scene may ask for: a planar mirror and a planar shadow.

Course section "The stencil Test": ``MarkMirrorDSS``, ``DrawReflectionDSS``,
``XMMatrixReflect``, ``CullClockwise``, ``XMMatrixShadow`` and
``shadowOffsetY``. These are plain data, like the rest of the Scene; the
matrices come from :mod:`glsandbox.transforms`, the passes from
:func:`glsandbox.plan.plan`, and the GL state from :mod:`glsandbox.gl.planar_state`.
No GL here.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from glsandbox import transforms
from glsandbox.errors import NUMBER_LIMIT, SandboxError, check_number, check_numbers, plain

Color = tuple[float, float, float, float]


def _bounded_plane(plane: tuple[float, ...], what: str) -> tuple[float, ...]:
    """The plane normalized (:func:`glsandbox.transforms.normalize_plane`), its distance
    from the origin within the scene's bound."""
    normalized = tuple(float(v) for v in transforms.normalize_plane(plane))
    check_number(normalized[3], f"{what} plane's distance from the origin (d of the normalized plane)")
    return normalized


def _kept(owner: object, name: str, make: Callable[[], np.ndarray]) -> np.ndarray:
    """``make()`` kept in the frozen ``owner`` under ``name`` (not a field: equality, hashing
    and repr ignore it), read-only so that no caller changes what the next one gets. The
    owner is immutable, so the matrix made from its fields stays right: the frames of a
    scene that only moves make it once."""
    matrix = owner.__dict__.get(name)
    if matrix is None:
        matrix = np.array(make(), dtype=np.float64)
        matrix.setflags(write=False)
        object.__setattr__(owner, name, matrix)
    return matrix


@dataclass(frozen=True)
class Mirror:
    """A planar mirror: the node that is the glass, its plane, and what it reflects.

    ``stencil=True`` is the course's method: mark the glass's pixels in the
    stencil buffer (``MarkMirrorDSS``: always pass, replace), then draw the
    reflected nodes only where the stencil matches (``DrawReflectionDSS``:
    equal, keep). ``stencil=False`` draws the reflection without the test, so
    it leaks outside the glass. ``reflected`` names the nodes drawn mirrored
    (the glass itself and the wall it sits in are not among them). The glass
    node's colour alpha is how much of the glass shows over the reflection.
    """

    node: str
    plane: tuple[float, float, float, float]
    reflected: tuple[str, ...]
    stencil: bool = True

    def __post_init__(self) -> None:
        # Normalized once here, so the plan and the executor see the same numbers.
        object.__setattr__(self, "plane", _bounded_plane(self.plane, "mirror"))
        if self.node in self.reflected:
            raise SandboxError(f"mirror node {self.node!r} cannot reflect itself")

    def matrix(self) -> np.ndarray:
        """The reflection matrix R (det -1, R² = I); made once per mirror (read-only)."""
        return _kept(self, "_matrix", lambda: transforms.reflection_matrix(self.plane))


@dataclass(frozen=True)
class PlanarShadow:
    """Casters flattened onto a receiver's plane along the light's rays.

    ``light`` is homogeneous: (x, y, z, 1) a point light, (x, y, z, 0) a
    directional light shining from direction (x, y, z). ``lift`` is the
    course's ``shadowOffsetY``: the shadow is moved this far off the plane,
    along its normal, so it wins the depth test against the receiver.
    ``polygon_offset`` pulls the shadow towards the camera in the depth test
    instead (``glPolygonOffset``: by the depth slope and a few depth steps),
    which holds at any distance. ``stencil=True`` darkens each pixel once
    (stencil equal 0, then set); ``False`` blends every overlapping
    triangle again (the ``double_blend`` mistake).
    """

    receiver: str
    plane: tuple[float, float, float, float]
    light: tuple[float, float, float, float]
    casters: tuple[str, ...]
    lift: float = 0.005
    polygon_offset: bool = True
    stencil: bool = True
    color: Color = (0.0, 0.0, 0.0, 0.5)

    def __post_init__(self) -> None:
        object.__setattr__(self, "plane", _bounded_plane(self.plane, "shadow"))
        check_numbers(self.light, "shadow light", (4,))  # a point light within the scene's bound
        object.__setattr__(self, "light", tuple(float(v) for v in transforms.light_vector(self.light)))
        if not (isinstance(self.lift, (int, float)) and math.isfinite(self.lift) and 0.0 <= self.lift <= NUMBER_LIMIT):
            raise SandboxError(f"shadow lift must be a finite number >= 0, got {plain(self.lift)}")
        object.__setattr__(self, "color", check_numbers(self.color, "shadow colour", (4,), low=0.0, high=1.0))

    @property
    def height(self) -> float:
        """``P·L``: the point light's height above the plane, or the cosine of
        a directional light with the normal; <= 0 means the receiver is unlit."""
        height = self.__dict__.get("_height")
        if height is None:  # the shadow is immutable: once per shadow, not per frame
            height = float(np.dot(self.plane, self.light))
            object.__setattr__(self, "_height", height)
        return height

    def matrix(self) -> np.ndarray:
        """The lifted shadow matrix ``T(lift·n) @ S`` (see :func:`glsandbox.transforms.shadow_matrix`);
        made once per shadow (read-only). A light the matrix refuses is refused at every call."""
        return _kept(self, "_matrix", lambda: transforms.offset_along_normal(self.plane, self.lift)
                     @ transforms.shadow_matrix(self.plane, self.light))


@dataclass(frozen=True)
class ShadowCasting:
    """Which casters cast a shadow, and why the others do not."""

    kept: tuple[str, ...]
    culled: tuple[tuple[str, str], ...] = field(default=())  # (node, reason)
    reason: str = ""  # non-empty: the whole shadow is culled

    @property
    def empty(self) -> bool:
        return not self.kept


def shadow_casters(shadow: PlanarShadow, models: dict[str, tuple[np.ndarray, np.ndarray]]) -> ShadowCasting:
    """Decide what the shadow pass may draw, so that it never draws garbage.

    ``models`` maps each caster to (model matrix, mesh positions). Cases:

    - a light lying in the plane or parallel to it: no shadow matrix exists;
      refused by :func:`glsandbox.transforms.shadow_matrix` with a message;
    - the light below the plane (``P·L < 0``): the receiver's upper side is
      not lit, so nothing is shadowed there: the whole pass is culled;
    - a point light and a caster with a vertex at or above the light's height
      (``P·X >= P·L``): that vertex's ray never reaches the plane (w <= 0 in
      :func:`glsandbox.transforms.shadow_matrix`) and its triangles would be
      projected through infinity: that caster is culled, with the reason.
    """
    shadow.matrix()  # refuses the degenerate lights (transforms.shadow_matrix)
    height = shadow.height
    if height < 0.0:
        return ShadowCasting((), reason=f"light is below the receiver plane (P·L = {height:.3g})")
    plane = np.asarray(shadow.plane)
    kept: list[str] = []
    culled: list[tuple[str, str]] = []
    for name in shadow.casters:
        if name not in models:
            raise SandboxError(f"shadow caster {name!r} is not a node of the scene")
        model, positions = models[name]
        if shadow.light[3] == 1.0 and not _below_by_box(shadow.plane, height, model, positions):
            world = transforms.transform_points(model, positions)
            top = float(np.max(world @ plane[:3] + plane[3]))
            if top >= height - transforms.SHADOW_EPSILON:
                culled.append((name, f"a vertex is {top:.3g} above the plane, not below the point light at {height:.3g}"))
                continue
        kept.append(name)
    return ShadowCasting(tuple(kept), tuple(culled))


#: Each caster mesh's bounding box, by its positions array: (the array, weakly; its centre; its
#: half sizes), made once per mesh (a mesh's arrays are read-only), so that a caster moving every
#: frame is checked from its box (:func:`_below_by_box`), not by transforming every vertex.
_BOXES: dict[int, tuple[weakref.ref, tuple[float, ...], tuple[float, ...]]] = {}


def _box(positions: np.ndarray) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """The centre and half sizes of the bounding box of ``positions`` (kept while the array lives),
    or None for an array that may change (writable) or holds no point."""
    kept = _BOXES.get(id(positions))
    if kept is not None and kept[0]() is positions:
        return kept[1], kept[2]
    if not isinstance(positions, np.ndarray) or positions.flags.writeable or positions.size == 0:
        return None
    points = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    low, high = points.min(axis=0), points.max(axis=0)
    centre, half = tuple((low + high) / 2.0), tuple((high - low) / 2.0)
    if len(_BOXES) >= 256:  # meshes made anew each frame: start again
        _BOXES.clear()
    _BOXES[id(positions)] = (weakref.ref(positions), centre, half)
    return centre, half


def _below_by_box(plane: tuple[float, ...], height: float, model: np.ndarray, positions: np.ndarray) -> bool:
    """True when every vertex of a caster lies below the point light's height, known from its
    mesh's box alone; False where the box cannot tell, and the vertices decide.

    For an affine model ``M = [A t; 0 1]`` a vertex v's height over the plane (n, d) is
    ``n·(A v + t) + d = a·v + n·t + d`` with ``a = Aᵀ n``. Over the box (centre c, half sizes h)
    the largest ``a·v`` is ``a·c + Σ |a_i| h_i``, and every vertex lies in the box, so no vertex is
    higher than that. Only a bound clearly below ``height - SHADOW_EPSILON`` (by a margin far above
    rounding) keeps the caster here: the decision is always the vertices' own, and the culling
    reason, which names the top vertex's height, always comes from them."""
    box = _box(positions)
    if box is None:
        return False
    m = np.asarray(model, dtype=np.float64)
    if m.shape != (4, 4):
        return False
    row_x, row_y, row_z, row_w = m.tolist()
    if row_w != [0.0, 0.0, 0.0, 1.0]:  # a projective model divides by w: only the vertices tell
        return False
    nx, ny, nz, d = plane
    (cx, cy, cz), (hx, hy, hz) = box
    ax = nx * row_x[0] + ny * row_y[0] + nz * row_z[0]
    ay = nx * row_x[1] + ny * row_y[1] + nz * row_z[1]
    az = nx * row_x[2] + ny * row_y[2] + nz * row_z[2]
    offset = nx * row_x[3] + ny * row_y[3] + nz * row_z[3] + d
    spread = abs(ax) * hx + abs(ay) * hy + abs(az) * hz
    top = ax * cx + ay * cy + az * cz + spread + offset
    size = abs(ax * cx) + abs(ay * cy) + abs(az * cz) + spread + abs(offset) + abs(height)
    return top < height - transforms.SHADOW_EPSILON - 1e-9 * (1.0 + size)
