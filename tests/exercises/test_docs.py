"""The exercises' page and the README list the catalogue as it is."""

from __future__ import annotations

from support import REPO_ROOT

from glsandbox.exercises.catalogue import all_exercises, markdown_table


def test_the_docs_table_is_the_catalogue() -> None:
    page = (REPO_ROOT / "docs" / "exercises.md").read_text(encoding="utf-8")
    start = page.index("-->\n", page.index("<!-- exercises table")) + len("-->\n")
    end = page.index("\n<!-- end of the exercises table -->")
    assert page[start:end] == markdown_table()


def test_the_readme_names_every_exercise_and_points_to_the_page() -> None:
    readme = (REPO_ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Exercises"):]
    section = section[:section.index("\n## ", 4)]
    assert "docs/exercises.md" in section and len(section.splitlines()) <= 25
    for exercise in all_exercises():
        assert f"`{exercise.name}`" in section and f"`{exercise.signature}`" in section
