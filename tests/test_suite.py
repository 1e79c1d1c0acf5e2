"""The test suite's own layout: every lesson has a test file and goldens, and test modules share
code only through tests/support.py (fixtures through conftest.py)."""

from __future__ import annotations

import ast

from support import GOLDENS_DIR, TESTS_DIR

from glsandbox.lesson import all_lessons

LESSON_NAMES = sorted(cls.name for cls in all_lessons())


def test_every_lesson_has_a_test_file_and_at_least_one_golden() -> None:
    missing_tests = [n for n in LESSON_NAMES if not (TESTS_DIR / "lessons" / f"test_{n}.py").is_file()]
    missing_goldens = [n for n in LESSON_NAMES if not any((GOLDENS_DIR / n).glob("*.png"))]
    assert missing_tests == [] and missing_goldens == [], (missing_tests, missing_goldens)


def test_goldens_are_grouped_by_lesson() -> None:
    """tests/goldens/<lesson>/<variant>.png, and the exercises' probe pictures in
    tests/goldens/exercises/<exercise>_<variant>.png: no loose files, no folder for a lesson or
    picture for an exercise that does not exist."""
    from glsandbox.exercises.catalogue import MODULES

    entries = sorted(GOLDENS_DIR.iterdir())
    assert [p.name for p in entries if not p.is_dir()] == []
    assert [p.name for p in entries if p.name not in LESSON_NAMES and p.name != "exercises"] == []
    assert all(any(p.name.startswith(f"{name}_") for name in MODULES) for p in (GOLDENS_DIR / "exercises").iterdir())
    assert all(p.suffix == ".png" and p.is_file() for folder in entries for p in folder.iterdir())


def test_no_test_module_imports_another_or_conftest() -> None:
    test_modules = {p.stem for p in TESTS_DIR.rglob("test_*.py")} | {"conftest"}
    offenders = []
    for path in sorted(TESTS_DIR.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            else:
                continue
            offenders += [f"{path.relative_to(TESTS_DIR)}:{node.lineno}: {name}"
                          for name in names if name.split(".")[0] in test_modules]
    assert offenders == []
