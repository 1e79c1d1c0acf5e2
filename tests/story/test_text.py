"""A ray-traced pixel's record as text (glsandbox/story/text.py): six significant digits, the
course's numbered steps, and the notes' worked examples word for word."""

from __future__ import annotations

import math

import pytest
from support import TESTS_DIR, course_ray

from glsandbox.story.text import num, render_story, vec


@pytest.mark.parametrize("fixture,lesson,direction,settings", [
    ("ray_spheres_t35.txt", "ray_spheres", "0,0.6,-0.8", ()),
    ("ray_phong_exam2013.txt", "ray_phong", "0.96,0.28,0", ("scene=exam2013",)),
])
def test_golden_traces(fixture: str, lesson: str, direction: str, settings: tuple[str, ...]) -> None:
    expected = (TESTS_DIR / "story" / "traces" / fixture).read_text(encoding="utf-8")
    assert course_ray(lesson, direction, *settings).text + "\n" == expected


def test_numbers_have_six_significant_digits_and_no_minus_zero() -> None:
    assert num(35.00000000000001) == "35" and num(-0.0) == "0" and num(-1e-9) == "-1e-09"
    assert num(2 / 3) == "0.666667" and num(2 / 3, 2) == "0.67" and num(None) == "none"
    assert (num(math.inf), num(-math.inf), num(math.nan)) == ("inf", "-inf", "nan")


def test_vectors_print_tiny_components_as_zero() -> None:
    assert vec((0.0, 0.6, -0.8)) == "(0, 0.6, -0.8)"
    assert vec((1e-17, 21.0, -28.0)) == "(0, 21, -28)"  # float noise beside 28 is printed as 0
    assert vec((1e-17, 1e-17, 0.0)) == "(1e-17, 1e-17, 0)"  # not when it is the largest component
    assert vec((0.0, 0.0, 0.0)) == "(0, 0, 0)" and vec(None) == "none"


def test_the_story_is_numbered_steps_ending_in_the_8_bit_colour() -> None:
    story = course_ray("ray_spheres", "0,0.6,-0.8")
    text = render_story(story.record)
    assert text == story.text
    lines = text.splitlines()
    assert lines[0].startswith(f"{story.record.title}: pixel 200,150 of 401x301")
    steps = [int(line.split(".")[0]) for line in lines if line[:1].isdigit()]
    assert steps == list(range(1, len(steps) + 1)) and len(steps) >= 3
    levels = ", ".join(str(v) for v in story.rgba8[:3])
    assert lines[-1].startswith(f"{steps[-1]}. Final colour") and lines[-1].endswith(f"({levels}) in 8-bit levels")
