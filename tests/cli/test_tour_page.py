"""The course page ``glsandbox tour`` writes, opened in headless Chromium.

A copy of the page gets one script that, once everything has loaded, unfolds
every ``<details>`` and writes what the browser measured into the page's title: the document's scroll
width against the window's, the elements reaching past the right edge, the
grid's column count, and every image's natural size. Chromium prints the DOM
(``--dump-dom``) and the test reads the title back. Chromium's window is at
least 500 px wide, so a phone's 390 px is an iframe of that width: the page
inside lays out for it, as on the phone, and posts its figures to the frame.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from support import EXAMPLES_DIR, chromium_command, run_cli

pytestmark = pytest.mark.slow
PHONE = (390, 844)
DESKTOP = (1400, 900)

MEASURE = """<script>
window.addEventListener("load", () => {
  document.querySelectorAll("details").forEach(d => { d.open = true; });  // the folded text must fit too
  const root = document.documentElement, width = root.clientWidth;
  const images = Array.from(document.images);
  const wide = Array.from(document.body.querySelectorAll("*"))
    .filter(e => e.getBoundingClientRect().right > width + 0.5)
    .map(e => e.tagName.toLowerCase() + (e.className ? "." + e.className : ""));
  const result = {
    scrollWidth: root.scrollWidth, clientWidth: width, innerWidth: window.innerWidth,
    columns: getComputedStyle(document.querySelector(".grid")).gridTemplateColumns.split(" ").length,
    images: images.map(i => ({src: i.getAttribute("src"), ok: i.complete && i.naturalWidth > 0,
                              width: i.naturalWidth, shown: i.getBoundingClientRect().width})),
    links: Array.from(document.querySelectorAll("a.shot")).map(a => a.getAttribute("href")),
    scripts: document.scripts.length,
    handlers: document.querySelectorAll("[onerror], [onload], [onclick]").length,
    headings: Array.from(document.querySelectorAll("h2")).map(h => h.textContent),
    wide: wide.slice(0, 10),
  };
  document.title = "MEASURED " + JSON.stringify(result);
  if (window.parent !== window) window.parent.postMessage(document.title, "*");
});
</script>"""


#: Chromium's narrowest window.
MIN_WINDOW = 500


def measure(binary: str, page: Path, size: tuple[int, int], tmp: Path) -> dict:
    """Open a copy of ``page`` (beside it, so its pictures load) at ``size``; what the script measured."""
    probe = page.with_name("measured.html")
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", MEASURE + "</body>"), encoding="utf-8")
    window = size
    if size[0] < MIN_WINDOW:
        frame = page.with_name("phone.html")
        frame.write_text(f'<!doctype html><html><head><title></title></head><body style="margin:0">'
                         f'<iframe src="measured.html" width="{size[0]}" height="{size[1]}" style="border:0">'
                         f'</iframe><script>addEventListener("message", e => {{ document.title = e.data; }});'
                         f"</script></body></html>", encoding="utf-8")
        probe, window = frame, (MIN_WINDOW, size[1])
    profile = tmp / f"profile-{size[0]}"
    profile.mkdir()
    proc = subprocess.run([*chromium_command(binary, profile, window), "--virtual-time-budget=10000", "--dump-dom",
                           probe.as_uri()], capture_output=True, text=True, timeout=120)
    found = re.search(r"<title>MEASURED (.*?)</title>", proc.stdout, re.S)
    assert found, f"no measurement in the page (chromium exit {proc.returncode}): {proc.stderr[-2000:]}"
    return json.loads(html.unescape(found.group(1)))


def assert_fits(result: dict, size: tuple[int, int]) -> None:
    assert result["innerWidth"] == size[0]  # the window really is that wide
    assert result["scrollWidth"] <= result["clientWidth"], result["wide"]  # no horizontal scroll
    assert result["wide"] == []
    broken = [i["src"] for i in result["images"] if not i["ok"]]
    assert broken == [], broken  # every picture loads
    assert all(i["shown"] <= result["clientWidth"] for i in result["images"])


@pytest.fixture(scope="module")
def course_tour(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tour")
    proc = run_cli("tour", "--out", str(out), "--size", "320x240")
    assert proc.returncode == 0, proc.stderr
    return out


def test_the_course_page_fits_a_desktop_and_a_phone_and_every_picture_loads(
        course_tour: Path, chromium: str, tmp_path: Path) -> None:
    summary = json.loads((course_tour / "tour.json").read_text())
    lessons = summary["lessons"]
    contrasts = [c for entry in lessons for c in entry["contrasts"]]
    # Every contrast the issue names is on the page, rendered.
    assert {(e["lesson"], c["vary"].partition("=")[0]) for e in lessons for c in e["contrasts"]} >= {
        ("mirror", "mirror"), ("transform_order", "order"), ("texture", "filter"), ("ray_phong", "renderer")}
    assert all(c.get("image") for c in contrasts)
    desktop = measure(chromium, course_tour / "index.html", DESKTOP, tmp_path)
    assert_fits(desktop, DESKTOP)
    assert desktop["columns"] == 3  # a grid, not one long column
    assert len(desktop["images"]) == len(lessons) + len(contrasts)
    assert desktop["links"] == [i["src"] for i in desktop["images"]]  # each picture links to its full size
    # course order, then the exercises
    assert [h.lstrip("0123456789") for h in desktop["headings"]] == [e["title"] for e in lessons] + ["Exercises"]
    phone = measure(chromium, course_tour / "index.html", PHONE, tmp_path)
    assert_fits(phone, PHONE)
    assert phone["columns"] == 1


ODD_LESSON = '''"""A <script>document.title = "doc"</script> & lesson.

It shows ``one cube`` & <b>bold</b>, and a word much too long for a phone:
{long}.
"""

from glsandbox import Lesson, Node, Scene, geometry


class Odd(Lesson):
    name = "odd"
    title = '<img src=x onerror="document.title=1">'
    course_section = "</h2><script>alert(1)</script>"

    def build(self) -> Scene:
        return Scene(self.name, nodes=(Node("cube", geometry.cube()),))
'''


def test_users_lesson_files_with_any_names_are_escaped_and_their_pictures_load(
        tmp_path: Path, chromium: str) -> None:
    lessons = tmp_path / "lessons"
    lessons.mkdir()
    odd_names = ['a <b>&"quote\'', "caf\udce9 100%", "#hash?query"]
    for name in odd_names:
        path = os.fsencode(lessons / f"{name}.py")  # "\udce9": the byte 0xE9, not UTF-8
        Path(os.fsdecode(path)).write_text(ODD_LESSON.format(long="x" * 300), encoding="utf-8")
    shutil.copy(EXAMPLES_DIR / "mirror_room.toml", lessons / "room.toml")
    (lessons / "zz <broken>.py").write_text("this is not python <script>\n")  # a card that says why
    out = tmp_path / "tour"
    proc = run_cli("tour", "--lessons", str(lessons), "--out", str(out), "--size", "96x72")
    assert proc.returncode == 1 and "zz <broken>: FAILED" in proc.stderr, proc.stderr
    page = (out / "index.html").read_bytes().decode("utf-8")  # valid UTF-8 whatever the names' bytes
    assert "<script>alert" not in page and "<img src=x" not in page and "<b>bold" not in page
    assert "&lt;img src=x onerror=" in page and "caf\ufffd 100%" in page
    assert "It shows <code>one cube</code> &amp; &lt;b&gt;bold&lt;/b&gt;" in page  # the file's docstring, as text
    assert '<p class="error">failed: ' in page and "zz &lt;broken&gt;.py" in page
    for result in (measure(chromium, out / "index.html", size, tmp_path) for size in (DESKTOP, PHONE)):
        assert_fits(result, (result["innerWidth"], 0))
        assert len(result["images"]) == len(odd_names) + 1
        assert result["scripts"] == 1 and result["handlers"] == 0  # only the test's own script runs
        titled = [h for h in result["headings"] if h.endswith('<img src=x onerror="document.title=1">')]
        assert len(titled) == len(odd_names)  # the title shown as text
