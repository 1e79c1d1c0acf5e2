"""Benchmark: effects on demand vs every effect forced on, for every lesson.

The baseline is the lesson's own plan (only the buffers, passes and tests its
scene needs); the subject is the same scene with ``--set effects=all``
(depth and stencil allocated and cleared in every viewport, the depth test
in every draw pass). Both draw the same picture (the table checks it); the
ratio is what the everything-on renderer costs: what planning saves.
"""

from __future__ import annotations


def cases(env) -> list:
    from glsandbox.lesson import all_lessons
    from glsandbox.measure.bench import Case, Side, same_pixels

    renderer, size = env.renderer, env.size
    found = []
    for cls in all_lessons():
        needed, forced = cls(), cls(effects="all")

        def side(lesson):
            return lambda k: renderer.render(lesson.at(0.01 * k), size).image

        found.append(Case("on-demand vs effects=all", cls.name, Side("on-demand plan", side(needed)),
                          Side("effects=all", side(forced)), repeat=30, compare=same_pixels))
    return found
