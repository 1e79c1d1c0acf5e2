"""The pass registry: every pass kind has its plan module (a describer) and its runner module
(a Runner record), a kind lacking a part fails naming both, an unregistered kind is refused by
name, and every pass leaves GL as it found it."""

from __future__ import annotations

import dataclasses
import importlib

import moderngl
import pytest

from glsandbox import passes as plan_passes
from glsandbox.errors import SandboxError
from glsandbox.gl import passes as gl_passes, rawgl
from glsandbox.plan import PASS_KINDS, Pass, plan
from glsandbox.lessons.mirror import MirrorLesson
from glsandbox.lessons.shadow_map import ShadowMapLesson

SIZE = (128, 128)


def missing_parts(kind: str) -> list[str]:
    """What pass kind ``kind`` lacks of its two modules, each part named."""
    missing = []
    plan_module = plan_passes.kind_module(kind)
    if not callable(getattr(plan_module, "describe", None)):
        missing.append(f"glsandbox/passes/{kind}.py: describe(step)")
    record = getattr(importlib.import_module(f"glsandbox.gl.passes.{kind}"), "RUNNER", None)
    if not isinstance(record, gl_passes.Runner) or record.kind != kind:
        missing.append(f"glsandbox/gl/passes/{kind}.py: RUNNER = Runner({kind!r}, ...)")
    else:
        missing += [f"glsandbox/gl/passes/{kind}.py: Runner.{part}" for part in ("run", "state")
                    if not callable(getattr(record, part))]
        if not isinstance(record.moved, bool):
            missing.append(f"glsandbox/gl/passes/{kind}.py: Runner.moved")
    return missing


def test_every_pass_kind_has_its_plan_module_and_its_runner_module():
    assert len(PASS_KINDS) == len(set(PASS_KINDS))
    assert {kind: parts for kind in PASS_KINDS if (parts := missing_parts(kind))} == {}
    for kind in PASS_KINDS:  # the registries find the same parts
        assert plan_passes.describer(kind) is plan_passes.kind_module(kind).describe
        assert gl_passes.runner(kind) is importlib.import_module(f"glsandbox.gl.passes.{kind}").RUNNER


def test_a_kind_with_a_part_removed_fails_naming_the_kind_and_the_part(monkeypatch):
    """Each part taken away in turn: the completeness check names it, and the registry refuses the kind."""
    draw_plan = plan_passes.kind_module("draw")
    monkeypatch.delattr(draw_plan, "describe")
    assert missing_parts("draw") == ["glsandbox/passes/draw.py: describe(step)"]
    with pytest.raises(SandboxError, match="pass kind 'draw' has no describer"):
        Pass("draw", 0).describe()
    monkeypatch.undo()
    overlay_runner = importlib.import_module("glsandbox.gl.passes.overlay")
    monkeypatch.delattr(overlay_runner, "RUNNER")
    monkeypatch.delitem(gl_passes.RUNNERS, "overlay", raising=False)
    assert missing_parts("overlay") == ["glsandbox/gl/passes/overlay.py: RUNNER = Runner('overlay', ...)"]
    with pytest.raises(SandboxError, match="pass kind 'overlay' has no runner"):
        gl_passes.runner("overlay")
    monkeypatch.undo()
    clear_runner = importlib.import_module("glsandbox.gl.passes.clear")
    monkeypatch.setattr(clear_runner, "RUNNER", dataclasses.replace(clear_runner.RUNNER, state=None))
    assert missing_parts("clear") == ["glsandbox/gl/passes/clear.py: Runner.state"]
    with pytest.raises(TypeError, match="moved"):  # a record cannot leave a part out
        gl_passes.Runner("clear", clear_runner.run, gl_passes.touches_nothing)  # type: ignore[call-arg]


def test_every_kind_module_is_registered():
    """A module in glsandbox/passes/ or glsandbox/gl/passes/ that holds a kind is one of PASS_KINDS."""
    from pathlib import Path

    for package, mark in ((plan_passes, "\ndef describe("), (gl_passes, "\nRUNNER = Runner(")):
        folder = Path(package.__file__).parent
        holding = {p.stem for p in folder.glob("*.py") if mark in p.read_text(encoding="utf-8")}
        assert holding == set(PASS_KINDS), (folder, holding ^ set(PASS_KINDS))


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


#: The snapshot's entries (glsandbox.gl.rawgl.RawGL.state_snapshot) of each group of
#: glsandbox.gl.passes.restore_state, and of culling.
GROUP_ENTRIES = {"stencil": ("stencil_test", "stencil_func", "stencil_value_mask", "stencil_fail",
                             "stencil_pass_depth_fail", "stencil_pass_depth_pass", "stencil_ref", "stencil_writemask"),
                 "masks": ("depth_writemask", "color_writemask"), "blend": ("blend", "blend_src_rgb", "blend_dst_rgb"),
                 "offset": ("polygon_offset_fill", "polygon_offset_factor", "polygon_offset_units")}
CULLING = ("cull_face", "front_face", "cull_face_mode")


def test_gl_state_is_the_same_when_every_pass_starts(gl, monkeypatch):
    """The registry's runners, each wrapped to read the GL state as it starts: every pass
    of a frame after the first finds what the first found, less the depth test (which the
    executor sets for each pass from the plan), the depth clear value (read only by clears,
    which set it), culling (which the executor sets for each draw) and the state groups the
    pass sets wholly itself before it draws (its Runner.state: a stencil pass after
    a stencil pass finds the last one's stencil, not the default)."""
    seen: list[tuple[str, str, dict]] = []
    for kind in PASS_KINDS:
        record = gl_passes.runner(kind)

        def spy(executor, frame, step, camera, runner=record.run, habits=record.state):
            state = executor.raw.state_snapshot()
            sets = habits(step)[0]
            for name in ("depth_test", "depth_clear_value", *CULLING,
                         *(entry for group in sets for entry in GROUP_ENTRIES[group])):
                del state[name]
            seen.append((frame.scene.name, step.kind, state))
            return runner(executor, frame, step, camera)
        monkeypatch.setitem(gl_passes.RUNNERS, kind, dataclasses.replace(record, run=spy))
    for _ in range(2):  # the first frame of each plan and a frame of a kept plan
        for lesson in (ShadowMapLesson(), MirrorLesson()):
            gl.render(lesson, SIZE)
    kinds = {kind for _, kind, _ in seen}
    assert {"shadow_map", "planar_shadow", "mark_mirror", "reflection", "mirror_surface", "draw", "clear"} <= kinds
    for name in ("shadow_map", "mirror"):  # a frame's depth mode (reverse-Z in the mirror) holds for all its passes
        states = [(kind, state) for scene, kind, state in seen if scene == name]
        first = states[0][1]
        assert [kind for kind, state in states if state != {k: first[k] for k in state}] == [], name


def test_a_pass_of_unknown_habits_starts_and_ends_in_the_default_state(gl, monkeypatch):
    """A runner of unknown habits (its Runner.state gl.passes.unknown_habits) finds every
    group put back, culling too, and whatever it sets is put back
    after it: the next pass finds the state the first pass found."""
    seen: dict[str, dict] = {}

    def odd(executor, frame, step, camera):  # a pass that leaves blending, culling and the stencil on
        seen["odd"] = executor.raw.state_snapshot()
        executor.ctx.enable(moderngl.BLEND | moderngl.CULL_FACE)
        executor.raw.glEnable(rawgl.GL_STENCIL_TEST)

    def spy_clear(executor, frame, step, camera, runner=gl_passes.runner("clear").run):
        seen.setdefault("clear", executor.raw.state_snapshot())
        return runner(executor, frame, step, camera)

    def spy_draw(executor, frame, step, camera, runner=gl_passes.runner("draw").run):
        seen["draw"] = executor.raw.state_snapshot()
        return runner(executor, frame, step, camera)

    monkeypatch.setitem(gl_passes.RUNNERS, "odd", gl_passes.Runner("odd", odd, gl_passes.unknown_habits, moved=False))
    monkeypatch.setitem(gl_passes.RUNNERS, "clear", dataclasses.replace(gl_passes.runner("clear"), run=spy_clear))
    monkeypatch.setitem(gl_passes.RUNNERS, "draw", dataclasses.replace(gl_passes.runner("draw"), run=spy_draw))
    scene = MirrorLesson().scene()
    frame_plan = plan(scene)
    draw_at = next(i for i, p in enumerate(frame_plan.passes) if p.kind == "draw")
    passes = (*frame_plan.passes[:draw_at + 1], Pass("odd", 0), *frame_plan.passes[draw_at + 1:],
              Pass("odd", 0), frame_plan.passes[draw_at])
    odd_plan = type(frame_plan)(**{**frame_plan.__dict__, "passes": passes})
    target = gl.target(SIZE, frame_plan.buffers)
    gl.executor.render(scene, target.framebuffer, SIZE, odd_plan)
    first = {k: v for k, v in seen["clear"].items() if k not in ("depth_test", "depth_clear_value")}
    for name in ("odd", "draw"):
        assert {k: seen[name][k] for k in first} == first, name


def test_a_frame_leaves_no_sampler_object_or_depth_test_even_when_a_pass_raises(gl, tmp_path):
    """The material's sampler object and the pass's depth test go with the frame: a sampler
    left on unit 0 overrides the filter of any texture a later user of the shared context
    binds there (a mipmapped filter on the gpu ray engine's record textures makes them
    incomplete: texelFetch reads zeros). The texture lesson's ground is drawn (its sampler
    bound, depth test on) before the cube's missing image stops the frame."""
    from glsandbox.errors import SandboxError
    from glsandbox.lessons.texture import TextureLesson

    gl.render(TextureLesson(filter="mip_linear"), (32, 32))
    assert gl.host.raw.sampler_bindings() == (0, 0, 0, 0)
    with pytest.raises(SandboxError, match="not found"):
        gl.render(TextureLesson(filter="mip_linear", image=str(tmp_path / "nope.png")), (32, 32))
    assert gl.host.raw.sampler_bindings() == (0, 0, 0, 0)
    assert gl.host.raw.state_snapshot()["depth_test"] is False
