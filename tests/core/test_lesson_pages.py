"""The docs site's lesson pages (glsandbox/lesson_pages.py): a lesson docstring's reST as Markdown,
the parameter table, the commands that run it, a page and the index, from the registry.
(tests/docs/ builds the site from them and runs every command they print.)"""

from __future__ import annotations

from glsandbox.lesson import SHARED_PARAMS, all_lessons, find_lesson
from glsandbox.lesson_pages import commands, inline, lesson_page, lessons_index, markdown_of_docstring, parameter_table


def test_inline_markup_becomes_markdown_code() -> None:
    assert inline("the ``near`` plane of :class:`~glsandbox.scene.Camera`") == \
        "the `near` plane of `glsandbox.scene.Camera`"
    assert inline(":func:`glsandbox.render` and ``a`` ``b``") == "`glsandbox.render` and `a` `b`"


def test_a_docstring_becomes_paragraphs_a_list_and_a_code_block() -> None:
    doc = "\n".join([
        "A first paragraph", "on two lines::", "",
        "    t = s - q", "      = 35", "",
        "- one item", "  that wraps", "* another ``item``", "",
        "Last words."])
    assert markdown_of_docstring(doc) == "\n\n".join([
        "A first paragraph on two lines:",
        "```text\nt = s - q\n  = 35\n```",
        "- one item that wraps\n- another `item`",
        "Last words."])


def test_the_parameter_table_has_a_row_per_parameter_and_names_the_shared_ones() -> None:
    cls = find_lesson("triangle")
    lines = parameter_table(cls).splitlines()
    assert lines[:2] == ["| parameter | default | values | what it does |", "|---|---|---|---|"]
    rows = [line for line in lines[2:] if line.startswith("| `")]
    assert [row.split("`")[1] for row in rows] == [p.name for p in cls.params]
    cull = next(row for row in rows if row.startswith("| `cull`"))
    assert cull.split(" | ")[1] in ("`on`", "`off`")  # a bool's default is on or off
    topology = next(p for p in cls.params if p.name == "topology")
    assert all(f"`{choice}`" in rows[0] for choice in topology.choices)
    assert all(f"`{p.name}=" in lines[-1] for p in SHARED_PARAMS) and "(../commands.md)" in lines[-1]
    assert parameter_table(find_lesson("ray_spheres")).startswith("This lesson has no parameters of its own.")


def test_the_commands_run_a_window_a_picture_the_plan_and_each_contrast() -> None:
    cls = find_lesson("phong")
    text = commands(cls)
    lines = text.splitlines()
    assert lines[0] == "```sh" and lines[-1] == "```"
    assert all(line.split()[:3] == ["uv", "run", "glsandbox"] and line.split()[4] == "phong" for line in lines[1:-1])
    assert [line.split()[3] for line in lines[1:-1]] == ["run", "render", "plan"] + ["compare"] * len(cls.contrasts)
    assert f"--vary {cls.contrasts[0][1]}" in text


def test_a_page_shows_the_first_picture_large_and_the_rest_small() -> None:
    cls = find_lesson("phong")
    page = lesson_page(cls, 5, ["img/phong/default.png", "img/phong/gouraud.png"])
    assert page.startswith(f"# 5. {cls.title}\n")
    assert f"![phong: {cls.title}](img/phong/default.png)" in page
    assert "`tests/goldens/phong/default.png`" in page
    assert "![gouraud](img/phong/gouraud.png){ width=160 } `gouraud`" in page
    assert page.index("## What it shows") < page.index("## Parameters") < page.index("## Commands")
    assert "## Golden images" not in lesson_page(cls, 5, ["img/phong/default.png"])
    assert "![" not in lesson_page(cls, 5, [])


def test_the_index_links_every_lesson_in_course_order() -> None:
    lessons = all_lessons()
    rows = [line for line in lessons_index(lessons).splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert [int(row.split(" | ")[0][2:]) for row in rows] == list(range(1, len(lessons) + 1))
    assert all(f"]({cls.name}.md) (`{cls.name}`)" in row for cls, row in zip(lessons, rows))
