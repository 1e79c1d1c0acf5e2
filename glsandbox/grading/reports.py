"""The reports of a graded folder: CSV, JSON, an HTML page, JUnit XML and Gradescope's ``results.json``
(the teacher's), and the student's page, which shows nothing of a hidden check.

Each is written atomically by the grader alone, from the results in folder
order. Names are written as :func:`glsandbox.grading.check.shown` gives them
(any bytes escaped), so no name breaks a writer or forges a line; the HTML
page and the XML escape them again for their own syntax.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr
from xml.sax.saxutils import escape as xml_escape

from glsandbox import files
from glsandbox.errors import SandboxError
from glsandbox.grading.check import OUTCOMES, PASS, CheckResult, Outcome, counts, points, read_reference, shown

__all__ = ["REPORTS", "write_reports"]


def _figures(o: Outcome) -> dict[str, object]:
    m = o.match
    return {"status": o.status,
            "bad_pixels": m.bad_pixels if m else None,
            "bad_share": round(m.bad_share, 6) if m else None,
            "max_diff": m.max_diff if m else None,
            "rmse": None if m is None or math.isnan(m.rmse) else round(m.rmse, 6),
            "threshold": m.threshold if m else None,
            "max_bad_share": m.max_bad_share if m else None,
            "seconds": round(o.seconds, 3), "error": shown(o.error)}


def rows(results: Sequence[CheckResult]) -> list[dict[str, object]]:
    """One flat row per submission (and check, when there are several)."""
    out = []
    for r in results:
        for o in r.outcomes:
            row: dict[str, object] = {"name": r.shown, "path": _path(r), "same_as": " ".join(map(shown, r.same_as))}
            if len(r.outcomes) > 1:
                row.update(check=o.check.name, points=o.points, of=o.check.points)
            out.append({**row, **_figures(o)})
    return out


def _path(r: CheckResult) -> str:
    return shown(str(r.path))


def _output(r: CheckResult) -> list[str]:
    """The submission's last printed lines, escaped as names are (its own text, any bytes)."""
    return [shown(line) for line in r.output]


def csv_text(results: Sequence[CheckResult], title: str) -> str:
    table = rows(results)
    if not table:  # an empty shard of a class
        return ""
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(table[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: "" if v is None else v for k, v in row.items()} for row in table)
    return out.getvalue()


def json_text(results: Sequence[CheckResult], title: str) -> str:
    submissions = []
    for r in results:
        entry: dict[str, object] = {"name": r.shown, "path": _path(r), "status": r.status,
                                    "score": r.score, "total": r.total, "output": _output(r),
                                    "digest": r.digest, "same_as": [shown(n) for n in r.same_as]}
        if len(r.outcomes) == 1:
            entry.update({k: v for k, v in _figures(r.outcomes[0]).items() if k != "status"})
            entry["detail"] = r.outcomes[0].detail()
            if r.outcomes[0].cases:
                entry["cases"] = r.outcomes[0].cases
        else:
            entry["checks"] = [{"check": o.check.name, "points": o.points, "of": o.check.points, **_figures(o),
                                "detail": o.detail(), **({"cases": o.cases} if o.cases else {})}
                               for o in r.outcomes]
        submissions.append(entry)
    c = {k.lower().replace(" ", "_"): v for k, v in counts(results).items()}
    return json.dumps({"reference": title, **c, "submissions": submissions}, indent=2) + "\n"


def junit_text(results: Sequence[CheckResult], title: str) -> str:
    """JUnit XML: one test case per submission and check; FAIL a failure, the others errors."""
    cases = []
    for r in results:
        for o in r.outcomes:
            name = quoteattr(r.shown if len(r.outcomes) == 1 else f"{r.shown} [{o.check.name}]")
            body = ""
            if o.status == "FAIL":
                body = f"<failure message={quoteattr(o.detail())} type=\"FAIL\"/>"
            elif o.status != PASS:
                body = f"<error message={quoteattr(o.detail())} type={quoteattr(o.status)}/>"
            if r.output:
                body += f"<system-out>{xml_escape(chr(10).join(_output(r)))}</system-out>"
            cases.append(f"  <testcase classname=\"glsandbox.check\" name={name} time=\"{o.seconds:.3f}\">"
                         f"{body}</testcase>")
    outcomes = [o for r in results for o in r.outcomes]
    failures = sum(o.status == "FAIL" for o in outcomes)
    errors = sum(o.status not in (PASS, "FAIL") for o in outcomes)
    return (f"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n<testsuite name={quoteattr('glsandbox check ' + title)} "
            f"tests=\"{len(outcomes)}\" failures=\"{failures}\" errors=\"{errors}\" "
            f"time=\"{sum(o.seconds for o in outcomes):.3f}\">\n" + "\n".join(cases) + "\n</testsuite>\n</testsuites>\n")


def gradescope_text(results: Sequence[CheckResult], title: str) -> str:
    """Gradescope's ``results.json`` for one student: a score and one test per check.

    Gradescope grades one submission at a time; with several submissions in
    the folder the tests of each are listed under its name.
    """
    tests = []
    for r in results:
        for o in r.outcomes:
            name = o.check.name if len(results) == 1 else f"{r.shown}: {o.check.name}"
            output = f"{o.status}: {o.detail() if o.student is None else o.student}".rstrip(": ")
            if o.check.hidden:  # shown after publishing: its outcome and points, never its figures or output
                output = o.status if o.student is None else output  # an exercise group: counts, case names
            elif r.output and o.status != PASS:
                output += "\nlast lines printed:\n" + "\n".join(_output(r))
            tests.append({"name": name, "score": o.points, "max_score": o.check.points, "output": output,
                          "status": "passed" if o.status == PASS else "failed",
                          "visibility": "after_published" if o.check.hidden else "visible"})
    score = sum(r.score for r in results)
    shown_now = [o for r in results for o in r.outcomes if not o.check.hidden]
    if len(shown_now) < sum(len(r.outcomes) for r in results):  # the hidden checks' points say nothing yet
        summary = (f"glsandbox check: {points(sum(o.points for o in shown_now))}/"
                   f"{points(sum(o.check.points for o in shown_now))} points on the checks shown now; "
                   "the others after the grades are published")
    else:
        summary = f"glsandbox check: {points(score)}/{points(sum(r.total for r in results))} points"
    # stdout (check's own lines, hidden checks' figures among them) is the teacher's alone
    return json.dumps({"score": score, "output": summary, "stdout_visibility": "hidden", "tests": tests},
                      indent=2) + "\n"


_COLOURS = {"PASS": "#d7f5d7", "FAIL": "#ffe0b3", "BROKEN": "#ffd0d0", "TIMEOUT": "#e4d7ff",
            "CRASHED": "#ffc0e0", "OUT OF MEMORY": "#d0e8ff"}


def _img(image, alt: str) -> str:
    if image is None:
        return '<span class="none">-</span>'
    data = base64.b64encode(files.png_bytes(image)).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(alt)}">'


def _story(o: Outcome) -> str:
    """A failed picture's first differing pixel and its story (``check --explain``), folded: the
    submission's own frame told by its own renderer, so escaped as its output is. The student's
    page calls it for the checks it shows only (never a hidden one)."""
    if o.first_difference is None or not o.story:
        return ""
    x, y = o.first_difference
    return (f'<details class="story"><summary>why pixel {x},{y} (the first that differs) looks as it does in the '
            f"submission</summary><pre>{html.escape(shown_text(o.story))}</pre></details>")


def shown_text(text: str) -> str:
    """Lines of untrusted text, each escaped as names are (:func:`shown`)."""
    return "\n".join(shown(line) for line in text.splitlines())


def html_text(results: Sequence[CheckResult], title: str) -> str:
    """One self-contained page: a row per student, reference | submission | difference per check,
    the score, the outcome's colour and the error line; click a heading to sort."""
    from glsandbox.grading.check import _thumbnail
    from glsandbox.measure.golden import _diff_image

    checks = [o.check for o in results[0].outcomes] if results else []
    references = {}
    for check in checks:
        try:
            references[check.name] = _thumbnail(read_reference(check.golden))
        except SandboxError:
            references[check.name] = None
    head = "".join(f"<th>{html.escape(c.name)} ({points(c.points)})<br><small>reference | submission | difference"
                   "</small></th>" for c in checks)
    body = []
    for r in results:
        cells = []
        for o in r.outcomes:
            ref = references.get(o.check.name)
            diff = None
            if o.thumb is not None and ref is not None:
                diff = _diff_image(o.thumb, ref, int(o.match.threshold if o.match else 2))
            text = html.escape(f"{o.status}: {o.detail()}")
            cells.append(f'<td style="background:{_COLOURS.get(o.status, "#fff")}">'
                         f"{_img(ref, 'reference')}{_img(o.thumb, 'submission')}{_img(diff, 'difference')}"
                         f'<div class="detail">{text}</div>{_story(o)}</td>')
        output = (f'<details><summary>output</summary><pre>{html.escape(chr(10).join(_output(r)))}</pre></details>'
                  if r.output else "")
        same = (f'<div class="same">same files as {html.escape(", ".join(map(shown, r.same_as)))}</div>'
                if r.same_as else "")
        body.append(f'<tr><td class="name">{html.escape(r.shown)}{same}{output}</td>'
                    f'<td style="background:{_COLOURS.get(r.status, "#fff")}">{html.escape(r.status)}</td>'
                    f'<td data-sort="{r.score}">{points(r.score)}/{points(r.total)}</td>{"".join(cells)}</tr>')
    c = counts(results)
    summary = ", ".join(f"{c[s]} {s}" for s in OUTCOMES)
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>glsandbox check: {html.escape(title)}</title>
<style>
body {{ font-family: sans-serif; margin: 1.5em; }}
table {{ border-collapse: collapse; }} th, td {{ border: 1px solid #bbb; padding: 4px; vertical-align: top; }}
th {{ cursor: pointer; background: #eee; }} img {{ image-rendering: pixelated; margin-right: 2px; }}
.detail {{ font-size: 80%; max-width: 40em; word-break: break-all; }} .name {{ font-family: monospace; }}
.same {{ color: #b00; font-weight: bold; }} .story pre {{ font-size: 75%; white-space: pre-wrap; max-width: 60em; }}
</style></head><body>
<h1>glsandbox check: {html.escape(title)}</h1>
<p>{len(results)} submissions: {html.escape(summary)}</p>
<table id="grades"><thead><tr><th>submission</th><th>outcome</th><th>score</th>{head}</tr></thead>
<tbody>
{chr(10).join(body)}
</tbody></table>
<script>
document.querySelectorAll("#grades th").forEach((th, column) => th.addEventListener("click", () => {{
  const body = document.querySelector("#grades tbody");
  const key = tr => {{ const td = tr.children[column]; return td.dataset.sort ?? td.textContent; }};
  const rows = [...body.rows], up = th.dataset.up !== "1";
  rows.sort((a, b) => {{ const x = key(a), y = key(b), nx = parseFloat(x), ny = parseFloat(y);
    const order = isNaN(nx) || isNaN(ny) ? x.localeCompare(y) : nx - ny; return up ? order : -order; }});
  th.dataset.up = up ? "1" : "0"; rows.forEach(tr => body.appendChild(tr));
}}));
</script>
</body></html>
"""


def student_text(results: Sequence[CheckResult], title: str) -> str:
    """The student's page (``--student-report``): for each check shown now, the reference, the
    submission, the difference and the figures; a hidden check only by its name and points, never
    its reference, difference, figures or outcome before the grades are published."""
    from glsandbox.grading.check import _thumbnail
    from glsandbox.measure.golden import _diff_image

    sections = []
    for r in results:
        rows_html = []
        for o in r.outcomes:
            if o.check.hidden:
                rows_html.append(f"<tr><td>{html.escape(o.check.name)}</td><td>- / {points(o.check.points)}</td>"
                                 '<td colspan="2">shown after the grades are published</td></tr>')
                continue
            try:
                ref = _thumbnail(read_reference(o.check.golden))
            except SandboxError:
                ref = None
            diff = None
            if o.thumb is not None and ref is not None and o.thumb.shape == ref.shape:
                diff = _diff_image(o.thumb, ref, int(o.match.threshold if o.match else 2))
            rows_html.append(
                f'<tr><td>{html.escape(o.check.name)}</td><td>{points(o.points)} / {points(o.check.points)}</td>'
                f'<td style="background:{_COLOURS.get(o.status, "#fff")}">{html.escape(o.status)}: '
                f'{html.escape(o.detail() if o.student is None else o.student)}{_story(o)}</td>'
                f"<td>{_img(ref, 'reference')}{_img(o.thumb, 'yours')}{_img(diff, 'difference')}</td></tr>")
        visible = [o for o in r.outcomes if not o.check.hidden]
        score = f"{points(sum(o.points for o in visible))} / {points(sum(o.check.points for o in visible))}"
        later = " (the hidden checks' points after publishing)" if len(visible) < len(r.outcomes) else ""
        output = (f"<details><summary>what your lesson printed</summary><pre>{html.escape(chr(10).join(_output(r)))}"
                  "</pre></details>" if r.output and not any(o.check.hidden for o in r.outcomes) else "")
        sections.append(f"<h2>{html.escape(r.shown)}: {score} points{later}</h2>\n<table><thead><tr><th>check</th>"
                        "<th>points</th><th>outcome</th><th>reference | yours | difference</th></tr></thead>"
                        f"<tbody>{''.join(rows_html)}</tbody></table>{output}")
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>glsandbox check</title>
<style>
body {{ font-family: sans-serif; margin: 1.5em; }}
table {{ border-collapse: collapse; }} th, td {{ border: 1px solid #bbb; padding: 4px; vertical-align: top; }}
img {{ image-rendering: pixelated; margin-right: 2px; }} .story pre {{ font-size: 75%; white-space: pre-wrap; }}
</style></head><body>
<h1>glsandbox check</h1>
{chr(10).join(sections)}
</body></html>
"""


#: The report kinds: the command-line flag and its writer.
REPORTS: dict[str, Callable[[Sequence[CheckResult], str], str]] = {
    "csv": csv_text, "json": json_text, "html": html_text, "junit": junit_text, "gradescope": gradescope_text,
    "student_report": student_text}


def write_reports(results: Sequence[CheckResult], targets: dict[str, Path | None], title: str) -> list[Path]:
    """Each asked-for report (kind -> path), written atomically."""
    written = []
    for kind, path in targets.items():
        if path is None:
            continue
        try:
            files.write_text(path, REPORTS[kind](results, title))
        except OSError as exc:
            raise SandboxError(f"--{kind.replace('_', '-')} {path}: cannot write ({exc.strerror or exc})") from None
        written.append(path)
    return written
