"""The exercises' functions as steps of one traced ray: each one a seam of the numpy engine.

:mod:`glsandbox.story.divergence` traces a pixel twice, once with an exercise's reference and
once with the student's function, each plugged into the one step of the engine's float64 path
that the function is (the engine's seams, :data:`glsandbox.raytrace.numpy_engine.SEAMS` and its
``hit_tests``). A plugged function changes only that step's results; every call is logged into
the trace's events as ``("call", {...})`` (its inputs, its answers, what each was asked about),
between the engine's own steps. The steps:

- ``ray_plane``: the first step of the triangles' test (course "Işın-Üçgen kesim testi"):
  ``t`` where the ray meets each triangle's plane ``N·P + d = 0`` (``N`` its unit normal,
  ``d = −N·V0``), then the engine's inside test at ``R0 + t·Rd``: ``P − V0 = u·e1 + v·e2``
  with ``u, v ≥ 0``, ``u + v ≤ 1``, from dot products (the notes' test III);
- ``aabb``: whether a ray enters a node's box (course "Hızlandırma: AABB"): ``t > 0`` from
  ``intersect_aabb`` is the box entered, and only then is the node tested;
- ``backface``: which triangles of a one-sided (culled) mesh face away (course "Hızlandırma:
  backface culling"); the others keep the engine's watertight test;
- ``reflect``: the reflected ray's direction ``R = Rd − 2(Rd·N)N`` (course "Yansıma vektörü");
- ``phong``: a white light's term ``ka·C + kd·max(0, N·L)·C + ks·max(0, R·E)^n`` at a lit hit
  (course "Phong boyama modeli"), with ``C`` in 0..255 as the exercise has it (the answer is
  divided by 255 and clamped as the engine's term is); a coloured light, a Blinn-Phong material
  and a point in shadow keep the engine's terms (in shadow only the ambient stays);
- ``triangle_normal``: a hit triangle's face normal ``(V1 − V0) × (V2 − V0)``, normalized
  (course "Vektörel işlemler"), where the tracer uses it: which side of a two-sided triangle
  the ray sees (its back face is lit with the normal reversed) and which way a secondary ray
  is moved off the surface (the shading normal stays the mesh's vertex normals);
- ``shadow``: whether a hit is in shadow of a light (course "Gölge testi"): ``in_shadow`` over
  the triangles of the scene's meshes (the light's own lamp left out, as the engine does),
  from the hit point itself (the function moves off the surface); an analytic shape (a
  sphere) between still shadows by the engine's own test, not being a triangle.

The student's function is only called through ``caller.batch(inputs)`` (their confined
process, or in a notebook their own function).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.exercises.definition import Exercise
from glsandbox.exercises.compare import WrongType, normalize

__all__ = ["STEPS", "Logged", "answers_of", "seams_for"]

#: Each exercise whose function a traced ray calls, and the step it is (see the module docstring).
STEPS = {"ray_sphere": "the sphere's hit test", "ray_triangle": "the triangles' hit test",
         "ray_plane": "the triangles' plane", "aabb": "the nodes' boxes", "backface": "backface culling",
         "reflect": "the reflected ray", "phong": "a white light's Phong term", "shadow": "the shadow test",
         "triangle_normal": "a hit triangle's face normal"}


def _vec(a: Any) -> tuple[float, ...]:
    return tuple(float(x) for x in np.asarray(a, dtype=np.float64).reshape(-1)[:3])


def answers_of(asker: Any, inputs: list[tuple[Any, ...]]) -> list[Any]:
    """Each input's answer from ``asker.caller``, normalized as ``asker.exercise`` returns: a
    value, or an ``error: ...`` string. A caller that stops answering sets ``asker.error``."""
    if not inputs:
        return []
    batch = asker.caller.batch(inputs) if not asker.error else None
    if batch is None or not isinstance(batch, tuple):
        asker.error = asker.error or f"your function stopped answering ({getattr(batch, 'error', '')})"
        return [f"error: {asker.error}"] * len(inputs)
    values, errors = batch
    out: list[Any] = []
    for i, value in enumerate(values):
        if i in errors:
            out.append(f"error: {errors[i]}")
            continue
        try:
            out.append(normalize(value, asker.exercise.returns))
        except WrongType as exc:
            out.append(f"error: {exc}")
    return out


class Logged:
    """A caller's function asked in batches, each batch logged into ``events`` (until the
    trace's ``end``) as ``("call", {"kind", "inputs", "answers", "what", ...})``."""

    kind = "call"

    def __init__(self, exercise: Exercise, caller: Any, events: list[tuple[str, dict[str, Any]]]) -> None:
        self.exercise, self.caller, self.events = exercise, caller, events
        self.error = ""

    def answers(self, inputs: list[tuple[Any, ...]]) -> list[Any]:
        return answers_of(self, inputs)

    def ask(self, inputs: list[tuple[Any, ...]], what: list[str], **extra: Any) -> list[Any]:
        """The answers to ``inputs``, the call logged with ``what`` each input was about."""
        answers = self.answers(inputs)
        if inputs and not (self.events and self.events[-1][0] == "end"):
            self.events.append(("call", {"kind": self.kind, "inputs": inputs, "answers": answers, "what": what,
                                         **extra}))
        return answers


def _t(answer: Any) -> float:
    """A ``t`` answer as the engine takes it: a number ``> 0``, else no hit (``inf``)."""
    return float(answer) if isinstance(answer, (int, float)) and not isinstance(answer, bool) and answer > 0 \
        else math.inf


class PlaneSeam(Logged):
    """``intersect_plane`` as the first step of the triangles' hit test (the engine's
    ``hit_tests["triangles"]``), the inside test after it the engine's."""

    kind = "plane"

    def __call__(self, o: NDArray[np.float64], d: NDArray[np.float64], v0: NDArray[np.float64],
                 v1: NDArray[np.float64], v2: NDArray[np.float64], one_sided: bool
                 ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        n, m = d.shape[0], v0.shape[0]
        e1, e2 = v1 - v0, v2 - v0
        normal = np.cross(e1, e2)
        size = np.linalg.norm(normal, axis=1)
        t = np.full((n, m), np.inf)
        open_ = np.flatnonzero(size > 0.0)  # a triangle of zero area has no plane
        unit = normal[open_] / size[open_, None]
        plane_d = -np.einsum("ij,ij->i", unit, v0[open_])  # N·V0 + d = 0
        inputs = [(_vec(o[i]), _vec(d[i]), _vec(unit[k]), float(plane_d[k])) for i in range(n)
                  for k in range(len(open_))]
        what = [f"on {{node}}, triangle {int(j)}'s plane" for _ in range(n) for j in open_]
        answers = self.ask(inputs, what, first=_vec(v0[0]) if m else None)
        if open_.size:
            t[:, open_] = np.array([_t(a) for a in answers], dtype=np.float64).reshape(n, open_.size)
        with np.errstate(invalid="ignore"):
            # The inside test at the plane's point (the notes' test III): P − V0 = u·e1 + v·e2.
            p = o[:, None, :] + np.where(np.isfinite(t), t, 0.0)[:, :, None] * d[:, None, :] - v0[None]
            d11, d12, d22 = (np.einsum("ij,ij->i", a, b) for a, b in ((e1, e1), (e1, e2), (e2, e2)))
            p1, p2 = np.einsum("nmj,mj->nm", p, e1), np.einsum("nmj,mj->nm", p, e2)
            det = np.where(d11 * d22 - d12 * d12 == 0.0, 1.0, d11 * d22 - d12 * d12)
            u, v = (d22 * p1 - d12 * p2) / det, (d11 * p2 - d12 * p1) / det
            inside = (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0)
        t = np.where(inside, t, np.inf)
        if one_sided:  # back-face culling is the engine's, not the exercise's: N·Rd > 0 is dropped
            t = np.where(d @ normal.T > 0.0, np.inf, t)
        j = np.argmin(t, axis=1) if m else np.zeros(n, dtype=np.intp)
        best = t[np.arange(n), j] if m else np.full(n, np.inf)
        return best, np.where(np.isfinite(best), j, -1)


class BoxSeam(Logged):
    """``intersect_aabb`` as the engine's box test of each node (``"aabb"``)."""

    kind = "aabb"

    def __call__(self, node: Any, o: NDArray[np.float64], d: NDArray[np.float64]) -> NDArray[np.bool_]:
        o = np.broadcast_to(o, d.shape)
        box = (_vec(node.box_min), _vec(node.box_max))
        answers = self.ask([(_vec(a), _vec(b), *box) for a, b in zip(o, d, strict=True)],
                           [f"on {node.name}'s box"] * d.shape[0])
        return np.array([math.isfinite(_t(a)) for a in answers], dtype=bool)


class BackfaceSeam(Logged):
    """``is_backface`` as the engine's culling of a one-sided mesh node (``"backface"``): the
    triangles it calls back faces are skipped, the others tested by the watertight test."""

    kind = "backface"

    def __call__(self, world: Any, node: Any, o: NDArray[np.float64], d: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        from glsandbox.raytrace.watertight import nearest_watertight

        rows = slice(node.start, node.start + node.count)
        v0, v1, v2 = world.v0[rows], world.v1[rows], world.v2[rows]
        n, m = d.shape[0], node.count
        inputs = [(_vec(v0[k]), _vec(v1[k]), _vec(v2[k]), _vec(d[i])) for i in range(n) for k in range(m)]
        answers = self.ask(inputs, [f"on {node.name}, triangle {k}" for _ in range(n) for k in range(m)])
        culled = np.array([a is True for a in answers], dtype=bool).reshape(n, m)

        def accept(rays: NDArray[np.intp], triangles: NDArray[np.intp], t: NDArray[np.float64]) -> NDArray[np.bool_]:
            return ~culled[rays, triangles]

        t, j = nearest_watertight(v0, v1, v2, np.broadcast_to(o, d.shape), d, cull_backfaces=False, accept=accept)
        return t, np.where(j >= 0, j + node.start, -1)


class ReflectSeam(Logged):
    """``reflect`` as the reflected ray's direction (``"reflect"``); a failed call's ray goes
    nowhere (its direction is not a number)."""

    kind = "reflect"

    def __call__(self, d: NDArray[np.float64], n: NDArray[np.float64]) -> NDArray[np.float64]:
        answers = self.ask([(_vec(a), _vec(b)) for a, b in zip(d, n, strict=True)],
                           ["for the reflected ray"] * d.shape[0])
        return np.array([a if isinstance(a, tuple) else (math.nan,) * 3 for a in answers], dtype=np.float64)


class PhongSeam(Logged):
    """``phong`` as a white light's term at each lit hit outside its shadow (``"phong"``)."""

    kind = "phong"

    def __call__(self, world: Any, index: int, nodes: NDArray[np.intp], v: dict[str, Any]) -> NDArray[np.float64]:
        term = np.array(v["term"], dtype=np.float64)
        white = bool(np.all(world.light_colors[index] == 1.0))
        blocked = v["blocked"] if v["blocked"] is not None else np.zeros(term.shape[0], dtype=bool)
        rows = [i for i in range(term.shape[0]) if white and not v["blinn"][i] and not blocked[i]]
        inputs = [(_vec(v["normal"][i]), _vec(v["to_light"][i]), _vec(v["to_eye"][i]),
                   _vec(255.0 * v["color"][i]), float(v["ka"][i, 0]), float(v["kd"][i, 0]), float(v["ks"][i, 0]),
                   float(v["shininess"][i])) for i in rows]
        answers = self.ask(inputs, [f"on {world.nodes[int(nodes[i])].name}" for i in rows], light=index)
        for i, answer in zip(rows, answers, strict=True):
            term[i] = np.minimum(np.asarray(answer, dtype=np.float64) / 255.0, 1.0) if isinstance(answer, tuple) \
                else 0.0  # a failed call lights nothing
        return term


class ShadowSeam(Logged):
    """``in_shadow`` over the scene's triangles as the shadow test (``"shadow"``)."""

    kind = "shadow"

    def __call__(self, world: Any, point: NDArray[np.float64], start: NDArray[np.float64], index: int,
                 cull: bool | None, aabb: bool) -> NDArray[np.bool_]:
        from glsandbox.raytrace import numpy_engine

        light = world.light_positions[index]
        triangles = [(_vec(world.v0[k]), _vec(world.v1[k]), _vec(world.v2[k])) for node in world.nodes
                     if node.kind.triangles and not node.lamp_of >> index & 1
                     for k in range(node.start, node.start + node.count)]
        answers = self.ask([(_vec(p), _vec(light), triangles) for p in point], ["towards its light"] * len(point))
        mine = np.array([a is True for a in answers], dtype=bool)
        shapes = [node for node in world.nodes if not node.kind.triangles]  # a sphere is not a triangle
        if not shapes:
            return mine
        analytic = replace(world, nodes=shapes, hit_tests={})
        return mine | numpy_engine._occluded(analytic, start, light - start, index, cull, aabb)


class NormalSeam(Logged):
    """``triangle_normal`` as the face normal of the hit triangles (``"normal"``); no normal (a
    None, a failed call) is the zero vector."""

    kind = "normal"

    def __call__(self, world: Any, node: Any, tri: NDArray[np.intp]) -> NDArray[np.float64]:
        answers = self.ask([(_vec(world.v0[k]), _vec(world.v1[k]), _vec(world.v2[k])) for k in tri],
                           [f"on {node.name}, triangle {int(k) - node.start}" for k in tri])
        return np.array([a if isinstance(a, tuple) else (0.0, 0.0, 0.0) for a in answers], dtype=np.float64
                        ).reshape(-1, 3)


#: Each exercise's seam: the World's key it takes and its class.
_SEAMS: dict[str, tuple[str, type[Logged]]] = {
    "ray_plane": ("triangles", PlaneSeam), "aabb": ("aabb", BoxSeam), "backface": ("backface", BackfaceSeam),
    "reflect": ("reflect", ReflectSeam), "phong": ("phong", PhongSeam), "shadow": ("shadow", ShadowSeam),
    "triangle_normal": ("normal", NormalSeam)}


def seams_for(exercise: Exercise, caller: Any, events: list[tuple[str, dict[str, Any]]]) -> tuple[dict[str, Any],
                                                                                                Logged] | None:
    """``(hit_tests, seam)`` plugging ``exercise``'s function into a traced ray, or None when it
    is not one of this module's (the sphere and triangle tests are :mod:`glsandbox.story.divergence`'s)."""
    if exercise.name not in _SEAMS:
        return None
    key, cls = _SEAMS[exercise.name]
    seam = cls(exercise, caller, events)
    return {key: seam}, seam
