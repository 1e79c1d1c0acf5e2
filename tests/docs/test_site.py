"""The manual's site: ``mkdocs build --strict`` from a clean copy of the repository, then its
home page and a lesson page opened in headless Chromium."""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from support import REPO_ROOT, chromium_command

from glsandbox.lesson import all_lessons

pytestmark = pytest.mark.slow

#: Once loaded: the page's heading, its pictures (loaded or not), its navigation's links and code blocks.
MEASURE = """<script>
window.addEventListener("load", () => {
  const result = {
    h1: (document.querySelector("article h1") || {}).textContent || "",
    images: Array.from(document.querySelectorAll("article img")).map(i => ({src: i.getAttribute("src"),
                                                                          ok: i.complete && i.naturalWidth > 0})),
    nav: Array.from(document.querySelectorAll("nav.md-nav--primary a.md-nav__link[href]")).map(a => a.textContent.trim()),
    code: Array.from(document.querySelectorAll("article pre code")).map(c => c.textContent),
    tables: document.querySelectorAll("article table").length,
  };
  document.title = "MEASURED " + JSON.stringify(result);
});
</script>"""


def repository_files() -> list[str]:
    """What a clean clone of this working tree holds: tracked files and untracked ones git does not ignore."""
    proc = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=REPO_ROOT,
                          capture_output=True, check=True)
    return [name for name in proc.stdout.decode().split("\0") if name and (REPO_ROOT / name).is_file()]


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if shutil.which("git") is None or not (REPO_ROOT / ".git").exists():
        assert not os.environ.get("CI"), "CI runs in a clone: the site is built from a clean copy of it"
        pytest.skip("not a git checkout: nothing to copy a clean clone from")
    clone = tmp_path_factory.mktemp("clone")
    for name in repository_files():
        target = clone / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPO_ROOT / name, target)
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(clone / "mkdocs.yml"), "--site-dir", str(out)],
                          cwd=clone, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert "WARNING" not in proc.stderr, proc.stderr[-4000:]
    return out


def test_the_site_has_every_page_and_a_page_per_lesson(site: Path) -> None:
    for page in ("index", "getting-started/index", "your-own/index", "models/index", "raytracer/index",
                 "grading/index", "grading-a-class/index", "accuracy/index", "numerics/index", "benchmarks/index", "how-it-works/index",
                 "api/index", "changelog/index", "lessons/index"):
        assert (site / f"{page}.html").is_file(), page
    for cls in all_lessons():
        page = (site / "lessons" / cls.name / "index.html").read_text(encoding="utf-8")
        text = html.unescape(re.sub(r"<[^>]+>", "", page))  # the highlighter's spans out
        assert f"glsandbox render {cls.name}" in text
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert 'id="glsandbox.lesson.Lesson"' in api  # mkdocstrings read the docstrings
    bench = (site / "benchmarks" / "index.html").read_text(encoding="utf-8")
    data = json.loads((REPO_ROOT / "docs" / "data" / "bench.json").read_text(encoding="utf-8"))
    assert f"Measured {data['date']}" in html.unescape(re.sub(r"<[^>]+>", "", bench))  # the tables come from the stored run
    assert html.escape(data["cases"][0]["name"], quote=False) in bench


def measure(binary: str, page: Path, tmp: Path) -> dict:
    """Open a copy of ``page`` (beside it, so its links resolve) in Chromium; what the script measured."""
    probe = page.with_name("measured.html")
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", MEASURE + "</body>"), encoding="utf-8")
    profile = tmp / f"profile-{page.parent.name}"
    profile.mkdir()
    proc = subprocess.run([*chromium_command(binary, profile, (1300, 900)), "--virtual-time-budget=10000",
                           "--dump-dom", probe.as_uri()], capture_output=True, text=True, timeout=120)
    found = re.search(r"<title>MEASURED (.*?)</title>", proc.stdout, re.S)
    assert found, f"no measurement in the page (chromium exit {proc.returncode}): {proc.stderr[-2000:]}"
    return json.loads(html.unescape(found.group(1)))


def test_the_home_page_and_a_lesson_page_open_in_chromium(site: Path, chromium: str, tmp_path: Path) -> None:
    home = measure(chromium, site / "index.html", tmp_path)
    assert home["h1"].strip().startswith("glsandbox")
    assert home["images"] and all(i["ok"] for i in home["images"]), home["images"]  # the course page picture
    assert {"Getting started", "The lessons", "Benchmarks", "API reference", "Changelog"} <= set(home["nav"])
    phong = next(cls for cls in all_lessons() if cls.name == "phong")
    lesson = measure(chromium, site / "lessons" / "phong" / "index.html", tmp_path)
    assert phong.title in lesson["h1"]
    assert len(lesson["images"]) == len(list((REPO_ROOT / "tests" / "goldens" / "phong").glob("*.png")))
    assert all(i["ok"] for i in lesson["images"]), lesson["images"]  # every golden picture loads
    assert lesson["tables"] == 1  # the parameters
    assert any("uv run glsandbox render phong" in block for block in lesson["code"])
