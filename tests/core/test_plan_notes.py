"""glsandbox.plan_notes: one note per setting a ray-traced viewport ignores, none under the rasterizer."""

from __future__ import annotations

from dataclasses import replace

from glsandbox import geometry
from glsandbox.plan_notes import ignored_settings_notes, renderer_notes, user_shader_notes
from glsandbox.scene import Material, Node, Scene, Viewport


def scene(*materials: Material, renderer: str = "ray", **settings: object) -> Scene:
    nodes = tuple(Node(f"n{i}", geometry.cube(), material=m) for i, m in enumerate(materials))
    return Scene("s", nodes=nodes, viewports=(Viewport(renderer=renderer),), **settings)  # type: ignore[arg-type]


def test_a_raster_frame_ignores_nothing() -> None:
    raster = scene(Material(shading="gouraud"), renderer="raster", samples=4, depth_mode="reverse_z")
    assert ignored_settings_notes(raster) == () and renderer_notes(raster) == ()


def test_each_raster_approximation_is_one_note_naming_its_nodes() -> None:
    notes = ignored_settings_notes(scene(Material(shading="gouraud"), Material(shading="gouraud", normals="naive")))
    assert notes == (
        "viewport 0 is ray-traced: shading=gouraud (nodes 'n0', 'n1') is a raster approximation; the ray tracer "
        "ignores it: shaded per pixel (Phong), the picture of shading=phong",
        "viewport 0 is ray-traced: normals=naive (node 'n1') is a raster approximation; the ray tracer ignores "
        "it: shaded with the normal matrix, the picture of normals=correct")


def test_msaa_and_reverse_z_are_the_rasterizers_buffers() -> None:
    notes = ignored_settings_notes(scene(Material(), samples=4, depth_mode="reverse_z"))
    assert len(notes) == 2
    assert notes[0].startswith("--samples 4: MSAA smooths rasterized edges only and every viewport is ray-traced")
    assert notes[1].startswith("viewport 0 is ray-traced: depth mode reverse_z is the rasterizer's depth buffer")


def test_a_split_screen_names_its_ray_traced_viewports() -> None:
    split = replace(scene(Material(shading="gouraud"), samples=4),
                    viewports=(Viewport(renderer="ray"), Viewport(), Viewport(renderer="ray_numpy")))
    notes = ignored_settings_notes(split)
    assert notes[0].startswith("viewports 0, 2 are ray-traced: shading=gouraud (node 'n0')")
    assert notes[1].startswith("--samples 4: MSAA smooths rasterized edges only and viewports 0, 2 are ray-traced")


def test_a_nodes_own_shader_is_traced_with_its_material() -> None:
    own = replace(scene(Material(shading="phong")), nodes=(Node("own", geometry.cube(), shader="my.glsl"),))
    assert len(user_shader_notes(own)) == 1 and "node 'own'" in user_shader_notes(own)[0]
    assert renderer_notes(own) == user_shader_notes(own)
