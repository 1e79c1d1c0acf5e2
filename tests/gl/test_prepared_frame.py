"""The draw passes of a kept plan prepared once (glsandbox/gl/prepared_frame.py): a frame moved
only by time draws the same pixels through them as through the pass runners, and a scene whose
structure changed (a node added, a pass turned on) gets passes prepared for it, never a stale one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import geometry, transforms
from glsandbox.gl import prepared_frame
from glsandbox.lesson import find_lesson
from glsandbox.scene import Camera, Light, Material, Motion, Node, Scene, ShadowMap, moved_scene

SIZE = (96, 72)
TIMES = (0.0, 0.41, 2.3)
#: The raster lessons whose default frames a motion of models and lights alone moves (the bench's rows;
#: the transform-order lesson moves its trail's mesh and its panel: drawn from its moved scene).
LESSONS = (("indexed_cube", {}), ("clear_and_swap", {}), ("triangle", {}), ("phong", {}),
           ("texture", {}), ("mirror", {}), ("shadow_map", {"show": "map"}))


@pytest.fixture
def prepared_draws(monkeypatch) -> list[int]:
    """How many prepared draw passes were drawn (one entry, its draw count, each)."""
    drawn: list[int] = []
    original = prepared_frame.draw_prepared

    def counted(ex, draws, *args) -> None:
        drawn.append(len(draws))
        original(ex, draws, *args)

    monkeypatch.setattr(prepared_frame, "draw_prepared", counted)
    return drawn


@pytest.mark.parametrize(("name", "settings"), LESSONS, ids=[name for name, _ in LESSONS])
def test_a_kept_plans_prepared_frame_draws_the_unprepared_pixels(gl, prepared_draws, name, settings):
    lesson = find_lesson(name)(**settings)
    gl.render(lesson, SIZE)  # the first frame plans, prepares and uploads
    for t in TIMES:
        scene, motion = lesson.at(t).moving()
        before = len(prepared_draws)
        kept = gl.render_motion(scene, motion, SIZE)
        assert kept is not None
        has_draws = any(step.kind == "draw" and step.draws for step in kept.plan.passes)
        assert (len(prepared_draws) > before) == has_draws  # through the prepared passes
        image = kept.image.copy()
        before = len(prepared_draws)
        fresh = gl.render_scene(moved_scene(scene, motion), SIZE)  # another scene: the pass runners
        assert len(prepared_draws) == before
        assert kept.plan == fresh.plan
        assert np.array_equal(image, fresh.image), f"{name} at t={t}"


def _scene(*extra: Node) -> Scene:
    lit = Material(color=(0.8, 0.3, 0.2, 1.0), shading="phong")
    nodes = (Node("floor", geometry.plane(6.0), transforms.translate(0.0, -1.0, 0.0), Material(shading="phong")),
             Node("cube", geometry.cube(), material=lit), *extra)
    return Scene("prepared", nodes=nodes, lights=(Light((2.0, 3.0, 2.0)),),
                 camera=Camera(eye=(0.0, 1.5, 5.0), target=(0.0, 0.0, 0.0)))


def _motion(t: float) -> Motion:
    return Motion(models={"cube": transforms.rotate_y(t)}, lights={0: (2.0 * np.cos(t), 3.0, 2.0 * np.sin(t))})


def _drawn(gl, scene: Scene, t: float) -> np.ndarray:
    frame = gl.render_motion(scene, _motion(t), SIZE)
    assert frame is not None
    image = frame.image.copy()
    fresh = gl.render_scene(moved_scene(scene, _motion(t)), SIZE)
    assert np.array_equal(image, fresh.image)
    return image


def test_a_node_added_is_drawn_by_passes_prepared_for_it(gl, prepared_draws):
    plain = _scene()
    first = _drawn(gl, plain, 0.3)
    assert prepared_draws == [2]
    added = _scene(Node("ball", geometry.sphere(), transforms.translate(1.5, 0.0, 0.0),
                        Material(color=(0.1, 0.9, 0.2, 1.0))))
    second = _drawn(gl, added, 0.3)
    assert prepared_draws == [2, 3]  # three draws now, none of the old pass
    assert not np.array_equal(first, second)
    assert np.array_equal(_drawn(gl, plain, 0.3), first)  # and the first scene's frames stay its own


def test_a_pass_turned_on_is_drawn(gl, prepared_draws):
    plain = _scene()
    first = _drawn(gl, plain, 1.1)
    shadowed = replace(plain, lights=(replace(plain.lights[0], shadow=ShadowMap(size=256)),))
    second = _drawn(gl, shadowed, 1.1)
    assert not np.array_equal(first, second)  # the shadow map's pass and its shadow
    assert len(prepared_draws) == 2


def test_draws_dropped_since_a_pass_was_prepared_are_drawn_through_the_runner(gl, prepared_draws):
    scene = _scene()
    first = _drawn(gl, scene, 0.7)
    gl.executor._steps.clear()  # (what a program reload or a mesh released does)
    assert np.array_equal(_drawn(gl, scene, 0.7), first)
    assert prepared_draws == [2]  # the second frame drew through the runner
