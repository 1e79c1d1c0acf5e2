"""``glsandbox explain``: the story on stdout, the record with --json, bad input one line and exit 2."""

from __future__ import annotations

import json

from support import assert_user_error, run_cli


def test_explain_prints_the_story() -> None:
    run = run_cli("explain", "ray_spheres", "--set", "camera=0,0,0,0,0.6,-0.8", "--size", "401x301", "--pixel", "200,150")
    assert run.returncode == 0, run.stderr
    assert "s = l·Rd = 80, m² = l·l − s² = 3600, q = √(r² − m²) = 45" in run.stdout
    assert "t = s − q = 35 → hit" in run.stdout and "P = R0 + t·Rd = (0, 21, -28)" in run.stdout


def test_explain_json_is_the_record() -> None:
    run = run_cli("explain", "ray_phong", "--set", "scene=exam2013", "--pixel", "10,10", "--size", "64x48", "--json")
    assert run.returncode == 0, run.stderr
    record = json.loads(run.stdout)
    assert record["pixel"] == [10, 10] and len(record["rgba8"]) == 4 and record["bounces"]


def test_explain_bad_input() -> None:
    assert_user_error(run_cli("explain", "ray_spheres", "--pixel", "1"), "--pixel", "X,Y")
    assert_user_error(run_cli("explain", "ray_spheres", "--pixel", "700,10"), "outside the 640x480 frame")
    assert_user_error(run_cli("explain", "no_such_lesson", "--pixel", "1,1"))
    assert_user_error(run_cli("explain", "ray_spheres", "--pixel", "1,1", "--size", "0x5"), "--size")


def test_the_docs_walk_through_show_todays_stories(gl) -> None:
    """docs/explain.md quotes three stories (two traced, one rasterised): each is what the command prints now."""
    import re

    from support import REPO_ROOT

    text = (REPO_ROOT / "docs" / "explain.md").read_text(encoding="utf-8")
    walks = re.findall(r"```sh\n(glsandbox explain [^\n]*)\n```\n\n```\n(.*?)\n```", text, re.S)
    assert len(walks) == 3
    for command, story in walks:
        run = run_cli(*command.split()[1:])
        assert run.returncode == 0, run.stderr
        assert run.stdout.rstrip("\n") == story, command
