"""Oracles for the rasterizer far from the origin and at small scale.

One scene, :func:`oracle_scene`: a floor, a box, a sphere and a thin decal a
hair (0.002 units) above the floor, lit by one point light with a shadow map.
The whole scene (nodes, light, camera, near and far) is scaled about the
origin by ``scale`` and then translated by ``offset`` along
:data:`~glsandbox.measure.knobs._far.DIRECTION`. Everything in the picture is
the same at every offset and scale, so the picture at the origin (same scale)
is the oracle for the others:

- :func:`triangle_ids`: each triangle drawn in a colour of its own, unlit
  (the ids are exact 8-bit levels, read back with :func:`decode_ids`). A
  triangle-id pixel that differs from the origin's picture is a vertex that
  moved on screen, or a depth test decided the other way (the decal loses to
  the floor: z-fighting). :func:`id_shift` counts both.
- :func:`shadow_state`: the lit/shadowed state of every pixel of the
  shadow-mapped frame against the ray tracer's shadow rays on the same scene
  (:mod:`glsandbox.measure.shadow_state`), off the reference's edge band.

Measured by tests/measure/test_far_raster.py and the ``far`` rows of
docs/numerics.md.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from glsandbox import geometry, transforms
from glsandbox.geometry import Mesh
from glsandbox.measure.knobs._far import DIRECTION
from glsandbox.measure.shadow_state import edge_band, shadow_mask, state_mismatch, without_shadows
from glsandbox.scene import Camera, Light, Material, Node, Scene, ShadowMap

#: Where the oracles place the scene (as the issue's table: 0, 1e3, 1e5, 9e5).
OFFSETS = (0.0, 1e3, 1e5, 9e5)
#: The small scene: 1e-4 of the size, placed at 1e3.
SMALL = (1e-4, 1e3)
#: The decal's height above the floor (unscaled units).
DECAL_LIFT = 0.002
#: Id levels step by 16 per channel: 15 ids a channel, nonzero, 3375 in all;
#: a level read back within 7 of a step is that step.
_ID_STEP = 16
_ID_BASE = 15


def _lit(rgb: tuple[float, float, float]) -> Material:
    return Material(color=(*rgb, 1.0), shading="phong", ambient=0.15, diffuse=0.85, specular=0.0)


def oracle_scene(offset: float = 0.0, scale: float = 1.0, shadow: ShadowMap | None = ShadowMap()) -> Scene:
    """The floor, box, sphere and decal, scaled by ``scale`` about the origin and moved by
    ``offset`` along ``DIRECTION``; the light casts ``shadow`` (None: no shadow map)."""
    shift = offset * DIRECTION
    place = transforms.translate(*shift) @ transforms.scale(scale, scale, scale)
    parts = (
        ("floor", geometry.plane(1.0), transforms.scale(10.0, 1.0, 10.0), (0.8, 0.8, 0.8)),
        ("box", geometry.cube24(), transforms.translate(-1.2, 0.6, -0.4) @ transforms.rotate_y(0.5)
         @ transforms.scale(0.6, 0.6, 0.6), (0.9, 0.35, 0.2)),
        ("sphere", geometry.sphere(), transforms.translate(1.1, 0.7, 0.3) @ transforms.scale(0.7, 0.7, 0.7),
         (0.25, 0.45, 0.9)),
        ("decal", geometry.plane(1.0), transforms.translate(0.2, DECAL_LIFT, 1.6) @ transforms.scale(1.2, 1.0, 0.8),
         (0.2, 0.75, 0.3)),
    )
    nodes = tuple(Node(name, mesh, place @ model, _lit(rgb), casts_shadow=name != "decal")
                  for name, mesh, model, rgb in parts)

    def point(p: tuple[float, float, float]) -> tuple[float, float, float]:
        return tuple(float(c) for c in scale * np.asarray(p, dtype=np.float64) + shift)  # type: ignore[return-value]

    camera = Camera(eye=point((2.2, 3.4, 5.6)), target=point((0.0, 0.3, 0.3)), fov_y=45.0,
                    near=0.05 * scale, far=40.0 * scale)
    light = Light(point((3.0, 5.0, 2.0)), shadow=shadow)
    return Scene("far_oracle", nodes=nodes, camera=camera, lights=(light,), clear_color=(0.0, 0.0, 0.0, 1.0))


def id_color(index: int) -> tuple[float, float, float]:
    """The colour (0..1) that stands for triangle ``index`` (from 0)."""
    digits = []
    for _ in range(3):
        digits.append(index % _ID_BASE + 1)
        index //= _ID_BASE
    if index:
        raise ValueError("too many triangles for an id picture")
    return tuple(d * _ID_STEP / 255.0 for d in digits)  # type: ignore[return-value]


def _id_mesh(mesh: Mesh, first: int) -> Mesh:
    """``mesh``'s triangles unshared, each vertex coloured with its triangle's id."""
    corners = mesh.triangle_indices()
    positions = mesh.positions[corners.reshape(-1)]
    colors = np.repeat(np.array([id_color(first + t) for t in range(len(corners))]), 3, axis=0)
    return Mesh(f"{mesh.name}_ids{first}", positions, colors=colors)


def triangle_ids(scene: Scene) -> Scene:
    """``scene`` with every node's triangles in colours of their own (unlit, no shadows)."""
    nodes, first = [], 0
    for node in scene.nodes:
        mesh = _id_mesh(node.mesh, first)
        first += len(node.mesh.triangle_indices())
        nodes.append(dataclasses.replace(node, mesh=mesh, material=Material(shading="vertex_color")))
    return dataclasses.replace(without_shadows(scene), nodes=tuple(nodes))


def node_triangles(scene: Scene) -> dict[str, range]:
    """The triangle ids :func:`triangle_ids` gives each node, by name."""
    out, first = {}, 0
    for node in scene.nodes:
        count = len(node.mesh.triangle_indices())
        out[node.name] = range(first, first + count)
        first += count
    return out


def decode_ids(image: np.ndarray) -> np.ndarray:
    """Triangle ids of an id picture's pixels (-1: background or a colour that is no id)."""
    rgb = np.asarray(image)[..., :3].astype(np.int32)
    digits = np.rint(rgb / _ID_STEP).astype(np.int32)
    exact = np.all(np.abs(rgb - digits * _ID_STEP) <= 7, axis=-1) & np.all((digits >= 1) & (digits <= _ID_BASE), -1)
    ids = (digits[..., 0] - 1) + _ID_BASE * (digits[..., 1] - 1) + _ID_BASE ** 2 * (digits[..., 2] - 1)
    return np.where(exact, ids, -1)


@dataclass(frozen=True)
class IdShift:
    """How a far picture's triangle ids differ from the origin's."""

    moved: int  # pixels whose id differs
    off_edge: int  # ... of them outside the origin picture's edge band (2 px)
    decal: int  # the decal's pixels at the origin
    decal_lost: int  # ... of them showing another id in the far picture

    def __str__(self) -> str:
        return (f"{self.moved} id px moved ({self.off_edge} off the edges), "
                f"decal {self.decal - self.decal_lost}/{self.decal} px")


def id_picture(renderer: Any, scene: Scene, size: tuple[int, int]) -> np.ndarray:
    """The triangle ids of ``scene`` rasterized by ``renderer`` (a HeadlessRenderer)."""
    return decode_ids(renderer.render_scene(triangle_ids(scene), size).image)


def compare_ids(far: np.ndarray, origin: np.ndarray, decal: range) -> IdShift:
    """:class:`IdShift` of id picture ``far`` against ``origin``; ``decal`` the decal's ids."""
    differ = far != origin
    edges = np.zeros(origin.shape, dtype=bool)
    for value in np.unique(origin):
        edges |= edge_band(origin == value)
    in_decal = np.isin(origin, np.asarray(decal))
    return IdShift(int(differ.sum()), int((differ & ~edges).sum()), int(in_decal.sum()),
                   int((in_decal & ~np.isin(far, np.asarray(decal))).sum()))


def id_shift(renderer: Any, offset: float, scale: float = 1.0, size: tuple[int, int] = (256, 192)) -> IdShift:
    """:class:`IdShift` of the oracle scene at ``offset`` (and ``scale``) against the same
    scene at the origin, both rasterized by ``renderer``."""
    origin_scene = oracle_scene(0.0, scale)
    decal = node_triangles(origin_scene)["decal"]
    return compare_ids(id_picture(renderer, oracle_scene(offset, scale), size),
                       id_picture(renderer, origin_scene, size), decal)


@dataclass(frozen=True)
class ShadowState:
    """Shadow-mapped pixels whose lit/shadowed state differs from the ray tracer's."""

    differ: int
    off_edge: int  # ... outside the rays' edge band (2 px)
    shadowed: int  # pixels the rays shadow

    def __str__(self) -> str:
        return f"{self.differ} px of the wrong state ({self.off_edge} off the edges; rays shadow {self.shadowed})"


def shadow_state(renderer: Any, offset: float, scale: float = 1.0, size: tuple[int, int] = (256, 192),
                 shadow: ShadowMap = ShadowMap(), ray_engine: str = "numpy", ctx: Any = None) -> ShadowState:
    """:class:`ShadowState` of the oracle scene at ``offset`` and ``scale`` with ``shadow``'s
    settings: the raster frame's shadows against the ``ray_engine``'s shadow rays, each judged
    against its own renderer's frame drawn without shadows (so one renderer's trouble far away
    does not move the other's mask)."""
    from glsandbox.raytrace import render

    scene = oracle_scene(offset, scale, shadow)
    unshadowed = renderer.render_scene(without_shadows(scene), size).image
    raster = shadow_mask(renderer.render_scene(scene, size).image, unshadowed)
    traced = [render(scene, size, ray_engine, ctx=ctx, max_depth=0, shadows=shadows) for shadows in (True, False)]
    rays = shadow_mask(*traced)
    found = state_mismatch(raster, rays)
    return ShadowState(found.differ, found.off_edge, found.reference_shadowed)


def ray_id_shift(offset: float, scale: float = 1.0, size: tuple[int, int] = (256, 192), engine: str = "numpy",
                 ctx: Any = None) -> IdShift:
    """:func:`id_shift` through a ray engine (its triangle-id picture against its own at the origin)."""
    from glsandbox.raytrace import render

    def ids(scene: Scene) -> np.ndarray:
        return decode_ids(render(triangle_ids(scene), size, engine, ctx=ctx, max_depth=0, shadows=False))

    origin_scene = oracle_scene(0.0, scale)
    return compare_ids(ids(oracle_scene(offset, scale)), ids(origin_scene), node_triangles(origin_scene)["decal"])


def contact_kept(offset: float, choice: str, engine: str = "numpy", ctx: Any = None,
                 size: tuple[int, int] = (96, 72)) -> float:
    """Share of the cube-on-a-floor contact shadow (:mod:`glsandbox.measure.knobs._far`) that
    shadow rays leaving by ``offset=choice`` keep at ``offset``, against the float64 engine's
    at the origin."""
    from glsandbox.measure.knobs._far import contact_shadow
    from glsandbox.raytrace import render

    def trace(scene: Scene, shape: tuple[int, int], **options: Any) -> np.ndarray:
        return render(scene, shape, engine, ctx=ctx, **options)

    _, want = contact_shadow(lambda s, shape, **o: render(s, shape, **o), 0.0, size)
    _, got = contact_shadow(trace, offset, size, offset=choice)
    return float(np.count_nonzero(want & got) / max(1, np.count_nonzero(want)))


def table(renderer: Any) -> list[str]:
    """The rows of docs/numerics.md's table, measured with ``renderer`` (a HeadlessRenderer)
    and both ray engines (the gpu one on the renderer's context)."""
    ctx = renderer.host.ctx
    places = [(o, 1.0, f"{o:g}") for o in OFFSETS] + [(SMALL[1], SMALL[0], "1e-4 at 1e3")]
    rows = ["| place | raster ids moved (off edges), decal kept | shadow map wrong px (off edges) | "
            "numpy ids moved | gpu ids moved | simple offset kept numpy / gpu | bound offset kept numpy / gpu |",
            "|---|---|---|---|---|---|---|"]
    for offset, scale, name in places:
        raster = id_shift(renderer, offset, scale)
        shadow = shadow_state(renderer, offset, scale)
        numpy_ids = ray_id_shift(offset, scale)
        gpu_ids = ray_id_shift(offset, scale, engine="gpu", ctx=ctx)
        kept = {(c, e): contact_kept(offset * (scale == 1.0), c, e, ctx) for c in ("simple", "bound")
                for e in ("numpy", "gpu")} if scale == 1.0 else None
        offsets = ("-", "-") if kept is None else tuple(
            f"{kept[c, 'numpy']:.0%} / {kept[c, 'gpu']:.0%}" for c in ("simple", "bound"))
        rows.append(f"| {name} | {raster.moved} ({raster.off_edge}), {raster.decal - raster.decal_lost}/"
                    f"{raster.decal} | {shadow.differ} ({shadow.off_edge}) | {numpy_ids.moved} | {gpu_ids.moved} | "
                    f"{offsets[0]} | {offsets[1]} |")
    return rows


if __name__ == "__main__":  # python -m glsandbox.measure.far_raster: the table of docs/numerics.md
    from glsandbox.frame import HeadlessRenderer

    with_renderer = HeadlessRenderer()
    try:
        print("\n".join(table(with_renderer)))
    finally:
        with_renderer.close()
