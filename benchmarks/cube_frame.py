"""Benchmark: the indexed cube at 800x600, raw ModernGL versus glsandbox.

Run: ``uv run python benchmarks/cube_frame.py [--frames N] [--rounds R]``;
``glsandbox bench`` runs the same case (:func:`cases`) with every other benchmark.

Both sides draw the same frame (clear, the course cube with its vertex
colours, depth test and back-face culling, the course camera, a rotation that
changes every frame) into an 800x600 offscreen framebuffer and read the pixels
back. The two are measured in alternating rounds in one process, on one
context, so machine noise hits both alike; the figure is the ratio of medians.
Goals: glsandbox <= 1.05x raw, and at most 50 us of extra main-thread
CPU per frame (the bench's "extra CPU" column). Cold start is process start to the
first PNG written, for ``glsandbox render`` and for this script's raw path.
"""

from __future__ import annotations

import argparse
import statistics
from dataclasses import replace
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import moderngl
import numpy as np

from _raw import (VERTEX_COLOR_FS, VERTEX_COLOR_VS, clear, eye_relative, framebuffer, from_eye, gl, look_at, perspective,
                  read, rotate_y)

SIZE = (800, 600)


class RawCube:
    """A hand-written ModernGL frame with no glsandbox code at all.

    Lean, as a careful hand-written program: the shaders, buffers, view and projection are made
    and written once at set-up; per frame the spinning model matrix only. Camera-relative as
    glsandbox draws (``_raw.eye_relative``): the view without its translation, the model
    ``T(-eye) @ R`` formed in float64, so both round the same numbers to float32 (identical pixels).
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int] = SIZE) -> None:
        self.ctx, self.size = ctx, size
        # The course cube already converted to OpenGL (z mirrored, two indices swapped).
        positions = np.array([(-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1),
                              (-1, -1, 1), (1, -1, 1), (1, -1, -1), (-1, -1, -1)], dtype="f4")
        colors = np.array([(0, 0, 1), (0, 1, 0), (0, 1, 1), (1, 0, 0), (1, 0, 1), (1, 1, 0), (1, 1, 1), (0, 0, 0)],
                          dtype="f4")
        indices = np.array([3, 1, 0, 2, 1, 3, 0, 5, 4, 1, 5, 0, 3, 4, 7, 0, 4, 3, 1, 6, 5, 2, 6, 1, 2, 7, 6, 3, 7, 2,
                            6, 4, 5, 7, 4, 6], dtype="u4").reshape(-1, 3)[:, [0, 2, 1]].copy()
        self.program = ctx.program(vertex_shader=VERTEX_COLOR_VS, fragment_shader=VERTEX_COLOR_FS)
        self.vao = ctx.vertex_array(self.program, [(ctx.buffer(positions.tobytes()), "3f", "in_position"),
                                                   (ctx.buffer(colors.tobytes()), "3f", "in_color")],
                                    index_buffer=ctx.buffer(indices.tobytes()))
        self.fbo = framebuffer(ctx, size)  # as glsandbox's frames
        self.eye = (0.0, 3.0, 10.0)
        self.program["m_view"].write(gl(eye_relative(look_at(self.eye, (0.0, 0.0, 0.0)), self.eye)))
        self.program["m_proj"].write(gl(perspective(45.0, size[0] / size[1], 0.01, 100.0)))
        self.model = self.program["m_model"]

    def frame(self, t: float) -> np.ndarray:
        """The frame at time ``t`` as (H, W, 4) uint8, top row first."""
        self.fbo.use()
        clear(self.fbo, 0.0, 0.125, 0.6, depth=1.0)
        self.ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        self.model.write(gl(from_eye(rotate_y(-t), self.eye)))
        self.vao.render(moderngl.TRIANGLES)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(self.fbo, self.size)


def cold_start(command: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - t0


def cases(env) -> list:
    """The bench case: raw ModernGL vs glsandbox on the indexed cube (one context, alternating rounds)."""
    from glsandbox.lesson import find_lesson
    from glsandbox.measure.bench import LESSON_FRAME_CPU_GOAL_US, LESSON_FRAME_GOAL, Case, Side, same_pixels

    renderer = env.renderer
    raw = RawCube(renderer.host.ctx)
    lesson = find_lesson("indexed_cube")()

    def ours(k: int) -> np.ndarray:
        return renderer.render(lesson.at(0.3 + 0.01 * k), SIZE).image

    def theirs(k: int) -> np.ndarray:
        return raw.frame(0.3 + 0.01 * k)

    return [Case("frame vs raw ModernGL", "indexed_cube", Side("raw ModernGL", theirs), Side("glsandbox", ours),
                 repeat=100, goal=LESSON_FRAME_GOAL,
                 cpu_goal_us=LESSON_FRAME_CPU_GOAL_US, compare=same_pixels)]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100, help="frames per round (default 100)")
    parser.add_argument("--rounds", type=int, default=7, help="alternating rounds (default 7)")
    parser.add_argument("--raw-once", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()

    if args.raw_once:  # the raw path's cold start: context, resources, one frame, one PNG
        from PIL import Image

        ctx = moderngl.create_standalone_context(backend="egl")
        pixels = RawCube(ctx).frame(0.0)
        Image.fromarray(pixels).save(args.raw_once)
        return 0

    from glsandbox.measure.bench import LESSON_FRAME_CPU_GOAL_US, LESSON_FRAME_GOAL, BenchEnv, measure

    env = BenchEnv()
    (case,) = cases(env)
    case = replace(case, repeat=args.frames)
    (result,) = measure([case], args.rounds)
    raw_times, our_times = result.baseline_s, result.subject_s
    raw_ms, our_ms = statistics.median(raw_times) * 1e3, statistics.median(our_times) * 1e3
    same = result.same == "identical"
    env.close()

    with tempfile.TemporaryDirectory() as tmp:
        ours_cold = statistics.median(cold_start([sys.executable, "-m", "glsandbox.cli", "render", "indexed_cube",
                                                  "--size", "800x600", "--out", f"{tmp}/a.png"]) for _ in range(3))
        raw_cold = statistics.median(cold_start([sys.executable, __file__, "--raw-once", f"{tmp}/b.png"])
                                     for _ in range(3))

    print(f"indexed cube, {SIZE[0]}x{SIZE[1]}, {args.rounds} alternating rounds of {args.frames} frames"
          f" (identical pixels: {'yes' if same else 'NO'})")
    print(f"{'':<22}{'raw ModernGL':>14}{'glsandbox':>12}{'ratio':>8}")
    print(f"{'frame (median, ms)':<22}{raw_ms:>14.3f}{our_ms:>12.3f}{our_ms / raw_ms:>7.2f}x")
    print(f"{'  spread (min-max)':<22}{min(raw_times) * 1e3:>6.3f}-{max(raw_times) * 1e3:<7.3f}"
          f"{min(our_times) * 1e3:>5.3f}-{max(our_times) * 1e3:<6.3f}")
    print(f"{'cold start (s)':<22}{raw_cold:>14.3f}{ours_cold:>12.3f}{ours_cold / raw_cold:>7.2f}x")
    print(f"{'extra CPU (us/frame)':<22}{result.extra_cpu_us:>26.0f}")
    goal, cpu_goal = LESSON_FRAME_GOAL, LESSON_FRAME_CPU_GOAL_US
    print(f"goal: frame ratio <= {goal:.2f}x:", "met" if our_ms / raw_ms <= goal else "NOT met")
    print(f"goal: extra CPU <= {cpu_goal:g} us:", "met" if result.extra_cpu_us <= cpu_goal else "NOT met")
    return 0


if __name__ == "__main__":
    sys.exit(main())
