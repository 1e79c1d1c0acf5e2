"""Where the course's lessons are (glsandbox/course_lessons.py): ``glsandbox.lessons`` found in a
checkout by the finder ``import glsandbox`` installs, and that import light (nothing of numpy)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from glsandbox import course_lessons

REPO = Path(__file__).resolve().parents[2]


def test_the_lessons_folder_is_the_checkouts_and_the_finder_answers_only_for_it() -> None:
    assert (course_lessons.BUILTIN_LESSONS / "__init__.py").is_file()
    finder = course_lessons.CourseLessonsFinder()
    spec = finder.find_spec(course_lessons.COURSE_PACKAGE)
    assert spec is not None and Path(spec.origin) == course_lessons.BUILTIN_LESSONS / "__init__.py"
    assert finder.find_spec("lessons") is None and finder.find_spec("glsandbox.lessonsx") is None


def test_import_glsandbox_imports_nothing_heavy_and_still_finds_the_lessons(tmp_path: Path) -> None:
    # a student's own lessons/ folder in the working directory neither hides nor is hidden
    (tmp_path / "lessons").mkdir()
    (tmp_path / "lessons" / "__init__.py").write_text("MINE = True\n")
    script = ("import json, sys\nimport glsandbox\n"
              "heavy = sorted(m for m in ('numpy', 'moderngl', 'typing', 'glsandbox.lesson') if m in sys.modules)\n"
              "import glsandbox.lessons.triangle as t, lessons\n"
              "print(json.dumps({'heavy': heavy, 'triangle': t.Triangle.name, 'mine': lessons.MINE}))\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path, timeout=120,
                          env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(REPO)})
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == {"heavy": [], "triangle": "triangle", "mine": True}


def test_a_lesson_module_runs_with_python_dash_m() -> None:
    proc = subprocess.run([sys.executable, "-m", "glsandbox.lessons.triangle", "--help"], capture_output=True,
                          text=True, cwd=REPO, timeout=120)
    assert proc.returncode == 0 and "python -m glsandbox.lessons.triangle" in proc.stdout, proc.stderr
