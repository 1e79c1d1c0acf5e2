"""Benchmark: the mirror lesson's frame time with each effect off and on.

Run: ``uv run python benchmarks/mirror_effects.py [--size 800x600] [--frames 20] [--rounds 5]``

Configurations of ``lessons/mirror.py`` (course section "The stencil Test"):
no effect (the room only: no stencil buffer, two passes), the stencil mirror
alone, the mirror without stencil, the stencil shadow alone, the shadow
without stencil (double blend), both effects, and both with standard depth
instead of reverse-Z. Each round renders every configuration for
``--frames`` frames (moving the cube, reading the pixels back), in turn, on
one context, so machine noise hits all alike; the figure is the median over
rounds of the per-frame time, and its ratio to the no-effect frame.
No assertion: the numbers are for reading; speed goals are never asserted
(docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from glsandbox.cli import parse_size
from glsandbox.frame import HeadlessRenderer  # noqa: E402
from glsandbox.plan import plan  # noqa: E402
from glsandbox.lessons.mirror import MirrorLesson  # noqa: E402

CONFIGS: dict[str, dict[str, object]] = {
    "no effect": dict(mirror="off", shadow="off"),
    "mirror (stencil)": dict(mirror="stencil", shadow="off"),
    "mirror (no stencil)": dict(mirror="no_stencil", shadow="off"),
    "shadow (stencil)": dict(mirror="off", shadow="on"),
    "shadow (double blend)": dict(mirror="off", shadow="double_blend"),
    "mirror + shadow": dict(mirror="stencil", shadow="on"),
    "mirror + shadow, standard depth": dict(mirror="stencil", shadow="on", depth="standard"),
}


def cases(env) -> list:
    """For ``glsandbox bench`` (when present): each effect configuration timed
    against the room with no effect, in its alternating rounds."""
    from glsandbox.measure.bench import Case, Side

    renderer, size = env.renderer, env.size

    def side(label: str, settings: dict[str, object]) -> Side:
        return Side(label, lambda k: renderer.render(MirrorLesson(time=0.05 * k, **settings), size).image)

    base = side("no effect", CONFIGS["no effect"])
    return [Case("mirror lesson: effect off vs on", name, base, side(name, settings), repeat=10)
            for name, settings in CONFIGS.items() if name != "no effect"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="800x600")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    size = parse_size(args.size)
    times: dict[str, list[float]] = {name: [] for name in CONFIGS}
    with HeadlessRenderer() as renderer:
        for settings in CONFIGS.values():  # warm up: compile programs, allocate targets
            renderer.render(MirrorLesson(**settings), size)
        for _ in range(args.rounds):
            for name, settings in CONFIGS.items():
                start = time.perf_counter()
                for k in range(args.frames):
                    renderer.render(MirrorLesson(time=0.05 * k, **settings), size)
                times[name].append((time.perf_counter() - start) / args.frames)
        print(f"mirror lesson, {size[0]}x{size[1]}, {args.frames} frames x {args.rounds} rounds "
              f"({renderer.host.renderer})")
    base = statistics.median(times["no effect"])
    print(f"{'configuration':34} {'passes':>6} {'buffers':46} {'ms/frame':>9} {'vs none':>8}")
    for name, settings in CONFIGS.items():
        frame_plan = plan(MirrorLesson(**settings).scene())
        median = statistics.median(times[name])
        print(f"{name:34} {len(frame_plan.passes):>6} {frame_plan.buffers.describe():46} "
              f"{median * 1000:>9.2f} {median / base:>7.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
