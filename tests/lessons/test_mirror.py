"""The stencil mirror, planar shadows and depth precision (course section "The stencil Test").

Maths first (reflection and shadow matrices, against the course's DirectX
formulas), then the plans (effects on demand), then rendered pixels: the
stencil marks, the leak without it, double blending, z-fighting pixels
counted per depth setting, GL state restored after every pass, and goldens.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import transforms
from glsandbox.errors import SandboxError
from glsandbox.measure.zfighting import count_z_fighting, flat_receiver, shade_mask
from glsandbox.plan import plan
from glsandbox.planar import Mirror, PlanarShadow
from glsandbox.scene import Scene
from glsandbox.lessons.mirror import MirrorLesson
from glsandbox.lessons.phong import PhongLesson

RNG = np.random.default_rng(5)
SIZE = (256, 256)


# --- reflection matrix (XMMatrixReflect) ------------------------------------------


def dx_reflect(plane: np.ndarray) -> np.ndarray:
    """DirectXMath's ``XMMatrixReflect`` in row-vector form, as documented."""
    a, b, c, d = transforms.normalize_plane(plane)
    s = -2.0 * np.array([a, b, c, d])
    return np.array([[a * s[0] + 1, b * s[0], c * s[0], 0.0],
                     [a * s[1], b * s[1] + 1, c * s[1], 0.0],
                     [a * s[2], b * s[2], c * s[2] + 1, 0.0],
                     [a * s[3], b * s[3], c * s[3], 1.0]])


def dx_shadow(plane: np.ndarray, light: np.ndarray) -> np.ndarray:
    """DirectXMath's ``XMMatrixShadow`` in row-vector form: ``M[i][j] = (P·L) δij - P_i L_j``."""
    p = transforms.normalize_plane(plane)
    dot = float(p @ light)
    return dot * np.eye(4) - np.outer(p, light)


@pytest.mark.parametrize("plane", [(0, 0, 1, 4), (0, 0, 3, 12), (1, 2, -2, 0.5), (0.3, -0.1, 0.9, -7)])
def test_reflection_is_an_involution_with_determinant_minus_one(plane):
    r = transforms.reflection_matrix(plane)
    np.testing.assert_allclose(r @ r, np.eye(4), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(-1.0, abs=1e-12)
    # A point at signed distance s lands at -s; points of the plane stay put.
    p = transforms.normalize_plane(plane)
    points = RNG.normal(size=(20, 3)) * 5
    images = transforms.transform_points(r, points)
    np.testing.assert_allclose(images @ p[:3] + p[3], -(points @ p[:3] + p[3]), atol=1e-9)
    on_plane = points - np.outer(points @ p[:3] + p[3], p[:3])
    np.testing.assert_allclose(transforms.transform_points(r, on_plane), on_plane, atol=1e-9)


def test_unnormalized_planes_are_normalized():
    np.testing.assert_allclose(transforms.normalize_plane((0, 0, 3, 12)), (0, 0, 1, 4))
    np.testing.assert_allclose(transforms.reflection_matrix((0, 0, 3, 12)), transforms.reflection_matrix((0, 0, 1, 4)))
    assert Mirror("glass", (0, 0, 2, 8), ("cube",)).plane == (0.0, 0.0, 1.0, 4.0)
    with pytest.raises(SandboxError, match="zero normal"):
        transforms.normalize_plane((0, 0, 0, 1))


def test_course_mirror_plane_matches_directx_reflect():
    # mirrorPlane = (0, 0, 1, -6): z = 6 in DirectX, z = -6 in OpenGL.
    course = np.array([0.0, 0.0, 1.0, -6.0])
    gl_plane = transforms.from_directx_plane(course)
    np.testing.assert_allclose(gl_plane, (0, 0, -1, -6))
    np.testing.assert_allclose(transforms.from_directx_matrix(dx_reflect(course)),
                               transforms.reflection_matrix(gl_plane), atol=1e-12)


# --- shadow matrix (XMMatrixShadow) -------------------------------------------------


def test_course_shadow_matches_directx_shadow():
    # shadowPlane = (0, 1, 0, 2), lightDir = (0.6, -0.8, 0), toMainLight = -lightDir, w = 0.
    plane = np.array([0.0, 1.0, 0.0, 2.0])
    light = np.array([-0.6, 0.8, 0.0, 0.0])
    gl_light = np.array([*transforms.from_directx_point(light[:3]), 0.0])
    np.testing.assert_allclose(transforms.from_directx_matrix(dx_shadow(plane, light)),
                               transforms.shadow_matrix(transforms.from_directx_plane(plane), gl_light), atol=1e-12)


@pytest.mark.parametrize("plane, light", [
    ((0, 1, 0, 0), (2.5, 4.5, 1.5, 1)),
    ((0, 2, 0, 4), (-0.6, 0.8, 0.0, 0)),       # the course's y = -2 plane, unnormalized, directional
    ((0.2, 1, -0.3, 1), (1.0, 9.0, -2.0, 1)),
    ((0.2, 1, -0.3, 1), (1.0, 3.0, 2.0, 0)),
])
def test_projected_points_lie_on_the_plane_and_on_the_light_ray(plane, light):
    s = transforms.shadow_matrix(plane, light)
    p = transforms.normalize_plane(plane)
    l = transforms.light_vector(light)
    points = RNG.uniform(-1.5, 1.5, size=(200, 3))
    if l[3] == 1.0:  # keep the points strictly below the point light
        height = p @ l
        points -= np.outer(np.maximum(points @ p[:3] + p[3] - 0.9 * height, 0.0), p[:3])
    projected = transforms.transform_points(s, points)
    np.testing.assert_allclose(projected @ p[:3] + p[3], 0.0, atol=1e-9)
    towards = (l[:3] - points) if l[3] == 1.0 else np.broadcast_to(l[:3], points.shape)
    # X, its projection and the light are collinear: (proj - X) x (towards light) = 0.
    np.testing.assert_allclose(np.cross(projected - points, towards), 0.0, atol=1e-9)


def test_light_parallel_to_the_plane_or_in_it_is_refused():
    with pytest.raises(SandboxError, match="parallel to the shadow plane"):
        transforms.shadow_matrix((0, 1, 0, 0), (1.0, 0.0, 0.0, 0.0))
    with pytest.raises(SandboxError, match="lies in the shadow plane"):
        transforms.shadow_matrix((0, 1, 0, 0), (3.0, 0.0, 1.0, 1.0))
    with pytest.raises(SandboxError, match="parallel to the shadow plane"):
        plan(MirrorLesson(light="directional", lx=1.0, ly=0.0, lz=0.0).scene())
    with pytest.raises(SandboxError, match="w = 1"):
        transforms.light_vector((0, 1, 0, 0.5))


def test_light_below_the_plane_culls_the_shadow_pass():
    step = [p for p in plan(MirrorLesson(ly=-1.0).scene()).passes if p.kind == "planar_shadow"][0]
    assert step.draws == () and "light is below the receiver plane" in step.describe()


def test_reverse_z_maps_near_to_one_and_far_to_zero():
    proj = transforms.reverse_z(transforms.perspective(45.0, 1.0, 0.01, 100.0))
    for z, depth in ((-0.01, 1.0), (-100.0, 0.0)):
        clip = proj @ np.array([0.0, 0.0, z, 1.0])
        assert clip[2] / clip[3] == pytest.approx(depth, abs=1e-12)


# --- plans: effects on demand ------------------------------------------------------

PINNED = """plan for mirror
buffers: colour RGBA8, depth 32F, stencil 8, no MSAA
programs:
  basic[SOLID_COLOR]
  phong[NUM_LIGHTS=1]
passes:
  1. clear viewport 0: colour (0.08, 0.08, 0.12, 1) + depth + stencil
  2. draw viewport 0 (depth test): floor with phong[NUM_LIGHTS=1]; wall_left with phong[NUM_LIGHTS=1]; \
wall_back_left with phong[NUM_LIGHTS=1]; wall_back_right with phong[NUM_LIGHTS=1]; wall_back_low with \
phong[NUM_LIGHTS=1]; wall_back_high with phong[NUM_LIGHTS=1]; cube with phong[NUM_LIGHTS=1]; light with basic[SOLID_COLOR]
  3. mark mirror viewport 0 (depth test, no colour or depth writes, stencil always, replace 1): glass with basic[SOLID_COLOR]
  4. reflection viewport 0 (depth test, stencil equal 1, keep, front faces clockwise, lights reflected): \
floor with phong[NUM_LIGHTS=1]; wall_left with phong[NUM_LIGHTS=1]; cube with phong[NUM_LIGHTS=1]; light with basic[SOLID_COLOR]
  5. mirror surface viewport 0 (depth test, blended): glass with basic[SOLID_COLOR]
  6. planar shadow viewport 0 (depth test, stencil equal 0 on bit 2, set it, lift 0.005, polygon offset, blended, \
no depth writes): cube with basic[SOLID_COLOR] (no culling)"""


def test_mirror_plan_is_pinned():
    assert plan(MirrorLesson().scene()).describe() == PINNED


@pytest.mark.parametrize("mirror, shadow, kinds, stencil", [
    ("off", "off", ["clear", "draw"], False),
    ("stencil", "off", ["clear", "draw", "mark_mirror", "reflection", "mirror_surface"], True),
    ("no_stencil", "off", ["clear", "draw", "reflection", "mirror_surface"], False),
    ("off", "on", ["clear", "draw", "planar_shadow"], True),
    ("off", "double_blend", ["clear", "draw", "planar_shadow"], False),
    ("no_stencil", "double_blend", ["clear", "draw", "reflection", "mirror_surface", "planar_shadow"], False),
])
def test_effect_passes_and_stencil_exist_only_when_asked_for(mirror, shadow, kinds, stencil):
    p = plan(MirrorLesson(mirror=mirror, shadow=shadow).scene())
    assert [s.kind for s in p.passes] == kinds
    assert p.buffers.stencil is stencil
    if mirror == "off":  # the glass is an ordinary node then
        assert "glass" in [d.node for d in p.passes[1].draws]


def test_plans_without_effects_are_unchanged():
    # The lessons that ask for no effect get no stencil and no effect pass.
    p = plan(PhongLesson().scene())
    assert not p.buffers.stencil and not p.buffers.float_depth
    assert [s.kind for s in p.passes] == ["clear", "draw"]
    assert "depth 24," in plan(MirrorLesson(depth="standard").scene()).buffers.describe() + ","


def test_planar_passes_carry_their_stencil_state_as_structure():
    # The executor sets exactly these numbers (glsandbox.gl.planar_state.set_stencil).
    from glsandbox.plan import StencilState

    stencils = {s.kind: s.stencil for s in plan(MirrorLesson().scene()).passes}
    assert stencils["mark_mirror"] == StencilState("always", 1, 0xFF, write_mask=1, on_pass="replace")
    assert stencils["reflection"] == StencilState("equal", 1, 1, write_mask=0, on_pass="keep")
    assert stencils["planar_shadow"] == StencilState("equal", 0, 2, write_mask=2, on_pass="invert")
    assert stencils["mirror_surface"] is None and stencils["draw"] is None
    leaky = {s.kind: s.stencil for s in plan(MirrorLesson(mirror="no_stencil", shadow="double_blend").scene()).passes}
    assert leaky["reflection"] is None and leaky["planar_shadow"] is None
    with pytest.raises(SandboxError, match="stencil test 'less'"):
        StencilState("less", 0)


def test_compare_cannot_compose_whole_frame_effects_so_it_stitches_them():
    from glsandbox.measure.compare import build_variants, composable, compose

    variants, columns = build_variants(MirrorLesson, ["shadow=on,off"], [])
    assert "stencil mirror" in composable(variants)
    with pytest.raises(SandboxError, match="cannot share a frame"):
        compose(variants, columns, SIZE)


def test_bad_values_are_refused_naming_them():
    with pytest.raises(SandboxError, match="mirror=glass"):
        MirrorLesson.from_settings(["mirror=glass"])
    with pytest.raises(SandboxError, match="near=5"):
        MirrorLesson.from_settings(["near=5", "far=2"]).scene()
    with pytest.raises(SandboxError, match="'nowhere'"):
        plan(replace(MirrorLesson().scene(), mirror=Mirror("glass", (0, 0, 1, 4), ("nowhere",))))
    with pytest.raises(SandboxError, match="cannot reflect itself"):
        Mirror("glass", (0, 0, 1, 4), ("glass",))
    with pytest.raises(SandboxError, match="lift"):
        PlanarShadow("floor", (0, 1, 0, 0), (0, 5, 0, 1), ("cube",), lift=-1.0)
    with pytest.raises(SandboxError, match="depth mode 'fast'"):
        Scene("x", depth_mode="fast")


# --- rendered pixels -----------------------------------------------------------------


def render(gl, scene: Scene, size=SIZE) -> np.ndarray:
    return gl.render_scene(scene, size).image[..., :3].astype(int)


def stencil_of_last_frame(gl, scene: Scene, size=SIZE) -> np.ndarray:
    target = gl.target(size, plan(scene).buffers)
    data = gl.host.raw.read_stencil(target._fbo_name, size)
    return np.frombuffer(data, dtype=np.uint8).reshape(size[1], size[0])[::-1]


def test_reflection_shows_inside_the_mirror_only(gl):
    scene = MirrorLesson(shadow="off").scene()
    mirrored = render(gl, scene)
    marks = stencil_of_last_frame(gl, scene) & 1
    plain = render(gl, MirrorLesson(mirror="off", shadow="off").scene())
    leaky = render(gl, MirrorLesson(mirror="no_stencil", shadow="off").scene())
    inside = marks.astype(bool)
    assert 2000 < inside.sum() < 0.2 * inside.size  # the glass's visible pixels
    # Outside the marked pixels the stencil frame is the plain frame, exactly.
    assert np.array_equal(mirrored[~inside], plain[~inside])
    # Inside, the reflection differs from the opaque glass.
    assert np.any(mirrored[inside] != plain[inside], axis=-1).mean() > 0.9
    # Without the stencil the reflection leaks outside the glass (over and beside the wall).
    leaked = np.any(leaky[~inside] != plain[~inside], axis=-1).sum()
    assert leaked > 1000


def test_stencil_darkens_each_shadow_pixel_once(gl):
    # Floor 204 (0.8); black at alpha 0.5 once: 102; twice: 51.
    once = render(gl, flat_receiver(MirrorLesson(mirror="off").scene()))
    twice = render(gl, flat_receiver(MirrorLesson(mirror="off", shadow="double_blend").scene()))
    assert shade_mask(once, 102).sum() > 500 and shade_mask(once, 51).sum() == 0
    assert shade_mask(twice, 51).sum() > 500
    assert np.array_equal(shade_mask(once, 102), shade_mask(twice, 51))


def z_fighting_pixels(gl, **settings) -> tuple[int, int]:
    """(shadow pixels, z-fighting pixels) for the lesson with an unlit floor
    (:func:`glsandbox.measure.zfighting.count_z_fighting`: the oracle is the same frame
    with the floor lowered by 0.25, where the shadow cannot fight)."""
    counted = count_z_fighting(gl, MirrorLesson(mirror="off", far=200.0, **settings).scene(), SIZE)
    return counted.shadow, counted.fighting


FAR_VIEWS = {"room": dict(distance=10.5, fov=45.0), "30": dict(distance=30.0, fov=17.0),
             "60": dict(distance=60.0, fov=8.5), "90": dict(distance=90.0, fov=5.7)}


@pytest.mark.parametrize("view", FAR_VIEWS)
def test_default_depth_settings_never_z_fight(gl, view):
    shadow, fighting = z_fighting_pixels(gl, **FAR_VIEWS[view])
    assert shadow > 800 and fighting == 0


@pytest.mark.parametrize("settings, expect", [
    # The course's lift alone in a 24-bit buffer: fine in the room, fights far away.
    (dict(depth="standard", offset=False, **FAR_VIEWS["room"]), "none"),
    (dict(depth="standard", offset=False, **FAR_VIEWS["60"]), "many"),
    (dict(depth="standard", offset=False, **FAR_VIEWS["90"]), "many"),
    # No lift at all: fights everywhere, whatever the buffer.
    (dict(depth="standard", offset=False, lift=0.0, **FAR_VIEWS["room"]), "many"),
    (dict(depth="reverse_z", offset=False, lift=0.0, **FAR_VIEWS["room"]), "many"),
    # Each remedy alone: a 10x nearer plane, reverse-Z, polygon offset.
    (dict(depth="standard", offset=False, near=0.1, **FAR_VIEWS["90"]), "none"),
    (dict(depth="reverse_z", offset=False, **FAR_VIEWS["90"]), "none"),
    (dict(depth="standard", offset=True, **FAR_VIEWS["90"]), "none"),
    (dict(depth="standard", offset=True, lift=0.0, **FAR_VIEWS["90"]), "none"),
])
def test_z_fighting_pixels_per_depth_setting(gl, settings, expect):
    shadow, fighting = z_fighting_pixels(gl, **settings)
    assert shadow > 800
    if expect == "none":
        assert fighting == 0
    else:
        # Transforms formed in float64 relative to the eye (gl.uniform_bytes.PassCamera) leave
        # the depth buffer as the only rounding: 217 of 907 pixels fight at 60, 65 of 894 at 90
        # (24-bit standard depth); with no lift 936 of 1003, and 39 of 1003 with reverse-Z.
        assert fighting > 0.03 * shadow


def test_hard_case_lights_draw_no_shadow_at_all(gl):
    no_shadow = render(gl, MirrorLesson(shadow="off", ly=1.0).scene())
    assert np.array_equal(render(gl, MirrorLesson(ly=1.0).scene()), no_shadow)  # cube culled
    below = render(gl, MirrorLesson(shadow="off", ly=-1.0).scene())
    assert np.array_equal(render(gl, MirrorLesson(ly=-1.0).scene()), below)  # light under the floor


def test_gl_state_is_restored_after_every_effect_pass(gl):
    plain = PhongLesson()
    before = gl.render(plain, SIZE).image.copy()
    before_state = gl.host.raw.state_snapshot()
    # Frames are drawn with alpha writes off (glsandbox.gl.target.FRAME_COLOR_MASK): that
    # is the colour mask a frame leaves, and the one the planar passes restore (the mirror's marking
    # turns all colour writes off; put back to (1, 1, 1, 1) the glass and shadow would write alpha).
    assert before_state["color_writemask"] == (1, 1, 1, 0)
    for lesson in (MirrorLesson(), MirrorLesson(mirror="no_stencil", shadow="double_blend", depth="standard")):
        assert (gl.render(lesson, SIZE).image[..., 3] == 255).all()
        assert gl.host.raw.state_snapshot() == before_state
    after = gl.render(plain, SIZE).image.copy()
    assert gl.host.raw.state_snapshot() == before_state
    assert np.array_equal(before, after)


# --- goldens: one per parameter value ---------------------------------------------------

GOLDENS = {
    "default": [],
    "mirror_no_stencil": ["mirror=no_stencil"],
    "mirror_off": ["mirror=off"],
    "shadow_double_blend": ["shadow=double_blend"],
    "shadow_off": ["shadow=off"],
    "light_directional": ["light=directional", "lx=-0.5", "ly=1", "lz=0.4"],
    "depth_standard": ["depth=standard"],
    "offset_off": ["offset=off"],
    "time_2": ["time=2"],
    # Far away: the course's lift alone z-fights in a 24-bit buffer; the default holds.
    "far_standard_no_offset": ["depth=standard", "offset=off", "distance=60", "fov=8.5", "far=200"],
    "far_default": ["distance=60", "fov=8.5", "far=200"],
    "far_near_0.1": ["depth=standard", "offset=off", "distance=60", "fov=8.5", "far=200", "near=0.1"],
}


@pytest.mark.parametrize("name", sorted(GOLDENS))
def test_mirror_goldens(gl, golden, name):
    frame = gl.render(MirrorLesson.from_settings(GOLDENS[name]), SIZE)
    golden(frame.image, f"mirror/{name}")
