"""Benchmark: ``glsandbox explain`` of one pixel, every lesson, against the goal of under 1 s.

Each lesson's scene (the ray lessons as they are, the others with
``renderer=ray_numpy``, and the others as they are: their pixel told pass by pass,
the frame drawn again with its X-ray) is built once; each repetition explains its centre pixel at
800x600 on a fresh copy of that Scene, so the World (and its BVHs) and the primary
rays are made again every time, as a new ``glsandbox explain`` process makes them
(the lesson's own build and the interpreter's start are not in it: a lesson such as
``ray_acceleration`` spends its time building its figures, which ``render`` pays too).
No baseline: the goal is absolute, printed under the table.

The X-ray rows (``glsandbox render LESSON --xray``'s work, the pictures' files left
out) draw a raster lesson's frame reading the target back after every pass, against
the same frame drawn and read back once: goal at most 3x.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

GROUP = "explain"
#: The goal: one pixel's story in under this many seconds, every lesson.
GOAL_S = 1.0
#: ``--quick``: these lessons only.
QUICK = ("ray_spheres", "ray_phong", "mirror")
#: The X-ray's goal: at most this ratio of the plain frame's time.
XRAY_GOAL = 3.0
#: The lessons whose frame is X-rayed (``--quick``: the first).
XRAY_LESSONS = ("mirror", "phong", "shadow_map")


def cases(env) -> list:
    from glsandbox.lesson import all_lessons
    from glsandbox.measure.bench import Case, Side
    from glsandbox.story.raster import explain_raster_pixel
    from glsandbox.story.ray_pixel import explain_ray_pixel

    out = []
    size = env.size
    for cls in all_lessons():
        if env.quick and cls.name not in QUICK:
            continue
        settings = [] if cls.defaults.get("renderer", "raster") != "raster" else ["renderer=ray_numpy"]
        scene = cls.from_settings(settings).scene()
        pixel = (size[0] // 2, size[1] // 2)

        def run(k: int, scene=scene, pixel=pixel) -> list[int]:
            return explain_ray_pixel(replace(scene), size, pixel).rgba8

        out.append(Case(GROUP, f"one pixel, {cls.name}", None, Side("explain", run), repeat=1, unit="ms",
                        note=f"goal < {GOAL_S:g} s"))
        if settings:  # a raster lesson: its pixel pass by pass too (the X-ray of its frame)
            raster = cls().scene()

            def run_raster(k: int, scene=raster, pixel=pixel) -> list[int]:
                return explain_raster_pixel(env.renderer, replace(scene), size, pixel).rgba8

            out.append(Case(GROUP, f"one pixel, {cls.name} (rasterised)", None, Side("explain", run_raster), repeat=1,
                            unit="ms", note=f"goal < {GOAL_S:g} s"))
    out.extend(exercise_cases(env))
    out.extend(xray_cases(env))
    return out


def exercise_cases(env) -> list:
    """``explain --exercise``: a pixel traced twice (the reference's and a function's, here the notes'
    geometric test in this process: the confined process's start is the grader's, not the trace's)."""
    from glsandbox.exercises.catalogue import get
    from glsandbox.lesson import find_lesson
    from glsandbox.measure.bench import Case, Side
    from glsandbox.story.divergence import Direct, explain_with_function

    out = []
    for name, lesson, variant in (("ray_sphere", "ray_spheres", "geometric"),
                                  ("ray_triangle", "indexed_cube", "moller_trumbore")):
        exercise = get(name)
        scene = find_lesson(lesson)().scene()
        caller = Direct(exercise.extra["variants"][variant])
        pixel = (env.size[0] // 2, env.size[1] // 2)

        def run(k: int, scene=scene, exercise=exercise, caller=caller, pixel=pixel) -> list[int]:
            return explain_with_function(replace(scene), env.size, pixel, exercise, caller).rgba8

        out.append(Case(GROUP, f"one pixel, {lesson} --exercise {name}", None, Side("explain", run), repeat=1,
                        unit="ms", note=f"goal < {GOAL_S:g} s"))
    return out


def xray_cases(env) -> list:
    from glsandbox.lesson import find_lesson
    from glsandbox.measure.bench import Case, Side
    from glsandbox.story.xray import xray

    out = []
    for name in XRAY_LESSONS[:1] if env.quick else XRAY_LESSONS:
        scene = find_lesson(name)().scene()

        def frame(k: int, scene=scene):
            return env.renderer.render_scene(scene, env.size).image.copy()

        def rayed(k: int, scene=scene):
            return xray(env.renderer, scene, env.size).frame

        out.append(Case(GROUP, f"X-ray, {name}", Side("frame", frame), Side("frame + X-ray", rayed), repeat=3,
                        goal=XRAY_GOAL, compare=lambda a, b: "yes" if (a == b).all() else "NO"))
    return out


def summarize(results: Sequence[Any]) -> list[str]:
    """The slowest lesson's explain against the goal."""
    times = {r.case.name.split(", ", 1)[1]: statistics.median(r.subject_s) for r in results
             if r.case.group == GROUP and r.subject_s and r.case.name.startswith("one pixel")}
    if not times:
        return []
    slowest = max(times, key=times.__getitem__)
    verdict = "met" if times[slowest] < GOAL_S else "NOT met"
    return [f"{GROUP}: one pixel's story, slowest lesson {slowest} {times[slowest] * 1000:.0f} ms "
            f"(goal: under {GOAL_S:g} s every lesson: {verdict})"]
