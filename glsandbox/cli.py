"""The ``glsandbox`` command, and ``python -m glsandbox.lessons.<module>``.

``list``, ``run LESSON``, ``render LESSON --out FILE.png``, ``explain LESSON --pixel X,Y``, ``tour [--out DIR]
[--lessons DIR]``, ``plan LESSON``, ``compare``, ``new NAME``, ``check LESSON
--golden REF.png``, ``exercise list|start|check``, ``tradeoffs`` and ``bench``, where LESSON is a lesson
name, a lesson ``.py`` file or a scene ``.toml`` file. :func:`lesson_main` is the entry point
of a lesson module (a window, or ``--headless --out FILE.png``). User errors
print ``error: <one line>`` and exit with status 2.
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from collections.abc import Callable
from typing import NoReturn
from dataclasses import replace
from pathlib import Path

import numpy as np

from glsandbox.errors import SandboxError, parse_size_text
from glsandbox.files import save_png, write_text
from glsandbox.frame import DEFAULT_SIZE, Frame, HeadlessRenderer, with_samples
from glsandbox.gl.context import BACKENDS
from glsandbox.interrupt_watch import EXIT_INTERRUPTED, watch_interrupts
from glsandbox.lesson import Lesson, all_lessons, find_lesson, lesson_description, lesson_files
from glsandbox.plan import plan
from glsandbox.progress import progress, ready, say
from glsandbox.scene import Scene

EXIT_USAGE = 2
#: What a Unix tool exits with when its reader went away (128 + SIGPIPE).
EXIT_BROKEN_PIPE = 141


class ArgumentParser(argparse.ArgumentParser):
    """argparse with the project's error contract: one ``error:`` line, exit 2 (no usage dump)."""

    def error(self, message: str) -> NoReturn:
        print(f"error: {SandboxError(f'{self.prog}: {message} (see {self.prog} --help)')}", file=sys.stderr)
        raise SystemExit(EXIT_USAGE)


def run_guarded(body: Callable[[], int]) -> int:
    """Run a command body; a :class:`SandboxError` becomes ``error: ...``, exit 2.

    A reader that stops early (``glsandbox plan LESSON | head -3``) ends the
    command quietly, as it ends any Unix tool.
    """
    try:
        status = body()
        sys.stdout.flush()  # a closed pipe shows here, inside the guard, not at interpreter exit
        return status
    except SandboxError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # Python would flush stdout again at exit and complain: point it at /dev/null.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE


# --- shared by the commands ------------------------------------------------


def check_writable(path: Path) -> None:
    """Refuse an output path we cannot write, before any work is done."""
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise SandboxError(f"--out {path}: is a folder, expected a .png file name")
    if path.suffix.lower() != ".png":
        raise SandboxError(f"--out {path}: the output must be a .png file")
    if not parent.is_dir():
        raise SandboxError(f"--out {path}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise SandboxError(f"--out {path}: not writable")


def render_to_file(lesson: Lesson, out: Path, size: tuple[int, int], samples: int = 0,
                   backend: str | None = None) -> Frame:
    """Render one lesson headless and write it as a PNG (atomically)."""
    check_writable(out)
    with HeadlessRenderer(backend) as renderer:
        frame = renderer.render(lesson, size, samples)
    write_png(frame.image, out)
    return frame


def write_png(image: np.ndarray, out: Path) -> None:
    """Write a PNG atomically; an OS failure becomes a one-line error naming the file."""
    try:
        save_png(image, out)
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot write ({exc.strerror or exc})") from None


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` -> (W, H), refusing anything else with the value named."""
    return parse_size_text(text, "--size")


def add_render_options(parser: argparse.ArgumentParser, settings: bool = True,
                       size_default: str = f"{DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]}") -> None:
    """The options shared by every command that renders (``settings``: ``--set``, for one lesson)."""
    parser.add_argument("--size", default=None, help=f"frame size WxH (default {size_default})")
    parser.add_argument("--samples", type=int, default=0, help="MSAA samples (0: none)")
    parser.add_argument("--backend", default=None, help=f"one of {', '.join(BACKENDS)} "
                        "(default: GLSANDBOX_BACKEND or auto)")
    if settings:
        parser.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                            help="a lesson parameter (repeatable); every lesson has time=SECONDS")


def _lesson(args: argparse.Namespace) -> Lesson:
    return find_lesson(args.lesson).from_settings(args.settings)


def _size(args: argparse.Namespace) -> tuple[int, int]:
    return parse_size(args.size) if args.size else DEFAULT_SIZE


def cmd_list(args: argparse.Namespace) -> int:
    for cls in all_lessons():
        print(f"{cls.name:<18} {cls.title}  [{cls.course_section}]")
        if args.verbose:
            for param in cls.all_params():  # with the lesson's own defaults (the ray lessons: renderer=ray)
                own = replace(param, default=cls.defaults[param.name]) if param.name in cls.defaults else param
                print(f"{'':<20}--set {own.describe()}")
    return 0


def cmd_plan(args: argparse.Namespace) -> int:
    lesson = _lesson(args)
    print(plan(with_samples(lesson.scene(), args.samples)).describe())
    return 0


def cmd_render(args: argparse.Namespace) -> int:
    lesson = _lesson(args)
    size = _size(args)
    if args.out is None and args.xray is None:
        raise SandboxError("glsandbox render: the following arguments are required: --out FILE.png, or --xray DIR "
                           "(see glsandbox render --help)")
    if args.out is not None:
        frame = render_to_file(lesson, args.out, size, args.samples, args.backend)
        print(f"wrote {args.out} ({size[0]}x{size[1]}, {frame.seconds * 1000:.1f} ms)")
    if args.xray is not None:
        from glsandbox.story.xray import write_xray, xray

        if args.xray.exists() and not args.xray.is_dir():
            raise SandboxError(f"--xray {args.xray}: is a file, expected a folder")
        with HeadlessRenderer(args.backend) as renderer:
            x = xray(renderer, with_samples(lesson.scene(), args.samples), size)
        written = write_xray(x, args.xray)
        for note in x.notes:
            print(f"note: {note}")
        print(f"wrote {len(written)} pictures of {len(x.passes)} passes to {args.xray} (contact_sheet.png: all of them)")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from glsandbox.app.window import run_window  # glfw and the panel only where a window opens

    run_window(_lesson(args), _size(args), args.samples, args.backend)
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    """``glsandbox compare``: tiles side by side, then which are identical and how far apart."""
    from glsandbox.measure.compare import build_variants, compare_variants, default_out

    lesson_cls = find_lesson(args.lesson)
    out: Path = args.out or default_out(lesson_cls.name, args.lesson)
    size = _size(args)
    check_writable(out)
    # Everything is parsed and every scene built before a context opens.
    variants, columns = build_variants(lesson_cls, args.vary, args.settings)
    variants = [replace(v, scene=with_samples(v.scene, args.samples)) for v in variants]
    # Each variant is drawn twice: in the composed frame, and alone for the figures.
    with HeadlessRenderer(args.backend) as renderer, progress(2 * len(variants), "compare", "tile") as bar:
        result = compare_variants(variants, columns, size, renderer, advance=bar.update)
    write_png(result.image, out)
    print(result.report())
    if result.difference is not None:  # the first two distinct pictures, amplified
        diff_out = out.with_name(f"{out.stem}-diff.png")
        write_png(result.difference, diff_out)
        print(f"wrote {diff_out} (difference of the first two distinct pictures, x4)")
    print(f"wrote {out} ({size[0]}x{size[1]}, {len(variants)} tiles)")
    return 0


def cmd_tour(args: argparse.Namespace) -> int:
    out: Path = args.out
    if args.lessons is not None and not args.lessons.is_dir():
        raise SandboxError(f"--lessons {args.lessons}: not a folder")
    size = _size(args)
    with_samples(Scene("samples"), args.samples)  # a bad --samples fails now, not once per lesson
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SandboxError(f"--out {out}: cannot create folder ({exc.strerror})") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise SandboxError(f"--out {out}: folder is not writable")
    started = time.perf_counter()
    if args.lessons is not None:  # students' code: isolated and limited as check grades it
        results, renderer_name, backend = _tour_isolated(args, size, out)
    else:
        results, renderer_name, backend = _tour_course(args, size, out)
    summary = {"size": list(size), "samples": args.samples, "backend": backend, "renderer": renderer_name,
               "folder": None if args.lessons is None else str(args.lessons),
               "seconds": round(time.perf_counter() - started, 3), "lessons": results}
    import json

    from glsandbox.course_page import course_page  # the tour's gallery page

    for name, text in (("tour.json", json.dumps(summary, indent=2) + "\n"), ("index.html", course_page(summary))):
        try:
            write_text(out / name, text)
        except OSError as exc:
            raise SandboxError(f"--out {out / name}: cannot write ({exc.strerror or exc})") from None
    failed = [r["lesson"] for r in results if not r["ok"] or any("error" in c for c in r["contrasts"])]
    print(f"tour: {len(results) - len(failed)} of {len(results)} rendered; course page {out / 'index.html'}",
          file=sys.stderr)
    if failed:
        print(f"tour: failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


def _tour_course(args: argparse.Namespace, size: tuple[int, int], out: Path) -> tuple[list[dict], str, str]:
    """The course's own lessons, rendered in this process on one context, with their contrasts."""
    lessons = all_lessons()
    results = []
    with HeadlessRenderer(args.backend) as renderer, progress(len(lessons), "tour", "lesson") as bar:
        say(f"tour: {len(lessons)} lessons at {size[0]}x{size[1]} on {renderer.host.backend} "
            f"({renderer.host.ctx.info['GL_RENDERER']}) -> {out}/")
        for number, cls in enumerate(lessons, start=1):
            entry = {"lesson": cls.name, "title": cls.title, "course_section": cls.course_section,
                     "command": f"glsandbox run {cls.name}", "contrasts": [], "description": lesson_description(cls)}
            prefix = f"[{number}/{len(lessons)}] {cls.name}"
            try:
                frame = renderer.render(cls(), size, args.samples)
                image_path = out / f"{cls.name}.png"
                write_png(frame.image, image_path)
                entry.update(ok=True, image=image_path.name, render_ms=round(frame.seconds * 1000, 2),
                             plan=frame.plan.to_dict(), plan_text=frame.plan.describe())
                say(f"{prefix}: ok, {frame.seconds * 1000:.1f} ms")
                entry["contrasts"] = _tour_contrasts(cls, out, size, args.samples, renderer, prefix)
            except SandboxError as exc:  # one broken lesson must not stop the tour
                entry.update(ok=False, error=str(exc))
                say(f"{prefix}: FAILED: {exc}")
            results.append(entry)
            bar.update(1)
        return results, renderer.host.renderer, renderer.host.backend


def _tour_isolated(args: argparse.Namespace, size: tuple[int, int], out: Path) -> tuple[list[dict], str, str]:
    """``tour --lessons DIR``: each lesson in a process of its own, under ``check``'s limits and
    confinement (:func:`glsandbox.grading.check.render_submissions`); a lesson that does not finish is
    TIMEOUT on its card, and the page is still written."""
    from glsandbox.grading.check import DEFAULT_MEMORY, Limits, default_jobs, render_submissions, shown

    found = lesson_files(args.lessons)
    if not found:
        raise SandboxError(f"--lessons {args.lessons}: no .py or .toml lesson files (nor subfolders holding one)")
    timeout = args.timeout
    if not 0 < timeout <= 3600:
        raise SandboxError(f"--timeout {timeout:g}: expected seconds, more than 0 and at most 3600")
    limits = Limits(float(timeout), DEFAULT_MEMORY, default_jobs())
    say(f"tour: {len(found)} lessons of {args.lessons} at {size[0]}x{size[1]}, each isolated "
        f"({timeout:g} s each) -> {out}/")
    position = {name: number for number, (name, _) in enumerate(found, start=1)}  # lines numbered in folder order
    with progress(len(found), "tour", "lesson") as bar:
        def heard(name: str, path: Path, result) -> None:
            picture = result.pictures[0] if result.pictures else None
            state = "ok" if picture is not None and picture.image is not None else \
                f"FAILED: {picture.status if picture else 'CRASHED'}: {shown(picture.error) if picture else ''}"
            say(f"[{position.get(name, 0)}/{len(found)}] {shown(name)}: {state}")
            bar.update(1)

        rendered = render_submissions(args.lessons, size, args.samples, args.backend, limits, heard)
    results = []
    for name, path, result in rendered:
        entry = {"lesson": name, "title": result.meta.get("title", ""), "contrasts": [],
                 "course_section": result.meta.get("course_section", ""),
                 "description": result.meta.get("description", ""),
                 "command": f"glsandbox run {shlex.quote(str(path))}"}
        picture = result.pictures[0] if result.pictures else None
        if picture is not None and picture.image is not None:
            image_path = out / f"{name}.png"
            write_png(picture.image, image_path)
            entry.update(ok=True, image=image_path.name, render_ms=round(picture.seconds * 1000, 2),
                         plan=picture.info.get("plan", {}), plan_text=str(picture.info.get("plan_text", "")))
        else:
            status = picture.status if picture is not None else "CRASHED"
            error = shown(picture.error) if picture is not None else "its grading process ended without a result"
            entry.update(ok=False, error=f"{status}: {error}")
        results.append(entry)
    return results, "each lesson in a process of its own", args.backend or "auto"


#: A contrast grid's columns on the course page: three tiles side by side still read on a card.
CONTRAST_COLUMNS = 3


def _tour_contrasts(cls: type[Lesson], out: Path, size: tuple[int, int], samples: int,
                    renderer: HeadlessRenderer, prefix: str) -> list[dict]:
    """The lesson's contrasts (``Lesson.contrasts``) as tile grids beside its picture: each tile
    half the tour's frame each way, the grid as ``glsandbox compare`` lays it out."""
    from glsandbox.measure.compare import build_variants, render_grid

    found = []
    for number, (caption, vary) in enumerate(cls.contrasts, start=1):
        entry: dict = {"caption": caption, "vary": vary,
                       "command": f"glsandbox compare {cls.name} --vary {shlex.quote(vary)}"}
        try:
            variants, _ = build_variants(cls, [vary], [])
            variants = [replace(v, scene=with_samples(v.scene, samples)) for v in variants]
            columns = min(len(variants), CONTRAST_COLUMNS)
            rows = -(-len(variants) // columns)
            grid_size = (columns * max(1, size[0] // 2), rows * max(1, size[1] // 2))
            image_path = out / f"{cls.name}.contrast{number}.png"
            grid = render_grid(variants, columns, grid_size, renderer).copy()
            tile = (grid_size[0] // columns, grid_size[1] // rows)
            for slot in range(len(variants), rows * columns):  # the last row's empty tiles: transparent
                x, y = (slot % columns) * tile[0], (slot // columns) * tile[1]
                grid[y:y + tile[1], x:x + tile[0]] = 0
            write_png(grid, image_path)
            entry.update(image=image_path.name, size=list(grid_size), labels=[v.label for v in variants])
        except SandboxError as exc:
            entry["error"] = str(exc)
            say(f"{prefix}: contrast {vary} FAILED: {exc}")
        found.append(entry)
    return found


def cmd_new(args: argparse.Namespace) -> int:
    """``glsandbox new NAME``: a commented starting lesson ``NAME.py``, scene file ``NAME.toml``
    and shader ``NAME.glsl`` (the scene's ball is drawn with it). ``new --assignment NAME``:
    the lesson as a model answer and a starting grading file ``NAME.grading.toml`` beside it."""
    from importlib.resources import files as package_files
    from string import Template

    from glsandbox.grading.rubric import STARTER

    if (args.name is None) == (args.assignment is None):
        raise SandboxError("new: give a NAME, or --assignment NAME (a model answer and its grading file)")
    name: str = args.name if args.name is not None else args.assignment
    if not name.isidentifier() or name.startswith("_") or not name.isascii():
        raise SandboxError(f"new {name!r}: the name must be a Python identifier: letters, digits and _, "
                           "not starting with a digit or _ (e.g. my_lesson)")
    folder: Path = args.dir
    if not folder.is_dir():
        raise SandboxError(f"--dir {folder}: folder does not exist")
    templates = package_files("glsandbox") / "templates"
    if args.assignment is None:
        targets = {folder / f"{name}.py": "lesson.py.tmpl", folder / f"{name}.toml": "scene.toml.tmpl",
                   folder / f"{name}.glsl": "shader.glsl.tmpl"}
    else:
        targets = {folder / f"{name}.py": "lesson.py.tmpl", folder / f"{name}.grading.toml": STARTER}
    existing = [str(path) for path in targets if path.exists() or path.is_symlink()]
    if existing:  # all or none: never part of a starter
        verb = "exists" if len(existing) == 1 else "exist"
        raise SandboxError(f"{', '.join(existing)} already {verb}; not overwritten (pick another NAME or --dir)")
    # The class name: my_lesson -> MyLesson (a name of capitals only stays as it is).
    cls = "".join(part[:1].upper() + part[1:] for part in name.split("_")) or "MyLesson"
    for path, template in targets.items():
        source = template if "\n" in template else templates.joinpath(template).read_text(encoding="utf-8")
        text = Template(source).substitute(name=name, cls=cls)
        try:
            write_text(path, text)
        except OSError as exc:
            raise SandboxError(f"{path}: cannot write ({exc.strerror or exc})") from None
        print(f"wrote {path}")
    if args.assignment is not None:
        rubric = folder / f"{name}.grading.toml"
        print(f"next: glsandbox check {folder / name}.py --rubric {rubric} --update   (the goldens, from the model answer)")
        print(f"then: glsandbox check SUBMISSIONS/ --rubric {rubric} --html report.html")
        return 0
    print(f"next: glsandbox run {folder / name}.py   (or glsandbox render {folder / name}.py --out {name}.png)")
    return 0


def _checks(args: argparse.Namespace) -> tuple[list, float | None, int | None]:
    """The checks of ``check``: a rubric's, or one from --golden, --set, --size and --tolerance."""
    from glsandbox.grading.rubric import Check, load_rubric, parse_tolerances

    if getattr(args, "exercise", None) is not None:
        if args.golden is not None or args.rubric is not None:
            raise SandboxError(f"--exercise {args.exercise}: grades by the exercise's cases; drop --golden and --rubric")
        from glsandbox.grading.exercise import default_check

        return [default_check(args.exercise)], None, None
    if (args.golden is None) == (args.rubric is None):
        raise SandboxError("check: give the reference with --golden REF.png or a grading file with --rubric FILE "
                           "(one of the two)")
    if args.rubric is not None:
        if args.settings or args.tolerance or args.size or args.samples:
            raise SandboxError(f"--rubric {args.rubric}: each check's settings, size and tolerance are in the "
                               "grading file; drop --set, --size, --samples and --tolerance")
        rubric = load_rubric(args.rubric)
        args.entry = rubric.entry
        return list(rubric.checks), rubric.timeout, rubric.memory
    reference: Path = args.golden
    if reference.suffix.lower() != ".png":
        raise SandboxError(f"--golden {reference}: the reference must be a .png file")
    tolerances = parse_tolerances(args.tolerance)
    size = parse_size(args.size) if args.size else None
    with_samples(Scene("samples"), args.samples)  # a bad --samples is refused before any work
    return [Check(reference.stem, reference, tuple(args.settings), size, args.samples, tolerances)], None, None


def _shard_filter(text: str | None, one: bool) -> Callable[[str], bool]:
    """``--shard K/N``: which submissions this run grades (:mod:`glsandbox.grading.shards`)."""
    if text is None:
        return lambda name: True
    from glsandbox.grading.shards import in_shard, parse_shard

    if one:
        raise SandboxError("--shard shares a folder of students among machines; --one grades one student")
    shard = parse_shard(text)
    return lambda name: in_shard(name, shard)


def check_merge_parser() -> ArgumentParser:
    """The parser of ``glsandbox check merge``, a verb of its own (:func:`main` sends it here before the others)."""
    parser = ArgumentParser(prog="glsandbox check merge",
                            description="Merge the JSON reports of check DIR --shard K/N into the whole class's "
                                        "reports, as one run would have written them.",
                            epilog="examples:\n  glsandbox check merge shard-*.json --rubric shading.grading.toml "
                                   "--json class.json --csv class.csv\n  glsandbox check merge a.json b.json "
                                   "--golden expected.png --html class.html",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("reports", nargs="+", type=Path, metavar="REPORT.json", help="the shards' --json reports")
    parser.add_argument("--golden", type=Path, default=None, metavar="REF.png", help="the reference they were graded with")
    parser.add_argument("--rubric", type=Path, default=None, metavar="FILE.toml", help="or the grading file")
    from glsandbox.grading.reports import REPORTS

    for kind in REPORTS:
        parser.add_argument(f"--{kind.replace('_', '-')}", dest=kind, type=Path, default=None, metavar="FILE",
                            help=f"write the {kind.replace('_', ' ')} report")
    return parser


def cmd_check_merge(argv: list[str]) -> int:
    """``glsandbox check merge REPORTS...``: the shards' JSON reports as the whole class's reports."""
    from glsandbox.grading.reports import REPORTS

    args = check_merge_parser().parse_args(argv)

    def body() -> int:
        from glsandbox.grading.check import summary_table
        from glsandbox.grading.reports import write_reports
        from glsandbox.grading.rubric import Check, load_rubric
        from glsandbox.grading.shards import merge_reports

        if (args.golden is None) == (args.rubric is None):
            raise SandboxError("check merge: give the reference with --golden REF.png or the grading file with "
                               "--rubric FILE (the one the shards were graded with)")
        checks = list(load_rubric(args.rubric).checks) if args.rubric else [Check(args.golden.stem, args.golden)]
        reports = {kind: getattr(args, kind) for kind in REPORTS}
        for kind, path in reports.items():
            if path is not None and path.is_dir():
                raise SandboxError(f"--{kind} {path}: is a folder, expected a file name")
        results = merge_reports(args.reports, checks)
        print(summary_table(results))
        for path in write_reports(results, reports, str(args.rubric or args.golden)):
            print(f"wrote {path}")
        return 0 if all(r.status == "PASS" for r in results) else 1

    return run_guarded(body)


def cmd_check(args: argparse.Namespace) -> int:
    """``glsandbox check``: render, compare with reference PNGs by the golden rule; 0 all pass, 1 not."""
    if Path(args.lesson).is_dir() and not args.update:  # a class: its zygote starts while the rest gets ready
        from glsandbox.grading.runner import prestart  # (started already where glsandbox.launch ran first)

        prestart()
    from glsandbox.grading.check import Limits, check_folder, check_one, default_jobs, summary_table
    from glsandbox.grading.reports import REPORTS, write_reports

    checks, rubric_timeout, rubric_memory = _checks(args)
    timeout = args.timeout if args.timeout is not None else rubric_timeout or 30.0
    memory = args.memory if args.memory is not None else rubric_memory or 2048
    if not 0 < timeout <= 3600:
        raise SandboxError(f"--timeout {timeout:g}: expected seconds, more than 0 and at most 3600")
    if not 64 <= memory <= 1 << 20:
        raise SandboxError(f"--memory {memory}: expected MB, at least 64")
    jobs = args.jobs if args.jobs is not None else default_jobs()
    if not 1 <= jobs <= 256:
        raise SandboxError(f"--jobs {jobs}: expected 1 to 256 submissions at once")
    limits = Limits(float(timeout), int(memory), jobs)
    reports = {kind: getattr(args, kind) for kind in REPORTS}
    for kind, path in reports.items():
        if path is not None and path.is_dir():
            raise SandboxError(f"--{kind} {path}: is a folder, expected a file name")
    target = Path(args.lesson)
    exercises = [c for c in checks if c.kind == "exercise"]
    if exercises and len(exercises) == len(checks):
        from glsandbox.grading.exercise import check_command

        if args.shard is not None:
            raise SandboxError(f"--shard {args.shard}: shares pictures among machines; grade an exercise in one run")
        return check_command(target, checks, limits, reports, str(args.rubric or args.exercise),
                             getattr(args, "entry", None), args.one, args.update)
    if args.one and not target.is_dir():
        raise SandboxError(f"--one {target}: expected a student's folder (a lesson and its helper files)")
    if target.is_dir():
        if args.update:
            raise SandboxError(f"--update writes references from the model answer: give one lesson, not the folder {target}")

        from glsandbox.grading import portable
        from glsandbox.grading.layers import describe
        from glsandbox.grading.runner import portable_wanted

        ready()  # the bar's module, while the zygote starts
        # which layers confine a submission on this machine
        layers_line = portable.describe() if portable_wanted() else describe()
        bars = []  # the progress bar, made when the first submission reports (the total known then)

        def report(done: int, total: int, result) -> None:
            if exercises:  # a grading file of pictures and exercises: the functions graded as each arrives
                from glsandbox.grading.exercise import with_exercises

                with_exercises(result, target, checks, limits, getattr(args, "entry", None), args.one)
            if not bars:  # the first line of the output (none when the run stops with an error)
                say(layers_line, file=sys.stdout)
                bars.append(progress(total, "check", "submission"))
            # Lines on stdout above the bar on stderr (only a terminal gets the bar).
            say(f"[{done}/{total}] {result.line()}", file=sys.stdout)
            for outcome in result.outcomes:
                for kind, path in outcome.artifacts.items():
                    say(f"       {kind:<8}: {path}", file=sys.stdout)
            bars[0].update(1)

        try:
            keep = _shard_filter(args.shard, args.one)
            pictures = [c for c in checks if c.kind != "exercise"]
            results = check_folder(target, pictures, args.backend, limits, report, getattr(args, "entry", None),
                                   one=args.one, keep=keep, explain=args.explain)
        finally:
            for bar in bars:
                bar.close()
        print()
        print(summary_table(results))
        title = str(args.rubric or args.golden)
        for path in write_reports(results, reports, title):
            print(f"wrote {path}")
        return 0 if all(r.status == "PASS" for r in results) else 1
    if args.shard is not None:
        raise SandboxError(f"--shard {args.shard}: shares a folder of submissions among machines; give a folder")
    if any(path is not None for path in reports.values()):
        raise SandboxError(f"--{', --'.join(k.replace('_', '-') for k in REPORTS)} report a folder of submissions; give a folder")
    failed = False
    if exercises and not args.update:  # the model answer's functions, as a student's would be graded
        from glsandbox.grading.exercise import grade_file

        # the lesson's folder: its function is the file that defines it (the lesson itself, or beside it)
        for o in grade_file(exercises, target.parent, limits, target.name):
            print(f"{args.lesson}: {o.status} {o.check.name} ({o.points:g}/{o.check.points:g}): {o.detail()}")
            failed = failed or o.status != "PASS"
    for one in check_one(args.lesson, [c for c in checks if c.kind != "exercise"], args.update, args.backend, limits):
        reference = one.check.golden
        if one.status:
            print(f"{args.lesson}: {one.status}: {one.error}")
            failed = True
            continue
        margin_line = ""  # with --update: the margin written beside the reference
        if one.margin_share is not None:
            from glsandbox.measure.margin import margin_path

            margin_line = (f"wrote margin {margin_path(reference)} ({one.margin_share:.2%} of its pixels near a "
                           "decision may differ)")
        if one.updated == "written":
            print(f"wrote reference {reference}")
            print(margin_line)
            continue
        print(f"{args.lesson}: {one.match.summary()}")
        if one.updated == "rewritten":
            print(f"rewrote reference {reference}")
            print(margin_line)
            continue
        if one.updated == "unchanged":
            print(f"reference {reference} unchanged (it passes)")
            print(margin_line)
            continue
        for kind, path in one.artifacts.items():
            print(f"  {kind:<8}: {path}")
        failed = failed or not one.match.passed
    return 1 if failed else 0


def cmd_gradescope(args: argparse.Namespace) -> int:
    """``glsandbox gradescope``: the Gradescope autograder zip of a grading file (:mod:`glsandbox.grading.gradescope`)."""
    from glsandbox.grading.gradescope import build_bundle

    names = build_bundle(args.assignment, args.out, args.wheel)
    print(f"wrote {args.out}: {', '.join(names)}")
    print("next: upload it as the assignment's autograder (Gradescope: Configure Autograder, zip file)")
    return 0


def cmd_tradeoffs(args: argparse.Namespace) -> int:
    """``glsandbox tradeoffs``: accuracy knobs, timed and compared with a reference (:mod:`glsandbox.measure.tradeoffs`)."""
    from glsandbox.measure.tradeoffs import run

    run(args.out, quick=args.quick, backend=args.backend, runs=args.runs, only=args.knob, passes=args.passes)
    print(f"wrote {args.out / 'report.md'}, {args.out / 'tradeoffs.csv'}, {args.out / 'tradeoffs.png'}")
    return 0


def cmd_explain(args: argparse.Namespace) -> int:
    """``glsandbox explain LESSON --pixel X,Y``: one pixel's story, or its raw record (``--json``)."""
    from glsandbox.frame import LazyRenderer
    from glsandbox.story import parse_pixel, pixel_story

    lesson = _lesson(args)
    if args.exercise:
        return _explain_exercise(args, lesson)
    lazy = LazyRenderer(args.backend)  # opened only for a rasterised pixel
    try:
        story = pixel_story(lesson.scene(), _size(args), parse_pixel(args.pixel), lesson.name, lambda: lazy.renderer)
    finally:
        lazy.close()
    print(story.to_json() if args.json else story.text)
    return 0


def _explain_exercise(args: argparse.Namespace, lesson: Lesson) -> int:
    """``explain ... --exercise NAME FILE.py``: the student's function, run in its confined process,
    traced beside the reference; exit 0 when the traces agree, 1 when they part (like diff)."""
    from glsandbox.exercises.catalogue import get
    from glsandbox.exercises.check import static_check
    from glsandbox.exercises.isolation import Isolated
    from glsandbox.story import parse_pixel
    from glsandbox.story.divergence import explain_with_function, render_exercise_story, traced_kind

    name, file = args.exercise
    exercise = get(name)
    traced_kind(exercise)
    pixel, size = parse_pixel(args.pixel), _size(args)
    path = Path(file)
    static_check(path, exercise)
    with Isolated(path, exercise.function) as caller:
        story = explain_with_function(lesson.scene(), size, pixel, exercise, caller, lesson.name)
        if caller.load_error:  # it did not load (raised at import): bad input, not a trace
            raise SandboxError(f"{path}: {caller.load_error}")
    import json

    print(json.dumps(story.to_dict(), indent=1, ensure_ascii=False) if args.json else render_exercise_story(story))
    return 0 if story.agree else 1


def cmd_bench(args: argparse.Namespace) -> int:
    """``glsandbox bench``: every benchmark in benchmarks/, one table of side-by-side ratios."""
    from glsandbox.measure.bench import run_all

    return run_all(json_path=args.json, quick=args.quick, only=args.only)


#: The manual's site configuration in a checkout: beside the package, at the repository's top.
MKDOCS_CONFIG = Path(__file__).resolve().parent.parent / "mkdocs.yml"


def cmd_docs(args: argparse.Namespace) -> int:
    """``glsandbox docs``: serve the manual's site (MkDocs) locally, or with ``--build`` write it strictly."""
    import importlib.util
    import os
    import subprocess

    if not MKDOCS_CONFIG.is_file():
        raise SandboxError(f"glsandbox docs builds the manual from a checkout: {MKDOCS_CONFIG} not found "
                           "(an installed glsandbox has no docs/ folder)")
    if importlib.util.find_spec("mkdocs") is None:
        raise SandboxError("glsandbox docs needs the docs dependency group: uv sync, or uv run --group docs "
                           "glsandbox docs")
    if not 0 < args.port < 65536:
        raise SandboxError(f"--port {args.port}: expected a port number 1-65535")
    if args.build is not None and args.build.exists() and not args.build.is_dir():
        raise SandboxError(f"--build {args.build}: not a folder")
    command = [sys.executable, "-m", "mkdocs"]
    if args.build is not None:
        command += ["build", "--strict", "--config-file", str(MKDOCS_CONFIG), "--site-dir", str(args.build.resolve())]
    else:
        command += ["serve", "--config-file", str(MKDOCS_CONFIG), "--dev-addr", f"127.0.0.1:{args.port}"]
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # the theme's notice about its successor, on every build
    try:
        return subprocess.run(command, env=env, cwd=MKDOCS_CONFIG.parent).returncode
    except KeyboardInterrupt:  # Ctrl+C ends serve
        return 0


#: Each command: (what it does, in one line; examples). ``glsandbox COMMAND --help`` shows both.
COMMANDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "list": ("list the course's lessons in course order, with -v each one's parameters",
             ("glsandbox list", "glsandbox list -v")),
    "run": ("open a lesson in a window (ESC quits, F1 the panel, F12 a screenshot, R reloads)",
            ("glsandbox run phong", "glsandbox run phong --set shading=gouraud --samples 4",
             "glsandbox run my_lesson.py")),
    "render": ("render a lesson headless to a PNG file",
               ("glsandbox render indexed_cube --out cube.png", "glsandbox render mirror --xray mirror_passes",
                "glsandbox render phong --set time=1.5 --size 800x600 --out phong.png")),
    "plan": ("print the passes, buffers and shader variants a lesson's frame needs",
             ("glsandbox plan mirror", "glsandbox plan scene.toml")),
    "explain": ("tell one pixel's story: the ray, each shape's test and t, the nearest hit, the shadow rays, "
                "Phong's terms, the reflections and the 8-bit colour",
                ("glsandbox explain ray_spheres --pixel 320,240",
                 "glsandbox explain ray_phong --set scene=exam2013 --pixel 300,200 --size 640x480",
                 "glsandbox explain mirror --set renderer=ray_numpy --pixel 100,100 --json",
                 "glsandbox explain ray_spheres --pixel 320,240 --exercise ray_sphere my_sphere.py")),
    "tour": ("render every lesson headless into a folder, with a gallery page (index.html) and tour.json",
             ("glsandbox tour", "glsandbox tour --out gallery --size 320x240",
              "glsandbox tour --lessons submissions/ --out checked")),
    "compare": ("render one lesson with several parameter values side by side, and say which pictures differ",
                ("glsandbox compare phong --vary shading=phong,gouraud,blinn_phong",
                 "glsandbox compare phong --vary shading=phong,gouraud --vary normals=correct,naive")),
    "new": ("write a small commented starting lesson NAME.py, scene file NAME.toml and shader NAME.glsl "
            "(or, with --assignment, a model answer and a grading file)",
            ("glsandbox new my_lesson", "glsandbox new my_lesson --dir lessons_of_mine",
             "glsandbox new --assignment shading")),
    "check": ("render a lesson (or each one in a folder) and compare it with a reference PNG or a grading "
              "file's checks: exit 0 match, 1 differs",
              ("glsandbox check my_lesson.py --golden expected.png",
               "glsandbox check submissions/ --golden expected.png --csv marks.csv",
               "glsandbox check submissions/ --rubric shading.grading.toml --html marks.html",
               "glsandbox check --one submission/ --rubric shading.grading.toml --student-report mine.html",
               "glsandbox check phong --golden phong.png --update")),
    "gradescope": ("build a Gradescope autograder zip from a grading file: setup.sh, run_autograder, the "
                   "checks, their goldens (hidden ones too) and this glsandbox as a wheel",
                   ("glsandbox gradescope shading.grading.toml --out autograder.zip",
                    "glsandbox gradescope shading.grading.toml --out autograder.zip --wheel dist/glsandbox-0.1.0-py3-none-any.whl")),
    "tradeoffs": ("time each accuracy knob and compare it with a reference (FLIP, RMSE): report.md, CSV and plot",
                  ("glsandbox tradeoffs --quick", "glsandbox tradeoffs --knob antialiasing --out out/aa")),
    "exercise": ("write the course's functions yourself: list the exercises, start one, check your file "
                 "(cases, hints, probe pictures; exit 0 when every visible case passes)",
                 ("glsandbox exercise list", "glsandbox exercise start ray_sphere --out my_sphere.py",
                  "glsandbox exercise check ray_sphere my_sphere.py",
                  "glsandbox exercise check ray_sphere my_sphere.py --html report.html")),
    "bench": ("run every benchmark in benchmarks/ and print one table of side-by-side ratios",
              ("glsandbox bench --quick", "glsandbox bench --only clear_and_swap --json bench.json")),
    "docs": ("serve the manual's site locally (MkDocs), or build it into a folder",
             ("glsandbox docs", "glsandbox docs --port 8001", "glsandbox docs --build site")),
}


def add_command(sub: argparse._SubParsersAction, name: str) -> argparse.ArgumentParser:
    """A subcommand whose ``--help`` starts with what it does and ends with examples."""
    summary, examples = COMMANDS[name]
    epilog = "examples:\n" + "\n".join(f"  {example}" for example in examples)
    return sub.add_parser(name, help=summary, description=summary[:1].upper() + summary[1:] + ".", epilog=epilog,
                          formatter_class=argparse.RawDescriptionHelpFormatter)


def _check_options(p: argparse.ArgumentParser) -> None:
    """``glsandbox check``'s options: one lesson, a folder of submissions, or one student's folder."""
    p.add_argument("lesson", metavar="LESSON_OR_DIR",
                   help="a lesson name, .py or .toml file, or a folder of them (one line each, and a table)")
    p.add_argument("--golden", type=Path, default=None, metavar="REF.png", help="the reference image")
    p.add_argument("--rubric", type=Path, default=None, metavar="FILE.toml",
                   help="a grading file: several checks, each with its golden, settings and points")
    p.add_argument("--exercise", default=None, metavar="NAME",
                   help="grade students' functions on an exercise (glsandbox exercise list): every case "
                        "group, one point each, hidden groups included")
    p.add_argument("--update", action="store_true",
                   help="write the references when missing or different (a passing one is kept)")
    p.add_argument("--tolerance", action="append", default=[], metavar="KEY=VALUE",
                   help="threshold=LEVELS (default 2) or max_bad_share=FRACTION (default 0.0005); repeatable")
    p.add_argument("--explain", action="store_true",
                   help="tell each failed picture's first differing pixel (glsandbox explain, in the submission's "
                        "confined renderer) in the HTML reports")
    p.add_argument("--one", action="store_true",
                   help="LESSON_OR_DIR is one student's folder (its lesson and helper files; Gradescope's "
                        "/autograder/submission), not a folder of students")
    p.add_argument("--shard", default=None, metavar="K/N",
                   help="grade only share K of N (by a stable hash of each submission's name; the same on every "
                        "machine); merge the shards' --json with: glsandbox check merge REPORTS...")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="submissions graded at once (default: the CPUs this process may use, by its "
                        "cgroup's quota and affinity)")
    p.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                   help="time for each picture of a submission (default 30)")
    p.add_argument("--memory", type=int, default=None, metavar="MB",
                   help="memory (address space) of each submission (default 2048)")
    for kind, text in (("csv", "the figures as CSV"), ("json", "the figures as JSON"),
                       ("html", "a page: a row per student with reference | submission | difference"),
                       ("junit", "JUnit XML (what CI systems read)"),
                       ("gradescope", "Gradescope's results.json"),
                       ("student_report", "the student's page: no hidden check's reference, difference or "
                                          "figures")):
        p.add_argument(f"--{kind.replace('_', '-')}", dest=kind, type=Path, default=None, metavar="FILE",
                       help=f"folder mode: {text}")
    add_render_options(p, size_default="the reference's size")
    p.set_defaults(func=cmd_check)


def add_explain_options(p: argparse.ArgumentParser) -> None:
    """``glsandbox explain``'s arguments."""
    p.add_argument("lesson", metavar="LESSON", help="a lesson name, a lesson .py file or a scene .toml file")
    p.add_argument("--pixel", required=True, metavar="X,Y", help="the pixel, x from the left, y from the top")
    p.add_argument("--size", default=None, help=f"frame size WxH (default {DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]})")
    p.add_argument("--set", dest="settings", action="append", default=[], metavar="KEY=VALUE",
                   help="a lesson parameter (repeatable); every lesson has time=SECONDS")
    p.add_argument("--json", action="store_true", help="print the raw record as JSON instead of the story")
    p.add_argument("--exercise", nargs=2, default=None, metavar=("NAME", "FILE.py"),
                   help="trace the pixel with your function of the exercise NAME (run confined) beside the "
                        "reference; exit 1 when the traces part")
    p.add_argument("--backend", default=None, help=f"a rasterised pixel: one of {', '.join(BACKENDS)} "
                   "(default: GLSANDBOX_BACKEND or auto)")
    p.set_defaults(func=cmd_explain)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser: every subcommand, or with ``command`` only that one (what a
    command line naming it parses: the others cost argparse about 1.5 ms of a cold start; the
    one built is the same)."""
    from glsandbox.version import __version__

    def wanted(name: str) -> bool:
        return command is None or name == command

    parser = ArgumentParser(prog="glsandbox", description="A graphics course as runnable ModernGL lessons.",
                            epilog="glsandbox COMMAND --help says what a command does, with examples.")
    parser.add_argument("--version", action="version", version=f"glsandbox {__version__}",
                        help="print glsandbox's version and exit")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    if wanted("list"):
        p = add_command(sub, "list")
        p.add_argument("-v", "--verbose", action="store_true", help="also list each lesson's parameters")
        p.set_defaults(func=cmd_list)

    for name, func in (("run", cmd_run), ("render", cmd_render), ("plan", cmd_plan)):
        if not wanted(name):
            continue
        p = add_command(sub, name)
        p.add_argument("lesson", metavar="LESSON", help="a lesson name, a lesson .py file or a scene .toml file")
        add_render_options(p)
        if name == "render":
            p.add_argument("--out", type=Path, default=None, help="the PNG file to write")
            p.add_argument("--xray", type=Path, default=None, metavar="DIR",
                           help="also (or instead) write each pass's colour, depth and stencil, and a contact sheet")
        p.set_defaults(func=func)

    if wanted("explain"):
        add_explain_options(add_command(sub, "explain"))

    if wanted("tour"):
        p = add_command(sub, "tour")
        add_render_options(p, settings=False)  # --set is per lesson: tour refuses it
        p.add_argument("--lessons", type=Path, default=None, metavar="DIR",
                       help="the lesson files (.py, .toml) in DIR instead of the course's lessons, each rendered "
                            "isolated as check grades it")
        p.add_argument("--timeout", type=float, default=30.0, metavar="SECONDS",
                       help="with --lessons: the time each lesson may take (default 30)")
        p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
        p.set_defaults(func=cmd_tour, settings=[])

    if wanted("compare"):
        p = add_command(sub, "compare")
        p.add_argument("lesson", metavar="LESSON", help="a lesson name, a lesson .py file or a scene .toml file")
        p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                       help="a parameter and its values, one tile each (twice: a grid)")
        add_render_options(p)
        p.add_argument("--out", type=Path, default=None, help="the PNG to write (default compare_LESSON.png; "
                       "for a lesson file, compare_NAME_py.png or compare_NAME_toml.png)")
        p.set_defaults(func=cmd_compare)

    if wanted("new"):
        p = add_command(sub, "new")
        p.add_argument("name", metavar="NAME", nargs="?", default=None,
                       help="the lesson's name, a Python identifier (e.g. my_lesson)")
        p.add_argument("--assignment", metavar="NAME", default=None,
                       help="instead: a model answer NAME.py and a starting grading file NAME.grading.toml")
        p.add_argument("--dir", type=Path, default=Path("."), help="the folder to write into (default: here)")
        p.set_defaults(func=cmd_new)

    if wanted("check"):
        _check_options(add_command(sub, "check"))

    if wanted("gradescope"):
        p = add_command(sub, "gradescope")
        p.add_argument("assignment", type=Path, metavar="ASSIGNMENT",
                       help="a grading file NAME.grading.toml (glsandbox new --assignment NAME writes one)")
        p.add_argument("--out", type=Path, default=Path("autograder.zip"), help="the zip to write (default autograder.zip)")
        p.add_argument("--wheel", type=Path, default=None, metavar="FILE",
                       help="this glsandbox's wheel (default: built from the checkout, or packed from the installed one)")
        p.set_defaults(func=cmd_gradescope)

    if wanted("tradeoffs"):
        p = add_command(sub, "tradeoffs")
        p.add_argument("--out", type=Path, default=Path("out/tradeoffs"), help="output folder (default out/tradeoffs)")
        p.add_argument("--quick", action="store_true", help="a reduced set at a small size (for CI)")
        p.add_argument("--runs", type=int, default=5, help="timed rounds per pass (at least 5, default 5)")
        p.add_argument("--passes", type=int, default=4,  # tradeoffs.PASSES (the measuring wing loads late)
                       help="independent passes of the rounds, each in a process of its own, whose medians give "
                            "each time's spread (at least 2, default 4)")
        p.add_argument("--knob", action="append", default=[], metavar="NAME", help="only this knob (repeatable)")
        p.add_argument("--backend", default=None, help="GL backend (default: GLSANDBOX_BACKEND or auto)")
        p.set_defaults(func=cmd_tradeoffs)

    if wanted("exercise"):
        from glsandbox.exercises.commands import add_arguments, cmd_exercise

        p = add_command(sub, "exercise")
        add_arguments(p)
        p.set_defaults(func=cmd_exercise)

    if wanted("bench"):
        p = add_command(sub, "bench")
        p.add_argument("--json", type=Path, default=None, metavar="FILE", help="also write the figures as JSON")
        p.add_argument("--quick", action="store_true", help="fewer frames and rounds (a smoke run)")
        p.add_argument("--only", action="append", default=[], metavar="NAME",
                       help="only benchmarks whose name contains NAME (repeatable)")
        p.set_defaults(func=cmd_bench)

    if wanted("docs"):
        p = add_command(sub, "docs")
        p.add_argument("--build", type=Path, default=None, metavar="DIR",
                       help="write the site into DIR (strict: a broken link fails) instead of serving it")
        p.add_argument("--port", type=int, default=8000, help="the local port to serve on (default 8000)")
        p.set_defaults(func=cmd_docs)
    return parser


def main(argv: list[str] | None = None) -> int:
    from glsandbox import supervise

    words = sys.argv[1:] if argv is None else argv
    if words[:2] == ["check", "merge"]:  # a verb of its own: the shards' reports, not a lesson named merge
        return cmd_check_merge(words[2:])
    if argv is None and supervise.CHILD_ENV not in os.environ:
        source = supervise.user_code_in(words)
        if source is not None:  # a lesson file of the user's: run in a child that cannot end us quietly
            return supervise.supervised(words, source)
    named = words[0] if words and words[0] in COMMANDS else None  # else: the whole parser (--help, a mistake)
    args = build_parser(named).parse_args(argv)
    if argv is None:  # the process's own command line: Ctrl-C ends it within a bound, stuck or not
        watch_interrupts()
    status = run_guarded(lambda: args.func(args))
    supervise.finished()
    if status == EXIT_INTERRUPTED and argv is None:  # the process's own command line: end it now
        end_interrupted()
    return status


def end_interrupted() -> NoReturn:
    """End the process after Ctrl-C, exit 130, once the command has unwound (its ``finally``
    blocks and ``with`` exits ran: atomic writes removed their temporary files, contexts were
    released).

    Python's own exit would go on to tear the interpreter down: free every module and
    object (GL objects after their context), then run the C libraries' exit handlers (Mesa's,
    which join the driver's threads). The interrupt can have left any of them half-way (a
    module whose import it cut short, a GL object between two calls, a helper thread still
    running), and an abort there (SIGABRT: exit -6 where 130 was due) is what an interrupted
    ``bench`` sometimes ended with. So only the Python exit handlers run (``atexit``:
    temporary folders, thread pools) and the process ends there; a second Ctrl-C (the
    process group's) is ignored meanwhile."""
    import atexit
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        atexit._run_exitfuncs()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(EXIT_INTERRUPTED)


def lesson_main(lesson_cls: type[Lesson], argv: list[str] | None = None) -> int:
    """Entry point of a lesson module: a window, or ``--headless --out FILE.png``."""
    prog = f"python -m glsandbox.lessons.{lesson_cls.name}"
    parser = ArgumentParser(prog=prog, description=f"{lesson_cls.title} ({lesson_cls.course_section}): "
                            "opens it in a window, or renders it headless to a PNG.",
                            epilog=f"examples:\n  {prog}\n  {prog} --headless --out {lesson_cls.name}.png",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    add_render_options(parser)
    parser.add_argument("--headless", action="store_true", help="render offscreen instead of opening a window")
    parser.add_argument("--out", type=Path, default=None, help="with --headless: the PNG to write")
    args = parser.parse_args(argv)

    def body() -> int:
        lesson = lesson_cls.from_settings(args.settings)
        size = parse_size(args.size) if args.size else DEFAULT_SIZE
        if args.headless:
            out = args.out or Path(f"{lesson_cls.name}.png")
            frame = render_to_file(lesson, out, size, args.samples, args.backend)
            print(f"wrote {out} ({size[0]}x{size[1]}, {frame.seconds * 1000:.1f} ms)")
        else:
            from glsandbox.app.window import run_window

            run_window(lesson, size, args.samples, args.backend,
                       instead=f"or render it headless: {prog} --headless --out FILE.png")
        return 0

    return run_guarded(body)


if __name__ == "__main__":
    sys.exit(main())
