"""The docs site's lesson pages: one Markdown page per course lesson, from the lesson registry.

A page has what the course page's card has (``glsandbox/course_page.py``), as
Markdown for MkDocs: the lesson's picture (its golden images, the pictures
the tests pin), its course section, what it shows and its worked example (the
lesson module's docstring), its parameters, and the commands that run it.
The site's build hook (``docs/_hooks/site.py``) writes one page per lesson
with :func:`lesson_page` and the index with :func:`lessons_index`.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from glsandbox.lesson import SHARED_PARAMS, Lesson, lesson_description

#: A Sphinx cross-reference, :class:`glsandbox.frame.Frame`: shown as code.
_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
#: reST literal ``code``: Markdown's `code`.
_CODE = re.compile(r"``(.+?)``")


def inline(text: str) -> str:
    """One reST paragraph's markup as Markdown: ``code`` and :role:`x` become `code`."""
    text = _ROLE.sub(lambda m: f"``{m.group(1)}``", text)
    return _CODE.sub(lambda m: f"`{m.group(1)}`", text)


def markdown_of_docstring(doc: str) -> str:
    """A lesson docstring as Markdown: prose paragraphs joined, an indented block a code block,
    ``- `` and ``* `` lines a list, a trailing ``::`` a single colon."""
    out: list[str] = []
    paragraph: list[str] = []

    def flush() -> None:
        if not paragraph:
            return
        if all(line.startswith((" ", "\t")) for line in paragraph):
            body = "\n".join(line.rstrip() for line in paragraph)
            out.append("```text\n" + _dedent(body) + "\n```")
        elif paragraph[0].startswith(("- ", "* ")):
            items: list[str] = []
            for line in paragraph:
                if line.startswith(("- ", "* ")):
                    items.append(line[2:].strip())
                else:
                    items[-1] += " " + line.strip()
            out.append("\n".join(f"- {inline(item)}" for item in items))
        else:
            text = " ".join(line.strip() for line in paragraph)
            if text.endswith("::"):
                text = text[:-1]
            out.append(inline(text))
        paragraph.clear()

    for line in doc.splitlines():
        if line.strip():
            paragraph.append(line.rstrip())
        else:
            flush()
    flush()
    return "\n\n".join(out)


def _dedent(text: str) -> str:
    lines = text.splitlines()
    indent = min(len(line) - len(line.lstrip()) for line in lines if line.strip())
    return "\n".join(line[indent:] for line in lines)


def _cell(text: object) -> str:
    """Text safe inside a Markdown table cell."""
    return inline(str(text)).replace("|", "\\|").replace("\n", " ")


def parameter_table(cls: type[Lesson]) -> str:
    """The lesson's own parameters as a table, and the shared ones (with this lesson's defaults)."""
    lines = ["| parameter | default | values | what it does |", "|---|---|---|---|"]
    for param in cls.params:
        default = cls.defaults.get(param.name, param.default)
        if param.kind is bool:
            default = "on" if default else "off"
        values = ", ".join(f"`{c}`" for c in param.choices) if param.choices else _range(param)
        lines.append(f"| `{param.name}` | `{default}` | {values} | {_cell(param.help)} |")
    if not cls.params:
        lines = ["This lesson has no parameters of its own."]
    shared = ", ".join(f"`{p.name}={cls.defaults.get(p.name, p.default)}`" for p in SHARED_PARAMS)
    lines.append("")
    lines.append(f"Every lesson also takes the shared parameters ({shared}): see "
                 "[the glsandbox command](../commands.md).")
    return "\n".join(lines)


def _range(param: object) -> str:
    low, high = getattr(param, "minimum", None), getattr(param, "maximum", None)
    if low is None and high is None:
        return "-"
    return f"{'' if low is None else f'{low:g}'} to {'' if high is None else f'{high:g}'}".strip()


def commands(cls: type[Lesson]) -> str:
    """The commands that run the lesson: a window, a picture, its plan, its comparisons."""
    name = cls.name
    lines = [f"uv run glsandbox run {name}                      # a window: ESC quits, F1 the panel",
             f"uv run glsandbox render {name} --out {name}.png --size 320x240",
             f"uv run glsandbox plan {name}                     # the passes, buffers and shader variants"]
    for caption, vary in cls.contrasts:
        lines.append(f"uv run glsandbox compare {name} --vary {vary} --size 160x120   # {caption}")
    return "```sh\n" + "\n".join(lines) + "\n```"


def lesson_page(cls: type[Lesson], number: int, pictures: Sequence[str]) -> str:
    """The page of lesson ``cls``, number ``number`` in course order; ``pictures`` are the
    page-relative paths of its golden images, the first shown large."""
    title = cls.title or cls.name
    parts = [f"# {number}. {title}", ""]
    if cls.course_section:
        parts += [f"**Course section:** {_cell(cls.course_section)}", ""]
    if pictures:
        first = pictures[0]
        parts += [f"![{cls.name}: {_cell(title)}]({first})", "",
                  f"*The picture the tests pin: `tests/goldens/{cls.name}/{Path(first).name}`.*", ""]
    description = lesson_description(cls)
    if description:
        parts += ["## What it shows", "", markdown_of_docstring(description), ""]
    parts += ["## Parameters", "", parameter_table(cls), "", "## Commands", "", commands(cls), ""]
    if len(pictures) > 1:
        parts += ["## Golden images", "", "Each setting the tests pin, by its golden file's name:", ""]
        parts += [f"![{Path(p).stem}]({p}){{ width=160 }} `{Path(p).stem}`" for p in pictures[1:]]
        parts.append("")
    return "\n".join(parts)


def lessons_index(lessons: Sequence[type[Lesson]]) -> str:
    """The lessons' index page: one row per lesson, in course order, linking its page."""
    lines = ["# The lessons", "", "Every lesson of the course, in course order. Each page has the lesson's "
             "picture, course section, what it shows, its parameters and the commands that run it; "
             "[Lesson notes](../lesson-notes.md) goes deeper into several.", "",
             "| # | lesson | course section |", "|---|---|---|"]
    for number, cls in enumerate(lessons, 1):
        lines.append(f"| {number} | [{_cell(cls.title or cls.name)}]({cls.name}.md) (`{cls.name}`) | "
                     f"{_cell(cls.course_section)} |")
    return "\n".join(lines) + "\n"
