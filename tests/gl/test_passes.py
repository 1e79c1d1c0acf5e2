"""The pass registry: every pass kind has a describer (plan) and a runner (executor),
an unregistered kind is refused by name, and every pass leaves GL as it found it."""

from __future__ import annotations

import pytest

from glsandbox.errors import SandboxError
from glsandbox.gl import executor as gl_executor
from glsandbox.plan import PASS_DESCRIBERS, PASS_KINDS, Pass, plan
from lessons.mirror import MirrorLesson
from lessons.shadow_map import ShadowMapLesson

SIZE = (128, 128)


def test_every_pass_kind_has_one_describer_and_one_runner():
    assert len(PASS_KINDS) == len(set(PASS_KINDS))
    assert set(PASS_KINDS) == set(PASS_DESCRIBERS) == set(gl_executor.PASS_RUNNERS)


def test_every_pass_kind_the_lessons_plan_is_registered():
    planned = {p.kind for lesson in (MirrorLesson(), ShadowMapLesson()) for p in plan(lesson.scene()).passes}
    assert planned <= set(PASS_KINDS)
    assert {"shadow_map", "planar_shadow", "mark_mirror", "reflection", "mirror_surface", "clear", "draw"} <= planned


def test_an_unregistered_kind_is_refused_by_name(gl):
    with pytest.raises(SandboxError, match="'sparkle' has no describer"):
        Pass("sparkle", 0).describe()
    scene = ShadowMapLesson(show="map").scene()
    frame_plan = plan(scene)
    bad = type(frame_plan)(**{**frame_plan.__dict__, "passes": (*frame_plan.passes, Pass("sparkle", 0))})
    target = gl.target(SIZE, frame_plan.buffers)
    with pytest.raises(SandboxError, match="'sparkle' has no runner"):
        gl.executor.render(scene, target.framebuffer, SIZE, bad)


def test_gl_state_is_the_same_when_every_pass_starts(gl, monkeypatch):
    """The registry's runners, each wrapped to read the GL state as it starts: every pass
    of a frame after the first finds what the first found (less the depth test, which the
    executor sets for each pass from the plan, and the depth clear value, which
    only a clear reads and every clear sets)."""
    seen: list[tuple[str, str, dict]] = []
    for kind, runner in list(gl_executor.PASS_RUNNERS.items()):
        def spy(executor, frame, step, camera, runner=runner):
            state = executor.raw.state_snapshot()
            state.pop("depth_test", None)
            state.pop("depth_clear_value", None)  # read only by clears, which set it
            seen.append((frame.scene.name, step.kind, state))
            return runner(executor, frame, step, camera)
        monkeypatch.setitem(gl_executor.PASS_RUNNERS, kind, spy)
    for lesson in (ShadowMapLesson(), MirrorLesson()):
        gl.render(lesson, SIZE)
    kinds = {kind for _, kind, _ in seen}
    assert {"shadow_map", "planar_shadow", "mark_mirror", "reflection", "mirror_surface", "draw", "clear"} <= kinds
    for name in ("shadow_map", "mirror"):  # a frame's depth mode (reverse-Z in the mirror) holds for all its passes
        states = [(kind, state) for scene, kind, state in seen if scene == name]
        assert [kind for kind, state in states if state != states[0][1]] == [], name


def test_a_frame_leaves_no_sampler_object_or_depth_test_even_when_a_pass_raises(gl, tmp_path):
    """The material's sampler object and the pass's depth test go with the frame: a sampler
    left on unit 0 overrides the filter of any texture a later user of the shared context
    binds there (a mipmapped filter on the gpu ray engine's record textures makes them
    incomplete: texelFetch reads zeros). The texture lesson's ground is drawn (its sampler
    bound, depth test on) before the cube's missing image stops the frame."""
    from glsandbox.errors import SandboxError
    from lessons.texture import TextureLesson

    gl.render(TextureLesson(filter="mip_linear"), (32, 32))
    assert gl.host.raw.sampler_bindings() == (0, 0, 0, 0)
    with pytest.raises(SandboxError, match="not found"):
        gl.render(TextureLesson(filter="mip_linear", image=str(tmp_path / "nope.png")), (32, 32))
    assert gl.host.raw.sampler_bindings() == (0, 0, 0, 0)
    assert gl.host.raw.state_snapshot()["depth_test"] is False
