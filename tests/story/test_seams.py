"""The other ray-tracer exercises plugged into one traced ray: the first divergence is their call.

For every named mistake of the exercises whose function a traced ray calls besides the hit
tests (ray_plane, aabb, backface, reflect, phong, shadow, triangle_normal: their catalogue's ``MISTAKES``), a
pixel where the mistake shows (the traces part there) is traced with the mistake: the first
divergence is a call of the mutated function, named with both values. A correct version of the
function written apart from the engine (the catalogue's plain-Python helper with nothing
wrong) agrees there step for step. A mistake the tracer cannot meet is listed with why.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from support import assert_user_error, run_cli

from glsandbox.app.notebook import scene_of
from glsandbox.errors import SandboxError
from glsandbox.exercises.catalogue import aabb, backface, get, phong, ray_plane, reflect, shadow, triangle_normal
from glsandbox.exercises.plain import cross, dot, sub
from glsandbox.story.divergence import Direct, explain_with_function, traced_kind
from glsandbox.story.seams import STEPS

SIZE = (64, 48)

#: (lesson, its settings, pixel) where each mistake shows, found by scanning the lesson's pixels.
WHERE = {
    ("ray_plane", "d_sign_flipped"): ("ray_phong", {}, (42, 17)),
    ("ray_plane", "minus_dropped"): ("ray_phong", {}, (42, 17)),
    ("ray_plane", "behind_accepted"): ("ray_phong", {}, (37, 22)),
    ("aabb", "no_swap"): ("ray_phong", {}, (17, 12)),
    ("aabb", "no_miss_test"): ("ray_phong", {}, (2, 2)),
    ("aabb", "behind_accepted"): ("ray_phong", {}, (27, 12)),
    ("aabb", "entry_from_inside"): ("ray_phong", {}, (27, 12)),
    ("backface", "sign_flipped"): ("ray_phong", {}, (42, 17)),
    ("backface", "view_axis"): ("ray_phong", {}, (42, 17)),
    ("backface", "from_the_origin"): ("ray_phong", {}, (42, 17)),
    ("reflect", "plus_sign"): ("ray_phong", {}, (27, 12)),
    ("reflect", "factor_two_missing"): ("ray_phong", {}, (27, 12)),
    ("reflect", "direction_normalized"): ("ray_phong", {}, (27, 12)),
    ("phong", "diffuse_unclamped"): ("ray_spheres", {}, (42, 22)),
    ("phong", "specular_behind"): ("ray_phong", {"camera": "-3,0.5,-3,0,1,0"}, (22, 27)),  # against the light
    ("phong", "reflected_wrong_way"): ("ray_phong", {}, (27, 17)),
    ("phong", "light_not_normalized"): ("ray_spheres", {}, (27, 12)),
    ("triangle_normal", "unnormalized"): ("ray_phong", {}, (47, 17)),
    ("triangle_normal", "reversed_order"): ("ray_phong", {}, (47, 17)),
    ("triangle_normal", "cross_y_sign"): ("ray_phong", {}, (47, 17)),
    ("triangle_normal", "vertices_not_edges"): ("ray_phong", {}, (47, 17)),
    ("shadow", "the_notes_erratum"): ("ray_phong", {"scene": "exam2012"}, (2, 2)),
    ("shadow", "no_offset"): ("ray_phong", {}, (47, 17)),
    ("shadow", "towards_the_point"): ("ray_phong", {}, (27, 12)),
}

#: Mistakes a traced ray cannot meet, and why: the traces agree there.
UNSEEN = {
    ("reflect", "normal_not_normalized"): "the engine hands reflect its unit shading normal",
}

#: A correct version of each function, apart from the engine's.
CORRECT = {
    "ray_plane": lambda o, d, n, k: ray_plane._t(o, d, n, k),
    "aabb": lambda o, d, lo, hi: (lambda e, x: None if e > x or x < 0 else (e if e > 0 else (x if x > 0 else None)))(
        *aabb._slabs(o, d, lo, hi)),
    "backface": lambda v0, v1, v2, d: dot(backface._normal(v0, v1, v2), d) > 0,
    "reflect": lambda d, n: reflect._reflect(d, n),
    "phong": lambda *args: phong._phong(*args),
    "shadow": lambda p, light, tris: shadow._shadow(p, light, tris),
    "triangle_normal": lambda v0, v1, v2: triangle_normal._normalized(cross(sub(v1, v0), sub(v2, v0))),
}

CASES = [(e, m.name) for e in CORRECT for m in get(e).mistakes]


def _scene(lesson: str, settings: dict[str, str]):
    return scene_of(lesson, "explain", overlay="off", **settings)[0]


def test_every_mistake_is_placed() -> None:
    assert sorted(CASES) == sorted([*WHERE, *UNSEEN])


@pytest.mark.parametrize(("name", "mistake"), CASES)
def test_the_first_divergence_is_in_the_mutated_function(name: str, mistake: str) -> None:
    exercise = get(name)
    wrong = next(m for m in exercise.mistakes if m.name == mistake).function
    lesson, settings, pixel = WHERE.get((name, mistake), ("ray_phong", {}, (27, 12)))
    scene = _scene(lesson, settings)
    story = explain_with_function(scene, SIZE, pixel, exercise, Direct(wrong))
    if (name, mistake) in UNSEEN:
        assert story.agree, story.divergence
        return
    assert story.divergence is not None, f"{mistake} at {pixel}: the traces agree"
    assert story.divergence.in_function, story.divergence.message
    assert story.divergence.message.startswith(f"{exercise.function} returned "), story.divergence.message
    assert "where the reference has" in story.divergence.message
    assert f"called as {exercise.function}(" in story.divergence.message
    assert story.yours.replay() == story.yours.rgba8  # the story with their function is still the whole story
    right = explain_with_function(scene, SIZE, pixel, exercise, Direct(CORRECT[name]))
    assert right.agree, right.divergence
    assert right.yours.rgba8 == right.reference.rgba8


def test_a_plugged_reference_renders_the_engines_pixel() -> None:
    """The reference plugged in changes nothing the engine does (to rounding): the same 8-bit colour
    as the traced pixel without a seam, and the replay of the plugged trace gives it."""
    from glsandbox.story.ray_pixel import explain_ray_pixel

    scene = _scene("ray_phong", {})
    plain = explain_ray_pixel(scene, SIZE, (27, 12), simple=True, traced=True)
    for name in CORRECT:
        story = explain_with_function(scene, SIZE, (27, 12), get(name), Direct(get(name).reference))
        assert story.agree
        assert story.reference.rgba8 == plain.rgba8, name
        assert story.yours.replay() == story.yours.rgba8, name


def test_the_story_says_which_term_the_function_gave() -> None:
    from glsandbox.story.text import render_story

    wrong = next(m for m in get("phong").mistakes if m.name == "light_not_normalized").function
    story = explain_with_function(_scene("ray_spheres", {}), SIZE, (27, 12), get("phong"), Direct(wrong))
    yours, reference = story.yours.bounces[0].lights[0], story.reference.bounces[0].lights[0]
    assert yours.given == yours.term == [1.0, 1.0, 1.0]  # 7e63 clamped to 1
    assert reference.given is not None and reference.given != yours.given
    text = render_story(story.yours)
    assert "the function's phong(N, L, E, 255·colour, ka, kd, ks, n)/255, each channel at most 1: (1, 1, 1)" in text


def test_a_failing_function_is_named_with_its_error() -> None:
    def raises(direction, normal):
        raise ValueError("not yet")

    story = explain_with_function(_scene("ray_phong", {}), SIZE, (27, 12), get("reflect"), Direct(raises))
    assert story.divergence is not None and story.divergence.in_function
    assert story.divergence.message.startswith("reflect returned error: ValueError: not yet where the reference has")


@pytest.mark.parametrize("name", ["image_plane", "camera_turn", "world_matrix", "cube_indices"])
def test_what_a_traced_ray_does_not_call_is_refused_in_one_line(name: str) -> None:
    with pytest.raises(SandboxError) as caught:
        traced_kind(get(name))
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"--exercise {name}: ")
    assert "explain traces the exercises " + ", ".join(STEPS) in message


def test_the_steps_are_every_traced_exercise() -> None:
    assert sorted(STEPS) == sorted(["ray_sphere", "ray_triangle", *CORRECT])
    assert all(traced_kind(get(name)) for name in STEPS)


REFLECT = """import math
def reflect(direction, normal):
    size = math.sqrt(sum(x * x for x in normal))
    n = [x / size for x in normal]
    dn = sum(a * b for a, b in zip(direction, n))
    return [a {sign} 2 * dn * b for a, b in zip(direction, n)]
"""


def test_the_command_runs_a_reflect_file_confined_and_exits_like_diff(tmp_path: Path) -> None:
    wrong, right = tmp_path / "plus.py", tmp_path / "minus.py"
    wrong.write_text(REFLECT.format(sign="+"))
    right.write_text(REFLECT.format(sign="-"))
    where = ("ray_phong", "--size", "64x48", "--pixel", "27,12")
    differ = run_cli("explain", *where, "--exercise", "reflect", str(wrong))
    assert differ.returncode == 1, differ.stderr
    assert differ.stdout.startswith("first difference: reflect returned (-0.125664, -0.524427, -1.06241) where the "
                                    "reference has (-0.0296657, 0.329944, -0.967306) (for the reflected ray, the "
                                    "ray of depth 1)")
    agree = run_cli("explain", *where, "--exercise", "reflect", str(right), "--json")
    assert agree.returncode == 0, agree.stderr
    assert json.loads(agree.stdout)["agree"] is True
    assert_user_error(run_cli("explain", *where, "--exercise", "image_plane", str(right)),
                      "--exercise image_plane: image_plane is not a step of a traced ray")
