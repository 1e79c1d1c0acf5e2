"""The test suite's own layout: every lesson has a test file and goldens, every module with logic
has a test file named after it, and test modules share code only through tests/support.py
(fixtures through conftest.py)."""

from __future__ import annotations

import ast

from pathlib import Path

from support import GOLDENS_DIR, REPO_ROOT, TESTS_DIR

from glsandbox.lesson import all_lessons

PACKAGE = REPO_ROOT / "glsandbox"
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


#: Modules with no logic of their own (a version string, an error type, a record of a kind's parts,
#: the executor's records of a prepared draw and frame).
PURE_DATA = {"version", "raytrace/raytrace_error", "raytrace/shape_kind", "gl/draw_steps"}


def listed_modules(test_file: Path) -> tuple[str, ...]:
    """The names in a parametrised test file's module-level ``MODULES = (...)``."""
    for node in ast.parse(test_file.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == ["MODULES"]:
            return tuple(ast.literal_eval(node.value))
    return ()


def catalogue_modules(test_file: Path) -> tuple[str, ...]:
    """The exercises' registry (``glsandbox.exercises.catalogue.MODULES``), which their test file runs over."""
    from glsandbox.exercises.catalogue import MODULES

    return MODULES


#: Folders of one-entry modules (a knob, an exercise), each tested together by one parametrised
#: file over every module a list names: the file's own ``MODULES = (...)``, or the registry's
#: (that file fails on a module of the folder the list leaves out). A module there may have its
#: own ``test_<name>.py`` as well, for what only it does.
TESTED_TOGETHER = {
    "measure/knobs": (TESTS_DIR / "measure" / "knobs" / "test_every_knob.py", listed_modules),
    "exercises/catalogue": (TESTS_DIR / "exercises" / "test_catalogue.py", catalogue_modules),
}


def named_test_file(module: str) -> list[Path]:
    """Where ``glsandbox/<module>.py``'s tests live: ``tests/<sub>/test_<name>.py`` for a
    module in a sub-package; ``tests/core/``, ``tests/cli/`` or ``tests/`` for a top-level one.
    A private module's leading ``_`` is dropped (``knobs/_far.py``: ``test_far.py``); a module
    of a :data:`TESTED_TOGETHER` folder is also tested by that folder's file when it is listed."""
    *folders, name = module.split("/")
    stem = name.lstrip("_")
    places = ["/".join(folders)] if folders else ["core", "cli", "."]
    found = [TESTS_DIR / place / f"test_{stem}.py" for place in places]
    found = [path for path in found if path.is_file()]
    together, listed = TESTED_TOGETHER.get("/".join(folders), (None, None))
    if together is not None and together.is_file() and name in listed(together):
        found.append(together)
    return found


def test_a_folder_tested_together_names_only_the_modules_its_file_lists() -> None:
    knobs = TESTED_TOGETHER["measure/knobs"][0]
    assert named_test_file("measure/knobs/lighting") == [knobs]
    assert knobs in named_test_file("measure/knobs/shadow_map")  # and its own file
    assert named_test_file("exercises/catalogue/ray_sphere") == [TESTED_TOGETHER["exercises/catalogue"][0]]
    assert named_test_file("measure/knobs/not_listed") == []
    assert named_test_file("measure/knobs/_far") == [TESTS_DIR / "measure" / "knobs" / "test_far.py"]


def package_modules() -> list[str]:
    return sorted(p.relative_to(PACKAGE).with_suffix("").as_posix() for p in PACKAGE.rglob("*.py")
                  if p.name not in ("__init__.py", "__main__.py"))




def test_every_module_with_logic_has_a_test_file_named_after_it() -> None:
    modules = package_modules()
    unnamed = [m for m in modules if not named_test_file(m) and m not in PURE_DATA]
    assert unnamed == [], "add tests/<layer>/test_<module>.py for: " + ", ".join(unnamed)
    stale = sorted(m for m in PURE_DATA if m not in modules or named_test_file(m))
    assert stale == [], f"take these off PURE_DATA (gone, or their test file exists): {stale}"
