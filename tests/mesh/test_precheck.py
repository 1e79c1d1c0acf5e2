"""Model files checked before they are read (glsandbox.mesh.precheck): ASCII PLY and OFF cut short or with a
face line that does not match its count, an OFF without its header, refused in one line naming the file
and line; a Latin-1 OBJ and a file whose name is not UTF-8 load."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from glsandbox.errors import SandboxError
from glsandbox.mesh.load import load_model
from support import assert_user_error, need, run_cli

PLY_HEAD = ("ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n")
VERTICES = "0 0 0\n1 0 0\n0 1 0\n"

BAD = {
    # name: (text, the line the error names, words in it)
    "cut_short.ply": (PLY_HEAD.format(faces=1_000_000) + VERTICES + "3 0 1 2\n", 14,
                      "the data ends after 1 of the 1,000,000 face lines"),
    "no_faces_left.ply": (PLY_HEAD.format(faces=2) + "0 0 0\n1 0 0\n", 12, "the data ends after 2 of the 3 vertex"),
    "count_255.ply": (PLY_HEAD.format(faces=1) + VERTICES + "255 0 1 2\n", 14,
                      "a face line with 4 values, but it starts with the count '255'"),
    "short_face.ply": (PLY_HEAD.format(faces=2) + VERTICES + "3 0 1 2\n3 0 2\n", 15,
                       "a face line with 3 values, but it starts with the count '3'"),
    "short_vertex.ply": (PLY_HEAD.format(faces=1) + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", 12,
                         "a vertex line with 2 values, expected 3"),
    "cut_short.off": ("OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n", 7,
                      "the data ends after 4 of 4 vertices and 1 of 2 faces"),
    "count_255.off": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n255 0 1 2\n", 6,
                      "a face line with 4 values, but it starts with the count '255'"),
    "no_header.off": ("3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 1, "an OFF file starts with the word OFF"),
    "only_keyword.off": ("OFF\n", 1, "the file ends after its OFF line"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_broken_text_model_is_one_error_naming_file_and_line(tmp_path: Path, name: str) -> None:
    text, line, words = BAD[name]
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(SandboxError) as caught:
        load_model(path)
    message = str(caught.value)
    assert "\n" not in message and f"model file {path}, line {line}: " in message and words in message, message


def test_a_cut_short_file_on_the_command_line_is_exit_2_and_writes_nothing(tmp_path: Path) -> None:
    path = tmp_path / "cut.off"
    path.write_text(BAD["cut_short.off"][0])
    out = tmp_path / "out" / "model.png"
    out.parent.mkdir()
    run = run_cli("render", "model", "--set", f"mesh={path}", "--out", str(out), "--size", "32x32",
                  unchanged=out.parent)
    assert_user_error(run, f"{path}, line 7")


@pytest.mark.parametrize("name, text", [
    ("comments.off", "OFF # a comment\n# another\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255 0 0\n"),
    ("counts_on_keyword.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
    ("colour.off", "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n"),
    ("quad.ply", PLY_HEAD.format(faces=1).replace("element vertex 3", "element vertex 4")
     + VERTICES + "1 1 0\n4 0 1 3 2\n"),
])
def test_good_text_models_pass_the_check(tmp_path: Path, name: str, text: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    assert load_model(path).triangles >= 1


def test_an_obj_with_a_latin1_comment_is_read(tmp_path: Path) -> None:
    path = tmp_path / "latin1.obj"
    path.write_bytes(b"# caf\xe9 model, \xa9 someone\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert load_model(path).triangles == 1


def test_a_file_whose_name_is_not_utf8_loads(tmp_path: Path) -> None:
    name = os.fsdecode(b"na\xefve.obj")  # Latin-1 bytes: not UTF-8, kept by Python as a surrogate
    path = tmp_path / name
    try:
        path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    except (OSError, UnicodeError):
        need("a file system that takes file names that are not UTF-8", str(tmp_path))
    model = load_model(path)
    assert model.triangles == 1 and model.mesh.vertex_count == 3
