"""``glsandbox bench --json`` figures as Markdown tables, for the docs site's benchmarks page.

The figures are data (``docs/data/bench.json``, written by a bench run), never
pasted by hand: the site's build hook renders them with :func:`bench_tables`,
one table per group of cases, under the run's date, machine and renderer.
"""

from __future__ import annotations

from typing import Any


def _time(summary: dict[str, float] | None, unit: str) -> str:
    if not summary:
        return "-"
    return f"{summary['median']:.3f} {unit} ({summary['min']:.3f}-{summary['max']:.3f})"


def _goal(case: dict[str, Any]) -> str:
    if case.get("goal") is None or case.get("goal_met") is None:
        return "-"
    return f"≤ {case['goal']:.2f}x: {'met' if case['goal_met'] else 'not met'}"


def _cpu(case: dict[str, Any]) -> str:
    extra = case.get("extra_cpu_us")
    if extra is None:
        return "-"
    text = f"{extra:+.0f} µs" if case.get("unit") == "ms" else f"{extra / 1e6:+.3f} s"
    if case.get("cpu_goal_us") is not None and case.get("cpu_goal_met") is not None:
        text += f" (≤ {case['cpu_goal_us']:g} µs: {'met' if case['cpu_goal_met'] else 'not met'})"
    return text


def _cell(text: object) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def bench_tables(data: dict[str, Any]) -> str:
    """The run's header line (date, machine, renderer, rounds), a table per group, and its notes."""
    for key in ("cases", "renderer", "rounds"):
        if key not in data:
            raise ValueError(f"bench JSON without {key!r}: not written by glsandbox bench --json")
    when = data.get("date", "an unrecorded date")
    machine = data.get("machine", "an unrecorded machine")
    quick = ", --quick" if data.get("quick") else ""
    lines = [f"Measured {when} on {machine}, {data['renderer']}; {data['rounds']} alternating rounds{quick}; "
             "ratio = subject / baseline (medians), spread min-max in brackets.", ""]
    groups: dict[str, list[dict[str, Any]]] = {}
    for case in data["cases"]:
        groups.setdefault(case["group"], []).append(case)
    for group, cases in groups.items():
        lines += [f"### {_cell(group)}", "",
                  "| case | baseline | subject | baseline time | subject time | ratio | goal | extra CPU |",
                  "|---|---|---|--:|--:|--:|---|---|"]
        for case in cases:
            ratio = "-" if case.get("ratio") is None else f"{case['ratio']:.2f}x"
            lines.append(f"| {_cell(case['name'])} | {_cell(case.get('baseline') or '-')} | "
                         f"{_cell(case['subject'])} | {_time(case.get('baseline_time'), case['unit'])} | "
                         f"{_time(case.get('subject_time'), case['unit'])} | {ratio} | {_goal(case)} | "
                         f"{_cpu(case)} |")
        lines.append("")
    if data.get("notes"):
        lines += ["Notes from the run:", ""] + [f"- {_cell(note)}" for note in data["notes"]] + [""]
    return "\n".join(lines)
