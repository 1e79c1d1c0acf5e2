"""A check's result for people: the terminal's table, the pictures as PNGs, an HTML page.

:func:`text` is what ``glsandbox exercise check`` prints: a ✓ or ✗ per case
with what was expected and what came back, the hint in words, where the
pictures went. :func:`write_pictures` writes the probe picture (and the
lesson's pictures, where there are) as PNG files; :func:`html` is the same
report as a page (the notebook shows it inline).
"""

from __future__ import annotations

import base64
import html as html_lib
from pathlib import Path

import numpy as np

from glsandbox.exercises.check import PASS, CheckResult
from glsandbox.exercises.probe import CLASSES, COLOURS
from glsandbox.files import png_bytes, save_png, write_text

__all__ = ["text", "write_pictures", "html", "pictures_of"]

_MARK = {True: "✓", False: "✗"}
_LEGEND = {"both none": "both: nothing", "agree": "both: the same (shaded by value)",
           "student only": "yours only", "reference only": "the reference's only",
           "value differs": "both, different values", "broken": "yours raised / NaN / wrong type"}


def _cut(value: str, width: int) -> str:
    return value if len(value) <= width else value[:width - 1] + "…"


def text(result: CheckResult, *, hidden_shown: bool = True) -> str:
    """The terminal's report (several lines, no colour codes)."""
    lines = [f"{result.exercise}: {result.signature}"]
    if result.load_error:
        lines.append(f"  ✗ the file did not load: {result.load_error}")
    width = max([len(c.name) for c in result.cases] + [10])
    width = min(width, 56)
    for group, (passed, total) in result.groups().items():
        if group != "visible" and not hidden_shown:
            continue
        lines.append(f"  {group} cases: {passed} of {total} pass")
        for case in result.group(group):
            mark = _MARK[case.status == PASS]
            row = f"    {mark} {_cut(case.name, width):<{width}}  expected {_cut(case.expected, 28):<28} got {_cut(case.got, 28)}"
            if case.status not in (PASS, "FAIL"):
                row += f"  [{case.status}]"
            lines.append(row)
            if case.note and case.status != PASS:
                lines.append(f"        {case.note}")
    for hint in result.hints:
        lines.append(f"  hint: {hint}")
    if result.probe is not None:
        lines.append(f"  probe: {result.probe.summary()}")
    if result.lesson is not None:
        lines.append(f"  lesson: {result.lesson.summary()}")
    for name, path in result.pictures.items():
        lines.append(f"  {name} picture: {path}")
    verdict = "every visible case passes" if result.visible_passed else "not every visible case passes yet"
    lines.append(f"  {verdict}")
    return "\n".join(lines)


def pictures_of(result: CheckResult) -> dict[str, np.ndarray]:
    """The result's pictures by name: ``probe``, and ``lesson`` (yours | reference | difference)."""
    out: dict[str, np.ndarray] = {}
    if result.probe is not None and result.probe.image is not None:
        out["probe"] = result.probe.image
    if result.lesson is not None and result.lesson.image is not None:
        out["lesson"] = result.lesson.image
    return out


def write_pictures(result: CheckResult, folder: Path) -> None:
    """Write the pictures as ``folder/EXERCISE_probe.png`` (and ``_lesson.png``); their paths go
    into ``result.pictures``."""
    pictures = pictures_of(result)
    if not pictures:
        return
    folder.mkdir(parents=True, exist_ok=True)
    for name, image in pictures.items():
        path = folder / f"{result.exercise}_{name}.png"
        save_png(image, path)
        result.pictures[name] = str(path)


def _img(image: np.ndarray, alt: str) -> str:
    data = base64.b64encode(png_bytes(image)).decode()
    return f'<img alt="{html_lib.escape(alt)}" src="data:image/png;base64,{data}" style="image-rendering:pixelated">'


def html(result: CheckResult, *, hidden_shown: bool = True) -> str:
    """The report as an HTML fragment: the table, the hints, the pictures inline, a legend."""
    e = html_lib.escape
    rows = []
    for case in result.cases:
        if case.group != "visible" and not hidden_shown:
            continue
        mark = _MARK[case.status == PASS]
        colour = "#1a7f37" if case.status == PASS else "#cf222e"
        note = f"<br><small>{e(case.note)}</small>" if case.note and case.status != PASS else ""
        rows.append(f'<tr><td style="color:{colour}">{mark} {e(case.status)}</td><td>{e(case.group)}</td>'
                    f"<td>{e(case.name)}<br><code>{e(case.call)}</code></td><td><code>{e(case.expected)}</code></td>"
                    f"<td><code>{e(case.got)}</code>{note}</td></tr>")
    parts = [f"<h3>{e(result.exercise)}: <code>{e(result.signature)}</code></h3>"]
    if result.load_error:
        parts.append(f"<p>✗ the file did not load: {e(result.load_error)}</p>")
    parts.append('<table border="1" cellpadding="4" style="border-collapse:collapse"><tr><th>result</th>'
                 "<th>group</th><th>case</th><th>expected</th><th>got</th></tr>" + "".join(rows) + "</table>")
    for hint in result.hints:
        parts.append(f"<p><b>hint:</b> {e(hint)}</p>")
    pictures = pictures_of(result)
    if "probe" in pictures:
        legend = " ".join(f'<span style="background:rgb{tuple(int(c) for c in COLOURS[i])};'
                          f'color:{"#000" if i in (1, 4) else "#fff"};padding:1px 4px">{e(_LEGEND[name])}</span>'
                          for i, name in enumerate(CLASSES) if name != "agree")
        parts.append(f"<p><b>probe</b>: {e(result.probe.summary())}</p>{_img(pictures['probe'], 'probe')}"
                     f"<p>{legend}</p>")
    if "lesson" in pictures:
        parts.append(f"<p><b>lesson</b>: {e(result.lesson.summary())}</p>{_img(pictures['lesson'], 'lesson')}")
    return "\n".join(parts)


def write_html(result: CheckResult, path: Path) -> None:
    """The report as a whole HTML page at ``path``."""
    page = (f"<!doctype html><meta charset=utf-8><title>{html_lib.escape(result.exercise)}</title>"
            f"<body style=\"font-family:sans-serif\">{html(result)}</body>")
    write_text(path, page)
