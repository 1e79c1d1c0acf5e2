"""The README and the manual's pages: the README stays a front door, no page or module names
a tracker's issue, and every ``glsandbox`` command and Python block in the docs is one that
works (the commands parse, name real lessons and parameters; the headless ones run)."""

from __future__ import annotations

import ast
import doctest
import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT, assert_user_error, run_cli

from glsandbox.cli import build_parser, check_merge_parser
from glsandbox.lesson import LESSON_SUFFIXES, all_lessons, find_lesson
from glsandbox.lesson_pages import lesson_page

README_LIMIT = 400
#: A reference to the project's tracker: "issue 21", "issues 20 and 24", "issue #6", "PR #3".
ISSUE_REFERENCE = re.compile(r"\b(?:issues?|PR|pull request)\s+#?\d+", re.I)
#: Where text and code live: everything but the changelog, which tells the history.
CHECKED = ("glsandbox", "lessons", "docs", "shaders", "benchmarks", "examples", "tests")
#: This file: the pattern's own examples below name issues on purpose.
PATTERN_EXAMPLES = Path(__file__).resolve()
SUFFIXES = {".py", ".md", ".glsl", ".toml", ".tmpl", ".html", ".txt", ".yml"}
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)


def pages() -> dict[str, str]:
    """The README, every hand-written page in docs/ and every generated lesson page, by name."""
    found = {"README.md": (REPO_ROOT / "README.md").read_text(encoding="utf-8")}
    found.update({p.name: p.read_text(encoding="utf-8") for p in sorted((REPO_ROOT / "docs").glob("*.md"))})
    for number, cls in enumerate(all_lessons(), 1):
        found[f"lessons/{cls.name}.md"] = lesson_page(cls, number, [])
    return found


def blocks(text: str, *languages: str) -> list[str]:
    return [body for lang, body in FENCE.findall(text) if lang in languages]


def glsandbox_commands() -> list[tuple[str, list[str]]]:
    """Every ``glsandbox ...`` command line in a shell block: (page, its words after ``glsandbox``)."""
    found = []
    for name, text in pages().items():
        for block in blocks(text, "sh", "bash", "shell"):
            for line in block.replace("\\\n", " ").splitlines():
                line = line.split(" #")[0].strip()
                for part in line.split(" && "):
                    words = shlex.split(part)
                    if "glsandbox" in words and words[0] in ("uv", "glsandbox", "xvfb-run"):
                        found.append((name, words[words.index("glsandbox") + 1:]))
    return found


def test_the_readme_is_a_front_door() -> None:
    lines = (REPO_ROOT / "README.md").read_text(encoding="utf-8").count("\n")
    assert lines <= README_LIMIT, f"README.md has {lines} lines: the manual goes in docs/"


def test_no_page_or_module_names_an_issue() -> None:
    files = [REPO_ROOT / "README.md"] + [p for folder in CHECKED for p in (REPO_ROOT / folder).rglob("*")
                                         if p.suffix in SUFFIXES and p.is_file() and "__pycache__" not in p.parts
                                         and p.resolve() != PATTERN_EXAMPLES]
    found = [f"{p.relative_to(REPO_ROOT)}:{n}: {line.strip()[:100]}" for p in files
             for n, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1)
             if ISSUE_REFERENCE.search(line)]
    assert not found, "history belongs in CHANGELOG.md:\n" + "\n".join(found)


def test_the_issue_pattern_finds_references_and_spares_the_course() -> None:
    assert ISSUE_REFERENCE.search("(issue 21, next section)") and ISSUE_REFERENCE.search("issues 20 and 24")
    assert ISSUE_REFERENCE.search("see Issue #6") and ISSUE_REFERENCE.search("PR #3")
    assert not ISSUE_REFERENCE.search("worked example #4 (t = 35)") and not ISSUE_REFERENCE.search("the #10 erratum")


def test_every_python_block_in_the_docs_is_python() -> None:
    bad = []
    for name, text in pages().items():
        for code in blocks(text, "python", "py"):
            if code.lstrip().startswith(">>>"):  # a session: its statements
                code = "".join(example.source for example in doctest.DocTestParser().get_examples(code))
            try:
                ast.parse(code)
            except SyntaxError as exc:
                bad.append(f"{name}: {exc}")
    assert not bad, bad


def test_every_glsandbox_command_in_the_docs_parses_with_real_lessons_and_parameters() -> None:
    commands = glsandbox_commands()
    assert len(commands) > 40  # the README, the hand pages and every lesson page
    problems = []
    for page, words in commands:
        if words[:2] == ["check", "merge"]:  # a verb of its own, parsed before the others (cli.main)
            try:
                check_merge_parser().parse_args(words[2:])
            except SystemExit:
                problems.append(f"{page}: glsandbox {shlex.join(words)}: does not parse")
            continue
        try:
            args = build_parser(words[0] if words else None).parse_args(words)
        except SystemExit:
            problems.append(f"{page}: glsandbox {shlex.join(words)}: does not parse")
            continue
        lesson = getattr(args, "lesson", None)
        if lesson is None or lesson.endswith(LESSON_SUFFIXES) or "/" in lesson:
            continue  # a user's file or folder, made by the page's earlier steps
        cls = find_lesson(lesson)
        for item in [*getattr(args, "settings", []), *getattr(args, "vary", [])]:
            cls.setting(item)  # a SandboxError names an unknown parameter
    assert not problems, problems


def runnable(words: list[str]) -> bool:
    """A headless command on a built-in lesson that needs no file a page made first."""
    if words[0] not in ("render", "plan", "compare", "list") or any(w.endswith(LESSON_SUFFIXES) for w in words):
        return False
    return not any(re.search(r"=\S*\.(obj|ply|stl|glb|gltf|png|off)$", w) for w in words if "=" in w)


#: Runs each command of a JSON list through ``glsandbox.cli.main``, as the ``glsandbox`` entry
#: point does, one after another in one process (a process each spent most of its time starting
#: Python and importing glsandbox): the exit status and the end of stderr of each.
RESULTS = "commands' results: "
COMMANDS_DRIVER = f"""
RESULTS = {RESULTS!r}
import contextlib, io, json, sys
from glsandbox.cli import main
results = []
for words in json.loads(sys.stdin.read()):
    errors = io.StringIO()
    with contextlib.redirect_stderr(errors):
        try:
            status = main(words)
        except SystemExit as exc:
            status = exc.code
    results.append([status, errors.getvalue()[-2000:]])
print("\\n" + RESULTS + json.dumps(results))
"""


@pytest.mark.slow
def test_the_headless_commands_in_the_docs_run(tmp_path: Path, gl) -> None:
    """Each render, plan, compare and list line, as written (small pictures where it names no size)."""
    seen: dict[tuple[str, ...], str] = {}
    for page, words in glsandbox_commands():
        if runnable(words) and tuple(words) not in seen:
            seen[tuple(words)] = page
    commands = [[*words, *(["--size", "64x48"] if words[0] in ("render", "compare") and "--size" not in words
                           else [])] for words in seen]
    proc = subprocess.run([sys.executable, "-c", COMMANDS_DRIVER], input=json.dumps(commands), cwd=tmp_path,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    [line] = [line for line in proc.stdout.splitlines() if line.startswith(RESULTS)]
    results = json.loads(line[len(RESULTS):])
    failed = [f"{page}: glsandbox {shlex.join(words)} (exit {status})\n{errors}"
              for (words, page), (status, errors) in zip(seen.items(), results) if status != 0]
    assert len(results) == len(seen) > 30 and not failed, failed
    assert (tmp_path / "phong.png").is_file()  # the phong page's render line wrote its picture


@pytest.mark.parametrize("args, message", [
    (["docs", "--port", "0", "--build", "README.md"], "--port 0: expected a port number 1-65535"),
    (["docs", "--build", "README.md"], "--build README.md: not a folder"),
])
def test_glsandbox_docs_mistakes_are_one_line(args: list[str], message: str) -> None:
    assert_user_error(run_cli(*args, cwd=REPO_ROOT), message)
