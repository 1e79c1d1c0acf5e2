"""Writing what ``glsandbox tradeoffs`` measured: ``tradeoffs.csv``, ``report.md`` and ``tradeoffs.png``.

- ``report.md``: one table per knob (with its notes and the error order
  it must keep), then the knobs that could not be measured here and why;
- ``tradeoffs.csv``: the same figures, one row per setting;
- ``tradeoffs.png``: error against time, one panel per knob (matplotlib,
  from the optional ``measure`` extra).

Every file is written atomically through :mod:`glsandbox.files`.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from glsandbox.files import atomic_write, write_text
from glsandbox.measure import extra
from glsandbox.measure.knob import BUSY_LOAD_PER_CPU, FRAME_NOISE_MS, RUN_DRIFT, WIDE_SPREAD, KnobResult, Row


__all__ = ["CSV_COLUMNS", "write_csv", "write_plot", "write_report"]

CSV_COLUMNS = ("knob", "setting", "reference", "width", "height", "runs", "time_median_ms", "time_min_ms",
               "time_max_ms", "rmse", "psnr_db", "flip", "count_px", "count_of_px", "count_share", "image",
               "error_map", "median_spread", "passes", "pass_medians_ms", "run_spread", "trusted", "busy",
               "stated_spread")


def _fmt_psnr(value: float) -> str:
    return "inf" if math.isinf(value) else f"{value:.2f}"


def write_csv(results: Sequence[KnobResult], size: tuple[int, int], path: Path) -> None:
    """``tradeoffs.csv``: one row per setting (:data:`CSV_COLUMNS`)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for result in results:
        for r in result.rows:
            low, high = r.spread_ms
            writer.writerow([r.knob, r.setting, int(r.reference), size[0], size[1], len(r.times_ms),
                             f"{r.median_ms:.3f}", f"{low:.3f}", f"{high:.3f}", f"{r.rmse:.6f}",
                             _fmt_psnr(r.psnr), "" if r.flip is None else f"{r.flip:.6f}",
                             *(("", "", "") if r.count is None else
                               (r.count.pixels, r.count.of, f"{r.count.share:.6f}")),
                             r.image, r.error_map, f"{r.median_spread:.4f}", len(r.pass_medians),
                             " ".join(f"{m:.3f}" for m in r.pass_medians), f"{r.run_spread:.4f}", int(r.trusted),
                             r.busy or "", f"{r.stated_spread:.4f}"])
    write_text(path, buffer.getvalue())


def time_cell(r: Row) -> str:
    """A setting's time for the report: the median ± its stated spread
    (:attr:`~glsandbox.measure.knob.Row.stated_spread`: the passes' whole range, at least the
    drift of whole runs and a frame's noise), or, where the
    passes disagree by more than :data:`~glsandbox.measure.knob.WIDE_SPREAD` or the machine
    was too busy (:func:`~glsandbox.measure.knob.machine_busy`), no figure."""
    passes = ", ".join(f"{m:.2f}" for m in r.pass_medians)
    if not r.trusted:
        why = f"{r.busy}; " if r.busy else ""
        return f"too noisy ({why}passes {passes} ms: ±{_percent_up(r.run_spread)}%)"
    return f"{r.median_ms:.2f} ±{_percent_up(r.stated_spread)}%"


def _percent_up(share: float) -> int:
    """``share`` in whole percent, rounded up: the range stated holds every pass's median."""
    return math.ceil(round(share * 100, 6))


def write_report(results: Sequence[KnobResult], info: Mapping[str, str], path: Path,
                 skipped: Mapping[str, str] | None = None) -> None:
    """``report.md``: a table per knob, then the ``skipped`` knobs (name: why) under "Not measured yet"."""
    lines = ["# Accuracy against time: the tradeoffs report", "",
             f"Renderer: {info['renderer']} ({info['backend']}); frame {info['size']}; "
             f"{info.get('passes', '1')} independent passes of {info['runs']} timed rounds, each pass in a "
             f"process of its own and each round every setting of every knob once, the knobs in turn; "
             f"{'quick set' if info['quick'] == 'yes' else 'full set'}.", ""]
    if "load" in info:
        lines += [f"Load average (1, 5, 15 min) on {info.get('cpus', '?')} CPUs: {info['load']}. A machine "
                  "busier than its CPUs moves every time; compare runs made at the same load.", ""]
    lines += ["Time is the whole frame as a user gets it: render, read back, and for supersampling the "
              "downsample: the median of all runs ± the whole spread of the passes' medians, but never less "
              f"than {RUN_DRIFT:.0%} (what whole runs move together on a shared machine) nor {FRAME_NOISE_MS:g} ms "
              "(a frame's noise): another run at the same load gives a figure whose range overlaps this one; "
              f"where the passes differ by more than {WIDE_SPREAD:.0%}, or the load average passed "
              f"{BUSY_LOAD_PER_CPU:g} runnable threads a CPU while the passes ran, the time is noise and "
              "the table says \"too noisy\" instead of a figure. Errors are against the knob's reference: "
              "RMSE (0..1 scale), PSNR (dB, higher is better), FLIP (mean perceptual error, 0..1, lower is "
              "better). The plot is `tradeoffs.png`.", ""]
    for result in results:
        knob = result.knob
        counted = f" {knob.count_label} | share of {knob.count_of} |" if knob.count_label else ""
        lines += [f"## {knob.title} (`{knob.name}`)", "", f"Scene: {knob.scene}.  ",
                  f"Reference: {knob.reference_note.rstrip('.')}.", "",
                  f"| setting | time (ms) | runs min-max (ms) |{counted} RMSE | PSNR (dB) | FLIP | error map |",
                  "|---|---:|---:|" + ("---:|---:|" if knob.count_label else "") + "---:|---:|---:|---|"]
        for r in result.rows:
            low, high = r.spread_ms
            name = (f"{r.setting} (reference)" if r.reference else r.setting).replace("|", "\\|")  # a cell
            count = "" if not knob.count_label else (
                " - | - |" if r.count is None else f" {r.count.pixels} | {r.count.share:.1%} |")
            lines.append(f"| {name} | {time_cell(r)} | {low:.2f}-{high:.2f} ({len(r.times_ms)} runs) |{count} "
                         f"{r.rmse:.4f} | "
                         f"{_fmt_psnr(r.psnr)} | {'-' if r.flip is None else f'{r.flip:.4f}'} | "
                         f"{f'[map]({r.error_map})' if r.error_map else '-'} |")
        noisy = [r.setting for r in result.rows if not r.trusted]
        busy = next((r.busy for r in result.rows if r.busy), None)
        if busy:
            lines += ["", f"Too noisy to give a time: {busy}, more than {BUSY_LOAD_PER_CPU:g} runnable threads a "
                          "CPU while it was timed; run again on a quieter machine."]
        elif noisy:
            lines += ["", f"Too noisy to give a time ({len(noisy)} of {len(result.rows)} settings): its passes "
                          f"differ by more than {WIDE_SPREAD:.0%}; run again on a quieter machine."]
        verdict = result.monotone_ok()
        if verdict is not None:
            chain = " >= ".join(label for label in knob.monotone if any(r.setting == label for r in result.rows))
            lines += ["", f"Error order {chain} (RMSE): {'holds' if verdict else 'DOES NOT HOLD'}."]
        if knob.notes:
            lines += ["", "Notes:", ""] + [f"- {note}" for note in knob.notes]
        lines.append("")
    measured = {r.knob.name for r in results}
    pending = {name: why for name, why in (skipped or {}).items() if name not in measured}
    if pending:
        lines += ["## Not measured yet", ""]
        lines += [f"- `{name}`: {why}" for name, why in pending.items()]
        lines.append("")
    write_text(path, "\n".join(lines))


def write_plot(results: Sequence[KnobResult], path: Path) -> None:
    """FLIP error against median time, one panel per knob, the spread as horizontal bars."""
    matplotlib = extra.require("matplotlib")
    matplotlib.use("Agg")
    plt = extra.require("matplotlib.pyplot")
    ticker = extra.require("matplotlib.ticker")

    count = len(results)
    columns = min(count, 2)
    rows = math.ceil(count / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(6.4 * columns, 4.6 * rows), squeeze=False)
    markers = "osD^vP<>Xh"
    for ax, result in zip(axes.flat, results):
        # One colour and marker per setting, named in the legend: labels written
        # next to the points would overlap where settings cost about the same.
        counted = bool(result.knob.count_label)
        no_flip = any(r.flip is None for r in result.rows)  # flip-evaluator not installed: RMSE instead
        for index, r in enumerate(result.rows):
            low, high = r.spread_ms
            marker = "*" if r.reference else markers[index % len(markers)]
            error = (r.count.share if r.count is not None else 0.0) if counted else (
                r.rmse if no_flip else r.flip)
            ax.errorbar([r.median_ms], [error], xerr=[[r.median_ms - low], [high - r.median_ms]],
                        fmt=marker, color="black" if r.reference else f"C{index % 10}",
                        markersize=12 if r.reference else 7, capsize=3,
                        mfc="none" if not r.trusted else None,  # hollow: too noisy to read its time
                        label=(f"{r.setting} (reference)" if r.reference else r.setting)
                        + ("" if r.trusted else " (time too noisy)"))
        lows, highs = zip(*(r.spread_ms for r in result.rows))
        wide = max(highs) > 4.0 * min(lows)  # a log axis only when times span a few times
        if wide:
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(ticker.FormatStrFormatter("%g"))
            ax.xaxis.set_minor_formatter(ticker.NullFormatter())  # minor labels overlap on short ranges
        ax.set_title(result.knob.title)
        ax.set_xlabel(f"frame time, median and min-max (ms{', log scale' if wide else ''})")
        ax.set_ylabel(f"{result.knob.count_label}, share of {result.knob.count_of}" if counted
                      else "RMSE vs reference (0 = same; FLIP not installed)" if no_flip
                      else "FLIP error vs reference (0 = same)")
        ax.grid(True, which="both", alpha=0.3)
        ax.margins(x=0.15, y=0.12)
        if counted:  # shares lie in 0..1; the room above keeps the legend off the points
            legend = min(0.8, 0.03 + 0.048 * len(result.rows))  # its height, as a share of the panel's
            ax.set_ylim(-0.05, max(1.9, (1.05 + 0.05 * legend) / (1.0 - legend)))
            ax.set_yticks([0.0, 0.25, 0.5, 0.75, 1.0])
        ax.legend(fontsize=8, loc="upper center" if counted else "best", framealpha=0.85)
    for ax in list(axes.flat)[count:]:
        ax.set_visible(False)
    fig.suptitle("Error against time (lower left is better)")
    fig.tight_layout()
    try:
        atomic_write(path, lambda f: fig.savefig(f, format="png", dpi=110))
    finally:
        plt.close(fig)
