"""MkDocs hooks for glsandbox's site: the pages generated when it is built.

- one page per lesson and their index (``lessons/``), from the lesson registry
  (:mod:`glsandbox.lesson_pages`), with the lesson's golden images as pictures;
- the benchmarks page's tables, from the ``glsandbox bench --json`` output kept
  in ``docs/data/bench.json`` (:mod:`glsandbox.measure.bench_tables`);
- the changelog, from the repository's ``CHANGELOG.md``;
- the exercises page in the navigation when ``docs/exercises.md`` exists.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

from glsandbox.lesson import all_lessons
from glsandbox.lesson_pages import lesson_page, lessons_index
from glsandbox.measure.bench_tables import bench_tables

ROOT = Path(__file__).resolve().parents[2]
GOLDENS = ROOT / "tests" / "goldens"
BENCH_DATA = ROOT / "docs" / "data" / "bench.json"
BENCH_MARK = "<!-- glsandbox: bench tables -->"


def golden_pictures(name: str) -> list[Path]:
    """A lesson's golden images, the one of its defaults first (``default.png``, else the one
    named as the lesson, else the first by name)."""
    found = sorted((GOLDENS / name).glob("*.png"))
    first = next((p for p in found if p.stem in ("default", name)), found[0] if found else None)
    return [first, *(p for p in found if p != first)] if first else []


def on_config(config: Any) -> Any:
    """The lessons' pages (and the exercises, where written) in the navigation after "Getting started"."""
    nav = config["nav"]
    entries: list[Any] = [{"Lessons": ["lessons/index.md", *({f"{n}. {cls.title or cls.name}": f"lessons/{cls.name}.md"}
                                                              for n, cls in enumerate(all_lessons(), 1))]}]
    if (Path(config["docs_dir"]) / "exercises.md").is_file():
        entries.append({"Exercises": "exercises.md"})
    at = next(i for i, item in enumerate(nav) if isinstance(item, dict) and "getting-started.md" in item.values())
    nav[at + 1:at + 1] = entries
    return config


def on_files(files: Files, config: Any) -> Files:
    lessons = all_lessons()
    files.append(File.generated(config, "lessons/index.md", content=lessons_index(lessons)))
    for number, cls in enumerate(lessons, 1):
        pictures = golden_pictures(cls.name)
        uris = []
        for picture in pictures:
            uri = f"lessons/pictures/{cls.name}/{picture.name}"
            files.append(File.generated(config, uri, abs_src_path=str(picture)))
            uris.append(f"pictures/{cls.name}/{picture.name}")
        files.append(File.generated(config, f"lessons/{cls.name}.md", content=lesson_page(cls, number, uris)))
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    files.append(File.generated(config, "changelog.md", content=changelog))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    if BENCH_MARK in markdown:
        data = json.loads(BENCH_DATA.read_text(encoding="utf-8"))
        markdown = markdown.replace(BENCH_MARK, bench_tables(data))
    return markdown
