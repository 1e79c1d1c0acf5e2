"""What several test modules share: paths, the command line's error contract (in this process
and in a subprocess), the window driver, and a few test scenes and files.

Fixtures live in ``conftest.py`` only; test modules import helpers from here and never from
another test module or from ``conftest.py`` (``tests/test_suite.py`` checks that).
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

REPO_ROOT = Path(__file__).resolve().parent.parent  # the folder with pyproject.toml
TESTS_DIR = REPO_ROOT / "tests"
GOLDENS_DIR = TESTS_DIR / "goldens"  # one folder per lesson: goldens/<lesson>/<variant>.png
RESULTS_DIR = REPO_ROOT / "test-results"  # failure artefacts (ignored by git)
EXAMPLES_DIR = REPO_ROOT / "examples"

COURSE_BLUE = (0, 32, 153)  # round(255 * (0, 0.125, 0.6)): the course's clear colour as RGB8
COURSE_BLUE_RGBA8 = (*COURSE_BLUE, 255)


# --- missing resources: skip locally, fail on CI ----------------------------------------------


#: Resources a CI runner's system cannot have (Windows and macOS have no Xvfb, EGL or xdotool),
#: comma-separated, e.g. ``GLSANDBOX_CI_WITHOUT=Xvfb,EGL,xdotool,named pipes``: they skip
#: even with CI set (.github/workflows/ci.yml sets it per system); everything else fails.
CI_WITHOUT = "GLSANDBOX_CI_WITHOUT"


def need(resource: str, reason: str) -> None:
    """Skip (locally) or fail (CI) because ``resource`` is unavailable: on CI a missing
    backend or X server is a broken set-up, never a reason to pass (unless the runner's
    system cannot have it: :data:`CI_WITHOUT`)."""
    message = f"{resource} unavailable: {reason}"
    without = {name.strip() for name in os.environ.get(CI_WITHOUT, "").split(",") if name.strip()}
    if os.environ.get("CI") and resource not in without:
        pytest.fail(f"{message} (CI is set, so this fails instead of skipping)", pytrace=False)
    pytest.skip(message)


def backend_available(name: str) -> str | None:
    """None when the headless backend ``name`` starts here, else the reason (asked in a
    subprocess, so a failed start cannot disturb this process's contexts)."""
    code = ("from glsandbox.gl.context import open_context; import sys; "
            f"h = open_context({name!r}); h.release()")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    return None if proc.returncode == 0 else (proc.stderr.strip().splitlines() or ["failed"])[-1]


# --- a measurement on each headless backend ----------------------------------------------------
# OSMesa and EGL must not be mixed in one process: a figure wanted from the backend the session's
# renderer is not on is measured in a subprocess of its own, by the same functions.

Call = tuple[Any, tuple]  # (function, args): function(renderer, *args), a module-level function


def measure_calls(renderer: Any, calls: list[Call]) -> list[Any]:
    """``function(renderer, *args)`` for each call, in order, with ``renderer``'s context current."""
    renderer.host.make_current()
    return [function(renderer, *args) for function, args in calls]


_ON_BACKEND = (
    "import pickle, sys\n"
    "from glsandbox.frame import HeadlessRenderer\n"
    "from support import measure_calls\n"
    "backend, calls, out = pickle.loads(sys.stdin.buffer.read())\n"
    "with HeadlessRenderer(backend) as renderer:\n"
    "    results = measure_calls(renderer, calls)\n"
    "open(out, 'wb').write(pickle.dumps(results))\n"
)


def renderer_backend(renderer: Any) -> str:
    """The backend the renderer's context is on (``egl``, ``osmesa``, ...)."""
    return renderer.host.backend


def shadow_depth_formats(renderer: Any) -> set[bool]:
    """Whether each shadow map the renderer has drawn holds 32-bit float depth (else 24-bit fixed)."""
    return set(renderer.executor.shadow_maps.float_depth.values())


def raster_image(renderer: Any, size: tuple[int, int], scene: Callable[..., Any], *args: Any) -> np.ndarray:
    """The rasterized picture of ``scene(*args)`` (``scene`` a module-level function: scenes do not pickle)."""
    return renderer.render_scene(scene(*args), size).image


def gpu_image(renderer: Any, size: tuple[int, int], scene: Callable[..., Any], *args: Any) -> np.ndarray:
    """The gpu ray engine's picture of ``scene(*args)`` on the renderer's context."""
    from glsandbox.raytrace import render

    return render(scene(*args), size, "gpu", ctx=renderer.host.ctx)


def gpu_contact_kept(renderer: Any, offset: float, choice: str) -> float:
    """:func:`glsandbox.measure.far_raster.contact_kept` for the gpu engine on the renderer's context."""
    from glsandbox.measure.far_raster import contact_kept

    return contact_kept(offset, choice, "gpu", renderer.host.ctx)


def shadow_knob_counts(renderer: Any, size: tuple[int, int], labels: tuple[str, ...]) -> dict[str, Any]:
    """The ``shadow_map`` tradeoffs knob's count for each setting in ``labels``, at ``size``."""
    from glsandbox.frame import LazyRenderer
    from glsandbox.measure.knob import all_knobs
    from glsandbox.measure.render_context import RenderContext

    context = RenderContext(size)
    context.gl = LazyRenderer(renderer=renderer)  # shared, not closed here
    settings = {s.label: s for s in next(k for k in all_knobs() if k.name == "shadow_map").settings}
    return {label: settings[label].count(context) for label in labels}


def on_backend(backend: str, session_renderer: Any, calls: list[Call]) -> list[Any]:
    """The results of ``calls`` (:func:`measure_calls`) on a headless renderer of ``backend``: the
    session's own when it is on ``backend``, else a new one in a subprocess (arguments and
    results pickled; a module-level function of glsandbox or of this module)."""
    import pickle
    import tempfile

    if session_renderer.host.backend == backend:
        return measure_calls(session_renderer, calls)
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "results.pickle"
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS_DIR), str(REPO_ROOT)])}
        proc = subprocess.run([sys.executable, "-c", _ON_BACKEND], input=pickle.dumps((backend, calls, str(out))),
                              capture_output=True, env=env, cwd=REPO_ROOT, timeout=600)
        if proc.returncode != 0:
            pytest.fail(f"measuring on {backend} failed: {proc.stderr.decode(errors='replace')[-2000:]}",
                        pytrace=False)
        return pickle.loads(out.read_bytes())


# --- the command line ------------------------------------------------------------------------
# The contract for everything a user hands glsandbox: success, or exit 2 with exactly one
# `error: ...` line on stderr, no traceback, no warning, and no file left behind.


@dataclass
class CliRun:
    """One run of ``glsandbox``: the fields of :class:`subprocess.CompletedProcess` that tests read."""

    args: list[str]
    returncode: int
    stdout: str
    stderr: str


def glsandbox(*args: str, env: dict | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``python -m glsandbox.cli ARGS`` in a subprocess: for tests where the process is the point
    (exit by signal, no display, a library path read at start-up, the installed entry point)."""
    full_env = {**os.environ, **(env or {})}
    return subprocess.run([sys.executable, "-m", "glsandbox.cli", *args], capture_output=True, text=True,
                          env=full_env, cwd=cwd or REPO_ROOT, timeout=180)


@contextlib.contextmanager
def _environment(env: dict[str, str] | None, cwd: Path | None) -> Iterator[None]:
    saved_env, saved_cwd = dict(os.environ), Path.cwd()
    os.environ.update(env or {})
    if cwd is not None:
        os.chdir(cwd)
    try:
        yield
    finally:
        os.chdir(saved_cwd)
        os.environ.clear()
        os.environ.update(saved_env)


def run_cli(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None,
            unchanged: Path | None = None) -> CliRun:
    """``glsandbox ARGS`` in this process (``cli.main``), with the contract checked on every run:
    no warning is raised; exit 2 is one ``error:`` line and no traceback; and, given
    ``unchanged``, a failed run (exit not 0) leaves that folder's files as they were.
    ``env`` entries are set for the run only; ``cwd`` is the working folder for the run
    (the repository, as for :func:`glsandbox`, unless given)."""
    from glsandbox import cli

    before = sorted(unchanged.rglob("*")) if unchanged is not None else None
    stdout, stderr = io.StringIO(), io.StringIO()
    with (_environment(env, cwd or REPO_ROOT), warnings.catch_warnings(record=True) as caught,
          contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr)):
        warnings.simplefilter("always")
        # pyrr's docstring escapes warn when it is first compiled (pyproject.toml's filter, not ours);
        # a ResourceWarning (never shown by Python by default) comes from whatever object the
        # garbage collector finalises during the run, often one an earlier test made.
        warnings.filterwarnings("ignore", "invalid escape sequence")
        warnings.simplefilter("ignore", ResourceWarning)
        try:
            status = cli.main(list(args))
        except SystemExit as exc:  # argparse's own usage errors
            status = exc.code if isinstance(exc.code, int) else 2
    run = CliRun(list(args), status, stdout.getvalue(), stderr.getvalue())
    raised = [f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})" for w in caught]
    assert raised == [], (raised, run)
    if status == 2:
        assert_user_error(run)
    if before is not None and status != 0:
        left = sorted(set(unchanged.rglob("*")) - set(before))
        assert left == [], f"files left behind: {[str(p) for p in left]}"
    return run


def assert_user_error(proc: CliRun | subprocess.CompletedProcess, *fragments: str) -> None:
    """Exit 2, exactly one ``error: ...`` line on stderr holding every fragment, no traceback."""
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), proc.stderr
    assert "Traceback" not in proc.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


# --- the window under Xvfb ---------------------------------------------------------------------


class LessonWindow:
    """A lesson running in its own process on the test's X server (``python -m ARGS``)."""

    def __init__(self, display: str, cwd: Path, *args: str, env: dict | None = None) -> None:
        self.env = {**os.environ, "DISPLAY": display, **(env or {})}
        self.display = display
        self.proc = subprocess.Popen([sys.executable, "-m", *args], cwd=cwd, env=self.env,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.window = self._wait(lambda: self._xdotool("search", "--name", "glsandbox").split()[:1])[0]

    def _xdotool(self, *args: str) -> str:
        proc = subprocess.run(["xdotool", *args], capture_output=True, text=True, env=self.env, timeout=20)
        return proc.stdout.strip()

    def _wait(self, probe, timeout: float = 30.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise AssertionError(f"lesson exited early with code {self.proc.returncode}: "
                                     f"{self.proc.stdout.read()} {self.proc.stderr.read()}")
            value = probe()
            if value:
                return value
            time.sleep(0.1)
        raise AssertionError("timed out waiting for the lesson window")

    def title(self) -> str:
        return self._xdotool("getwindowname", self.window)

    def wait_title(self, predicate) -> str:
        return self._wait(lambda: (t := self.title()) and predicate(t) and t)

    def key(self, name: str) -> None:
        self._xdotool("windowfocus", "--sync", self.window)
        self._xdotool("key", "--window", self.window, name)

    def screen(self) -> np.ndarray:
        from PIL import ImageGrab

        return np.asarray(ImageGrab.grab(xdisplay=self.display).convert("RGB"))

    def close(self) -> int:
        # Escape through XTEST to the focused window, not XSendEvent to our
        # window: the lesson destroys its window on the press, the release
        # sent to that window then fails, and xdotool leaves Escape held in
        # the server, where autorepeat closes the next test's window.
        self._xdotool("windowfocus", "--sync", self.window)
        self._xdotool("key", "Escape")
        try:
            return self.proc.wait(timeout=20)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()


def not_blank(image: np.ndarray) -> bool:
    """More than a clear colour: many distinct colours."""
    return len(np.unique(image.reshape(-1, 4), axis=0)) > 20


def wait_for(path: Path, timeout: float = 20.0) -> Path:
    """``path`` once it exists (a screenshot the window writes), or an AssertionError."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists():
            time.sleep(0.2)  # the file is written atomically; give the rename a moment
            return path
        time.sleep(0.1)
    raise AssertionError(f"{path} was not written")


# --- files and scenes several modules use ------------------------------------------------------

#: A shader of the user's with a uniform of each kind the panel gives a widget of its own:
#: a number, a colour, two numbers and an on/off (``UNIFORM_SCENE`` sets them).
UNIFORM_SHADER = """\
#version 330 core
#include "common/transform.glsl"
uniform float gain;
uniform vec3 base_color;
uniform vec2 offset;
uniform bool flat_look;
#if defined(VERTEX_SHADER)
in vec3 in_position;
void main() { gl_Position = m_proj * m_view * m_model * vec4(in_position, 1.0); }
#elif defined(FRAGMENT_SHADER)
out vec4 frag_color;
void main() {
    vec3 shift = flat_look ? vec3(offset, 0.0) : vec3(0.0);
    frag_color = vec4(clamp(base_color * gain + shift, 0.0, 1.0), 1.0);
}
#endif
"""

#: Two cubes drawn with ``UNIFORM_SHADER``, each with its own uniforms (the first node's are the panel's).
UNIFORM_SCENE = """\
[camera]
eye = [1, 1.5, 6]
target = [1, 0, 0]

[[nodes]]
mesh = "cube24"
shader = "own.glsl"

[nodes.uniforms]
gain = 0.5
base_color = [1, 0.5, 0]
offset = [0.1, 0.2]
flat_look = true

[[nodes]]
mesh = "cube24"
translate = [2.5, 0, 0]
shader = "own.glsl"
uniforms = { gain = 2.0, base_color = [0, 0, 0.4], offset = [0, 0], flat_look = false }
"""


def write_uniform_scene(folder: Path) -> Path:
    """``UNIFORM_SCENE`` and its shader written into ``folder``: the scene file's path."""
    (folder / "own.glsl").write_text(UNIFORM_SHADER)
    (folder / "own.toml").write_text(UNIFORM_SCENE)
    return folder / "own.toml"


#: A lesson file: a spinning cube whose name clashes with a built-in lesson (which it must not shadow).
SPIN = '''
import glsandbox
from glsandbox import Lesson, Node, Param, Scene, geometry, register, transforms

@register
class Spin(Lesson):
    name = "phong"          # the same name as a built-in lesson: it must not shadow it
    animated = True
    params = (Param("speed", 1.0, "radians per second"),)

    def build(self) -> Scene:
        turn = transforms.rotate_y(self.values["speed"] * self.time)
        return Scene(self.name, nodes=(Node("cube", geometry.cube(), turn),))
'''

# A unit cube as an OBJ: 8 vertices, 12 counter-clockwise triangles (outward fronts).
CUBE_OBJ = """\
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3
f 1 3 2
f 5 6 7
f 5 7 8
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
f 4 8 7
f 4 7 3
f 1 2 6
f 1 6 5
"""


def quadrant_image():
    """Red top-left, green top-right, blue bottom-left, yellow bottom-right: 16x16 pixels, so that
    bilinear sampling (the ray tracer's) reads pure colours inside each quadrant."""
    from PIL import Image

    quadrants = np.array([[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (255, 255, 0)]], dtype=np.uint8)
    return Image.fromarray(np.repeat(np.repeat(quadrants, 8, axis=0), 8, axis=1))


def textured_quad_glb(path: Path) -> Path:
    """A unit quad in the xy plane facing +z, with the quadrant image as its glTF base colour texture
    (white factor), uv laid so the image shows upright seen from +z."""
    import trimesh

    quad = trimesh.Trimesh(vertices=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], faces=[[0, 1, 2], [0, 2, 3]],
                           process=False)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=quadrant_image(),
                                                   baseColorFactor=[255, 255, 255, 255])
    # trimesh's uv: v up (OpenGL); it writes glTF's v-down uv itself.
    quad.visual = trimesh.visual.TextureVisuals(uv=[[0, 0], [1, 0], [1, 1], [0, 1]], material=material)
    quad.export(path)
    return path


def far_triangle_scene(count: int = 70_000):
    """One mesh node of ``count`` triangles whose only visible one is the last (index
    ``count − 1``, past llvmpipe's 65,535 loop iterations): the others are tiny and behind the camera."""
    from glsandbox import Camera, Light, Material, Mesh, Node, Scene

    base = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0]])
    hidden = base[None] + np.array([0.0, 0.0, 50.0]) + (np.arange(count - 1) * 1e-3)[:, None, None] * [1.0, 0, 0]
    visible = np.array([[[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]])
    positions = np.concatenate([hidden, visible]).reshape(-1, 3)
    mesh = Mesh("far_triangle", positions, normals=np.tile([0.0, 0.0, 1.0], (positions.shape[0], 1)))
    material = Material(color=(0.9, 0.2, 0.2, 1.0), shading="solid")
    return Scene("far_triangle", nodes=(Node("big", mesh, np.eye(4), material),),
                 camera=Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0)), lights=(Light((0.0, 3.0, 3.0)),),
                 clear_color=(0.0, 0.0, 0.0, 1.0))


def stray_scene(parts: dict[str, np.ndarray]):
    """One unlit node per ``name: positions`` (tests/raytrace/test_far_vertices.py's quad and stray
    triangle), seen from 2.5 in front of the origin."""
    from glsandbox import Camera, Material, Mesh, Node, Scene

    material = Material(color=(0.9, 0.4, 0.2, 1.0))
    nodes = tuple(Node(name, Mesh(name, positions), np.eye(4), material) for name, positions in parts.items())
    return Scene("stray", nodes=nodes, camera=Camera(eye=(0.0, 0.0, 2.5), target=(0.0, 0.0, 0.0)),
                 clear_color=(0.0, 0.0, 0.0, 1.0))


# --- lessons and their goldens -------------------------------------------------------------------


def variant_name(settings: tuple[str, ...] | list[str]) -> str:
    """A golden's file stem for a lesson's ``--set`` values: ``default``, or ``scene_exam2012``."""
    return "-".join(s.replace("=", "_") for s in settings) or "default"


def lesson_image(gl, name: str, *settings: str, size: tuple[int, int] = (256, 256), samples: int = 0) -> np.ndarray:
    """Built-in lesson ``name`` with ``--set`` values ``settings``, rendered headless by ``gl``."""
    from glsandbox.lesson import find_lesson

    return gl.render(find_lesson(name).from_settings(list(settings)), size, samples).image


def count_color(image: np.ndarray, rgba) -> int:
    """How many pixels of ``image`` are exactly ``rgba``."""
    return int(np.all(image == np.array(rgba, dtype=np.uint8), axis=-1).sum())


def check_lesson_golden(gl, golden, name: str, *settings: str, size: tuple[int, int] = (256, 256)) -> np.ndarray:
    """Render lesson ``name`` with ``settings`` headless and check it against
    ``tests/goldens/<name>/<variant>.png``; the image, for further checks."""
    image = lesson_image(gl, name, *settings, size=size)
    golden(image, f"{name}/{variant_name(settings)}")
    return image


# --- model files with materials (tests/mesh/test_load_materials.py, tests/lessons/test_model_materials.py) ---
# Each is small, lies in the box -1..1 (so the model lesson's fit leaves it as it is, up to a
# shift in z), and has its parts at known places, so a test can read each part's colour from a frame.

QUAD_FACES = np.array([[0, 1, 2], [0, 2, 3]])


def quad(x0: float, x1: float, z: float = 0.0, facing: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A square from x0 to x1, y -1..1 at depth z; facing +z (counter-clockwise seen from +z) or -z."""
    vertices = np.array([[x0, -1, z], [x1, -1, z], [x1, 1, z], [x0, 1, z]], dtype=np.float64)
    return vertices, QUAD_FACES if facing > 0 else QUAD_FACES[:, ::-1]


def gltf_part(vertices: np.ndarray, faces: np.ndarray, **material: object):
    """A trimesh mesh with a glTF (PBR) material, for a trimesh.Scene to export."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(**material))
    return mesh


def two_material_glb(path: Path) -> Path:
    """An opaque red square on the left and a half-transparent blue one in front, on the right."""
    import trimesh

    red = gltf_part(*quad(-1.0, 0.2), name="paint", baseColorFactor=[255, 0, 0, 255])
    glass = gltf_part(*quad(-0.2, 1.0, z=0.4), name="glass", baseColorFactor=[0, 0, 255, 128], alphaMode="BLEND")
    trimesh.Scene([red, glass]).export(path)
    return path


def two_usemtl_obj(folder: Path, extra_mtl: str = "") -> Path:
    """Two squares side by side, one usemtl group each: red on the left, blue on the right (Kd)."""
    (folder / "two.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n" + extra_mtl)
    (folder / "two.obj").write_text(
        "mtllib two.mtl\n"
        "v -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\n"
        "v 0.05 -1 0\nv 1 -1 0\nv 1 1 0\nv 0.05 1 0\n"
        "usemtl red\nf 1 2 3\nf 1 3 4\n"
        "usemtl blue\nf 5 6 7\nf 5 7 8\n")
    return folder / "two.obj"


def coloured_ply(path: Path) -> Path:
    """Two squares with vertex colours, red on the left and blue on the right (ASCII PLY)."""
    rows = [(-1, -1, 255, 0, 0), (0, -1, 255, 0, 0), (0, 1, 255, 0, 0), (-1, 1, 255, 0, 0),
            (0.05, -1, 0, 0, 255), (1, -1, 0, 0, 255), (1, 1, 0, 0, 255), (0.05, 1, 0, 0, 255)]
    header = ("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 4\n"
              "property list uchar int vertex_indices\nend_header\n")
    body = "".join(f"{x} {y} 0 {r} {g} {b}\n" for x, y, r, g, b in rows)
    path.write_text(header + body + "3 0 1 2\n3 0 2 3\n3 4 5 6\n3 4 6 7\n")
    return path


def reversed_obj(folder: Path) -> Path:
    """An open square wound clockwise as seen from +z (its front faces -z: a scan the wrong way
    round), green."""
    (folder / "back.mtl").write_text("newmtl green\nKd 0 1 0\n")
    (folder / "back.obj").write_text("mtllib back.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                     "usemtl green\nf 1 3 2\nf 1 4 3\n")
    return folder / "back.obj"



def double_sided_glb(path: Path, double_sided: bool = True) -> Path:
    """A green square whose front faces away from +z (where the model lesson's camera is):
    seen only from behind, so drawn only when the material is double-sided."""
    import trimesh

    plane = gltf_part(*quad(-1, 1, facing=-1), name="leaf", baseColorFactor=[0, 255, 0, 255],
                      doubleSided=double_sided)
    trimesh.Scene([plane]).export(path)
    return path


def masked_glb(path: Path) -> Path:
    """A red square behind a white one cut out by a texture's alpha (glTF MASK): the white
    square's left half (alpha 0) is cut away, its right half (alpha 255) is drawn."""
    import trimesh
    from PIL import Image

    red = gltf_part(*quad(-1, 1, z=-0.2), name="wall", baseColorFactor=[255, 0, 0, 255])
    vertices, faces = quad(-1, 1, z=0.2)
    pixels = np.full((1, 4, 4), 255, dtype=np.uint8)
    pixels[0, :2, 3] = 0  # the left half transparent
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    stencil = trimesh.Trimesh(vertices, faces, process=False)
    image = Image.fromarray(pixels.repeat(4, axis=0), "RGBA")  # 4x4: each column's alpha as above
    material = trimesh.visual.material.PBRMaterial(name="stencil", baseColorTexture=image, alphaMode="MASK",
                                                   alphaCutoff=0.5)
    stencil.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    trimesh.Scene([red, stencil]).export(path)
    return path


def two_textures_glb(path: Path) -> Path:
    """Two squares side by side with a texture each (white factor): red pixels on the left
    part, blue on the right (a boat of several textures, each part its own)."""
    import trimesh
    from PIL import Image

    parts = []
    for name, x0, x1, rgb in (("hull", -1.0, 0.0, (255, 0, 0)), ("sail", 0.05, 1.0, (0, 0, 255))):
        vertices, faces = quad(x0, x1)
        square = trimesh.Trimesh(vertices, faces, process=False)
        square.visual = trimesh.visual.TextureVisuals(
            uv=[[0, 0], [1, 0], [1, 1], [0, 1]],
            material=trimesh.visual.material.PBRMaterial(name=name, baseColorTexture=Image.new("RGB", (4, 4), rgb)))
        parts.append(square)
    trimesh.Scene(parts).export(path)
    return path


def chromium_command(binary: str, profile: Path, size: tuple[int, int]) -> list[str]:
    """Headless Chromium, offline and quiet, with a fresh profile."""
    return [binary, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--hide-scrollbars", f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}"]


# --- a user's own lessons/ package beside the course's ---------------------------------------

#: Run in a folder made by :func:`student_lessons_folder` with ``theirs first`` or ``course first``:
#: prints the user's ``lessons`` package's file, the course's package's file and the module a
#: course lesson found by name comes from.
STUDENT_LESSONS_CHECK = """
import sys
def theirs():
    import lessons, lessons.indexed_cube
    assert lessons.indexed_cube.MINE == "the user's own", lessons.indexed_cube
    return lessons.__file__
def course():
    import glsandbox, glsandbox.lesson as L
    cls = L.find_lesson("indexed_cube")
    L.all_lessons()
    glsandbox.lesson.builtin_lessons()
    return sys.modules["glsandbox.lessons"].__file__, cls.__module__
if sys.argv[1] == "theirs first":
    mine = theirs(); (package, module) = course()
else:
    (package, module) = course(); mine = theirs()
print(mine, package, module)
"""


def student_lessons_folder(tmp_path: Path) -> Path:
    """A working directory with a user's own ``lessons`` package, which has an ``indexed_cube`` of its own."""
    (tmp_path / "lessons").mkdir()
    (tmp_path / "lessons" / "__init__.py").write_text('"""A student\'s own lessons."""\n')
    (tmp_path / "lessons" / "indexed_cube.py").write_text('MINE = "the user\'s own"\n')
    return tmp_path


#: A student's right ``ray_sphere`` answer, the notes' geometric test (l, s, m², q; s - q from outside).
SPHERE_ANSWER = """
import math

def intersect_sphere(origin, direction, center, radius):
    l = [c - o for c, o in zip(center, origin)]
    s = sum(a * b for a, b in zip(l, direction))
    l2 = sum(a * a for a in l)
    m2 = l2 - s * s
    if m2 > radius * radius:
        return None
    q = math.sqrt(radius * radius - m2)
    if l2 > radius * radius:
        return None if s < 0 else s - q
    return s + q
"""


def course_ray(lesson: str, direction: str, *settings: str):
    """The centre pixel of an odd-sized frame whose camera sits at the origin looking along
    ``direction`` (a glsandbox.story.Story): that pixel's ray is the notes' ray from (0, 0, 0)."""
    from glsandbox.story import explain

    return explain(lesson, (200, 150), (401, 301), camera=f"0,0,0,{direction}", **dict(s.split("=") for s in settings))


def knob_counts(knob, size: tuple[int, int]) -> dict:
    """Each setting's (and the reference's) pixel count of a tradeoffs knob that counts without
    rendering (its ``count`` reads only ``context.size``), by label."""
    from types import SimpleNamespace

    context = SimpleNamespace(size=size)
    return {s.label: s.count(context) for s in (*knob.settings, knob.reference)}


# --- the BVH's random triangles and rays (tests/raytrace/) -----------------------------------


def triangle_soup(seed: int, count: int, spread: float = 4.0, size: float = 0.6) -> tuple[np.ndarray, ...]:
    """``count`` random triangles, some of them degenerate and some duplicated."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-spread, spread, (count, 3))
    b = a + rng.normal(0.0, size, (count, 3))
    c = a + rng.normal(0.0, size, (count, 3))
    if count >= 6:
        c[0] = b[0]  # a repeated corner: zero area
        c[1] = a[1] + 2.0 * (b[1] - a[1])  # collinear: zero area
        a[2], b[2], c[2] = a[3], b[3], c[3]  # a duplicate: a tie at every t
    return a, b, c


def random_rays(seed: int, count: int, spread: float = 6.0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed + 1000)
    return rng.uniform(-spread, spread, (count, 3)), rng.normal(size=(count, 3))


def soup_and_rays(seed: int, count: int, limited: bool, rays: int = 300) -> tuple[np.ndarray, ...]:
    """``(a, b, c, o, d, t_max)``: :func:`triangle_soup` and :func:`random_rays`, the first 50 rays
    aimed straight at vertices, ``t_max`` random per ray (``limited``) or infinite."""
    a, b, c = triangle_soup(seed, count)
    o, d = random_rays(seed, rays)
    d[:50] = a[np.arange(50) % count] - o[:50]
    t_max = np.random.default_rng(seed).uniform(0.2, 3.0, len(o)) if limited else np.full(len(o), np.inf)
    return a, b, c, o, d, t_max


def assert_same_hits(got, want) -> None:
    np.testing.assert_array_equal(got.triangle, want.triangle)
    np.testing.assert_array_equal(got.t, want.t)
    np.testing.assert_array_equal(got.u, want.u)
    np.testing.assert_array_equal(got.v, want.v)
