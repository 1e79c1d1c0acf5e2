"""The raster half's exercises: the convention each matrix exercise accepts, the cube's index
buffer judged by the faces it covers, and the drawn probe pictures (the cube's image under a
matrix, the box seen from four sides)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.exercises import get
from glsandbox.exercises.check import PASS, check_file, check_function
from glsandbox.exercises.isolation import InProcess
from glsandbox.exercises.probe import probe_picture, reference_values

MATRICES = ["world_matrix", "look_at", "perspective", "normal_matrix", "reflect_matrix", "shadow_matrix"]
#: The named mistake a transposed answer is: the column-vector form (for the normal matrix, the
#: transpose of the inverse transpose is the inverse).
TRANSPOSED = {name: "column_vectors" for name in MATRICES} | {"normal_matrix": "inverse_only"}


class _Reference:
    def __init__(self, exercise) -> None:
        self.exercise = exercise

    def batch(self, inputs):
        return reference_values(self.exercise, inputs), {}


@pytest.mark.parametrize("name", MATRICES)
def test_each_matrix_exercise_says_its_convention_and_names_the_transpose(name: str) -> None:
    exercise = get(name)
    assert "row vectors" in exercise.convention and "transpose" in exercise.convention
    assert "row vectors" in exercise.doc or "Convention" in exercise.doc or "p·" in exercise.doc

    def transposed(*args):
        return np.asarray(exercise.reference(*args)).T.tolist()

    result = check_function(exercise, transposed, hidden=True, probe_size=64)
    assert not result.visible_passed
    assert result.mistakes[:1] == [TRANSPOSED[name]], result.mistakes
    assert "transpose" in result.hints[0]


@pytest.mark.parametrize("name", MATRICES)
def test_the_reference_draws_the_cube_in_grey_only_and_the_transpose_draws_its_own_edges(name: str) -> None:
    exercise = get(name)
    same = probe_picture(exercise, _Reference(exercise), 128)
    counts = same.counts()
    assert same.agrees and counts["agree"] > 200, counts
    wrong = probe_picture(exercise, InProcess(lambda *a: np.asarray(exercise.reference(*a)).T), 128)
    counts = wrong.counts()
    assert counts["student only"] + counts["reference only"] > 100, counts
    assert len(wrong.sample(8)) == len(wrong.inputs)  # one piece of evidence an input


NOTES = ((-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1), (-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1))
BUFFER = [3, 1, 0, 2, 1, 3, 0, 5, 4, 1, 5, 0, 3, 4, 7, 0, 4, 3, 1, 6, 5, 2, 6, 1, 2, 7, 6, 3, 7, 2, 6, 4, 5, 7, 4, 6]


def _notes_only(vertices):
    return list(BUFFER)


def test_the_notes_index_buffer_passes_its_worked_example_and_its_triangles_in_any_order_and_turn() -> None:
    exercise = get("cube_indices")
    triangles = [BUFFER[i:i + 3] for i in range(0, 36, 3)]
    shuffled = [t[1:] + t[:1] for t in triangles[::-1]]  # each started at its second corner, listed backwards
    for answer in (BUFFER, [k for t in shuffled for k in t]):
        result = check_function(exercise, lambda v, a=answer: a, probe=False)
        assert result.visible_passed, result.cases
    # the notes' buffer copied does not pass the corners listed in another order
    result = check_function(exercise, _notes_only, hidden=True, probe=False)
    assert result.visible_passed and not all(c.passed for c in result.cases)


def test_a_cube_buffer_that_covers_a_face_with_overlapping_triangles_fails() -> None:
    exercise = get("cube_indices")
    overlapping = list(BUFFER)
    # the top face's triangles (3, 1, 0) and (0, 2, 1): both clockwise from above, but they share
    # the edge 0-1, not a diagonal, so they overlap and leave a quarter of the face open
    overlapping[3:6] = [0, 2, 1]
    result = check_function(exercise, lambda v: overlapping, probe=False)
    assert not result.visible_passed


def test_a_cube_buffer_of_the_wrong_type_fails_with_a_note(tmp_path) -> None:
    exercise = get("cube_indices")
    path = tmp_path / "cube.py"
    path.write_text("def cube_indices(vertices):\n    return [float(i) for i in range(36)]\n", encoding="utf-8")
    result = check_file(exercise, path, probe_size=64)
    assert result.cases[0].status != PASS and "whole numbers" in result.cases[0].note
    assert result.probe.counts()["broken"] > 0


def test_each_cube_mistake_draws_its_face_differently() -> None:
    exercise = get("cube_indices")
    pictures = {}
    for mistake in exercise.mistakes:
        probe = probe_picture(exercise, InProcess(mistake.function), 128)
        counts = probe.counts()
        assert counts["value differs"] + counts["reference only"] > 0, (mistake.name, counts)
        pictures[mistake.name] = counts
    # a back face is seen from behind (amber); a missing face shows the inside of the box (amber too,
    # but another face), a triangle twice leaves half a face: no two mistakes count alike
    assert len({tuple(sorted(c.items())) for c in pictures.values()}) == len(pictures)


GOLDENS = [("world_matrix", "column_vectors"), ("look_at", None), ("shadow_matrix", "whole_sign"),
           ("cube_indices", "face_made_back")]


@pytest.mark.parametrize(("name", "mistake"), GOLDENS)
def test_drawn_probe_pictures_match_their_goldens(golden, name: str, mistake: str | None) -> None:
    exercise = get(name)
    caller = _Reference(exercise) if mistake is None else \
        InProcess(next(m.function for m in exercise.mistakes if m.name == mistake))
    probe = probe_picture(exercise, caller, 256)
    assert probe.image.shape == (256, 256, 4) and probe.agrees == (mistake is None)
    golden(probe.image, f"exercises/{name}_{mistake or 'reference'}", threshold=0, max_bad_share=0.0)
