"""The course page ``glsandbox tour`` writes (``index.html``): the lessons as cards in course order.

Each card has the lesson's picture (a link to the full-size PNG), its course
section, what it shows (its docstring: the first paragraphs shown, the rest
folded under "More"), the command that runs it, the contrasts it is about
(labelled tile grids, each with the ``glsandbox compare`` line that makes
it), and, folded away, its plan and render time. The grid has as many
columns as fit cards of 400 px (one on a phone); nothing on the page is wider
than the screen: long words, paths and plans wrap.

Everything on the page comes from lessons, and ``tour --lessons DIR`` reads
users' files, so every text is escaped and every file name percent-encoded
(a name may hold any bytes the file system allows). The course's page ends
with the exercises (:mod:`glsandbox.exercises`): what to type to write each
of the course's functions yourself.
"""

from __future__ import annotations

import html
import os
import re
from urllib.parse import quote

#: C0 control characters other than tab and newline: no meaning on a page.
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")
_CODE = re.compile(r"``(.+?)``")
#: A Sphinx cross-reference, :class:`glsandbox.frame.Frame`: shown as code.
_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
_STRONG = re.compile(r"\*\*(.+?)\*\*")
_EMPHASIS = re.compile(r"(?<![\w*])\*([^*\s][^*]*?)\*(?![\w*])")
#: Bullets in a docstring: "- item" or "* item".
_BULLET = re.compile(r"[-*] ")
#: Paragraphs are shown on the card until this much text is (the rest is under "More").
SHOWN_CHARACTERS = 280


def clean(text: str) -> str:
    """``text`` as UTF-8 can carry it: undecodable bytes (surrogate escapes) become U+FFFD,
    control characters go."""
    try:  # a file name's undecodable bytes arrive as surrogate escapes: back to the bytes, then replaced
        raw = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # other lone surrogates
        raw = text.encode("utf-8", "surrogatepass")
    return _CONTROL.sub("", raw.decode("utf-8", "replace"))


def esc(text: object) -> str:
    """Escaped for HTML text and attribute values."""
    return html.escape(clean(str(text)), quote=True)


def url(name: str) -> str:
    """A file name in the page's folder as a relative URL: its exact bytes, percent-encoded."""
    return html.escape(quote(os.fsencode(name)), quote=True)


def inline(text: str) -> str:
    """One paragraph's text: escaped, then ``code``, **strong** and *emphasis* marked up."""
    out = _ROLE.sub(lambda m: f"``{m.group(1)}``", esc(text))
    out = _CODE.sub(lambda m: f"<code>{m.group(1)}</code>", out)
    out = _STRONG.sub(lambda m: f"<strong>{m.group(1)}</strong>", out)
    return _EMPHASIS.sub(lambda m: f"<em>{m.group(1)}</em>", out)


def paragraphs(doc: str) -> list[list[str]]:
    """A docstring's paragraphs, each its lines (blank lines separate them)."""
    found: list[list[str]] = [[]]
    for line in doc.splitlines():
        if line.strip():
            found[-1].append(line.rstrip())
        elif found[-1]:
            found.append([])
    return [p for p in found if p]


def block(lines: list[str]) -> str:
    """One paragraph as HTML: an indented block is literal, ``- `` or ``* `` lines a list, else prose."""
    if all(line.startswith((" ", "\t")) for line in lines):
        return f"<pre>{esc(chr(10).join(lines))}</pre>"
    if _BULLET.match(lines[0]):
        items: list[str] = []
        for line in lines:
            if _BULLET.match(line):
                items.append(line[2:])
            else:
                items[-1] += " " + line.strip()
        return "<ul>" + "".join(f"<li>{inline(item)}</li>" for item in items) + "</ul>"
    text = " ".join(line.strip() for line in lines)
    if text.endswith("::"):  # reST: the literal block follows
        text = text[:-1]
    return f"<p>{inline(text)}</p>"


def describe(doc: str) -> tuple[str, str, str]:
    """(lead sentence, the paragraphs after it shown on the card, the rest) as HTML: paragraphs
    are shown until :data:`SHOWN_CHARACTERS` of text are."""
    found = paragraphs(doc)
    if not found:
        return "", "", ""
    lead = inline(" ".join(line.strip() for line in found[0]))
    shown, length = 0, 0
    while shown < len(found) - 1 and length < SHOWN_CHARACTERS:
        length += sum(len(line.strip()) for line in found[1 + shown])
        shown += 1
    body = [block(p) for p in found[1:]]
    return lead, "".join(body[:shown]), "".join(body[shown:])


def picture(name: str, alt: str, size: tuple[int, int] | None) -> str:
    dims = f' width="{int(size[0])}" height="{int(size[1])}"' if size else ""
    return f'<a class="shot" href="{url(name)}"><img src="{url(name)}" alt="{esc(alt)}"{dims}></a>'


def card(number: int, entry: dict, size: tuple[int, int]) -> str:
    name, title = entry["lesson"], entry.get("title") or entry["lesson"]
    lead, shown, rest = describe(entry.get("description", ""))
    parts = [f'<article class="card" id="{esc(name)}">']
    if entry.get("ok"):
        parts.append(picture(entry["image"], f"{name}: {title}", size))
    parts.append('<div class="body">')
    if entry.get("course_section"):
        parts.append(f'<p class="section">{esc(entry["course_section"])}</p>')
    parts.append(f'<h2><span class="num">{number}</span>{esc(title)}</h2>')
    if lead:
        parts.append(f'<p class="lead">{lead}</p>')
    parts.append(shown)
    if rest:
        parts.append(f"<details><summary>More about {esc(name)}</summary>{rest}</details>")
    if entry.get("command"):
        parts.append(f'<p class="label">Run it</p><pre class="cmd"><code>{esc(entry["command"])}</code></pre>')
    if not entry.get("ok"):
        parts.append(f'<p class="error">failed: {esc(entry.get("error", ""))}</p>')
    if entry.get("contrasts"):
        parts.append('<p class="label">Compare</p>')
    for contrast in entry.get("contrasts", ()):
        if contrast.get("image"):
            shot = picture(contrast["image"], contrast["caption"], tuple(contrast["size"]))
        else:
            shot = f'<p class="error">failed: {esc(contrast.get("error", ""))}</p>'
        tiles = " ".join(f"<code>{esc(label)}</code>" for label in contrast.get("labels", ()))
        order = f'<br><span class="tiles">tiles, in reading order: {tiles}</span>' if tiles else ""
        parts.append(f'<figure class="contrast">{shot}<figcaption><strong>{esc(contrast["caption"])}</strong>'
                     f'{order}<pre class="cmd"><code>{esc(contrast["command"])}</code></pre></figcaption></figure>')
    if entry.get("ok"):
        parts.append(f"<details><summary>Plan and timing</summary>"
                     f"<p>rendered in {float(entry['render_ms']):.1f} ms at {size[0]}x{size[1]}</p>"
                     f"<pre>{esc(entry.get('plan_text', ''))}</pre></details>")
    parts.append("</div></article>")
    return "".join(parts)


STYLE = """
:root { --ink: #1b2333; --muted: #5a6478; --accent: #0020a0; --bg: #eef1f7; }
* { box-sizing: border-box; }
html { -webkit-text-size-adjust: 100%; }
body { margin: 0; font: 16px/1.55 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", sans-serif;
       color: var(--ink); background: var(--bg); }
header { background: linear-gradient(135deg, #00208f, #0a3bd0); color: #fff;
         padding: 2.2rem clamp(1rem, 4vw, 3rem) 1.8rem; }
header h1 { margin: 0 0 .4rem; font-size: clamp(1.6rem, 3.5vw, 2.4rem); line-height: 1.2; }
header p { margin: .3rem 0; max-width: 60rem; opacity: .92; }
header code { background: rgba(255,255,255,.16); color: #fff; }
main { padding: 1.6rem clamp(.75rem, 3vw, 3rem) 3rem; }
.grid { display: grid; gap: 1.5rem; grid-template-columns: repeat(auto-fill, minmax(min(100%, 400px), 1fr));
        align-items: stretch; }
.card { background: #fff; border-radius: 12px; overflow: hidden; min-width: 0;
        box-shadow: 0 1px 2px rgba(16,24,40,.08), 0 4px 14px rgba(16,24,40,.06); }
.card > .shot img { border-bottom: 1px solid #e3e7ef; }
.shot { display: block; }
img { display: block; width: 100%; height: auto; background: #111; }
.body { padding: 1rem 1.15rem 1.2rem; }
.section { margin: 0; font-size: .78rem; font-weight: 600; letter-spacing: .04em; text-transform: uppercase;
           color: var(--accent); }
h2 { margin: .25rem 0 .5rem; font-size: 1.15rem; line-height: 1.3; }
.num { display: inline-block; min-width: 1.7em; margin-right: .5em; padding: 0 .35em; border-radius: 6px;
       background: var(--accent); color: #fff; font-size: .85em; text-align: center; }
.lead { font-weight: 600; }
p, li, h1, h2, summary, figcaption, code, pre { overflow-wrap: anywhere; }
p { margin: .45rem 0; }
ul { padding-left: 1.2rem; }
code { font: .88em/1.4 ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; background: #eef1f7;
       padding: .05em .3em; border-radius: 4px; }
pre { white-space: pre-wrap; margin: .4rem 0; padding: .6rem .75rem; border-radius: 8px; background: #f3f5fa;
      font: .8rem/1.45 ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; }
pre code { background: none; padding: 0; font-size: 1em; }
.cmd { background: #131a2e; color: #e8eefc; }
.label { margin: .8rem 0 0; font-size: .78rem; font-weight: 600; text-transform: uppercase; color: var(--muted); }
details { margin-top: .7rem; border-top: 1px solid #e6e9f0; padding-top: .5rem; }
summary { cursor: pointer; color: var(--accent); font-weight: 600; }
figure.contrast { margin: .4rem 0 .9rem; }
figure.contrast img { border-radius: 8px; background: none; }
figcaption { margin-top: .35rem; font-size: .92rem; color: var(--muted); }
figcaption strong { color: var(--ink); }
.tiles { font-size: .85rem; }
.error { color: #b00020; font-weight: 600; }
footer { padding: 0 clamp(.75rem, 3vw, 3rem) 2rem; color: var(--muted); font-size: .9rem; }
.exercises { margin-top: 2rem; background: #fff; border-radius: 12px; padding: 1rem 1.15rem 1.2rem;
             box-shadow: 0 1px 2px rgba(16,24,40,.08), 0 4px 14px rgba(16,24,40,.06); overflow-x: auto; }
.exercises table { border-collapse: collapse; width: 100%; }
.exercises th, .exercises td { text-align: left; vertical-align: top; padding: .35rem .6rem;
                               border-top: 1px solid #e6e9f0; overflow-wrap: anywhere; }
"""


COURSE_HEADER = """<h1>Real-time graphics, lesson by lesson</h1>
<p>Every lesson of the course as it renders: the picture, what it shows, the command that runs it, and the
comparisons it is about. Click a picture for full size. With glsandbox installed, <code>glsandbox run NAME</code>
opens a lesson in a window (drag to orbit), <code>glsandbox list -v</code> lists the lessons and their parameters,
and <code>glsandbox compare NAME --vary KEY=A,B</code> draws any comparison of your own.</p>"""


def folder_header(folder: str) -> str:
    return (f"<h1>Lessons in {esc(folder)}</h1><p>Each lesson file of the folder as it renders, with what its "
            "docstring says and the command that runs it. Click a picture for full size.</p>")


def exercises_section() -> str:
    """The Exercises section: each exercise's function, course section and what to type."""
    from glsandbox.exercises.catalogue import all_exercises

    rows = "\n".join(
        f"<tr><td><code>{esc(e.name)}</code></td><td>{esc(e.section)}</td><td><code>{esc(e.signature)}</code>"
        f"<br>{esc(e.summary)}</td></tr>" for e in all_exercises())
    return f"""<section class="exercises"><h2>Exercises</h2>
<p>Write the course's functions yourself. <code>glsandbox exercise start NAME</code> writes a starter
(the signature, the notes' formula and worked example); <code>glsandbox exercise check NAME FILE.py</code>
runs the notes' worked examples on it, names a known mistake when it sees one, and draws where your
answers differ from the reference's. In a notebook: <code>glsandbox.exercise("ray_sphere", my_function)</code>.</p>
<table><tr><th>exercise</th><th>course section</th><th>function</th></tr>
{rows}
</table></section>"""


def course_page(summary: dict) -> str:
    """The whole page for a tour's summary (``tour.json``'s contents); with ``summary["folder"]``
    (``tour --lessons DIR``) the page is about that folder's lessons, not the course."""
    size = (int(summary["size"][0]), int(summary["size"][1]))
    lessons = summary["lessons"]
    cards = "\n".join(card(number, entry, size) for number, entry in enumerate(lessons, start=1))
    rendered = sum(1 for entry in lessons if entry.get("ok"))
    folder = summary.get("folder")
    title = f"glsandbox: {esc(folder)}" if folder else "glsandbox: the course, lesson by lesson"
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{STYLE}</style></head><body>
<header>
{folder_header(folder) if folder else COURSE_HEADER}
</header>
<main><div class="grid">
{cards}
</div>
{"" if folder else exercises_section()}</main>
<footer>{rendered} of {len(lessons)} lessons rendered by {esc(summary['renderer'])} ({esc(summary['backend'])}) at
{size[0]}x{size[1]} in {float(summary['seconds']):.1f} s; written by <code>glsandbox tour</code>.</footer>
</body></html>
"""
