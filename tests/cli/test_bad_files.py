"""Hostile files: named pipes and folders where a file belongs, 16-bit and oversized
images, shaders that are not UTF-8. Each is one ``error:`` line and exit 2 (or, for the 16-bit
image, the right pixels), never a hang, a warning or a traceback."""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from glsandbox.errors import SandboxError
from glsandbox.images import load_image
from support import REPO_ROOT as REPO
from support import assert_user_error, need, run_cli

@pytest.fixture
def needs_fifo() -> None:
    """Named pipes are a machine resource: skip locally without them, fail under CI."""
    if not hasattr(os, "mkfifo"):
        need("named pipes", "os.mkfifo is missing on this system")


def textured_scene(tmp_path: Path, texture: str) -> Path:
    scene = tmp_path / "textured.toml"
    scene.write_text(f'[[nodes]]\nmesh = "cube24"\ntexture = "{texture}"\n')
    return scene


# --- named pipes and folders where a file belongs -------------------------------------


@pytest.mark.usefixtures("needs_fifo")
@pytest.mark.parametrize("renderer", ["raster", "ray_numpy"])
def test_a_named_pipe_as_a_texture_is_refused_not_waited_on(tmp_path: Path, renderer: str) -> None:
    os.mkfifo(tmp_path / "pipe.png")  # opening it for reading blocked forever: no writer ever comes
    out = tmp_path / "x.png"
    proc = run_cli("render", str(textured_scene(tmp_path, "pipe.png")), "--size", "16x16", "--set",
                   f"renderer={renderer}", "--out", str(out))
    assert_user_error(proc, f"texture file {tmp_path / 'pipe.png'} is a named pipe (FIFO), expected an image file")
    assert not out.exists()


@pytest.mark.usefixtures("needs_fifo")
def test_a_named_pipe_as_the_lesson_image_or_the_scene_file_is_refused(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")
    out = tmp_path / "x.png"
    assert_user_error(run_cli("render", "texture", "--size", "16x16", "--set", f"image={tmp_path / 'pipe'}",
                              "--out", str(out)), "is a named pipe (FIFO)")
    os.mkfifo(tmp_path / "pipe.toml")
    assert_user_error(run_cli("render", str(tmp_path / "pipe.toml"), "--out", str(out)),
                      f"scene file {tmp_path / 'pipe.toml'} is a named pipe (FIFO), expected a scene .toml file")
    assert not out.exists()


def test_a_folder_as_a_texture_or_scene_is_refused(tmp_path: Path) -> None:
    (tmp_path / "folder.png").mkdir()
    with pytest.raises(SandboxError, match="is a folder, expected an image file"):
        load_image(tmp_path / "folder.png")
    (tmp_path / "folder.toml").mkdir()
    assert_user_error(run_cli("render", str(tmp_path / "folder.toml"), "--out", str(tmp_path / "x.png")),
                      "is a folder, expected a scene .toml file")


# --- images -------------------------------------------------------------------------------


def test_a_16_bit_greyscale_image_is_scaled_not_clipped(tmp_path: Path) -> None:
    ramp = np.linspace(0, 65535, 256).round().astype(np.uint16).reshape(1, 256)
    Image.fromarray(ramp).save(tmp_path / "ramp16.png")
    # Pillow opens it as mode I;16, and 10.1 (the floor below 3.13) as mode I: both are scaled.
    assert Image.open(tmp_path / "ramp16.png").mode in ("I;16", "I")
    image = load_image(tmp_path / "ramp16.png")
    assert image.shape == (1, 256, 4)
    np.testing.assert_array_equal(image[0, :, 0], np.arange(256))  # was 99.6% white
    np.testing.assert_array_equal(image[0, :, 0], image[0, :, 2])
    assert np.all(image[..., 3] == 255)
    # 32-bit integer greyscale (mode I, e.g. a TIFF) is taken as 16-bit samples too.
    Image.fromarray(ramp.astype(np.int32), "I").save(tmp_path / "ramp32.tif")
    np.testing.assert_array_equal(load_image(tmp_path / "ramp32.tif")[0, :, 0], np.arange(256))


def test_a_16_bit_texture_renders_its_grey_through_the_cli(tmp_path: Path, gl) -> None:
    Image.fromarray(np.full((8, 8), 32896, dtype=np.uint16)).save(tmp_path / "grey16.png")  # 32896 = 128 * 257
    scene = tmp_path / "grey.toml"
    scene.write_text('[camera]\neye = [0, 0, 4]\n\n[[nodes]]\nmesh = "cube24"\ntexture = "grey16.png"\n'
                     'filter = "nearest"\n')
    out = tmp_path / "x.png"
    proc = run_cli("render", str(scene), "--size", "16x16", "--out", str(out))
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    from glsandbox.files import load_png

    assert tuple(load_png(out)[8, 8, :3]) == (128, 128, 128)


def test_a_decompression_bomb_is_one_error_line_and_no_warning(tmp_path: Path) -> None:
    # 9500 x 9500 pixels (above Pillow's MAX_IMAGE_PIXELS, 89,478,485) in an 11 KB file:
    # Pillow warned on stderr before the image was refused or decoded.
    Image.new("1", (9500, 9500)).save(tmp_path / "bomb.png")
    out = tmp_path / "x.png"
    for renderer in ("raster", "ray_numpy"):
        proc = run_cli("render", str(textured_scene(tmp_path, "bomb.png")), "--size", "16x16", "--set",
                       f"renderer={renderer}", "--out", str(out))
        assert_user_error(proc, f"texture file {tmp_path / 'bomb.png'}", "too large")
        assert "DecompressionBombWarning" not in proc.stderr
    assert not out.exists()


def test_pillows_size_warning_becomes_the_error_in_process(tmp_path: Path, monkeypatch, capsys) -> None:
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 1000)
    Image.new("RGB", (40, 40)).save(tmp_path / "big.png")  # 1,600 pixels: warned, not refused, by Pillow
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(SandboxError, match="too large to decode safely"):
            load_image(tmp_path / "big.png")
    assert caught == []


# --- shaders -------------------------------------------------------------------------------


@pytest.mark.parametrize("broken", ["phong.glsl", "common/lighting.glsl"])
def test_a_shader_file_that_is_not_utf8_is_one_line_naming_it(tmp_path: Path, broken: str, gl) -> None:
    shaders = tmp_path / "shaders"
    shutil.copytree(REPO / "shaders", shaders)
    text = (shaders / broken).read_bytes()
    (shaders / broken).write_bytes(text + b"// caf\xe9 in Latin-1\n")
    line = text.count(b"\n") + 1
    out = tmp_path / "x.png"
    proc = run_cli("render", "phong", "--size", "16x16", "--out", str(out), env={"GLSANDBOX_SHADER_DIR": str(shaders)})
    assert_user_error(proc, f"{shaders / broken}:{line}: shader file is not UTF-8 text (byte 0xe9)")
    assert not out.exists()
