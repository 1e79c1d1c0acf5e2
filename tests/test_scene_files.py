"""TOML scene files: a valid one loads; each mistake names the file and line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.plan import plan
from glsandbox.scene import load_scene

GOOD = """\
name = "two boxes"
clear_color = [0.1, 0.1, 0.1]

[camera]
eye = [0, 3, 10]
fov_y = 45

[[nodes]]
name = "left"
mesh = "cube"
translate = [-2, 0, 0]

[[nodes]]
name = "right"
mesh = "cube"
order = "TRS"
scale = [0.5, 1, 0.5]
translate = [2, 0, 0]
rotate = [0, 90, 0]
color = [1, 0, 0]
shading = "solid"
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def test_a_valid_scene_loads_with_its_transforms(tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path, GOOD))
    assert scene.name == "two boxes"
    assert [n.name for n in scene.nodes] == ["left", "right"]
    assert scene.clear_color == (0.1, 0.1, 0.1, 1.0)
    # TRS: translate, then rotate about y by 90°, then scale: (2,0,0) -> (0,0,-2) -> (0,0,-1).
    np.testing.assert_allclose(scene.nodes[1].model[:3, 3], (0, 0, -1), atol=1e-12)
    assert scene.nodes[0].material.shading == "vertex_color"
    assert plan(scene).buffers.depth


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("name = \n", r"scene.toml:1: malformed TOML"),
        ("[[nodes]]\nmesh = \"cbe\"\n", r"scene.toml:2: nodes\[0\].mesh: unknown mesh 'cbe'"),
        ("[[nodes]]\nmesh = \"cube\"\n\n[[nodes]]\nmesh = \"cube\"\norder = \"SST\"\n",
         r"scene.toml:6: nodes\[1\].order: .*valid orders"),
        ("[[nodes]]\nmesh = \"cube\"\ncolor = [2, 0, 0]\n", r"scene.toml:3: nodes\[0\].color: colour channels"),
        ("[[nodes]]\nmesh = \"cube\"\nscale = [1, 1]\n", r"scene.toml:3: nodes\[0\].scale: expected a list of 3"),
        ("[[nodes]]\nmesh = \"cube\"\nspin = 3\n", r"scene.toml:3: nodes\[0\].spin: unknown key"),
        ("[camera]\neye = [0, 0, 0]\ntarget = [0, 5, 0]\n", r"scene.toml:1: camera: .*parallel"),
        ("[[nodes]]\nname = \"x\"\n", r"scene.toml:1: nodes\[0\]: every node needs mesh"),
        ("[[nodes]]\nmesh = \"triangle\"\nshading = \"vertex_color\"\n",
         r"scene.toml:3: nodes\[0\].shading: mesh 'triangle' has no vertex colours"),
    ],
)
def test_scene_errors_name_file_and_line(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(SandboxError, match=expected) as info:
        load_scene(write(tmp_path, text))
    assert "\n" not in str(info.value)


def test_missing_scene_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(SandboxError, match="nothere.toml: scene file not found"):
        load_scene(tmp_path / "nothere.toml")
