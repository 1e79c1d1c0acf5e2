"""What a frame does differently from what the scene asks, because of who renders it.

A ray-traced viewport cannot run a node's own GLSL, and ignores the settings that
belong to the rasterizer (raster approximations and raster techniques): each such
setting gets one note, which ``glsandbox plan``, ``render`` and ``run`` print.
"""

from __future__ import annotations

from glsandbox.scene import Node, Scene


def user_shader_note(viewport: int, node: Node) -> str:
    """What a ray-traced viewport does with a node that has a shader of its own."""
    return (f"viewport {viewport} is ray-traced: the ray tracer cannot run GLSL, so node {node.name!r} "
            f"(shader {node.shader}) is traced with its material ({node.material.shading})")


def user_shader_notes(scene: Scene) -> tuple[str, ...]:
    """One :func:`user_shader_note` per node with its own shader in each ray-traced viewport."""
    return tuple(user_shader_note(index, node) for index, viewport in enumerate(scene.viewports)
                 if viewport.renderer != "raster" for node in scene.nodes
                 if node.shader is not None and node.shown_in(index))


def _nodes(names: list[str]) -> str:
    """``node 'a'`` or ``nodes 'a', 'b'``."""
    return f"node{'s' if len(names) > 1 else ''} {', '.join(repr(name) for name in names)}"


def _approximation_notes(where: str, shown: list[Node]) -> list[str]:
    """Gouraud shading and naive normals: the ray tracer shades every pixel with the normal matrix."""
    notes = []
    for what, picked, instead in (
            ("shading=gouraud", [n.name for n in shown if n.material.shading == "gouraud"],
             "shaded per pixel (Phong), the picture of shading=phong"),
            ("normals=naive", [n.name for n in shown if n.material.normals == "naive"],
             "shaded with the normal matrix, the picture of normals=correct")):
        if picked:
            notes.append(f"{where} ray-traced: {what} ({_nodes(picked)}) is a raster approximation; "
                         f"the ray tracer ignores it: {instead}")
    return notes


def _filter_notes(where: str, shown: list[Node]) -> list[str]:
    """Texture filters other than ``linear``: a ray samples the base level bilinearly."""
    filtered: dict[str, list[str]] = {}
    for node in shown:
        texture = node.material.texture
        if texture is not None and texture.filter != "linear":
            filtered.setdefault(texture.filter, []).append(node.name)
    return [f"{where} ray-traced: texture filter {name} ({_nodes(nodes)}) is the rasterizer's sampler; the ray "
            "tracer samples the base level bilinearly (filter=linear, no mipmaps: a ray has no footprint)"
            for name, nodes in filtered.items()]


def _technique_notes(scene: Scene, where: str, shown: list[Node]) -> list[str]:
    """The planar mirror and shadow, and the shadow map: the ray tracer traces reflection and shadow rays."""
    notes = []
    names = {node.name for node in shown}
    if scene.mirror is not None and scene.mirror.node in names:
        how = "through the stencil" if scene.mirror.stencil else "without the stencil (it leaks)"
        notes.append(f"{where} ray-traced: the planar mirror {scene.mirror.node!r} drawn {how} is a raster "
                     "technique; the ray tracer traces reflection rays off the glass instead")
    planar = scene.planar_shadow
    if planar is not None and planar.receiver in names:
        notes.append(f"{where} ray-traced: the planar shadow on {planar.receiver!r} is a raster technique; "
                     "the ray tracer casts shadow rays to the lights instead")
    mapped = [i for i, light in enumerate(scene.lights) if light.shadow is not None]
    if mapped and any(node.receives_shadow and node.material.lit for node in shown):
        notes.append(f"{where} ray-traced: light {mapped[0]}'s shadow map is a raster technique; the ray tracer "
                     "casts shadow rays to the lights instead (exact: no resolution, bias or filter)")
    return notes


def _buffer_notes(scene: Scene, where: str, ray: list[int]) -> list[str]:
    """MSAA (one ray per pixel) and reverse-Z (a depth buffer)."""
    notes = []
    if scene.samples > 1:
        every = "every viewport is" if len(ray) == len(scene.viewports) else f"{where}"
        notes.append(f"--samples {scene.samples}: MSAA smooths rasterized edges only and {every} ray-traced "
                     "with 1 ray per pixel, so its picture does not change")
    if scene.depth_mode != "standard":
        notes.append(f"{where} ray-traced: depth mode {scene.depth_mode} is the rasterizer's depth buffer; "
                     "the ray tracer compares hit distances in float64/float32 and ignores it")
    return notes


def ignored_settings_notes(scene: Scene) -> tuple[str, ...]:
    """What a ray-traced viewport ignores of what the scene asks, one note each: Gouraud
    shading and naive normals (raster approximations: the ray tracer shades every pixel
    with the normal matrix), texture filters other than ``linear`` (a ray samples the
    base level bilinearly), the planar mirror and shadow (raster techniques: the ray
    tracer traces reflection and shadow rays), MSAA (one ray per pixel), reverse-Z
    (a depth buffer)."""
    ray = [i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"]
    if not ray:
        return ()
    where = f"viewport {ray[0]} is" if len(ray) == 1 else f"viewports {', '.join(map(str, ray))} are"
    shown = [node for node in scene.nodes if any(node.shown_in(i) for i in ray)]
    return (*_approximation_notes(where, shown), *_filter_notes(where, shown),
            *_technique_notes(scene, where, shown), *_buffer_notes(scene, where, ray))


def renderer_notes(scene: Scene) -> tuple[str, ...]:
    """Everything a frame does differently from what the scene asks, because of who renders
    it: a node's own shader traced with its material, settings the ray tracer ignores."""
    return (*user_shader_notes(scene), *ignored_settings_notes(scene))
