"""Benchmark: loading real models: file to drawn first frame, the BVH build, peak memory.

Three models, made once per run in a temporary folder (nothing downloaded,
nothing shipped):

- ``bunny``: the Stanford bunny pymeshlab ships in its wheel (56,172
  triangles, an OBJ with normals: they are used as given);
- ``bunny 1.27M``: the same scan subdivided by pymeshlab (the recipe,
  :func:`big_bunny`: midpoint subdivision, 3 passes, edges over 0.175% of the
  box's diagonal split), written as a binary PLY *without* normals, so the
  crease normals are made at load;
- ``fan 1M``: a million slivers around one vertex (binary PLY), made with
  numpy: the case that was quadratic.

Rows per model (``--quick``: the bunny only):

- **load + first frame**: trimesh's own ``load`` of the file plus raw ModernGL
  uploading its vertices and faces and drawing them once (``finish``: the
  limit) against ``glsandbox.load_model`` (normals, vertex merging, checks)
  and glsandbox's first frame of the mesh on the same context (goal: 3x);
- **BVH build**: Embree (``embreex``, in its own TBB threads) building its tree
  for the same triangles against :func:`glsandbox.raytrace.bvh.build_bvh` (goal:
  2x; threads on the CPUs that are idle when it starts, see
  :func:`~glsandbox.raytrace.bvh.build_threads`), the SAH cost of glsandbox's
  tree in the note.

Under the table: peak memory per triangle of a load and first frame, measured
in a fresh process that has loaded and drawn the model once already (the
context, shaders and reader's imports are not the model's), as its peak
resident size (Linux: reset just before the second load) less what it held
then; goal: at most 250 bytes. Beside it: trimesh's own ``load_scene`` of the
file alone, measured the same way in another fresh process (the reader's part,
which glsandbox cannot make smaller: an OBJ's text parse is most of an OBJ's
peak), and from ``tracemalloc`` in a third load the peak of Python's and
numpy's allocations while trimesh parses the file and the peak of everything
after it (glsandbox's own part: normals, vertices, checks, the first frame),
what is held after, and the loaded model's own arrays (what the load cache
keeps). pymeshlab and embreex come with
``uv run --group bench``; without them those rows are skipped and said so.
"""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
from collections.abc import Sequence
from functools import cache
from pathlib import Path

from _scratch import scratch_folder
from typing import Any

import numpy as np
from _bunny import bunny_path

GROUP = "model files: load"
#: The goals: load + first frame against trimesh + raw upload; BVH build against Embree.
LOAD_GOAL = 3.0
BUILD_GOAL = 2.0
BYTES_GOAL = 250
FAN_TRIANGLES = 1_000_000
_TMP = scratch_folder("glsandbox-models-")
_ANGLES = itertools.count()


@cache
def big_bunny() -> Path:
    """The recipe for the 1.27M-triangle model: the bunny subdivided by pymeshlab, binary PLY, no normals."""
    import pymeshlab

    path = _TMP / "bunny_subdivided.ply"
    meshes = pymeshlab.MeshSet()
    meshes.load_new_mesh(str(bunny_path()))
    meshes.meshing_surface_subdivision_midpoint(iterations=3, threshold=pymeshlab.PercentageValue(0.175))
    meshes.save_current_mesh(str(path), binary=True, save_vertex_normal=False, save_vertex_color=False,
                             save_face_color=False, save_wedge_texcoord=False, save_vertex_quality=False,
                             save_face_quality=False)
    return path


@cache
def fan() -> Path:
    """:data:`FAN_TRIANGLES` slivers around one vertex, three quarters of a disc, binary PLY."""
    import trimesh

    path = _TMP / "fan.ply"
    angle = np.linspace(0.0, 1.5 * np.pi, FAN_TRIANGLES + 1)
    rim = np.c_[np.cos(angle), np.sin(angle), np.zeros(FAN_TRIANGLES + 1)]
    faces = np.c_[np.zeros(FAN_TRIANGLES, dtype=np.int64), np.arange(1, FAN_TRIANGLES + 1),
                  np.arange(2, FAN_TRIANGLES + 2)]
    trimesh.Trimesh(np.r_[[[0.0, 0.0, 0.0]], rim], faces, process=False).export(path)
    return path


MODELS = {"bunny": bunny_path, "bunny 1.27M": big_bunny, "fan 1M": fan}

#: Linear loads: the sizes of the two files a growth row loads (``--quick``: a quarter of each).
REPEATED_TRIANGLES = (250_000, 1_000_000)
CHAIN_NODES = (1_000, 4_000)
#: The goal of a growth row: four times the size in at most this many times the time (linear: 4x;
#: a quadratic step makes it 16x).
GROWTH_GOAL = 4.6


@cache
def repeated_obj(n: int) -> Path:
    """An OBJ that lists one triangle ``n`` times, its three vertices too (every vertex repeated)."""
    path = _TMP / f"repeated_{n}.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n" * n)
    return path


@cache
def node_chain(n: int) -> Path:
    """A glTF of ``n`` nested nodes, each moved 1 along x from its parent and holding one triangle."""
    import base64

    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32).tobytes()
    nodes = [{"translation": [1.0, 0.0, 0.0], "mesh": 0, **({"children": [i + 1]} if i + 1 < n else {})}
             for i in range(n)]
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes,
            "buffers": [{"byteLength": 36,
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(positions).decode()}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}
    path = _TMP / f"chain_{n}.gltf"
    path.write_text(json.dumps(gltf))
    return path


def growth_cases(env: Any, case: Any, side: Any) -> list:
    """Every load stays linear: ``load_model`` of a file against the same kind four times as large,
    side by side in one run (the ratio: the large one's time over the small one's; goal
    :data:`GROWTH_GOAL`). A new crease angle each time: the load cache is bypassed."""
    from glsandbox import load_model

    def load(make: Any, n: int) -> Any:
        return lambda _: load_model(make(n), crease_angle=30.0 + 1e-6 * next(_ANGLES))

    found = []
    for what, make, sizes, unit in (("repeated-triangle OBJ", repeated_obj, REPEATED_TRIANGLES, "triangles"),
                                    ("nested glTF nodes", node_chain, CHAIN_NODES, "nodes")):
        small, large = (n // 4 for n in sizes) if env.quick else sizes
        found.append(case(GROUP, f"4x the size, {what}", side(f"load_model, {small:,} {unit}", load(make, small)),
                          side(f"load_model, {large:,} {unit}", load(make, large)), repeat=1, unit="s",
                          goal=GROWTH_GOAL, note="linear: 4x the time; a step quadratic in the size: 16x"))
    return found

RAW_VS = """#version 330 core
in vec3 in_position; void main() { gl_Position = vec4(in_position * 0.5, 1.0); }"""
RAW_FS = """#version 330 core
out vec4 frag_color; void main() { frag_color = vec4(1.0); }"""


def raw_load_and_draw(ctx: Any, path: Path) -> None:
    """trimesh's load, then raw ModernGL: the vertices and faces uploaded as they are, drawn once."""
    import trimesh

    mesh = trimesh.load(path, process=False, force="mesh")
    program = ctx.program(vertex_shader=RAW_VS, fragment_shader=RAW_FS)
    vbo = ctx.buffer(np.asarray(mesh.vertices, dtype="f4").tobytes())
    ibo = ctx.buffer(np.asarray(mesh.faces, dtype="u4").tobytes())
    vao = ctx.vertex_array(program, [(vbo, "3f", "in_position")], ibo)
    fbo = ctx.simple_framebuffer((256, 256))
    fbo.use()
    vao.render()
    ctx.finish()
    for thing in (vao, vbo, ibo, fbo, program):
        thing.release()


def glsandbox_load_and_draw(env: Any, path: Path) -> None:
    """glsandbox: the model file loaded (a new crease angle each time: the cache is bypassed) and its
    first frame drawn by the headless renderer on the same context."""
    from glsandbox import Camera, Light, Material, Node, Scene, load_model
    from glsandbox.lesson import Lesson

    mesh = load_model(path, fit=True, crease_angle=30.0 + 1e-6 * next(_ANGLES)).mesh
    scene = Scene("model", nodes=(Node("model", mesh, material=Material(shading="phong")),),
                  camera=Camera(eye=(0.0, 0.5, 3.0)), lights=(Light((1.0, 3.0, 1.5)),))

    class Model(Lesson):
        name = "bench_model"

        def build(self) -> Any:
            return scene

    env.renderer.render(Model(), (256, 256))


def cases(env: Any) -> list:
    from glsandbox.measure.bench import Case, Side

    labels = [label for label in MODELS if bunny_path() is not None or label == "fan 1M"]
    if bunny_path() is None:
        env.note(f"{GROUP}: the bunny rows skipped: pymeshlab not installed (uv run --group bench glsandbox bench)")
    if env.quick:
        labels = labels[:1]
    found = []
    for label in labels:
        path = MODELS[label]
        found.append(Case(GROUP, f"load + first frame, {label}",
                          Side("trimesh load + raw ModernGL upload and draw",
                               lambda _, p=path: raw_load_and_draw(env.renderer.host.ctx, p())),
                          Side("glsandbox load_model + first frame", lambda _, p=path: glsandbox_load_and_draw(env, p())),
                          repeat=1, unit="s", goal=LOAD_GOAL,
                          note="load: file to a drawable mesh with normals; first frame: upload and draw"))
    found += growth_cases(env, Case, Side)
    try:
        from raytrace import embree_available
    except ImportError:  # run from elsewhere than benchmarks/
        return found
    if not embree_available():
        env.note(f"{GROUP}: the BVH rows skipped: embreex not installed (uv run --group bench glsandbox bench)")
        return found
    for label in labels:
        found.append(build_case(label, Case, Side))
    return found


@cache
def _triangles(label: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from glsandbox import load_model
    from glsandbox.raytrace.bvh import mesh_world_triangles

    return mesh_world_triangles(load_model(MODELS[label](), fit=True).mesh)


def build_case(label: str, case: Any, side: Any) -> Any:
    """The BVH build of a model's triangles: Embree's against glsandbox's (SAH cost in the note)."""
    from glsandbox.raytrace.bvh import build_bvh

    def embree(_: int) -> None:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, np.stack(_triangles(label), axis=1).astype(np.float32))
        one = np.zeros((1, 3), dtype=np.float32)
        scene.run(one, one + np.float32(1.0), output=1)  # Embree builds at its first query

    def ours(_: int) -> float:
        return build_bvh(*_triangles(label)).build_seconds

    return case(GROUP, f"BVH build, {label}", side("Embree (embreex, its own threads)", embree),
                side("build_bvh (binned SAH, threads on idle CPUs)", ours),
                repeat=1, unit="s", goal=BUILD_GOAL,
                note="both from the same float64 triangles, made once; sah_cost() of glsandbox's tree is printed "
                     "under the table")


_MEASURE_PRELUDE = """
import gc, json, sys, tracemalloc
from pathlib import Path
sys.path.insert(0, sys.argv[2])
from _memory import peak_growth, peak_start
def grown(load):
    # Linux: the peak resident size (VmHWM) starts again from the current one; then its growth.
    gc.collect()  # what an earlier load left in reference cycles (trimesh's scenes) goes first
    start = peak_start()
    load()
    return peak_growth(start)
path = Path(sys.argv[1])
"""

#: A load and first frame by glsandbox: the peak resident size's growth, then traced: the peak of trimesh's
#: parse (``meshfile._trimesh_scene``, wrapped) and of all that follows it (glsandbox's own part), what is
#: held after, and the loaded model's arrays.
_GLSANDBOX_MEMORY = _MEASURE_PRELUDE + """
import trimesh, glsandbox, glsandbox.mesh.load as meshfile
from glsandbox.measure.bench import BenchEnv
import model_load
env = BenchEnv()
model_load.glsandbox_load_and_draw(env, path)  # warm: the context, the shaders, the reader's imports
rss = grown(lambda: model_load.glsandbox_load_and_draw(env, path))  # a new crease angle: loaded and drawn again
parse = []
read = meshfile._trimesh_scene
def traced_read(*args):
    scene = read(*args)
    parse.append(tracemalloc.get_traced_memory()[1] - start)
    tracemalloc.reset_peak()  # from here on: glsandbox's own part
    return scene
meshfile._trimesh_scene = traced_read
tracemalloc.start()  # a third time, traced (tracing's own records would swell the resident size above)
start = tracemalloc.get_traced_memory()[0]
model_load.glsandbox_load_and_draw(env, path)
held, own = (m - start for m in tracemalloc.get_traced_memory())
tracemalloc.stop()
meshfile._trimesh_scene = read
model = meshfile.load_model(path, fit=True, crease_angle=30.0 + 1e-6)
arrays = sum(a.nbytes for part in model.parts for a in (part.mesh.positions, part.mesh.indices, part.mesh.normals,
                                                         part.mesh.uvs, part.mesh.colors) if a is not None)
print(json.dumps({"triangles": model.triangles, "rss": rss, "parse": parse[0], "own": own, "held": held,
                  "arrays": arrays}))
"""

#: trimesh alone reading the same file the way glsandbox has it read (``load_scene``, nothing processed).
_TRIMESH_MEMORY = _MEASURE_PRELUDE + """
import trimesh
def load():
    loader = getattr(trimesh, "load_scene", None)
    return loader(path, process=False) if loader else trimesh.load(path, process=False, force="scene")
load()  # warm: the reader's imports
rss = grown(load)
tracemalloc.start()
start = tracemalloc.get_traced_memory()[0]
load()
peak = tracemalloc.get_traced_memory()[1] - start
print(json.dumps({"rss": rss, "peak": peak}))
"""


def _measured(code: str, path: Path) -> dict[str, float]:
    """The JSON line a fresh Python process running ``code`` on ``path`` prints."""
    done = subprocess.run([sys.executable, "-c", code, str(path), str(Path(__file__).resolve().parent)],
                          capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise RuntimeError(done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "failed")
    return json.loads(done.stdout.strip().splitlines()[-1])


def peak_bytes_per_triangle(path: Path) -> dict[str, float]:
    """Memory of a load and first frame, each in a fresh process, in bytes per triangle (and
    ``triangles``): ``peak``, the growth of the peak resident size (what the system sees; the GPU
    buffers included, which llvmpipe keeps in host memory); ``trimesh``, the same for trimesh's
    own ``load_scene`` of the file alone, and ``trimesh_traced``, its traced peak; from ``tracemalloc``
    (Python's and numpy's allocations: the reader's and glsandbox's arrays, not the driver's) in
    glsandbox's load: ``parse``, the peak while trimesh reads the file, ``own``, the peak of
    everything after (glsandbox's own part: normals, vertices, first frame), ``held``, what is still
    held at the end; and ``arrays``, the loaded model's own arrays (kept in the load cache)."""
    ours = _measured(_GLSANDBOX_MEMORY, path)
    alone = _measured(_TRIMESH_MEMORY, path)
    t = ours["triangles"]
    return {"triangles": t, "peak": ours["rss"] / t, "trimesh": alone["rss"] / t,
            "trimesh_traced": alone["peak"] / t, "parse": ours["parse"] / t, "own": ours["own"] / t,
            "held": ours["held"] / t, "arrays": ours["arrays"] / t}


def summarize(results: Sequence[Any]) -> list[str]:
    """Peak memory per triangle of the models the table loaded, and the SAH costs of their trees."""
    lines = []
    loaded = [r.case.name.split(", ", 1)[1] for r in results
              if r.case.group == GROUP and r.case.name.startswith("load") and r.subject_s]
    for label in loaded:
        try:
            m = peak_bytes_per_triangle(MODELS[label]())
        except (RuntimeError, subprocess.TimeoutExpired) as exc:
            lines.append(f"{GROUP}: peak memory, {label}: not measured ({exc})")
            continue
        verdict = "met" if m["peak"] <= BYTES_GOAL else "NOT met"
        own = "met" if m["own"] <= BYTES_GOAL else "NOT met"
        lines.append(f"{GROUP}: peak memory of load + first frame, {label} ({m['triangles']:,} triangles): "
                     f"{m['peak']:.0f} bytes per triangle (goal: at most {BYTES_GOAL}: {verdict}); trimesh's own "
                     f"load_scene of the file alone: {m['trimesh']:.0f} ({m['trimesh_traced']:.0f} traced); "
                     f"numpy and Python allocations: trimesh's parse {m['parse']:.0f} at its peak, glsandbox's own "
                     f"part after it {m['own']:.0f} at its peak ({own}), {m['held']:.0f} held after; the loaded "
                     f"model's arrays: {m['arrays']:.0f}")
    from glsandbox.raytrace.bvh import build_bvh, sah_cost

    for result in results:
        if result.case.group == GROUP and result.case.name.startswith("BVH build") and result.subject_s:
            label = result.case.name.split(", ", 1)[1]
            lines.append(f"{GROUP}: SAH cost of the tree, {label}: {sah_cost(build_bvh(*_triangles(label))):.2f}")
    return lines
