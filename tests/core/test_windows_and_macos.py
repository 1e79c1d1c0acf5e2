"""What differs on Windows and macOS, checked here: user files are read in binary mode, paths
written in scene and grading files mean the same on every system, and an output's atomic
replace waits for a program that holds the old file open (Windows refuses to replace it)."""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np
import pytest
from support import CUBE_OBJ, assert_user_error, quadrant_image, run_cli

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.files import atomic_write, open_regular, read_user_file, written_path
from glsandbox.scene_file import load_scene

# --- binary reads ------------------------------------------------------------------------------


def test_user_files_are_opened_with_windows_binary_flag(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Windows's os.open reads in text mode unless O_BINARY is given: a PNG's signature
    (89 50 4E 47 0D 0A 1A 0A) would lose its CR and end at the 0x1A byte."""
    png = tmp_path / "a.png"
    signature = b"\x89PNG\r\n\x1a\n"
    png.write_bytes(signature + b"\r\n\x1a rest")
    seen: list[int] = []
    real_open = os.open

    def recording_open(path, flags, *args):
        seen.append(flags)
        return real_open(path, flags & ~0x8000, *args)  # this system has no O_BINARY bit to give

    monkeypatch.setattr(os, "O_BINARY", 0x8000, raising=False)
    monkeypatch.setattr(files, "READ_FLAGS", files.READ_FLAGS | 0x8000)  # what the module computes on Windows
    monkeypatch.setattr(os, "open", recording_open)
    assert read_user_file(png, "texture", "a PNG") == signature + b"\r\n\x1a rest"
    with open_regular(png) as handle:
        assert handle.read() == signature + b"\r\n\x1a rest"
    assert seen and all(flags & 0x8000 for flags in seen)


def test_the_read_flags_ask_for_binary_wherever_the_system_has_it() -> None:
    assert files.READ_FLAGS & getattr(os, "O_BINARY", 0) == getattr(os, "O_BINARY", 0)
    assert files.READ_FLAGS & os.O_ACCMODE == os.O_RDONLY


def test_a_texture_with_crlf_and_ctrl_z_bytes_loads_whole(tmp_path: Path) -> None:
    """A PNG whose compressed data holds CR LF and 0x1A bytes reads back exactly."""
    from glsandbox.files import load_png, save_png

    image = np.zeros((8, 8, 4), np.uint8)
    image[..., 0], image[..., 1], image[..., 3] = 0x0D, 0x1A, 255
    save_png(image, tmp_path / "t.png")
    data = read_user_file(tmp_path / "t.png", "texture", "a PNG")
    assert data == (tmp_path / "t.png").read_bytes()
    np.testing.assert_array_equal(load_png(tmp_path / "t.png"), image)


# --- paths written in files ----------------------------------------------------------------------


@pytest.mark.parametrize("text, expected", [
    ("textures\\brick.png", "/course/scenes/textures/brick.png"),
    ("textures/brick.png", "/course/scenes/textures/brick.png"),
    ("..\\shared\\brick.png", "/course/scenes/../shared/brick.png"),
    ("/srv/brick.png", "/srv/brick.png"),
])
def test_paths_in_files_mean_the_same_on_linux_and_macos(text: str, expected: str) -> None:
    assert files._written(text, PurePosixPath("/course/scenes"), windows=False) == PurePosixPath(expected)


@pytest.mark.parametrize("text, expected", [
    ("textures\\brick.png", "D:\\course\\scenes\\textures\\brick.png"),
    ("textures/brick.png", "D:\\course\\scenes\\textures\\brick.png"),
    ("C:\\Users\\ada\\brick.png", "C:\\Users\\ada\\brick.png"),
    ("C:/Users/ada/brick.png", "C:\\Users\\ada\\brick.png"),
    ("\\\\server\\share\\brick.png", "\\\\server\\share\\brick.png"),
])
def test_paths_in_files_mean_the_same_on_windows(text: str, expected: str) -> None:
    assert files._written(text, PureWindowsPath("D:\\course\\scenes"), windows=True) == PureWindowsPath(expected)


@pytest.mark.parametrize("text", ["C:\\Users\\ada\\brick.png", "c:/brick.png", "\\\\server\\share\\brick.png"])
def test_a_windows_drive_path_elsewhere_is_one_clear_error(text: str) -> None:
    with pytest.raises(SandboxError, match="is a Windows path"):
        files._written(text, PurePosixPath("/course"), windows=False)


def scene_with(tmp_path: Path, key: str, value: str) -> Path:
    lit = 'shading = "phong"\n' if key == "texture" else ""
    mesh = 'mesh = "cube24"\n' if key != "mesh" else ""
    text = f'name = "s"\n\n[[lights]]\nposition = [2, 3, 4]\n\n[[nodes]]\nname = "n"\n{mesh}{lit}{key} = {value!r}\n'
    path = tmp_path / "scene.toml"
    path.write_text(text.replace("'", '"'), encoding="utf-8")
    return path


def test_a_scene_file_from_windows_finds_its_texture_and_model_by_backslash_paths(tmp_path: Path) -> None:
    (tmp_path / "textures").mkdir()
    quadrant_image().save(tmp_path / "textures" / "q.png")
    scene = load_scene(scene_with(tmp_path, "texture", "textures\\q.png"))
    assert Path(scene.nodes[0].material.texture.source) == tmp_path / "textures" / "q.png"
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "cube.obj").write_text(CUBE_OBJ)
    scene = load_scene(scene_with(tmp_path, "mesh", "models\\cube.obj"))
    assert len(scene.nodes[0].mesh.indices) > 0


def test_a_drive_letter_path_in_a_scene_file_names_the_file_and_line(tmp_path: Path) -> None:
    path = scene_with(tmp_path, "texture", "C:\\Users\\ada\\q.png")
    if os.name == "nt":
        pytest.skip("a drive letter is this system's own path")
    assert_user_error(run_cli("render", str(path), "--out", str(tmp_path / "o.png")),
                      f"{path}:10: nodes[0].texture:", "is a Windows path (drive C:)")
    assert not (tmp_path / "o.png").exists()


# --- replacing an output that another program holds open ---------------------------------------


def test_an_output_held_open_is_replaced_once_the_holder_lets_go(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Windows: os.replace raises PermissionError (a sharing violation) while a viewer has the
    file open; the write waits and tries again."""
    target = tmp_path / "frame.png"
    target.write_bytes(b"old")
    real_replace = os.replace
    refusals = iter([True, True, False])

    def windows_replace(src, dst):
        if next(refusals):
            raise PermissionError(13, "The process cannot access the file because it is being used by another process")
        real_replace(src, dst)

    monkeypatch.setattr(files, "REPLACE_WAIT_S", 0.0)
    monkeypatch.setattr(os, "replace", windows_replace)
    atomic_write(target, b"new")
    assert target.read_bytes() == b"new"
    assert [p.name for p in tmp_path.iterdir()] == ["frame.png"]  # no temporary file left


def test_an_output_held_open_for_good_is_one_error_and_the_old_file_stays(tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "frame.png"
    target.write_bytes(b"old")

    def refuse(src, dst):
        raise PermissionError(13, "Access is denied")

    monkeypatch.setattr(files, "REPLACE_WAIT_S", 0.0)
    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(PermissionError, match="another program has it open"):
        atomic_write(target, b"new")
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["frame.png"]


def test_an_output_open_for_reading_here_is_replaced_and_the_reader_keeps_the_old_bytes(tmp_path: Path) -> None:
    target = tmp_path / "frame.png"
    target.write_bytes(b"old")
    with open(target, "rb") as reader:
        atomic_write(target, b"new")
        assert reader.read() == b"old"
    assert target.read_bytes() == b"new"
