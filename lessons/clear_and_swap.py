"""Lesson 1: clear and swap, and the split screen.

Course section "DirectX 11: device, context, swap chain, back/front buffer"
and "Viewport (two-player split screen)". Every frame starts by clearing the
back buffer to the course's colour (0, 0.125, 0.6) and ends with a swap that
shows it. A viewport is a rectangle of the frame that the clear and every
draw are restricted to; two of them side by side are the course's
two-player split screen.
"""

from __future__ import annotations

import sys

import glsandbox
from glsandbox import COURSE_BLUE, Lesson, Motion, Param, Scene, Viewport, register


#: Player two's colour: the course's blue with red and blue swapped.
PLAYER_TWO = (0.6, 0.125, 0.0, 1.0)


@register
class ClearAndSwap(Lesson):
    name = "clear_and_swap"
    title = "Clear and swap, two viewports"
    course_section = "DirectX 11: device, context, swap chain; Viewport"
    order = 10
    params = (Param("split", True, "two viewports side by side (the split screen), or one"),)

    def build(self) -> Scene:
        if not self.values["split"]:
            return Scene(self.name, clear_color=COURSE_BLUE)
        left = Viewport(rect=(0.0, 0.0, 0.5, 1.0), clear_color=COURSE_BLUE, label="player 1")
        right = Viewport(rect=(0.5, 0.0, 0.5, 1.0), clear_color=PLAYER_TWO, label="player 2")
        return Scene(self.name, clear_color=COURSE_BLUE, viewports=(left, right))

    def motion(self) -> Motion:
        """Nothing moves: the scene is built once per set of values."""
        return Motion()


if __name__ == "__main__":
    sys.exit(glsandbox.run(ClearAndSwap))
