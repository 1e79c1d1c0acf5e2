"""The plan of a frame with ray-traced viewports tells the truth.

``glsandbox plan ray_phong --set renderer=ray`` listed a 24-bit depth buffer and
Phong draw passes, while the frame is a ray-traced picture under an overlay.
Now a ``trace`` pass says who traces each such viewport and how, and the
raster passes are those of the frame actually drawn.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from glsandbox.frame import trace_viewports, with_samples
from glsandbox.lesson import find_lesson
from glsandbox.plan import ignored_settings_notes, plan, traced_reflectivity


def lesson_scene(name: str, *settings: str):
    return find_lesson(name).from_settings(settings).scene()


def test_a_ray_traced_viewport_is_a_trace_pass_and_no_raster_draw() -> None:
    scene = lesson_scene("ray_phong", "renderer=ray")
    frame = plan(scene)
    first = frame.passes[0]
    assert first.kind == "trace" and first.viewport == 0
    text = first.describe()
    assert text.startswith("trace viewport 0 (GLSL ray tracer, float32, 1 primary ray per pixel, "
                           "shadow rays to 2 lights, reflections up to 2 bounces, shown as overlay raytrace/0): ")
    assert [d.node for d in first.draws] == [n.name for n in scene.nodes]
    assert "mirror (phong, reflects 0.6)" in text and "lamp0 (solid)" in text
    # what the rasterizer then does: a clear without depth, the traced image, the figures
    assert [p.kind for p in frame.passes[1:]] == ["clear", "overlay", "overlay"]
    assert not frame.buffers.depth and [p.key for p in frame.programs] == ["overlay"]
    assert frame.passes[2].describe() == "overlay viewport 0 (blended, no depth test): raytrace/0"
    # the raster renderer's plan of the same lesson draws Phong with depth, and traces nothing
    raster = plan(lesson_scene("ray_phong", "renderer=raster"))
    assert raster.buffers.depth and all(p.kind != "trace" for p in raster.passes)


def test_the_numpy_engine_is_named_and_a_split_screen_traces_only_its_ray_side() -> None:
    assert plan(lesson_scene("ray_phong", "renderer=ray_numpy")).passes[0].describe().startswith(
        "trace viewport 0 (numpy ray tracer, float64, ")
    model = plan(lesson_scene("model"))  # rasterizer left, ray tracer right
    traced = [p.viewport for p in model.passes if p.kind == "trace"]
    drawn = [p.viewport for p in model.passes if p.kind == "draw"]
    assert traced == [1] and drawn == [0]


def test_the_printed_plan_is_the_plan_of_the_frame_drawn(gl) -> None:
    for name, settings in (("ray_phong", ("renderer=ray",)), ("model", ("mesh=rock",)),
                           ("phong", ("renderer=ray_numpy",)), ("phong", ())):
        scene = lesson_scene(name, *settings)
        frame = gl.render_scene(scene, (48, 36))
        assert frame.plan.describe() == plan(scene).describe(), name
        # and its raster passes are exactly those the executor ran on the traced scene
        executed = plan(trace_viewports(scene, (48, 36), gl.host.ctx))
        assert [p for p in frame.plan.passes if p.kind != "trace"] == list(executed.passes), name
        assert frame.plan.buffers == executed.buffers


def test_settings_the_ray_tracer_ignores_are_notes_and_really_change_nothing(gl) -> None:
    phong = lesson_scene("phong", "renderer=ray", "time=1")
    gouraud = lesson_scene("phong", "renderer=ray", "time=1", "shading=gouraud", "normals=naive")
    notes = ignored_settings_notes(gouraud)
    assert len(notes) == 2
    assert notes[0].startswith("viewport 0 is ray-traced: shading=gouraud (nodes 'ground', 'ellipsoid') is a raster "
                               "approximation; the ray tracer ignores it")
    assert notes[1].startswith("viewport 0 is ray-traced: normals=naive (nodes 'ground', 'ellipsoid')")
    assert plan(gouraud).notes == notes and ignored_settings_notes(phong) == ()
    # what the notes claim: the same picture
    size = (48, 36)
    np.testing.assert_array_equal(gl.render_scene(phong, size).image, gl.render_scene(gouraud, size).image)
    # the rasterizer does draw Gouraud: no note there
    assert ignored_settings_notes(lesson_scene("phong", "shading=gouraud", "normals=naive")) == ()


def test_msaa_under_the_ray_tracer_is_a_note_and_the_same_picture(gl) -> None:
    scene = lesson_scene("ray_spheres")  # renderer=ray by default
    four = with_samples(scene, 4)
    assert ignored_settings_notes(four) == ("--samples 4: MSAA smooths rasterized edges only and every viewport is "
                                            "ray-traced with 1 ray per pixel, so its picture does not change",)
    np.testing.assert_array_equal(gl.render_scene(scene, (48, 36)).image, gl.render_scene(four, (48, 36)).image)
    split = lesson_scene("model", "mesh=rock")  # one raster viewport: MSAA does smooth that one
    assert ignored_settings_notes(with_samples(split, 4))[0].startswith(
        "--samples 4: MSAA smooths rasterized edges only and viewport 1 is ray-traced")


def test_the_mirrors_glass_reflects_as_the_tracer_traces_it() -> None:
    scene = lesson_scene("mirror")
    glass = next(n for n in scene.nodes if n.name == scene.mirror.node)
    assert traced_reflectivity(scene, glass) == max(glass.material.reflectivity, 1.0 - glass.material.color[3])
    other = next(n for n in scene.nodes if n.name != scene.mirror.node)
    assert traced_reflectivity(scene, other) == other.material.reflectivity
    traced = plan(replace(scene, viewports=tuple(replace(v, renderer="ray") for v in scene.viewports)))
    assert f"{glass.name} (" in traced.passes[0].describe()


def test_raster_techniques_and_samplers_under_the_ray_tracer_are_notes(gl) -> None:
    mirror = ignored_settings_notes(lesson_scene("mirror", "renderer=ray", "mirror=no_stencil"))
    assert [note.split(": ", 1)[1].split(" is ")[0] for note in mirror] == [
        "the planar mirror 'glass' drawn without the stencil (it leaks)", "the planar shadow on 'floor'",
        "depth mode reverse_z"]
    assert ignored_settings_notes(lesson_scene("mirror", "renderer=raster")) == ()
    texture = ignored_settings_notes(lesson_scene("texture", "renderer=ray", "filter=anisotropic"))
    assert texture == ("viewport 0 is ray-traced: texture filter anisotropic (nodes 'ground', 'cube') is the "
                       "rasterizer's sampler; the ray tracer samples the base level bilinearly (filter=linear, "
                       "no mipmaps: a ray has no footprint)",)
    assert ignored_settings_notes(lesson_scene("texture", "renderer=ray", "filter=linear")) == ()
    # the claim: under the ray tracer every filter gives the linear picture
    pictures = [gl.render_scene(lesson_scene("texture", "renderer=ray", f"filter={name}", "time=1"), (48, 36)).image
                for name in ("linear", "mip_linear", "nearest")]
    np.testing.assert_array_equal(pictures[0], pictures[1])
    np.testing.assert_array_equal(pictures[0], pictures[2])
