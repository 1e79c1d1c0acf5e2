"""glsandbox.course_page without a browser: docstrings to HTML, escaping, file names as URLs."""

from __future__ import annotations

import html
import os

from glsandbox.course_page import clean, course_page, describe, url

DOC = """Lesson 9: a title line.

Course section "X". The first paragraph, with ``code`` and :class:`glsandbox.scene.Scene`
and *emphasis*.

- **one**: an item
  that goes on;
- two

The formula::

    t = -(N.R0 + D) / (N.Rd)

The last paragraph.
"""


def test_a_docstring_becomes_a_lead_the_shown_paragraphs_and_the_rest() -> None:
    lead, shown, rest = describe(DOC)
    assert lead == "Lesson 9: a title line."
    assert shown.startswith("<p>Course section &quot;X&quot;. The first paragraph, with <code>code</code> and "
                            "<code>glsandbox.scene.Scene</code> and <em>emphasis</em>.</p>")
    assert "<ul><li><strong>one</strong>: an item that goes on;</li><li>two</li></ul>" in shown + rest
    assert "<p>The formula:</p><pre>    t = -(N.R0 + D) / (N.Rd)</pre>" in shown + rest
    assert (shown + rest).endswith("<p>The last paragraph.</p>")
    assert describe("") == ("", "", "")
    # Paragraphs are shown until about 280 characters are; the rest is folded under "More".
    _, shown, rest = describe("Lead.\n\n" + "word " * 60 + "\n\nSecond.")
    assert shown.startswith("<p>word word") and rest == "<p>Second.</p>"


def test_text_is_escaped_and_names_become_their_exact_bytes_in_urls() -> None:
    assert clean("caf\udce9\x00 \x1b[31m") == "caf\ufffd [31m"  # not UTF-8: replaced; control characters: gone
    assert url("a <b>&\"'#?% caf\udce9") == "a%20%3Cb%3E%26%22%27%23%3F%25%20caf%E9"
    assert os.fsdecode(bytes.fromhex("636166e9")) == "caf\udce9"  # the name the url above stands for
    summary = {"size": [64, 48], "renderer": "<r>", "backend": "egl", "seconds": 1.0, "lessons": [
        {"lesson": "<x>", "title": "<script>t</script>", "course_section": "&", "ok": False, "error": "<e>",
         "command": "glsandbox run '<x>.py'", "description": "<b>lead</b>\n\n<i>body</i>", "contrasts": []}]}
    page = course_page(summary)
    for raw in ("<script>t", "<x>", "<e>", "<b>lead", "<i>body", "<r>"):
        assert raw not in page
    assert "&lt;script&gt;t&lt;/script&gt;" in page and "failed: &lt;e&gt;" in page


def test_the_course_page_ends_with_the_exercises_and_a_folders_page_does_not() -> None:
    from glsandbox.exercises import all_exercises

    summary = {"size": [64, 48], "renderer": "r", "backend": "egl", "seconds": 1.0, "lessons": []}
    page = course_page(summary)
    assert "<h2>Exercises</h2>" in page and "glsandbox exercise check NAME FILE.py" in page
    for exercise in all_exercises():
        assert f"<code>{exercise.name}</code>" in page
        assert f"<code>{html.escape(exercise.signature)}</code>" in page
    assert "<h2>Exercises</h2>" not in course_page({**summary, "folder": "mine"})
