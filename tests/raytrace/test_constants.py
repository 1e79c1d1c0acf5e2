"""raytrace/constants.py is where the engines' pads and guards are named: the shaders get
them as defines, and the fallbacks the shared GLSL files carry (for a shader that includes
them without the defines) are the same numbers; the gpu records' layout is one table."""

from __future__ import annotations

import re

import numpy as np

from glsandbox.gl.shaders import shader_root
from glsandbox.lesson import find_lesson
from glsandbox.raytrace.constants import glsl_defines
from glsandbox.raytrace.gpu import pack_nodes, pack_triangles
from glsandbox.raytrace.gpu_records import NODE, TRI, layout_defines
from glsandbox.raytrace.world import NodeKind, build_world, kind_defines


def test_the_shared_glsl_fallbacks_are_the_constants() -> None:
    defines = dict(glsl_defines())
    found = 0
    for name in ("watertight.glsl", "bvh.glsl"):
        text = (shader_root() / "common" / name).read_text()
        for key, value in re.findall(r"#ifndef (\w+)\n#define \1 (\S+)\n", text):
            if key in defines:
                assert float(value) == float(defines[key]), (name, key)
                found += 1
    assert found >= 5  # GAMMA2/3/5, DIRECTION_TINY, BVH_PAD


def test_no_bare_number_stands_for_a_defined_one_in_the_ray_tracer() -> None:
    text = (shader_root() / "raytrace.glsl").read_text()
    assert not re.search(r"(node|tri)_rec\(\w+, \d+\)", text)  # records by the layout's names
    for name in ("#define INF", "#define NODE_RECORDS", "#define TRI_RECORDS", "1.1754944e-38"):
        assert name not in text
    names = dict(layout_defines() + kind_defines() + glsl_defines())
    names.update(NODE_COUNT="scene", TRI_COUNT="scene")  # gpu._Uploaded.defines: the scene's sizes
    used = set(re.findall(r"\b(NODE_[A-Z_]+|TRI_[A-Z0-9_]+|KIND_[A-Z]+)\b", text))
    assert used and used <= set(names)  # every one the shader reads is generated


def test_the_records_are_packed_as_the_layout_says() -> None:
    world = build_world(find_lesson("ray_phong")().scene())
    nodes = pack_nodes(world).reshape(len(world.nodes), NODE.records, 4)
    tris = pack_triangles(world).reshape(world.triangle_count, TRI.records, 4)
    kinds = {kind.code: kind for kind in NodeKind}
    assert [kinds[int(code)] for code in nodes[:, NODE["box_min"], 3]] == \
        sorted((node.kind for node in world.nodes), key=lambda kind: not kind.triangles)
    first = next(k for k, node in enumerate(world.nodes) if node.kind.triangles)
    np.testing.assert_array_equal(nodes[0, NODE["range"], :2], [world.nodes[first].start, world.nodes[first].count])
    np.testing.assert_allclose(tris[:, TRI["v1"], :3], world.v1, rtol=1e-6, atol=1e-6)
    assert dict(layout_defines())["NODE_RECORDS"] == str(NODE.records) == "13"
