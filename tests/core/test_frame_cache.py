"""Frames that pay only for what changed: a lesson's Motion, the kept Scene and plan.

A lesson that says what ``time`` moves (:meth:`glsandbox.Lesson.motion`) builds its scene
once per set of its other values and per frame only moves it
(:func:`glsandbox.scene.moved_scene`); the frame renderer keeps the plan while only positions
and cameras change. These tests hold every built-in lesson to its promise: a moved scene is
the scene a fresh build gives, part for part and pixel for pixel, and changing a parameter
between frames changes the picture.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import geometry
from glsandbox.errors import SandboxError
from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.planar import Mirror, PlanarShadow
from glsandbox.plan import motion_decisions, plan
from glsandbox.scene import Camera, Light, Material, Motion, Node, Scene, motion_parts, moved_scene, scene_origin

#: Moments the frames are checked at (seconds): the first, and three that turn things well apart.
TIMES = (0.0, 0.37, 1.9, 7.3)
#: The settings each lesson is checked with besides its defaults (the bench's shadow-map frame).
EXTRA_SETTINGS = {"shadow_map": ({"show": "map"},), "phong": ({"lights": 1, "shading": "gouraud"},),
                  "mirror": ({"light": "directional", "shadow": "double_blend"},),
                  "transform_order": ({"view": "split"}, {"order": "RTS", "overlay": False}),
                  "model": ({"view": "raster", "mesh": "rock"},)}


def moving_lessons() -> list[tuple[str, dict]]:
    """(lesson name, settings) for every built-in lesson that declares a motion."""
    found = []
    for cls in all_lessons():
        if cls().motion() is not None:
            found += [(cls.name, {}), *((cls.name, s) for s in EXTRA_SETTINGS.get(cls.name, ()))]
    return found


def assert_same_scene(moved: Scene, built: Scene) -> None:
    """Everything a renderer reads is equal (models exactly: the same floats)."""
    assert moved.name == built.name
    assert [n.name for n in moved.nodes] == [n.name for n in built.nodes]
    for a, b in zip(moved.nodes, built.nodes):
        assert np.array_equal(np.asarray(a.model), np.asarray(b.model)), a.name
        assert a.material == b.material and a.mesh.name == b.mesh.name, a.name
        assert np.array_equal(a.mesh.positions, b.mesh.positions), a.name  # a trail moves its points
        assert (a.cull_back_faces, a.viewports, a.casts_shadow, a.receives_shadow) == \
            (b.cull_back_faces, b.viewports, b.casts_shadow, b.receives_shadow), a.name
    assert moved.lights == built.lights
    assert (moved.camera, moved.viewports, moved.mirror, moved.planar_shadow, moved.depth_mode, moved.plan_mode) == \
        (built.camera, built.viewports, built.mirror, built.planar_shadow, built.depth_mode, built.plan_mode)
    assert [o.name for o in moved.overlays] == [o.name for o in built.overlays]
    for a, b in zip(moved.overlays, built.overlays):
        assert np.array_equal(a.image, b.image) and (a.viewport, a.position) == (b.viewport, b.position), a.name


def test_the_course_lessons_that_move_declare_it():
    names = {name for name, _ in moving_lessons()}
    assert {"clear_and_swap", "triangle", "indexed_cube", "phong", "texture", "mirror", "shadow_map",
            "transform_order"} <= names


@pytest.mark.parametrize(("name", "settings"), moving_lessons(), ids=lambda v: str(v) if v else "")
def test_a_moved_scene_is_a_fresh_build(name, settings):
    lesson = find_lesson(name)(**settings)
    first = lesson.scene()
    for t in TIMES:
        moment = lesson.at(t)
        scene = moment.scene()
        assert scene_origin(scene) is scene_origin(first)  # built once, moved since
        assert_same_scene(scene, moment._scene_as_built())


def test_a_changed_value_builds_the_scene_again():
    lesson = find_lesson("phong")()
    before = lesson.scene()
    lesson.on_key("4")  # the next shading
    after = lesson.scene()
    assert scene_origin(after) is not scene_origin(before)
    assert {n.material.shading for n in after.nodes if n.material.lit} == {"gouraud"}
    lesson.on_key("4"), lesson.on_key("4")  # back to phong: the kept scene again
    assert scene_origin(lesson.scene()) is scene_origin(before)


def test_a_lesson_without_motion_is_built_every_frame():
    lesson = find_lesson("ray_spheres")()
    assert lesson.motion() is None
    assert scene_origin(lesson.scene()) is None


def test_a_scene_file_is_read_once_and_again_by_a_reload(tmp_path):
    from glsandbox.lesson import reload_lesson

    path = tmp_path / "room.toml"
    path.write_text('name = "room"\n[[nodes]]\nname = "box"\nmesh = "cube"\n', encoding="utf-8")
    lesson = find_lesson(str(path))()
    first = lesson.scene()
    for t in TIMES:
        scene = lesson.at(t).scene()
        assert scene_origin(scene) is scene_origin(first)  # read and built once, moved since
        assert_same_scene(scene, lesson.at(t)._scene_as_built())
    path.write_text('name = "room"\n[[nodes]]\nname = "ball"\nmesh = "sphere"\n', encoding="utf-8")
    assert [n.name for n in reload_lesson(lesson).scene().nodes] == ["ball"]  # the saved file, read again


def _lit_scene() -> Scene:
    return Scene("s", nodes=(Node("ball", geometry.sphere(), material=Material(shading="phong")),
                             Node("flat", geometry.cube())), lights=(Light((1.0, 2.0, 3.0)),))


def test_moved_scene_changes_only_what_moves():
    scene = _lit_scene()
    moved = moved_scene(scene, Motion(models={"ball": np.diag([2.0, 2.0, 2.0, 1.0])}, lights={0: (0.0, 5.0, 0.0)}))
    assert scene_origin(moved) is scene and moved.nodes[1] is scene.nodes[1]
    assert moved.nodes[0].mesh is scene.nodes[0].mesh and moved.nodes[0].model[0, 0] == 2.0
    assert moved.lights[0].position == (0.0, 5.0, 0.0) and scene.lights[0].position == (1.0, 2.0, 3.0)
    again = moved_scene(moved, Motion(camera=Camera(eye=(0.0, 0.0, 5.0))))
    assert scene_origin(again) is scene and again.camera.eye == (0.0, 0.0, 5.0)
    assert scene_origin(replace(moved, name="other")) is None  # made another way: planned afresh


@pytest.mark.parametrize(("motion", "message"), [
    (Motion(models={"ghost": np.eye(4)}), "'ghost', which is not a node"),
    (Motion(models={"ball": np.diag([1.0, 0.0, 1.0, 1.0])}), "node 'ball': model matrix is singular"),
    (Motion(models={"flat": np.full((4, 4), np.nan)}), "node 'flat': model matrix has a non-finite entry"),
    (Motion(models={"flat": np.eye(3)}), "node 'flat': model matrix must be 4x4"),
    (Motion(lights={1: (0.0, 0.0, 0.0)}), "moves light 1, and the scene has 1"),
    (Motion(lights={0: (0.0, float("inf"), 0.0)}), "light position"),
    (Motion(positions={"flat": np.zeros((3, 3))}), "mesh 'cube': moved positions must be a (8, 3) array"),
    (Motion(positions={"flat": np.full((8, 3), np.nan)}), "mesh 'cube': moved positions[0] is not finite"),
    (Motion(positions={"ghost": np.zeros((8, 3))}), "'ghost', which is not a node"),
    (Motion(overlays={"label": np.zeros((2, 2, 4), np.uint8)}), "overlay 'label', which is not an overlay"),
])
def test_moved_scene_checks_what_moves(motion, message):
    with pytest.raises(SandboxError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[0]", r"\[0\]")) as error:
        moved_scene(_lit_scene(), motion)
    if not motion.positions and not motion.overlays:  # what a headless frame checks without the moved scene
        with pytest.raises(SandboxError) as handed_over:
            motion_parts(_lit_scene(), motion)
        assert str(handed_over.value) == str(error.value)


def test_moved_scene_moves_every_node_of_a_moved_name_in_scene_order():
    """Nodes are found by name once per scene moved from; two nodes may share a name, and the
    first bad one (in the scene's order) is named whatever order the motion lists them in."""
    twice = Scene("s", nodes=(Node("a", geometry.cube()), Node("b", geometry.sphere()), Node("a", geometry.cube()),
                              Node("c", geometry.cube())))
    turned = np.diag([2.0, 3.0, 4.0, 1.0])
    moved = moved_scene(twice, Motion(models={"a": turned}, positions={"c": geometry.cube().positions + 1.0}))
    assert [n.name for n in moved.nodes] == ["a", "b", "a", "c"] and moved.nodes[1] is twice.nodes[1]
    assert moved.nodes[0].model is turned and moved.nodes[2].model is turned
    assert np.array_equal(moved.nodes[3].mesh.positions, twice.nodes[3].mesh.positions + 1.0)
    again = moved_scene(moved, Motion(models={"b": np.eye(4)}))  # from the moved one: the same places
    assert again.nodes[0] is moved.nodes[0] and again.nodes[1].model is not twice.nodes[1].model
    with pytest.raises(SandboxError, match="node 'a'"):
        moved_scene(twice, Motion(models={"c": np.full((4, 4), np.nan), "a": np.full((4, 4), np.nan)}))
    with pytest.raises(SandboxError, match="node 'a'"):
        motion_parts(twice, Motion(models={"c": np.full((4, 4), np.nan), "a": np.full((4, 4), np.nan)}))
    lit = Scene("s", nodes=(Node("a", geometry.cube()), Node("b", geometry.sphere(), material=Material(shading="phong")),
                            Node("a", geometry.sphere(), material=Material(shading="phong"))))
    flat = np.diag([1.0, 0.0, 1.0, 1.0])  # fine for the unlit first 'a', singular for the lit second one
    for check in (moved_scene, motion_parts):
        with pytest.raises(SandboxError, match="node 'a': model matrix is singular"):
            check(lit, Motion(models={"a": flat}))


def test_a_moved_scenes_decisions_are_a_fresh_scenes():
    """motion_decisions finds the blended nodes, the reflected ones and the casters once per scene
    moved from; every moved scene decides as the same scene made anew (no origin) does."""
    glass = Material(color=(0.2, 0.4, 1.0, 0.5), alpha_mode="blend")
    scene = Scene("decide", nodes=(
        Node("floor", geometry.plane(8.0)), Node("wall", geometry.plane(8.0), material=glass),
        Node("a", geometry.cube(), material=glass), Node("b", geometry.cube(), material=glass),
        Node("caster", geometry.cube())),
        camera=Camera(eye=(0.0, 2.0, 10.0)),
        mirror=Mirror("wall", (0.0, 0.0, 1.0, 5.0), ("a", "b", "caster")),
        planar_shadow=PlanarShadow("floor", (0.0, 1.0, 0.0, 0.0), (0.0, 4.0, 0.0, 1.0), ("caster", "a")))
    seen = set()
    for z_a, y_caster in ((3.0, 1.0), (-2.0, 1.0), (3.0, 6.0), (-2.0, 6.0)):
        ahead, lifted = np.eye(4), np.eye(4)
        ahead[2, 3], lifted[1, 3] = z_a, y_caster
        moved = moved_scene(scene, Motion(models={"a": ahead, "caster": lifted}))
        decisions = motion_decisions(moved)
        assert decisions == motion_decisions(replace(moved, name=moved.name))  # made anew: no origin
        assert decisions == motion_decisions(scene, {"a": ahead, "caster": lifted})  # the motion handed over
        seen.add(decisions)
    assert len(seen) == 4  # the order of a and b, and the caster culled above the light, both move


@pytest.mark.parametrize(("name", "settings"), moving_lessons(), ids=lambda v: str(v) if v else "")
def test_a_motion_handed_over_is_the_moved_scenes(name, settings):
    """What a headless frame hands the executor instead of the moved scene (motion_parts: models
    by name and lights; the decisions from them) is exactly what the moved scene holds."""
    lesson = find_lesson(name)(**settings)
    for t in TIMES:
        scene, motion = lesson.at(t).moving()
        if motion.positions or motion.overlays or motion.camera is not None:
            continue  # (drawn from the moved scene: FrameRenderer.render_motion)
        moved = moved_scene(scene, motion)
        models, lights = motion_parts(scene, motion)
        assert set(models) <= {node.name for node in scene.nodes}
        for before, after in zip(scene.nodes, moved.nodes):
            assert np.array_equal(np.asarray(models.get(before.name, before.model)), np.asarray(after.model))
        assert lights == moved.lights
        assert motion_decisions(scene, models) == motion_decisions(moved)


def test_the_camera_keys_move_the_scene():
    from glsandbox.camera import CameraInput

    scene = find_lesson("indexed_cube")().scene()
    camera = CameraInput()
    camera.scroll(1.0, scene)
    seen = camera.apply(scene)
    assert scene_origin(seen) is scene_origin(scene) and seen.camera != scene.camera


# --- on a GL context ------------------------------------------------------------

SIZE = (96, 72)


@pytest.mark.parametrize(("name", "settings"), [
    case for case in moving_lessons() if case != ("model", {})])  # (the default traces half the frame)
def test_time_only_frames_equal_a_fresh_build_pixel_for_pixel(gl, name, settings):
    lesson = find_lesson(name)(**settings)
    gl.render(lesson, SIZE)  # the first frame builds, plans and uploads
    for t in TIMES:
        moment = lesson.at(t)
        kept = gl.render(moment, SIZE)
        fresh = gl.render_scene(moment._scene_as_built(), SIZE)  # built, planned and drawn afresh
        assert kept.plan == fresh.plan
        assert np.array_equal(kept.image, fresh.image), f"{name} {settings} at t={t}"


def test_a_parameter_changed_between_frames_changes_the_picture(gl):
    lesson = find_lesson("phong")()
    before = gl.render(lesson.at(1.0), SIZE).image.copy()
    lesson.values["specular"] = False  # as the window's key 3 does
    after = gl.render(lesson.at(1.0), SIZE)
    assert not np.array_equal(before, after.image)
    fresh = gl.render_scene(lesson.at(1.0)._scene_as_built(), SIZE)
    assert np.array_equal(after.image, fresh.image)
    cube = find_lesson("indexed_cube")()
    turning = [gl.render(cube.at(t), SIZE).image.copy() for t in (0.0, 0.5)]
    assert not np.array_equal(*turning)  # time moves the cube


def test_the_plan_is_kept_only_while_it_would_be_the_same(gl):
    """A blended node passing another flips their drawing order: the kept plan is not reused."""
    glass = Material(color=(0.2, 0.4, 1.0, 0.5), alpha_mode="blend")
    scene = Scene("blend", nodes=(Node("a", geometry.cube(), material=glass), Node("b", geometry.cube(), material=glass)),
                  camera=Camera(eye=(0.0, 0.0, 10.0)))
    first = gl.plan(moved_scene(scene, Motion(models={"a": np.eye(4)})))
    assert gl.plan(moved_scene(scene, Motion(models={"b": np.eye(4)}))) is first  # same order: kept
    ahead = np.eye(4)
    ahead[2, 3] = 3.0  # a nearer the eye: drawn last now
    flipped = moved_scene(scene, Motion(models={"a": ahead}))
    assert gl.plan(flipped) is not first and gl.plan(flipped) == plan(flipped)
    assert [d.node for d in gl.plan(flipped).passes[-1].draws] == ["b", "a"]


def test_a_model_array_changed_in_place_is_drawn_where_it_is_now(gl):
    """The executor keeps uniform bytes by a matrix's content, not by the array object."""
    model = np.eye(4)

    def frame() -> np.ndarray:
        node = Node("cube", geometry.cube(), model, Material(shading="vertex_color"))
        return gl.render_scene(Scene("s", nodes=(node,), camera=Camera(eye=(0.0, 0.0, 8.0))), SIZE).image.copy()

    first = frame()
    model[0, 3] = 1.5  # the same array, moved
    moved = frame()
    assert not np.array_equal(first, moved)
    fresh = gl.render_scene(Scene("s", nodes=(Node("cube", geometry.cube(), model.copy(),
                                                   Material(shading="vertex_color")),),
                                  camera=Camera(eye=(0.0, 0.0, 8.0))), SIZE).image
    assert np.array_equal(moved, fresh)


def _trail_scene(points: np.ndarray) -> Scene:
    line = geometry.Mesh("trail", points, mode="line_strip")
    return Scene("trail", nodes=(Node("trail", line, material=Material((1.0, 0.8, 0.1, 1.0)), cull_back_faces=False),
                                 Node("copy", geometry.Mesh("trail", points.copy(), mode="line_strip"),
                                      np.diag([1.0, -1.0, 1.0, 1.0]), Material((0.2, 1.0, 0.3, 1.0)),
                                      cull_back_faces=False)),
                 camera=Camera(eye=(0.0, 0.0, 6.0)))


def test_a_moved_mesh_is_rewritten_in_its_own_buffer(gl):
    """Motion.positions: the trail's points move each frame in one vertex buffer, not a new mesh per
    frame; a node of the same content (sharing buffers with the built mesh) keeps its own points."""
    t = np.linspace(0.0, 3.0, 32)
    start = np.stack([np.cos(t), np.sin(t), 0.0 * t], 1)
    scene = _trail_scene(start)
    gl.render_scene(scene, SIZE)
    meshes = gl.executor.mesh_count
    for turn in (0.4, 1.1, 2.5):
        points = start @ np.array([[np.cos(turn), -np.sin(turn), 0.0], [np.sin(turn), np.cos(turn), 0.0], [0, 0, 1]])
        moved = moved_scene(scene, Motion(positions={"trail": points}))
        assert moved.nodes[1] is scene.nodes[1] and moved.nodes[0].mesh.positions is not points  # its own copy
        kept = gl.render_scene(moved, SIZE).image.copy()
        fresh = gl.render_scene(replace(_trail_scene(start), nodes=(
            replace(scene.nodes[0], mesh=geometry.Mesh("trail", points, mode="line_strip")), scene.nodes[1])),
            SIZE).image
        assert np.array_equal(kept, fresh), turn
        assert not np.array_equal(kept, gl.render_scene(scene, SIZE).image)
    # The built scene and each fresh one: one shared content mesh apiece (3 turns); the moved frames
    # added one buffer set, written in place three times.
    assert gl.executor.mesh_count == meshes + 3 + 1


def test_a_moved_overlay_shows_its_new_image(gl):
    from glsandbox import Overlay, text_image

    scene = Scene("panel", overlays=(Overlay("label", text_image(["0 deg"])),))
    gl.render_scene(scene, SIZE)
    moved = moved_scene(scene, Motion(overlays={"label": text_image(["90 deg"])}))
    fresh = Scene("panel", overlays=(Overlay("label", text_image(["90 deg"])),))
    assert np.array_equal(gl.render_scene(moved, SIZE).image, gl.render_scene(fresh, SIZE).image)


# --- headless frames moved only by time: the motion handed over ------------------------------


def _counting_moved_scenes(monkeypatch) -> list:
    """Every moved scene the frame renderer makes from now on (glsandbox.frame.moved_scene)."""
    import glsandbox.frame

    made = []

    def counted(scene, motion):
        made.append(scene)
        return moved_scene(scene, motion)

    monkeypatch.setattr(glsandbox.frame, "moved_scene", counted)
    return made


@pytest.mark.parametrize(("name", "settings", "handed_over"), [
    ("indexed_cube", {}, True), ("phong", {}, True), ("texture", {}, True), ("mirror", {}, True),
    ("mirror", {"light": "directional", "shadow": "double_blend"}, True),
    ("shadow_map", {"show": "map"}, True),  # its light's frustum fitted to the models handed over
    ("transform_order", {}, False),  # its trail's points and its panel move: meshes and overlays
])
def test_a_headless_frame_moved_by_time_makes_no_moved_scene(gl, monkeypatch, name, settings, handed_over):
    lesson = find_lesson(name)(**settings)
    gl.render(lesson, SIZE)  # the first frame builds, plans (from a moved scene) and uploads
    made = _counting_moved_scenes(monkeypatch)
    for t in TIMES:
        moment = lesson.at(t)
        kept = gl.render(moment, SIZE)
        fresh = gl.render_scene(moment._scene_as_built(), SIZE)
        assert kept.plan == fresh.plan
        assert np.array_equal(kept.image, fresh.image), f"{name} {settings} at t={t}"
    assert len(made) == (0 if handed_over else len(TIMES))


class _BadCube(find_lesson("indexed_cube")):
    """The indexed cube whose motion gives a bad matrix from time 1 on (not registered)."""

    def motion(self) -> Motion:
        model = self.cube_model()
        if self.time >= 1.0:
            model = model.copy()
            model[0, 3] = float("nan") if self.time < 2.0 else 2e9
        return Motion(models={"cube": model})


def test_a_bad_motion_fails_a_headless_frame_as_it_fails_the_moved_scene(gl):
    lesson = _BadCube()
    good = gl.render(lesson.at(0.5), SIZE).image.copy()
    for t in (1.5, 2.5):
        with pytest.raises(SandboxError) as error:
            gl.render(lesson.at(t), SIZE)
        with pytest.raises(SandboxError) as expected:
            lesson.at(t).scene()
        assert str(error.value) == str(expected.value) and "node 'cube': model matrix" in str(error.value)
    assert np.array_equal(gl.render(lesson.at(0.5), SIZE).image, good)  # and the next good frame draws


def test_a_frame_after_a_changed_value_is_drawn_from_its_new_scene(gl):
    """A value changed between frames (a key) builds the scene again; the motion then moves that."""
    lesson = find_lesson("phong")()
    before_scene, _ = lesson.at(1.0).moving()
    gl.render(lesson.at(1.0), SIZE)
    lesson.on_key("4")  # the next shading
    after_scene, _ = lesson.at(1.0).moving()
    assert after_scene is not before_scene
    after = gl.render(lesson.at(1.0), SIZE)
    fresh = gl.render_scene(lesson.at(1.0)._scene_as_built(), SIZE)
    assert after.plan == fresh.plan and np.array_equal(after.image, fresh.image)


def test_a_moved_shadow_map_frame_fits_its_light_to_the_models_handed_over(gl):
    """The shadow map's light frustum follows the turning cube: drawn from the motion handed over
    (no moved scene), the frame is the moved scene's, pixel for pixel, and the map moves with it."""
    lesson = find_lesson("shadow_map")(show="map")
    images = []
    for t in (0.5, 3.0):
        scene, motion = lesson.at(t).moving()
        handed = gl.render_motion(scene, motion, SIZE)
        assert handed is not None
        fresh = gl.render_scene(moved_scene(scene, motion), SIZE)
        assert handed.plan == fresh.plan and np.array_equal(handed.image, fresh.image), f"t={t}"
        images.append(handed.image.copy())
    assert not np.array_equal(*images)  # the cube and its shadow turned


def test_the_last_frames_scene_is_found_again_only_for_the_same_values():
    """Lesson.moving finds the last frame's scene by comparing the values (no key hashed): the
    same values in another type, or a value holding an array, are not the same values."""
    cls = find_lesson("indexed_cube")
    first, _ = cls().at(0.3).moving()
    assert cls().at(1.7).moving()[0] is first
    other = cls(speed=2)  # an int, not the float default: another key, built again
    assert other.moving()[0] is not first and cls().moving()[0] is first
    held = cls()
    held.values["cull"] = (1.0,)  # a tuple: a key like any (build() reads it as true)
    kept, _ = held.moving()
    odd = cls()
    odd.values["cull"] = (np.array([1.0, 2.0]),)  # from Python: a tuple of the same type that cannot be a key
    assert odd.moving()[0] is not kept and held.moving()[0] is kept and cls().moving()[0] is first
