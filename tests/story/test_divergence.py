"""A pixel traced with a student's function beside the reference: the first step where they part.

Every named mistake of the exercises the ray tracer traces (their catalogue's ``MISTAKES``) is
traced at a pixel where it shows (from the lesson picture's difference, or, for a mistake the
lesson's camera never meets, the lesson seen from where it does): the first divergence is a
call of the mutated function, named with both values; a correct variant of the same function
agrees there, step for step.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support import assert_user_error, run_cli

from glsandbox.errors import SandboxError
from glsandbox.exercises.catalogue import all_exercises, get
from glsandbox.exercises.lesson_view import THRESHOLD, render_lesson
from glsandbox.app.notebook import scene_of
from glsandbox.story.divergence import (
    Direct,
    explain_with_function,
    render_exercise_story,
    traced_kind,
)

TRACED = [e for e in all_exercises() if e.lesson is not None]

#: Where a mistake the lesson's own camera never meets shows: the lesson and a camera
#: (eye, target) from which rays meet what the mistake gets wrong.
SEEN_FROM = {
    # inside the big sphere's box, outside the sphere, looking away: the sphere is tested, behind the ray
    ("ray_sphere", "behind_accepted"): ("ray_spheres", "70,70,-100,140,140,-100"),
    ("ray_sphere", "no_inside"): ("ray_spheres", "0,0,-100,0,0,-200"),  # from the big sphere's centre
    ("ray_triangle", "behind_accepted"): ("indexed_cube", "0,0,0,0,0,-1"),  # inside the cube: a face behind
    ("ray_triangle", "one_sided"): ("indexed_cube", "0,0,0,0,0,-1"),  # inside the cube: only back faces
}

#: A correct variant of each traced function (another algorithm, agreeing to rounding).
CORRECT = {"ray_sphere": "geometric", "ray_triangle": "moller_trumbore"}

CASES = [(e.name, m.name) for e in TRACED for m in e.mistakes]


def _where_it_shows(exercise, mistake):
    """``(scene, size, pixel)``: a pixel of the lesson picture the mistake changes, else ``SEEN_FROM``."""
    view = exercise.lesson
    if (exercise.name, mistake.name) in SEEN_FROM:
        lesson, camera = SEEN_FROM[(exercise.name, mistake.name)]
        return scene_of(lesson, "explain", camera=camera, overlay="off")[0], view.size, (view.size[0] // 2,
                                                                                         view.size[1] // 2)
    result = render_lesson(exercise, Direct(mistake.function))
    w = view.size[0]
    yours, reference = result.image[:, :w, :3].astype(int), result.image[:, w + 4:2 * w + 4, :3].astype(int)
    ys, xs = np.nonzero(np.abs(yours - reference).max(axis=2) > THRESHOLD)
    assert xs.size, f"{mistake.name}: the lesson picture shows no difference; say where it shows in SEEN_FROM"
    k = xs.size // 2
    return view.scene(), view.size, (int(xs[k]), int(ys[k]))


def test_the_traced_exercises_are_the_hit_tests() -> None:
    assert sorted(e.name for e in TRACED) == ["ray_sphere", "ray_triangle"]
    with pytest.raises(SandboxError, match="is not a step of a traced ray"):
        traced_kind(get("camera_turn"))


@pytest.mark.parametrize(("name", "mistake"), CASES)
def test_the_first_divergence_is_in_the_mutated_function(name: str, mistake: str) -> None:
    exercise = get(name)
    wrong = next(m for m in exercise.mistakes if m.name == mistake)
    scene, size, pixel = _where_it_shows(exercise, wrong)
    story = explain_with_function(scene, size, pixel, exercise, Direct(wrong.function))
    assert story.divergence is not None, f"{mistake} at {pixel}: the traces agree"
    assert story.divergence.in_function, story.divergence.message
    assert story.divergence.message.startswith(f"{exercise.function} returned "), story.divergence.message
    assert "where the reference has" in story.divergence.message
    right = explain_with_function(scene, size, pixel, exercise, Direct(exercise.extra["variants"][CORRECT[name]]))
    assert right.agree, right.divergence
    assert right.yours.rgba8 == right.reference.rgba8


def test_the_notes_worked_example_is_named_in_the_scene_units() -> None:
    """The notes' #4 (C (0,0,100), r 75, Rd (0,0.6,0.8)): the far root is 125 where the reference has 35."""
    exercise = get("ray_sphere")
    far_root = next(m for m in exercise.mistakes if m.name == "far_root").function
    scene, _ = scene_of("ray_spheres", "explain", camera="0,0,0,0,0.6,-0.8")
    story = explain_with_function(scene, (401, 301), (200, 150), exercise, Direct(far_root))
    assert story.divergence is not None and story.divergence.index == 0
    assert story.divergence.message.startswith("intersect_sphere returned t = 125 where the reference has 35 "
                                               "(big, the primary ray)")
    assert story.reference.bounces[0].t == pytest.approx(35.0) and story.yours.bounces[0].t == pytest.approx(125.0)
    text = render_exercise_story(story)
    assert text.splitlines()[0].startswith("first difference: intersect_sphere returned t = 125")
    left, right = text.splitlines()[2].split(" │ ")  # the two columns' titles, aligned
    assert left.startswith("yours") and right == "the reference"
    assert any("your intersect_sphere gave t = 125" in line for line in text.splitlines())


SPHERE = """import math
def intersect_sphere(origin, direction, center, radius):
    l = [c - o for c, o in zip(center, origin)]
    s = sum(a * b for a, b in zip(l, direction))
    l2 = sum(a * a for a in l)
    m2, r2 = l2 - s * s, radius * radius
    if m2 > r2 or (l2 > r2 and s < 0):
        return None
    t = {root}
    return t if t > 0 else None
"""


def test_the_command_runs_the_file_confined_and_exits_like_diff(tmp_path: Path) -> None:
    far = tmp_path / "far.py"
    far.write_text(SPHERE.format(root="s + math.sqrt(r2 - m2)"))
    good = tmp_path / "good.py"
    good.write_text(SPHERE.format(root="s - math.sqrt(r2 - m2) if l2 > r2 else s + math.sqrt(r2 - m2)"))
    where = ("ray_spheres", "--set", "camera=0,0,0,0,0.6,-0.8", "--size", "401x301", "--pixel", "200,150")
    differ = run_cli("explain", *where, "--exercise", "ray_sphere", str(far))
    assert differ.returncode == 1, differ.stderr
    assert differ.stdout.startswith("first difference: intersect_sphere returned t = 125 "
                                    "where the reference has 35")
    agree = run_cli("explain", *where, "--exercise", "ray_sphere", str(good), "--json")
    assert agree.returncode == 0, agree.stderr
    record = json.loads(agree.stdout)
    assert record["agree"] is True and record["yours"]["rgba8"] == record["reference"]["rgba8"]
    assert_user_error(run_cli("explain", *where, "--exercise", "camera_turn", str(good)), "--exercise camera_turn")
    assert_user_error(run_cli("explain", *where, "--exercise", "ray_sphere", str(tmp_path / "none.py")), "none.py")
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('at import')\ndef intersect_sphere(origin, direction, center, radius):\n"
                      "    return None\n")
    assert_user_error(run_cli("explain", *where, "--exercise", "ray_sphere", str(broken)), "broken.py")


def test_the_notebook_traces_a_function_of_the_kernel() -> None:
    import glsandbox

    exercise = get("ray_sphere")
    far_root = next(m for m in exercise.mistakes if m.name == "far_root").function
    story = glsandbox.explain("ray_spheres", (200, 150), (401, 301), exercise=("ray_sphere", far_root),
                              camera="0,0,0,0,0.6,-0.8")
    assert story.text.startswith("first difference: intersect_sphere returned t = 125 where the reference has 35")
    assert story.rgba8 == story.record.yours.rgba8 and "<pre" in story._repr_html_()

    def raises(origin, direction, center, radius):
        raise ValueError("not yet")

    broken = glsandbox.explain("ray_spheres", (200, 150), (401, 301), exercise=("ray_sphere", raises),
                               camera="0,0,0,0,0.6,-0.8")
    assert "intersect_sphere returned error: ValueError: not yet where the reference has 35" in broken.text
