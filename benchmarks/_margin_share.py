"""The share of each lesson's pixels inside its reference's margin (:mod:`glsandbox.measure.margin`).

``uv run python benchmarks/_margin_share.py [WIDTHxHEIGHT]`` (default 320x240) prints one row per
built-in lesson at its defaults: the share of pixels a machine may draw differently (those a nudge
of an eighth of a pixel or a 0.1 % near plane changes by more than the threshold), and the median
and largest allowance among them. Not a timing: ``glsandbox bench`` skips it (no ``cases``).
"""

from __future__ import annotations

import sys

from glsandbox.frame import HeadlessRenderer
from glsandbox.lesson import all_lessons
from glsandbox.measure.margin import share_rows


def main(argv: list[str]) -> None:
    size = tuple(int(v) for v in (argv[0] if argv else "320x240").split("x"))
    with HeadlessRenderer() as renderer:
        rows = share_rows(renderer, all_lessons(), size)
    print(f"{'lesson':<20} {'inside %':>8} {'median':>6} {'max':>4}   ({size[0]}x{size[1]}, threshold 2)")
    for name, share, median, largest in rows:
        print(f"{name:<20} {share * 100:>8.2f} {median:>6} {largest:>4}")


if __name__ == "__main__":
    main(sys.argv[1:])
