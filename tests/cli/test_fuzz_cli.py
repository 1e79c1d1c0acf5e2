"""Property-based fuzzing of the command line's contract.

Scene files, ``--set`` values and texture images are generated (valid, half
valid and hostile), the CLI runs in this process, and every run must end in
one of two ways:

- exit 0 and a readable PNG of the asked size, or
- exit 2, exactly one ``error:`` line on stderr, no traceback, and no new
  file in the output folder;

and in neither case a warning (numpy's RuntimeWarnings, Pillow's, glfw's),
which would reach stderr beside the output.

The examples per test are bounded so the suite stays fast; set
``GLSANDBOX_FUZZ=long`` for a longer run (the ``long`` hypothesis profile).
"""

from __future__ import annotations

import io
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from support import REPO_ROOT as REPO
from support import run_cli

from glsandbox.files import load_png

settings.register_profile("ci", max_examples=100, deadline=None, derandomize=True,
                          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
settings.register_profile("long", max_examples=400, deadline=None,
                          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
PROFILE = "long" if os.environ.get("GLSANDBOX_FUZZ") == "long" else "ci"

SIZE = (24, 18)

# --- values, from ordinary to hostile ---------------------------------------

hostile_floats = st.sampled_from([0.0, -0.0, 1e-320, 1e200, -1e300, 1e308, math.inf, -math.inf, math.nan])
numbers = st.one_of(st.floats(-10, 10, allow_nan=False), st.integers(-5, 5), hostile_floats)
vectors = st.one_of(st.lists(numbers, min_size=3, max_size=3), st.lists(numbers, max_size=5),
                    st.just("text"), numbers, st.just([[1, 2, 3]]))
colors = st.one_of(st.lists(st.floats(0, 1), min_size=3, max_size=4), vectors)
words = st.one_of(st.sampled_from(["cube", "cube24", "sphere", "plane", "quad_strip", "triangle", "phong",
                                   "solid", "gouraud", "STR", "trs", "checker", "labels", "nearest", "clamp"]),
                  st.text(max_size=8))
shadings = st.sampled_from(["solid", "vertex_color", "phong", "gouraud", "blinn_phong", "toon"])


def toml_value(value: Any) -> str:
    """A value in TOML syntax (floats keep nan/inf, which TOML has)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return '"' + value.encode("unicode_escape").decode("ascii").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):  # an inline table
        return "{" + ", ".join(f"{toml_value(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(value)


def toml_table(header: str, table: dict[str, Any]) -> str:
    return f"{header}\n" + "".join(f"{k} = {toml_value(v)}\n" for k, v in table.items())


nodes = st.fixed_dictionaries({"mesh": words}, optional={
    "scale": vectors, "translate": vectors, "rotate": vectors, "color": colors, "shading": shadings,
    "order": words, "texture": st.sampled_from(["checker", "labels", "img.png", "missing.png", "pipe.png"]),
    "filter": words, "wrap": words, "ambient": numbers, "shininess": numbers, "cull_back_faces": st.booleans(),
    "viewports": st.one_of(st.just([0]), st.just([5]), st.just(["a"])),
    # A node's own shader (toon.glsl is the example's, copied in) and its uniforms.
    "shader": st.sampled_from(["toon.glsl", "missing.glsl", "img.png", "pipe.png", ""]),
    "uniforms": st.dictionaries(st.sampled_from(["bands", "outline", "nope", "m_model", "x y"]),
                                st.one_of(numbers, vectors, st.booleans()), max_size=3),
})
cameras = st.fixed_dictionaries({}, optional={"eye": vectors, "target": vectors, "up": vectors,
                                              "fov_y": numbers, "near": numbers, "far": numbers})
lights = st.fixed_dictionaries({"position": vectors}, optional={"color": colors})
# A planar shadow on the first node, cast by the second, from a light that may or may not be one of the scene's.
shadows = st.fixed_dictionaries({"receiver": st.sampled_from(["node0", "ghost"]), "casters": st.just(["node1"])},
                                optional={"plane": st.one_of(st.just([0, 1, 0, 0]), vectors),
                                          "light": st.one_of(st.just([1, 4, 2, 1]), st.just([0, 1, 0, 0]), vectors),
                                          "lift": numbers})
scenes = st.builds(
    lambda top, camera, node_list, light_list, shadow: "".join(
        [toml_table("", top).lstrip("\n"), toml_table("[camera]", camera) if camera else "",
         *(toml_table("[[nodes]]", n) for n in node_list), *(toml_table("[[lights]]", li) for li in light_list),
         toml_table("[shadow]", shadow) if shadow else ""]),
    st.fixed_dictionaries({}, optional={"name": words, "clear_color": colors, "samples": st.integers(-1, 5),
                                        "depth_mode": words, "nodes": st.just([1, 2])}),
    cameras, st.lists(nodes, max_size=3),
    st.one_of(st.lists(lights, max_size=3), st.just([{"position": [1, 4, 2]}])),
    st.one_of(st.none(), shadows),
)
hostile_text = st.one_of(st.text(max_size=200), st.just("a = " + "[" * 2000 + "]" * 2000),
                         st.just("[[nodes]]\nmesh = 'cube'\n" * 3 + "\x00\xff"))


def png_bytes(mode: str, size: tuple[int, int], seed: int) -> bytes:
    rng = np.random.default_rng(seed)
    if mode == "I;16":
        image = Image.fromarray(rng.integers(0, 65535, size[::-1], dtype=np.uint16))
    else:
        bands = {"L": 1, "LA": 2, "RGB": 3, "RGBA": 4, "P": 1}[mode]
        data = rng.integers(0, 255, (*size[::-1], bands), dtype=np.uint8)
        image = Image.fromarray(data[..., 0] if bands == 1 else data, "L" if bands == 1 else mode)
        if mode == "P":
            image = image.convert("P")
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


images = st.one_of(
    st.builds(png_bytes, st.sampled_from(["L", "LA", "RGB", "RGBA", "P", "I;16"]),
              st.tuples(st.integers(1, 9), st.integers(1, 9)), st.integers(0, 99)),
    st.binary(max_size=64),
    st.builds(lambda b: b[: len(b) // 2], st.builds(png_bytes, st.just("RGB"), st.just((8, 8)), st.just(1))),
)

# --- the contract -----------------------------------------------------------


def check_contract(args: list[str], out_dir: Path, cwd: Path) -> int:
    """One run in this process (support.run_cli checks exit 2's one line, no warning and no file
    left in ``out_dir``): exit 0 and a PNG of the asked size, or exit 2."""
    run = run_cli(*args, cwd=cwd, unchanged=out_dir)
    if run.returncode == 0:
        out = Path(args[args.index("--out") + 1])
        image = load_png(out)
        assert image.shape == (SIZE[1], SIZE[0], 4)
        out.unlink()
    else:
        assert run.returncode == 2, run
    return run.returncode


@pytest.fixture
def workdir(tmp_path: Path, gl) -> Path:  # `gl`: a GL backend, or a skip (fail under CI)
    if hasattr(os, "mkfifo"):  # a named pipe where an image belongs: reading it would wait forever
        os.mkfifo(tmp_path / "pipe.png")
    (tmp_path / "toon.glsl").write_bytes((REPO / "examples" / "toon" / "toon.glsl").read_bytes())
    return tmp_path


@settings(settings.get_profile(PROFILE))
@given(text=st.one_of(scenes, hostile_text), image=images)
def test_generated_scene_files_keep_the_contract(workdir: Path, text: str, image: bytes) -> None:
    scene = workdir / "scene.toml"
    scene.write_text(text, encoding="utf-8", errors="surrogateescape")
    (workdir / "img.png").write_bytes(image)
    out_dir = workdir / "out"
    out_dir.mkdir(exist_ok=True)
    for renderer in ("raster", "ray_numpy"):
        check_contract(["render", str(scene), "--size", f"{SIZE[0]}x{SIZE[1]}", "--set", f"renderer={renderer}",
                        "--out", str(out_dir / "x.png")], out_dir, workdir)


SET_LESSONS = ["indexed_cube", "transform_order", "phong", "texture", "mirror", "ray_spheres"]
set_texts = st.one_of(st.sampled_from(["1e308", "-1e308", "nan", "inf", "-0", "0", "180", "1e-320", "3", "on",
                                       "off", "STR", "tsr", "split", "directional", "reverse_z", "img.png",
                                       "pipe.png"]),
                      st.floats(allow_nan=True).map(repr), st.text(max_size=6))


@settings(settings.get_profile(PROFILE))
@given(lesson=st.sampled_from(SET_LESSONS), data=st.data())
def test_generated_set_values_keep_the_contract(workdir: Path, lesson: str, data: st.DataObject) -> None:
    from glsandbox.lesson import find_lesson

    names = [p.name for p in find_lesson(lesson).all_params() if p.name != "effects"]
    chosen = data.draw(st.lists(st.tuples(st.sampled_from(names), set_texts), min_size=1, max_size=3))
    (workdir / "img.png").write_bytes(data.draw(images))
    out_dir = workdir / "out"
    out_dir.mkdir(exist_ok=True)
    settings_args = [a for key, text in chosen for a in ("--set", f"{key}={text}")]
    # In the work folder: `image=img.png` is read relative to the working folder.
    check_contract(["render", lesson, "--size", f"{SIZE[0]}x{SIZE[1]}", *settings_args, "--out", str(out_dir / "x.png")],
                   out_dir, workdir)
