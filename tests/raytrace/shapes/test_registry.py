"""The shape registry is complete: every analytic kind has all its parts in both engines,
and the GLSL dispatch has no default case (a kind code without one fails loudly).

A shape's own behaviour is tested in its own file (``test_cylinder.py`` is the template)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from glsandbox import transforms
from glsandbox.geometry import Mesh
from glsandbox.raytrace import shapes
from glsandbox.raytrace.gpu_records import NODE
from glsandbox.raytrace.shapes import KINDS, ShapeKind
from glsandbox.raytrace.world import NodeKind, build_world
from glsandbox.scene import Camera, Light, Material, Node, Scene

REPO = Path(__file__).resolve().parents[3]
SHADERS = REPO / "shaders"
PACKAGE = REPO / "glsandbox" / "raytrace" / "shapes"


def missing_parts(kind: ShapeKind, shader_root: Path = SHADERS) -> list[str]:
    """What ``kind`` lacks, each named: numpy test, bounds, normal, on-shape check, record, raster
    mesh, GLSL file, its two functions, its #include in the ray tracer shader, its NodeKind."""
    missing = []
    for part in ("hit", "surface", "holds", "mesh"):
        if not callable(getattr(kind, part, None)):
            missing.append(f"{kind.name}: {part} (not callable)")
    box = np.asarray(kind.own_box)
    if box.shape != (2, 3) or not np.all(box[0] < box[1]):
        missing.append(f"{kind.name}: own_box (a (2, 3) min and max)")
    unknown = [f for f in kind.record if f not in {name for name, _, _ in NODE.fields}]
    if not kind.record or unknown:
        missing.append(f"{kind.name}: record (node fields {unknown or 'none'})")
    glsl = shader_root / shapes.glsl_path(kind)
    if not glsl.is_file():
        missing.append(f"{kind.name}: GLSL file {glsl}")
    else:
        text = glsl.read_text()
        signatures = {f"float {kind.name}_t(vec3 o, vec3 d, bool cull)":
                      rf"float\s+{kind.name}_t\s*\(\s*vec3\s+\w+\s*,\s*vec3\s+\w+\s*,\s*bool\s+\w+\s*\)",
                      f"void {kind.name}_surface(vec3 q, out vec3 n, out vec2 uv)":
                      rf"void\s+{kind.name}_surface\s*\(\s*vec3\s+\w+\s*,\s*out\s+vec3\s+\w+\s*,"
                      rf"\s*out\s+vec2\s+\w+\s*\)"}
        missing += [f"{kind.name}: GLSL function {label} in {glsl.name}"
                    for label, pattern in signatures.items() if not re.search(pattern, text)]
    if f'#include "{shapes.glsl_path(kind).as_posix()}"' not in (shader_root / "raytrace.glsl").read_text():
        missing.append(f"{kind.name}: #include in raytrace.glsl")
    if kind.name not in {k.value for k in NodeKind}:
        missing.append(f"{kind.name}: NodeKind member")
    return missing


def test_every_module_in_the_package_is_registered() -> None:
    modules = sorted(p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__")
    assert modules == sorted(kind.name for kind in KINDS)
    assert [k.value for k in NodeKind] == ["mesh", *(kind.name for kind in KINDS)]


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_every_kind_has_all_its_parts(kind: ShapeKind) -> None:
    assert missing_parts(kind) == []


def test_a_kind_with_a_part_removed_is_named(tmp_path: Path) -> None:
    """The check itself: each part taken away from a registered kind is reported by name."""
    sphere = shapes.by_name("sphere")
    assert missing_parts(dataclasses.replace(sphere, surface=None)) == ["sphere: surface (not callable)"]
    assert missing_parts(dataclasses.replace(sphere, record=("radius",))) == [
        "sphere: record (node fields ['radius'])"]
    assert missing_parts(dataclasses.replace(sphere, name="cone")) == [
        f"cone: GLSL file {SHADERS / 'shapes' / 'cone.glsl'}", "cone: #include in raytrace.glsl",
        "cone: NodeKind member"]
    (tmp_path / "shapes").mkdir()
    (tmp_path / "raytrace.glsl").write_text((SHADERS / "raytrace.glsl").read_text())
    (tmp_path / "shapes" / "sphere.glsl").write_text(
        re.sub(r"void sphere_surface\(", "void sphere_shading(", (SHADERS / "shapes/sphere.glsl").read_text()))
    assert missing_parts(sphere, tmp_path) == [
        "sphere: GLSL function void sphere_surface(vec3 q, out vec3 n, out vec2 uv) in sphere.glsl"]


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_each_kind_is_traced_as_the_mesh_the_rasterizer_draws(kind: ShapeKind) -> None:
    """The parts agree with each other: the raster mesh says it is the kind and lies on it,
    its vertices are inside the bounds, rays aimed at them from outside along the normals
    the surface gives hit them first, and those normals face the rays."""
    mesh = kind.mesh()
    assert mesh.analytic == kind.name and kind.holds(mesh.positions)
    assert not kind.holds(mesh.positions * 1.01)
    points = mesh.positions
    assert np.all(points >= kind.own_box[0] - 1e-12) and np.all(points <= kind.own_box[1] + 1e-12)
    normals, uv = kind.surface(points)
    assert uv.shape == (len(points), 2) and np.all(np.isfinite(uv))
    origins = points + 2.0 * normals
    t = kind.hit(origins, points - origins, False)
    np.testing.assert_allclose(t, 1.0, rtol=0, atol=1e-9)
    # From inside, the one-sided test sees no front face.
    assert np.all(np.isinf(kind.hit(np.zeros((len(points), 3)), points, True)))


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_build_world_makes_each_kind_its_node_kind(kind: ShapeKind) -> None:
    node = Node(kind.name, kind.mesh(), transforms.translate(1.0, 2.0, 3.0) @ transforms.scale(2.0, 1.0, 0.5))
    world = build_world(Scene(kind.name, nodes=(node,)))
    assert world.nodes[0].kind is NodeKind(kind.name) and world.triangle_count == 0
    np.testing.assert_allclose(world.nodes[0].box_min, [-1.0, 1.0, 2.5])
    np.testing.assert_allclose(world.nodes[0].box_max, [3.0, 3.0, 3.5])


def test_the_shader_dispatch_has_no_default_case() -> None:
    """``shape_t`` and ``shape_surface`` call no kind's functions outside the generated cases,
    and each case is there for the kinds asked, none for the others."""
    text = (SHADERS / "raytrace.glsl").read_text()
    for name in ("float shape_t(", "void shape_surface("):
        body = text[text.index(name):]
        body = body[:body.index("\n}\n")]
        assert not re.search(r"\b\w+_(t|surface)\s*\(", body.split("{", 1)[1]), body
        assert "g_bad_kind = true;" in body
    cases = dict(shapes.glsl_dispatch({"cylinder"}))
    assert "cylinder_t(o, d, cull)" in cases["SHAPE_T_CASES"] and "sphere" not in cases["SHAPE_T_CASES"]
    assert "cylinder_surface(q, n, uv)" in cases["SHAPE_SURFACE_CASES"]
    assert all(value == "" for value in dict(shapes.glsl_dispatch(set())).values())


def shape_scene() -> Scene:
    nodes = tuple(Node(kind.name, kind.mesh(), transforms.translate(2.5 * i - 1.25, 0.0, 0.0),
                       Material(color=(0.8, 0.5, 0.3, 1.0), shading="phong")) for i, kind in enumerate(KINDS))
    return Scene("shapes", nodes=nodes, camera=Camera(eye=(0.0, 1.0, 7.0), target=(0.0, 0.0, 0.0)),
                 lights=(Light((3.0, 4.0, 3.0)),))


@pytest.mark.parametrize("unroll", [True, False], ids=["unrolled", "loops"])
def test_a_kind_with_no_gpu_case_fails_loudly(gl, monkeypatch, unroll: bool) -> None:
    """A kind whose case is missing from the shader's dispatch (here: the cylinder's taken out)
    is refused with an error, never traced as another kind (as a sphere, before the registry)."""
    from glsandbox.raytrace import gpu as gpu_engine
    from glsandbox.raytrace import render
    from glsandbox.raytrace.raytrace_error import RayTraceError

    tracer = gpu_engine.gpu_tracer(gl.host.ctx)
    tracer.forget_scenes()
    if not unroll:
        monkeypatch.setattr(gpu_engine, "UNROLL_NODES", 0)
    try:
        good = render(shape_scene(), (64, 48), "gpu", ctx=gl.host.ctx)
        assert np.any(good != good[0, 0], axis=-1).mean() > 0.05
        original = gpu_engine.glsl_dispatch
        monkeypatch.setattr(gpu_engine, "glsl_dispatch", lambda names: original(set(names) - {"cylinder"}))
        with pytest.raises(RayTraceError, match="node kind with no GLSL case"):
            render(shape_scene(), (64, 48), "gpu", ctx=gl.host.ctx)
    finally:  # the program without the case stays cached under its own defines, never picked again
        tracer.forget_scenes()


def test_a_mesh_claiming_an_unknown_kind_keeps_its_triangles() -> None:
    mesh = shapes.by_name("sphere").mesh()
    cone = Mesh("cone", mesh.positions, mesh.indices, mesh.normals, mesh.uvs, analytic="cone")
    assert build_world(Scene("cone", nodes=(Node("cone", cone),))).nodes[0].kind is NodeKind.MESH
    with pytest.raises(KeyError, match="no shape kind 'cone'; known: sphere, cylinder"):
        shapes.by_name("cone")
