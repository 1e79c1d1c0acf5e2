"""One ray-traced pixel's story: the record of a single ray through the numpy engine.

:func:`explain_ray_pixel` traces one pixel's primary ray, in float64, through the
*same* functions the numpy engine renders with (:mod:`glsandbox.raytrace.numpy_engine`:
its nearest hit, surface, per-light Phong, shadow rays, reflections), listening on the
engine's probe seam, and keeps what each step computed in a :class:`PixelTrace`:

- the primary ray ``R = R0 + t·Rd`` through the pixel's centre (course "Bakış
  noktası, görüntü düzlemi");
- every node's test (:class:`ShapeTest`): its box (course "Hızlandırma: AABB"),
  then its own test, hit or miss and why, in the course's names: a sphere's
  ``l, s, m², q`` (course "Işın-Küre kesim testi"), a triangle's plane ``N·P + D = 0``
  and barycentric ``u, v`` (course "Işın-Üçgen kesim testi"); a miss is *behind*
  (``t ≤ 0``), *parallel* (``N·Rd = 0``), *outside* the triangle, or the box missed;
- the nearest hit (``min_indis``), its point, normal and colour;
- per light (:class:`LightStep`) the shadow ray from the point moved off its surface
  (course "Gölge testi": blocked iff ``0 < s < 1`` towards the light), and the Phong
  terms ``ka·ambient + kd·diffuse + ks·specular`` (course "Phong boyama modeli");
- the reflected ray ``R = Rd − 2(Rd·N)N`` (course "Yansıma vektörü") and its own story,
  to the render's depth;
- the final colour and its 8-bit levels.

:meth:`PixelTrace.replay` adds the recorded terms up again, step by step, and gives the
rendered pixel exactly (the tests check it on a grid of every ray lesson's pixels).
The engine's nearest hit decides the story; the per-node tests are each node's own test
(the same kind functions), listed so a student sees every ``t`` the ``min_indis`` loop compares.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.errors import SandboxError
from glsandbox.frame import single_viewport
from glsandbox.plan import TRACE_OPTIONS
from glsandbox.raytrace import numpy_engine
from glsandbox.raytrace.aabb import AABB, reciprocals
from glsandbox.raytrace.constants import OFFSETS
from glsandbox.raytrace.numpy_engine import RenderStats, to_rgba8
from glsandbox.raytrace.world import NodeInfo, NodeKind, World
from glsandbox.scene import Scene

__all__ = ["Bounce", "LightStep", "PixelTrace", "ShapeTest", "explain_ray_pixel", "locate_pixel"]

#: At most this many triangles of one mesh node are described one by one; a bigger
#: mesh is summed up (how many were behind, parallel, outside).
LISTED_TRIANGLES = 4


@dataclass
class ShapeTest:
    """One node's test against one ray: what the ``min_indis`` loop compares.

    ``verdict`` is ``hit``, ``box`` (its box missed: nothing inside is tested),
    ``miss`` (a sphere passing farther than ``r``), ``behind`` (the only ``t`` are
    ``≤ 0``), ``parallel``, ``outside`` (the plane is met outside the triangle),
    ``culled`` (a one-sided surface seen from behind) or ``beyond`` (a shadow ray's
    occluder test: found beyond the light). ``t`` is along the ray as cast (units of
    its direction); ``values`` holds the course's named numbers of the test.
    """

    node: str
    kind: str
    verdict: str
    why: str
    t: float | None = None
    triangle: int | None = None
    values: dict[str, Any] = field(default_factory=dict)


@dataclass
class LightStep:
    """One light at one hit: the shadow ray and its verdict, and the Phong terms.

    The colour is the engine's (the rasterizer's) per-light formula,
    ``min(ka·colour + kd·max(N·L, 0)·colour⊙light + ks·max(R·E, 0)^n·light, 1)``;
    in shadow only the ambient term stays. ``offset`` is how far the shadow ray's
    origin was moved off the surface (along the normal), ``distance`` the length
    from there to the light; ``blocker``/``blocker_s`` the nearest occluder at
    ``0 < s < 1`` (``s = 1`` is the light).
    """

    index: int
    position: list[float]
    color: list[float]
    to_light: list[float]
    n_dot_l: float
    cosine: float
    blinn: bool
    shininess: float
    ka: float
    kd: float
    ks: float
    ambient: list[float]
    diffuse: list[float]
    specular: list[float]
    shadows: bool
    origin: list[float] | None = None
    offset: float | None = None
    distance: float | None = None
    blocked: bool = False
    blocker: str | None = None
    blocker_s: float | None = None
    term: list[float] = field(default_factory=list)
    #: The term an exercise's function gave instead (``phong`` traced with a student's
    #: function, :mod:`glsandbox.story.seams`): the pixel adds this one up.
    given: list[float] | None = None


@dataclass
class Bounce:
    """One ray of the pixel's path (depth 0: the primary ray) and what it found.

    ``weight`` is its share of the pixel; ``contribution`` what it adds to the pixel
    (``weight·a·(1 − r)·local``, or ``weight·background`` for a miss). ``next`` says
    which ray follows: ``reflection``, ``through`` (a see-through surface) or None.
    """

    depth: int
    origin: list[float]
    direction: list[float]
    weight: float
    tests: list[ShapeTest]
    hit: str | None = None
    t: float | None = None
    triangle: int | None = None
    point: list[float] | None = None
    normal: list[float] | None = None
    base: list[float] | None = None
    alpha: float = 1.0
    lit: bool = False
    lights: list[LightStep] = field(default_factory=list)
    local: list[float] | None = None
    reflectivity: float = 0.0
    coverage: float = 1.0
    last: bool = False
    contribution: list[float] = field(default_factory=list)
    next: str | None = None


@dataclass
class PixelTrace:
    """A ray-traced pixel's whole story (see the module docstring)."""

    title: str
    pixel: tuple[int, int]
    size: tuple[int, int]
    viewport: int
    local_pixel: tuple[int, int]
    viewport_size: tuple[int, int]
    renderer: str
    max_depth: int
    background: list[float]
    bounces: list[Bounce]
    color: list[float]
    rgba8: list[int]
    #: What else the frame shows at the pixel (an overlay drawn over it).
    notes: list[str] = field(default_factory=list)

    def replay(self) -> list[int]:
        """The pixel again from the recorded terms alone, in the engine's order: each
        light's ``min(ka·colour + kd·diffuse + ks·specular, 1)`` (only the ambient in
        shadow) summed, each ray's ``weight·a·(1 − r)·local`` (or ``weight·background``)
        added up, then clamped and rounded to 8 bits. Equals the rendered pixel."""
        out = [0.0, 0.0, 0.0]
        weight = 1.0
        for bounce in self.bounces:
            if bounce.hit is None:
                out = [o + weight * b for o, b in zip(out, self.background)]
                break
            local = _replayed_local(bounce)
            share = weight * bounce.coverage * (1.0 - bounce.reflectivity)
            out = [o + share * c for o, c in zip(out, local)]
            weight = weight * (1.0 - bounce.coverage) if bounce.coverage < 1.0 else weight * bounce.reflectivity
        return [int(v) for v in to_rgba8(np.array(out))]

    def to_dict(self) -> dict[str, Any]:
        """The raw record as plain JSON values (``glsandbox explain --json``)."""
        return asdict(self)


def _replayed_local(bounce: Bounce) -> list[float]:
    """A hit's local colour from its recorded terms (the engine's arithmetic, in its order)."""
    assert bounce.base is not None
    if not bounce.lit:
        return list(bounce.base)
    total = [0.0, 0.0, 0.0]
    for light in bounce.lights:
        if light.given is not None:
            total = [a + b for a, b in zip(total, light.given)]
            continue
        gate = 0.0 if light.blocked else 1.0
        for c in range(3):
            lighting = (light.kd * light.diffuse[c] + light.ks * light.specular[c]) * gate
            total[c] += min(light.ka * bounce.base[c] + lighting, 1.0)
    return total


def _vec(a: Any) -> list[float]:
    return [float(v) for v in np.asarray(a, dtype=np.float64).reshape(-1)[:3]]


def locate_pixel(scene: Scene, size: tuple[int, int], pixel: tuple[int, int]) -> tuple[int, tuple[int, int],
                                                                                      tuple[int, int]]:
    """``(viewport, (x, y) inside it, its (w, h))`` of frame pixel ``(x, y)`` (row 0 at the
    top, as images count); the last viewport drawn there wins. Refuses a pixel outside."""
    width, height = size
    x, y = pixel
    if not (0 <= x < width and 0 <= y < height):
        raise SandboxError(f"--pixel {x},{y}: outside the {width}x{height} frame (x 0..{width - 1}, "
                           f"y 0..{height - 1}, y from the top)")
    found = None
    for i, vp in enumerate(scene.viewports):
        vx, vy, w, h = vp.pixels(width, height)
        top = height - vy - h  # viewports count from the bottom, images from the top
        if vx <= x < vx + w and top <= y < top + h:
            found = (i, (x - vx, y - top), (w, h))
    if found is None:
        raise SandboxError(f"--pixel {x},{y}: no viewport covers it (the clear colour)")
    return found


class _Recorder:
    """The probe: keeps a copy of every step's arrays, in order (one ray, so row 0)."""

    def __init__(self, events: list[tuple[str, dict[str, Any]]] | None = None) -> None:
        self.events: list[tuple[str, dict[str, Any]]] = events if events is not None else []

    def __call__(self, step: str, **values: Any) -> None:
        kept: dict[str, Any] = {}
        for key, value in values.items():
            if isinstance(value, np.ndarray):
                value = value.copy()
            elif value is not None and hasattr(value, "subset"):  # the engine's spawn points
                value = {"point": value.point.copy(), "normal": value.normal.copy()}
            kept[key] = value
        self.events.append((step, kept))


def explain_ray_pixel(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], title: str = "", *,
                      hit_tests: dict[str, Any] | None = None, simple: bool = False,
                      events: list[tuple[str, dict[str, Any]]] | None = None, traced: bool = False) -> PixelTrace:
    """The story of frame pixel ``pixel = (x, y)`` (row 0 at the top) of ``scene`` traced at
    ``size``: the numpy engine's float64 path, with the options frames are traced with
    (:data:`glsandbox.plan.TRACE_OPTIONS`). The pixel must lie in a ray-traced viewport
    (``renderer=ray`` or ``ray_numpy``).

    ``hit_tests`` replaces a node kind's test as :func:`~glsandbox.raytrace.numpy_engine.render_viewport`'s
    does (an exercise's function; no BVH then), ``simple`` takes the course's simple offset for
    secondary rays, and ``events``, when given, receives the engine's recorded steps in order
    (:mod:`glsandbox.story.divergence` compares two of them). ``traced`` traces a rasterised
    viewport's pixel too (as the numpy engine would draw it: an exercise's lesson picture)."""
    index, (lx, ly), (w, h) = locate_pixel(scene, size, pixel)
    vp = scene.viewports[index]
    if vp.renderer == "raster" and not traced:
        raise SandboxError(f"--pixel {pixel[0]},{pixel[1]}: viewport {index} is rasterised; "
                           "its story is the X-ray's (glsandbox.story.raster), or trace it with --set renderer=ray_numpy")
    single = single_viewport(scene, index)
    world, accel = numpy_engine._world_of(single, 0, True, not hit_tests)
    if hit_tests:
        world, accel = replace(world, hit_tests=dict(hit_tests)), None
    eye, dirs = numpy_engine._rays_of(single, 0, w, h)
    row = ly * w + lx
    max_depth = int(TRACE_OPTIONS["max_depth"])
    shadows = bool(TRACE_OPTIONS["shadows"])
    recorder = _Recorder(events)
    rgb = numpy_engine._trace(world, eye, dirs[row:row + 1], max_depth, shadows, None, True, RenderStats(), accel,
                              OFFSETS["simple"] if simple else OFFSETS["bound"], probe=recorder)
    recorder.events.append(("end", {}))  # what a hit test handed in is asked after this is not the trace's
    bounces = _bounces(world, [e for e in recorder.events if e[0] not in ("call", "end")], shadows)
    return PixelTrace(title=title or scene.name, pixel=(int(pixel[0]), int(pixel[1])), size=(int(size[0]), int(size[1])),
                      viewport=index, local_pixel=(lx, ly), viewport_size=(w, h),
                      renderer="ray_numpy" if vp.renderer == "raster" else vp.renderer,
                      max_depth=max_depth, background=_vec(world.background), bounces=bounces, color=_vec(rgb),
                      rgba8=[int(v) for v in to_rgba8(rgb)[0]], notes=overlays_over(scene, size, pixel))


def overlays_over(scene: Scene, size: tuple[int, int], pixel: tuple[int, int]) -> list[str]:
    """A line for each overlay (a lesson's text panel) drawn over frame pixel ``(x, y)``: the frame
    shows it there, over the traced colour."""
    width, height = size
    x, gl_y = pixel[0], height - 1 - pixel[1]  # overlays are placed in GL's rows (y up)
    lines = []
    for overlay in scene.overlays:
        viewport = scene.viewports[overlay.viewport] if overlay.viewport is not None else None
        region = viewport.pixels(width, height) if viewport is not None else (0, 0, width, height)
        # A figure in the world (the exam's rays) is drawn where the camera sees it.
        overlay = overlay.seen_by(viewport.camera if viewport is not None and viewport.camera else scene.camera, region)
        ox, oy, ow, oh = overlay.placement(region)
        if ox <= x < ox + ow and oy <= gl_y < oy + oh and overlay.image[oy + oh - 1 - gl_y, x - ox, 3] > 0:
            lines.append(f"the overlay {overlay.name!r} is drawn over this pixel: the frame shows it here, "
                         "over the traced colour below")
    return lines


def _bounces(world: World, events: list[tuple[str, dict[str, Any]]], shadows: bool) -> list[Bounce]:
    """The recorded steps, grouped ray by ray."""
    bounces: list[Bounce] = []
    weight_of_next = 1.0
    current: Bounce | None = None
    spawn_point: NDArray[np.float64] | None = None
    for step, v in events:
        if step == "ray":
            o = np.asarray(v["origin"], dtype=np.float64).reshape(-1, 3)[:1]
            d = np.asarray(v["direction"], dtype=np.float64)[:1]
            current = Bounce(depth=int(v["depth"]), origin=_vec(o), direction=_vec(d),
                             weight=float(np.asarray(v["weight"]).reshape(-1)[0]), tests=_node_tests(world, o, d))
            node = int(v["node"][0])
            bounces.append(current)
            if node < 0:
                current.contribution = [current.weight * b for b in _vec(world.background)]
                continue
            current.hit = world.nodes[node].name
            current.t = float(v["t"][0])
            tri = int(v["tri"][0])
            current.triangle = tri - world.nodes[node].start if tri >= 0 else None
        elif step == "surface":
            assert current is not None
            current.point = _vec(v["point"])
            current.normal = _vec(v["normal"])
            current.base = _vec(v["base"])
            current.alpha = float(v["alpha"][0])
            current.lit = bool(v["lit"][0])
            spawn_point = None if v["spawn"] is None else np.asarray(v["spawn"]["point"])[0]
        elif step == "light":
            assert current is not None
            current.lights.append(_light_step(world, current, v, spawn_point, shadows))
        elif step == "local":
            assert current is not None
            current.local = _vec(v["local"])
            current.reflectivity = float(v["reflectivity"][0])
            current.coverage = float(v["coverage"][0])
            current.last = bool(v["last"])
            share = current.weight * current.coverage * (1.0 - current.reflectivity)
            current.contribution = [share * c for c in current.local]
        elif step == "bounce":
            assert current is not None
            current.next = "through" if bool(v["through"][0]) else "reflection"
    return bounces


def _light_step(world: World, bounce: Bounce, v: dict[str, Any], spawn: NDArray[np.float64] | None,
                shadows: bool) -> LightStep:
    index = int(v["index"])
    position = world.light_positions[index]
    color = world.light_colors[index]
    ka, kd, ks = (float(np.asarray(v[k]).reshape(-1)[0]) for k in ("ka", "kd", "ks"))
    base = np.asarray(bounce.base)
    diffuse, specular = _vec(v["diffuse"]), _vec(v["specular"])
    step = LightStep(index=index, position=_vec(position), color=_vec(color), to_light=_vec(v["to_light"]),
                     n_dot_l=float(v["n_dot_l"][0]), cosine=float(v["cosine"][0]), blinn=bool(v["blinn"][0]),
                     shininess=float(v["shininess"][0]), ka=ka, kd=kd, ks=ks, ambient=_vec(ka * base),
                     diffuse=diffuse, specular=specular, shadows=shadows)
    if shadows and v["start"] is not None:
        start = np.asarray(v["start"], dtype=np.float64)[:1]
        step.origin = _vec(start)
        step.blocked = bool(v["blocked"][0])
        reference = spawn if spawn is not None else np.asarray(bounce.point)
        step.offset = float(np.linalg.norm(start[0] - reference))
        step.distance = float(np.linalg.norm(position - start[0]))
        hits = numpy_engine._top_level(world, start, position - start, 1.0, None, True, index, None, None)
        if int(hits.node[0]) >= 0:
            step.blocker = world.nodes[int(hits.node[0])].name
            step.blocker_s = float(hits.t[0])
    gate = 0.0 if step.blocked else 1.0
    step.term = [float(min(ka * base[c] + (kd * diffuse[c] + ks * specular[c]) * gate, 1.0)) for c in range(3)]
    if v.get("given") is not None:
        step.given = step.term = _vec(v["given"])
    return step


# --- each node's own test, in the course's names ---------------------------------


def _node_tests(world: World, o: NDArray[np.float64], d: NDArray[np.float64]) -> list[ShapeTest]:
    """Every node's box and own test against the ray ``o + t·d`` (``(1, 3)`` each)."""
    inverse = reciprocals(d)
    tests = []
    for k, node in enumerate(world.nodes):
        near, far = AABB(node.box_min, node.box_max).slabs_reciprocal(o, inverse)
        if not (near[0] <= far[0] and far[0] > 0.0):
            why = "the ray misses its box (AABB), so nothing inside is tested" if near[0] > far[0] else \
                "its box (AABB) is behind the ray"
            tests.append(ShapeTest(node.name, node.kind.value, "box", why))
            continue
        one_sided = bool(node.cull)
        t, j = numpy_engine._hit_node(world, k, o, d, one_sided)
        t_hit = float(t[0]) if math.isfinite(float(t[0])) else None
        if node.kind is NodeKind.SPHERE:
            tests.append(_sphere_test(node, o[0], d[0], t_hit, one_sided))
        elif node.kind is NodeKind.MESH:
            tests.append(_mesh_test(world, node, o, d, t_hit, int(j[0]), one_sided))
        else:
            why = f"meets the capped cylinder at t = {t_hit:.6g}" if t_hit is not None else \
                "misses the capped cylinder (x² + z² ≤ 1, |y| ≤ 1 in its own space)"
            tests.append(ShapeTest(node.name, node.kind.value, "hit" if t_hit is not None else "miss", why, t_hit))
    return tests


def _sphere_test(node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64], t_hit: float | None,
                 one_sided: bool) -> ShapeTest:
    """The course's geometric sphere test with the world's centre and radius (an ellipsoid:
    in the node's own space, where it is the unit sphere). The engine's ``t`` is from the
    stable form (``glsandbox.raytrace.sphere``); the two agree to rounding."""
    model = np.linalg.inv(node.inverse)
    m3 = model[:3, :3]
    gram = m3.T @ m3
    uniform = bool(np.allclose(gram, gram[0, 0] * np.eye(3), rtol=1e-9, atol=1e-12 * gram[0, 0]))
    if uniform:
        center, radius, oo, dd, space = model[:3, 3], math.sqrt(gram[0, 0]), o, d, "world"
    else:
        inv = node.inverse
        center, radius = np.zeros(3), 1.0
        oo, dd, space = inv[:3, :3] @ o + inv[:3, 3], inv[:3, :3] @ d, "own"
    d_len = float(np.linalg.norm(dd))
    unit = dd / d_len  # the course's Rd is a unit vector
    l = center - oo  # noqa: E741 (the course's l)
    s = float(l @ unit)
    l2 = float(l @ l)
    m2 = l2 - s * s
    r2 = radius * radius
    values: dict[str, Any] = {"space": space, "C": _vec(center), "r": radius, "l": _vec(l), "s": s, "m2": m2,
                              "r2": r2, "direction_length": d_len}
    if t_hit is None and one_sided and l2 < r2:
        return ShapeTest(node.name, "sphere", "culled", "the ray starts inside a one-sided sphere: "
                         "every front face faces away", None, values=values)
    if m2 > r2:
        why = f"m² = {m2:.6g} > r² = {r2:.6g}: the ray passes {math.sqrt(max(m2, 0.0)):.6g} from the centre"
        return ShapeTest(node.name, "sphere", "miss", why, t_hit, values=values)
    q = math.sqrt(r2 - m2)
    values["q"] = q
    outside = l2 > r2
    values["outside"] = outside
    t_unit = s - q if outside else s + q
    values["t_unit"] = t_unit
    if t_hit is None:
        why = "s < 0 and the origin is outside: the sphere is behind the ray" if outside and s < 0.0 else \
            f"t = {t_unit:.6g} ≤ 0: behind the ray"
        return ShapeTest(node.name, "sphere", "behind", why, None, values=values)
    form = "outside (l·l > r²), so t = s − q" if outside else "inside (l·l ≤ r²), so t = s + q"
    return ShapeTest(node.name, "sphere", "hit", form, t_hit, values=values)


def _mesh_test(world: World, node: NodeInfo, o: NDArray[np.float64], d: NDArray[np.float64], t_hit: float | None,
               j: int, one_sided: bool) -> ShapeTest:
    """A mesh node's triangles, each classified as the course's two-step test does: the
    plane ``N·P + D = 0`` first (parallel, behind, a back face culled), then whether the
    plane's point is inside (barycentric ``u, v ≥ 0``, ``u + v ≤ 1``). The engine's hit
    is its watertight test's (an edge shared by two triangles goes to one of them)."""
    rows = slice(node.start, node.start + node.count)
    v0, v1, v2 = world.v0[rows], world.v1[rows], world.v2[rows]
    e1, e2 = v1 - v0, v2 - v0
    n = np.cross(e1, e2)
    n_len = np.linalg.norm(n, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit_n = n / n_len[:, None]
        plane_d = -np.einsum("ij,ij->i", unit_n, v0)  # the course's D: N·V0 + D = 0
        n_dot_d = unit_n @ d[0]
        t_plane = -(unit_n @ o[0] + plane_d) / n_dot_d
        u, v = numpy_engine._barycentric(v0, e1, e2, np.broadcast_to(o[0], v0.shape),
                                         np.broadcast_to(d[0], v0.shape))
    degenerate = ~(n_len > 0.0)
    parallel = ~degenerate & (n_dot_d == 0.0)
    behind = ~degenerate & ~parallel & ~(t_plane > 0.0)
    culled = ~degenerate & ~parallel & ~behind & one_sided & (n_dot_d > 0.0)
    open_ = ~(degenerate | parallel | behind | culled)
    outside = open_ & ((u < 0.0) | (v < 0.0) | (u + v > 1.0))
    local = j - node.start if j >= 0 else -1
    counts = {"triangles": int(node.count), "parallel": int(parallel.sum()), "behind": int(behind.sum()),
              "culled": int(culled.sum()), "outside": int(outside.sum()), "degenerate": int(degenerate.sum())}

    def about(i: int) -> dict[str, Any]:
        return {"triangle": i, "N": _vec(unit_n[i]), "D": float(plane_d[i]), "N_dot_Rd": float(n_dot_d[i]),
                "t_plane": float(t_plane[i]), "u": float(u[i]), "v": float(v[i])}

    values: dict[str, Any] = {"counts": counts}
    if node.count <= LISTED_TRIANGLES:
        values["each"] = [about(i) | {"verdict": _triangle_verdict(i, local, parallel, behind, culled, outside,
                                                                   degenerate)} for i in range(node.count)]
    if t_hit is not None:
        values["hit"] = about(local)
        return ShapeTest(node.name, "mesh", "hit", f"triangle {local} of {node.count}", t_hit, local, values)
    # The nearest reason, for the story: an "outside" plane hit, else behind, parallel, culled.
    for verdict, mask in (("outside", outside), ("culled", culled), ("behind", behind), ("parallel", parallel)):
        if mask.any():
            candidates = np.flatnonzero(mask)
            i = int(candidates[np.argmin(np.where(np.isfinite(t_plane[candidates]), np.abs(t_plane[candidates]),
                                                  np.inf))])
            values["nearest"] = about(i)
            return ShapeTest(node.name, "mesh", verdict, _mesh_why(verdict, counts), None, i, values)
    return ShapeTest(node.name, "mesh", "miss", "no triangle of non-zero area", None, values=values)


def _triangle_verdict(i: int, hit: int, parallel: NDArray[np.bool_], behind: NDArray[np.bool_],
                      culled: NDArray[np.bool_], outside: NDArray[np.bool_], degenerate: NDArray[np.bool_]) -> str:
    if i == hit:
        return "hit"
    for name, mask in (("degenerate", degenerate), ("parallel", parallel), ("behind", behind), ("culled", culled),
                       ("outside", outside)):
        if mask[i]:
            return name
    return "not the nearest"  # inside, on an edge the watertight test gave to another triangle


def _mesh_why(verdict: str, counts: dict[str, int]) -> str:
    parts = [f"{counts[k]} {k}" for k in ("outside", "behind", "parallel", "culled", "degenerate") if counts[k]]
    lead = {"outside": "every plane it meets in front is met outside its triangle",
            "behind": "every triangle's plane is behind the ray",
            "parallel": "the ray runs parallel to the triangles' planes",
            "culled": "the triangles it meets face away (backface culling)"}[verdict]
    return f"{lead} ({', '.join(parts)} of {counts['triangles']})"
