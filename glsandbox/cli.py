"""The ``glsandbox`` command.

``list``, ``run LESSON``, ``render LESSON --out FILE.png``, ``tour [--out DIR]``
and ``plan LESSON``, where LESSON is a lesson name or a scene ``.toml`` file.
User errors print ``error: <one line>`` and exit with status 2.
"""

from __future__ import annotations

import argparse
import html
import json
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from glsandbox.errors import SandboxError

EXIT_USAGE = 2


def run_guarded(body: Callable[[], int]) -> int:
    """Run a command body; a :class:`SandboxError` becomes ``error: ...``, exit 2."""
    try:
        return body()
    except SandboxError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


def _lesson(args: argparse.Namespace):  # -> Lesson
    from glsandbox.lesson import find_lesson

    return find_lesson(args.lesson).from_settings(args.settings)


def _size(args: argparse.Namespace) -> tuple[int, int]:
    from glsandbox.app import DEFAULT_SIZE, parse_size

    return parse_size(args.size) if args.size else DEFAULT_SIZE


def cmd_list(args: argparse.Namespace) -> int:
    from glsandbox.lesson import all_lessons

    for cls in all_lessons():
        print(f"{cls.name:<18} {cls.title}  [{cls.course_section}]")
        if args.verbose:
            for param in cls.all_params():
                print(f"{'':<20}--set {param.describe()}")
    return 0


def cmd_plan(args: argparse.Namespace) -> int:
    from glsandbox.app import with_samples
    from glsandbox.plan import plan

    lesson = _lesson(args)
    print(plan(with_samples(lesson.scene(), args.samples)).describe())
    return 0


def cmd_render(args: argparse.Namespace) -> int:
    from glsandbox.app import render_to_file

    lesson = _lesson(args)
    size = _size(args)
    frame = render_to_file(lesson, args.out, size, args.samples, args.backend)
    print(f"wrote {args.out} ({size[0]}x{size[1]}, {frame.seconds * 1000:.1f} ms)")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from glsandbox.app import run_window

    run_window(_lesson(args), _size(args), args.samples, args.backend)
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    """``glsandbox compare``: tiles side by side, then which are identical and how far apart."""
    from glsandbox.app import HeadlessRenderer, check_writable, with_samples
    from glsandbox.compare import build_variants, compare_variants, default_out
    from glsandbox.golden import save_png
    from glsandbox.lesson import find_lesson

    lesson_cls = find_lesson(args.lesson)
    out: Path = args.out or default_out(lesson_cls.name)
    size = _size(args)
    check_writable(out)
    # Everything is parsed and every scene built before a context opens.
    variants, columns = build_variants(lesson_cls, args.vary, args.settings)
    variants = [replace(v, scene=with_samples(v.scene, args.samples)) for v in variants]
    with HeadlessRenderer(args.backend) as renderer:
        result = compare_variants(variants, columns, size, renderer)
    save_png(result.image, out)
    print(result.report())
    if result.difference is not None:  # the first two distinct pictures, amplified
        diff_out = out.with_name(f"{out.stem}-diff.png")
        save_png(result.difference, diff_out)
        print(f"wrote {diff_out} (difference of the first two distinct pictures, x4)")
    print(f"wrote {out} ({size[0]}x{size[1]}, {len(variants)} tiles)")
    return 0


def cmd_tour(args: argparse.Namespace) -> int:
    from glsandbox.app import HeadlessRenderer, write_png
    from glsandbox.lesson import all_lessons

    out: Path = args.out
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot create folder ({exc.strerror})") from None
    size = _size(args)
    lessons = all_lessons()
    if args.settings:
        raise SandboxError("--set is per lesson; use glsandbox render LESSON --set ... instead of tour")
    results = []
    started = time.perf_counter()
    with HeadlessRenderer(args.backend) as renderer:
        print(f"tour: {len(lessons)} lessons at {size[0]}x{size[1]} on {renderer.host.backend} "
              f"({renderer.host.ctx.info['GL_RENDERER']}) -> {out}/", file=sys.stderr)
        for number, cls in enumerate(lessons, start=1):
            entry = {"lesson": cls.name, "title": cls.title, "course_section": cls.course_section}
            prefix = f"[{number}/{len(lessons)}] {cls.name}"
            try:
                frame = renderer.render(cls(), size, args.samples)
                image_path = out / f"{cls.name}.png"
                write_png(frame.image, image_path)
                entry.update(ok=True, image=image_path.name, render_ms=round(frame.seconds * 1000, 2),
                             plan=frame.plan.to_dict(), plan_text=frame.plan.describe())
                print(f"{prefix}: ok, {frame.seconds * 1000:.1f} ms", file=sys.stderr, flush=True)
            except SandboxError as exc:  # one broken lesson must not stop the tour
                entry.update(ok=False, error=str(exc))
                print(f"{prefix}: FAILED: {exc}", file=sys.stderr, flush=True)
            results.append(entry)
        renderer_name = renderer.host.renderer
        backend = renderer.host.backend
    summary = {"size": list(size), "samples": args.samples, "backend": backend, "renderer": renderer_name,
               "seconds": round(time.perf_counter() - started, 3), "lessons": results}
    _write_text(out / "tour.json", json.dumps(summary, indent=2) + "\n")
    _write_text(out / "index.html", _gallery(summary))
    failed = [r["lesson"] for r in results if not r["ok"]]
    print(f"tour: {len(results) - len(failed)} of {len(results)} rendered; gallery {out / 'index.html'}",
          file=sys.stderr)
    if failed:
        print(f"tour: failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


def _write_text(path: Path, text: str) -> None:
    """Write via a temporary file, so a reader never sees half a file."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


def _gallery(summary: dict) -> str:
    cards = []
    for r in summary["lessons"]:
        title = html.escape(f"{r['lesson']}: {r['title']}")
        section = html.escape(r["course_section"])
        if r["ok"]:
            body = (f'<img src="{html.escape(r["image"])}" alt="{title}">'
                    f"<p>render {r['render_ms']:.1f} ms</p><pre>{html.escape(r['plan_text'])}</pre>")
        else:
            body = f'<p class="error">failed: {html.escape(r["error"])}</p>'
        cards.append(f"<section><h2>{title}</h2><p class=\"section\">course: {section}</p>{body}</section>")
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>glsandbox tour</title>
<style>
body {{ font-family: sans-serif; margin: 2em; background: #f4f4f4; }}
section {{ background: white; padding: 1em; margin-bottom: 1.5em; border-radius: 6px; }}
img {{ image-rendering: pixelated; border: 1px solid #ccc; }}
pre {{ background: #eee; padding: 0.5em; }}
.section {{ color: #555; }} .error {{ color: #b00; }}
</style></head><body>
<h1>glsandbox tour</h1>
<p>{html.escape(summary['renderer'])} ({html.escape(summary['backend'])}),
{summary['size'][0]}x{summary['size'][1]}, {summary['seconds']:.2f} s in all</p>
{''.join(cards)}
</body></html>
"""


def cmd_tradeoffs(args: argparse.Namespace) -> int:
    """``glsandbox tradeoffs``: accuracy knobs, timed and compared with a reference (:mod:`glsandbox.tradeoffs`)."""
    from glsandbox.tradeoffs import run

    run(args.out, quick=args.quick, backend=args.backend, runs=args.runs, only=args.knob)
    print(f"wrote {args.out / 'report.md'}, {args.out / 'tradeoffs.csv'}, {args.out / 'tradeoffs.png'}")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """``glsandbox bench``: every benchmark in benchmarks/, one table of side-by-side ratios."""
    from glsandbox.bench import run_all

    return run_all(json_path=args.json, quick=args.quick, only=args.only)


def build_parser() -> argparse.ArgumentParser:
    from glsandbox.app import add_render_options

    parser = argparse.ArgumentParser(prog="glsandbox", description="A graphics course as runnable ModernGL lessons.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("list", help="list the lessons")
    p.add_argument("-v", "--verbose", action="store_true", help="also list each lesson's parameters")
    p.set_defaults(func=cmd_list)

    for name, func, help_text in (("run", cmd_run, "open a lesson in a window"),
                                  ("render", cmd_render, "render a lesson headless to a PNG"),
                                  ("plan", cmd_plan, "print the passes a lesson's scene needs")):
        p = sub.add_parser(name, help=help_text)
        p.add_argument("lesson", metavar="LESSON", help="a lesson name or a scene .toml file")
        add_render_options(p)
        if name == "render":
            p.add_argument("--out", type=Path, required=True, help="the PNG file to write")
        p.set_defaults(func=func)

    p = sub.add_parser("tour", help="render every lesson headless, with a gallery page")
    add_render_options(p)
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
    p.set_defaults(func=cmd_tour)

    p = sub.add_parser("compare", help="render one lesson with several parameter values side by side")
    p.add_argument("lesson", metavar="LESSON", help="a lesson name or a scene .toml file")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a parameter and its values, one tile each (twice: a grid)")
    add_render_options(p)
    p.add_argument("--out", type=Path, default=None, help="the PNG to write (default compare_LESSON.png)")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("tradeoffs", help="what accuracy costs in time: each knob timed and compared with a reference")
    p.add_argument("--out", type=Path, default=Path("out/tradeoffs"), help="output folder (default out/tradeoffs)")
    p.add_argument("--quick", action="store_true", help="a reduced set at a small size (for CI)")
    p.add_argument("--runs", type=int, default=5, help="timed runs per setting (at least 5, default 5)")
    p.add_argument("--knob", action="append", default=[], metavar="NAME", help="only this knob (repeatable)")
    p.add_argument("--backend", default=None, help="GL backend (default: GLSANDBOX_BACKEND or auto)")
    p.set_defaults(func=cmd_tradeoffs)

    p = sub.add_parser("bench", help="run every benchmark in benchmarks/ and print one table of ratios")
    p.add_argument("--json", type=Path, default=None, metavar="FILE", help="also write the figures as JSON")
    p.add_argument("--quick", action="store_true", help="fewer frames and rounds (a smoke run)")
    p.add_argument("--only", action="append", default=[], metavar="NAME",
                   help="only benchmarks whose name contains NAME (repeatable)")
    p.set_defaults(func=cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return run_guarded(lambda: args.func(args))


if __name__ == "__main__":
    sys.exit(main())
