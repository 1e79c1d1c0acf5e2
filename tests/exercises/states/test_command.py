"""``glsandbox exercise start|check mirror_states`` (glsandbox/exercises/states/command.py): the
starter refused as blank, the reference passing with its leak map written, a mistake's hint, and
bad input one ``error:`` line with nothing half-written."""

from __future__ import annotations

from pathlib import Path

from support import assert_user_error, run_cli

from glsandbox.exercises.states.mirror import REFERENCE_SOURCE


def test_start_then_check_from_the_command_line(gl, tmp_path: Path) -> None:
    run = run_cli("exercise", "start", "mirror_states", cwd=tmp_path)
    assert run.returncode == 0 and (tmp_path / "mirror_states.py").is_file()
    assert_user_error(run_cli("exercise", "check", "mirror_states", "mirror_states.py", cwd=tmp_path),
                      "mirror_states.py:10:", "left blank")
    assert not (tmp_path / "mirror_states_check").exists()  # nothing half-written
    (tmp_path / "right.py").write_text(REFERENCE_SOURCE, encoding="utf-8")
    run = run_cli("exercise", "check", "mirror_states", "right.py", cwd=tmp_path)
    assert run.returncode == 0 and "PASS" in run.stdout
    assert (tmp_path / "right_check" / "leak_map.png").is_file()
    (tmp_path / "wrong.py").write_text(REFERENCE_SOURCE.replace('"StencilFunc": "D3D11_COMPARISON_EQUAL",\n    '
                                                                '"StencilPassOp": "D3D11_STENCIL_OP_KEEP"',
                                                                '"StencilFunc": "D3D11_COMPARISON_ALWAYS",\n    '
                                                                '"StencilPassOp": "D3D11_STENCIL_OP_KEEP"'),
                                       encoding="utf-8")
    run = run_cli("exercise", "check", "mirror_states", "wrong.py", cwd=tmp_path)
    assert run.returncode == 1 and "hint: stencil_always:" in run.stdout
    assert "reflection outside the mirror" in run.stdout


def test_check_of_a_missing_file_is_one_error_line(tmp_path: Path) -> None:
    assert_user_error(run_cli("exercise", "check", "mirror_states", "nowhere.py", cwd=tmp_path), "nowhere.py")


def test_a_state_exercise_has_no_html_report(tmp_path: Path) -> None:
    (tmp_path / "right.py").write_text(REFERENCE_SOURCE, encoding="utf-8")
    assert_user_error(run_cli("exercise", "check", "mirror_states", "right.py", "--html", "r.html", cwd=tmp_path),
                      "--html", "leak map")
    assert not (tmp_path / "r.html").exists() and not (tmp_path / "right_check").exists()
