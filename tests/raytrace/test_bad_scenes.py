"""The ray tracer on hostile but legal scenes: nodes flattened by a scale of 0 (or
nearly), tiny nodes, one texture on the GLSL engine, and tracers freed with their contexts."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np

from glsandbox import geometry, transforms
from glsandbox.files import load_png
from glsandbox.raytrace.render import render
from glsandbox.raytrace.world import build_world
from glsandbox.scene import Camera, Material, Node, Scene, Texture
from support import REPO_ROOT as REPO
from support import run_cli

FLAT = """\
[camera]
eye = [0, 3, 6]

[[nodes]]
name = "disc"
mesh = "sphere"
scale = [1, 0, 1]
rotate = [30, 0, 0]
color = [1, 0.5, 0]

[[nodes]]
name = "gone"
mesh = "sphere"
scale = [0, 0, 0]
translate = [2, 0, 0]

[[nodes]]
name = "sheet"
mesh = "cube24"
scale = [0, 1, 1]
translate = [-2, 0, 0]
color = [0, 0.5, 1]
"""


def test_flattened_spheres_trace_their_triangles_on_both_engines(tmp_path: Path, gl) -> None:
    scene = tmp_path / "flat.toml"
    scene.write_text(FLAT)
    images = {}
    for renderer in ("raster", "ray", "ray_numpy"):  # the ray engines raised numpy's LinAlgError
        out = tmp_path / f"{renderer}.png"
        proc = run_cli("render", str(scene), "--size", "96x64", "--set", f"renderer={renderer}", "--out", str(out))
        assert proc.returncode == 0 and proc.stderr == "", proc.stderr
        images[renderer] = load_png(out)[..., :3].astype(int)
    background = images["raster"][0, 0]
    drawn = np.any(images["raster"] != background, axis=-1)
    assert drawn.sum() > 100  # the disc and the sheet
    for renderer in ("ray", "ray_numpy"):
        differ = np.any(images[renderer] != images["raster"], axis=-1)
        assert differ.sum() <= 0.02 * drawn.sum(), (renderer, differ.sum())


def test_a_tracer_is_freed_with_its_renderer() -> None:
    # In a subprocess: opening and closing contexts here would leave the session's context not current.
    script = textwrap.dedent("""
        import gc, weakref
        from glsandbox.errors import SandboxError
        from glsandbox.frame import HeadlessRenderer
        from glsandbox.lesson import find_lesson
        from glsandbox.raytrace.gpu import gpu_tracer

        lesson = find_lesson("ray_spheres")()
        tracers = []
        for _ in range(3):
            try:
                renderer = HeadlessRenderer()
            except SandboxError as exc:
                print("no-gl", exc)
                raise SystemExit(0)
            with renderer:
                renderer.render(lesson, (16, 12))
                tracers.append(weakref.ref(gpu_tracer(renderer.host.ctx)))
            del renderer
            gc.collect()
        print([t() is None for t in tracers])
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO, timeout=180)
    assert proc.returncode == 0, proc.stderr
    if proc.stdout.startswith("no-gl"):
        from support import need

        need("headless OpenGL", proc.stdout)
    # Each tracer (programs, targets, uploads: about 0.1 MB) went with its context; a module-level
    # table kept every one of them, and through their GL objects every context, alive.
    assert proc.stdout.strip() == "[True, True, True]"


def test_a_tiny_node_keeps_its_face_normals_and_warns_nothing() -> None:
    # |e1 x e2|^2 underflows for a node scaled by 1e-100: its face normals came out 1e100 long.
    node = Node("speck", geometry.quad_list(), transforms.scale(1e-100, 1e-100, 1e-100))
    world = build_world(Scene("speck", nodes=(node,)))
    np.testing.assert_allclose(np.linalg.norm(world.normals, axis=-1), 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        image = render(Scene("speck", nodes=(node,)), (16, 12))
    assert np.all(image == image[0, 0])  # far below a pixel: only the background


def test_one_texture_on_the_glsl_engine(gl) -> None:
    # The shader's int u_wrap[1] took no Python list: a scene with one texture raised struct.error.
    scene = Scene("one texture", nodes=(Node("box", geometry.cube24(), material=Material(texture=Texture("checker"))),),
                  camera=Camera(eye=(2.0, 2.0, 3.0)))
    gl.host.make_current()  # an in-process command may have opened and closed another context
    fast = render(scene, (48, 36), "gpu", ctx=gl.host.ctx)
    reference = render(scene, (48, 36))
    assert np.mean(np.abs(fast.astype(int) - reference.astype(int)) > 2) < 0.01
