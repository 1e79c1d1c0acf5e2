"""What the shader saw at a rasterised pixel, and a blended pass's inputs and result.

The X-ray (:mod:`glsandbox.story.xray`) names the node and triangle whose fragment
wrote a pixel in each pass (``gl_PrimitiveID``). :func:`fragment_values` finds the
values the rasterizer interpolated for that fragment: its triangle as the pass drew
it (the node's model matrix, times the mirror's reflection ``R`` in the reflected
pass or the lifted shadow matrix ``S`` in the planar shadow, course "XMMatrixReflect,
XMMatrixShadow") is met by the eye's ray through the pixel's centre; where it meets it
are the perspective-correct barycentric weights (the ray-triangle test's ``u, v``,
course "Işın-Üçgen kesim testi": a perspective projection maps the triangle's plane
to the screen projectively, so the weights that interpolate correctly on screen are
the 3D point's). With them: the world position, the normal (the vertex normals through
the normal matrix ``(M⁻¹)ᵀ``, before the shader normalizes them), the texture
coordinates, and the window depth the depth test compared (the position projected as
the pass projects it, reverse-Z when the scene asks: the tests compare it with the
depth buffer read back).

:func:`blend_values` gives a blended pass's inputs and result: the source colour and
its alpha, the destination (the colour before the pass) and the result
``src·a + dst·(1 − a)`` (``glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA)``, the
planar shadow's, course "blending"), beside the result read back. An 8-bit target
blends in 8 bits: ``a`` is the source alpha as the target stores it (0.5 is 128/255),
so 65 blended with black is 32, not 33.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from glsandbox import transforms
from glsandbox.scene import Scene

__all__ = ["blend_values", "fragment_values"]


def _pass_matrix(scene: Scene, kind: str) -> np.ndarray | None:
    """What the pass multiplies the model matrix by: ``R`` (reflection), ``S`` (planar shadow), or nothing."""
    if kind == "reflection" and scene.mirror is not None:
        return scene.mirror.matrix()
    if kind == "planar_shadow" and scene.planar_shadow is not None:
        return scene.planar_shadow.matrix()
    return None


def _triangle(node: Any, triangle: int) -> tuple[int, int, int] | None:
    mesh = node.mesh
    if mesh.mode != "triangles":
        return None
    indices = np.arange(len(mesh.positions)) if mesh.indices is None else np.asarray(mesh.indices).reshape(-1)
    if not 0 <= triangle < len(indices) // 3:
        return None
    a, b, c = (int(i) for i in indices[3 * triangle:3 * triangle + 3])
    return a, b, c


def fragment_values(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], viewport: int, kind: str,
                    node_name: str, triangle: int) -> dict[str, Any] | None:
    """The interpolated values of ``node_name``'s triangle ``triangle`` at frame pixel ``pixel`` (row 0
    at the top) as pass ``kind`` drew it in ``viewport``: ``uvw`` (the barycentric weights of the
    triangle's three vertices), ``position``, ``normal`` (as interpolated; ``normal_unit`` normalized),
    ``uv``, ``depth`` (the window depth). None where they cannot be told (not a triangle mesh, or the
    eye's ray misses the triangle's plane)."""
    node = next((n for n in scene.nodes if n.name == node_name), None)
    if node is None:
        return None
    corners = _triangle(node, triangle)
    if corners is None:
        return None
    world = np.asarray(node.model, dtype=np.float64)
    extra = _pass_matrix(scene, kind)
    if extra is not None:
        world = np.asarray(extra, dtype=np.float64) @ world
    mesh = node.mesh
    points = transforms.transform_points(world, np.asarray(mesh.positions, dtype=np.float64)[list(corners)])
    vp = scene.viewports[viewport]
    width, height = size
    vx, vy, w, h = vp.pixels(width, height)
    camera = vp.camera or scene.camera
    view_proj = camera.projection(w / h) @ camera.view()
    # The pixel's centre in normalized device coordinates (GL's rows count up from the bottom).
    gl_row = height - 1 - pixel[1]
    ndc_x = 2.0 * (pixel[0] - vx + 0.5) / w - 1.0
    ndc_y = 2.0 * (gl_row - vy + 0.5) / h - 1.0
    inverse = np.linalg.inv(view_proj)
    near, far = (transforms.transform_points(inverse, np.array([[ndc_x, ndc_y, z]]))[0] for z in (-1.0, 1.0))
    direction = far - near
    # The eye's ray against the triangle's plane: R0 + t·Rd = (1 − u − v)·A + u·B + v·C.
    a, b, c = points
    e1, e2 = b - a, c - a
    matrix = np.column_stack([-direction, e1, e2])
    if abs(np.linalg.det(matrix)) < 1e-300:
        return None
    t, u, v = np.linalg.solve(matrix, near - a)
    weights = np.array([1.0 - u - v, u, v])
    position = weights @ points
    out: dict[str, Any] = {"node": node_name, "triangle": triangle, "vertices": list(corners),
                           "uvw": [float(x) for x in weights], "position": [float(x) for x in position]}
    flat = kind == "planar_shadow"  # one colour, unlit, untextured: no normal or uv (and S is singular)
    if mesh.normals is not None and not flat:
        normal_matrix = np.linalg.inv(world[:3, :3]).T  # normals go by (M⁻¹)ᵀ (course: the normal matrix)
        normals = np.asarray(mesh.normals, dtype=np.float64)[list(corners)] @ normal_matrix.T
        normal = weights @ normals
        length = float(np.linalg.norm(normal))
        out["normal"] = [float(x) for x in normal]
        out["normal_unit"] = [float(x) / length for x in normal] if length > 0 else None
    if mesh.uvs is not None and not flat:
        out["uv"] = [float(x) for x in weights @ np.asarray(mesh.uvs, dtype=np.float64)[list(corners)]]
    from glsandbox.gl.depth import (
        projection_for,  # the pass's own projection: reverse-Z when the scene asks
    )

    clip = projection_for(scene, camera.projection(w / h)) @ camera.view() @ np.append(position, 1.0)
    z = clip[2] / clip[3]
    out["depth"] = float(z if scene.depth_mode == "reverse_z" else 0.5 * z + 0.5)
    return out


def blend_values(scene: Scene, kind: str, before: list[int], after: list[int]) -> dict[str, Any] | None:
    """A blended pass's inputs and result at one pixel (8-bit levels): the planar shadow's source is
    its colour and alpha (one colour, unlit); the result is ``src·a + dst·(1 − a)``, beside the level
    read back. None for a pass whose source is not one colour (the glass: lit, per pixel)."""
    if kind != "planar_shadow" or scene.planar_shadow is None:
        return None
    color = scene.planar_shadow.color
    alpha = float(color[3])
    stored = float(np.floor(alpha * 255.0 + 0.5)) / 255.0  # an 8-bit target blends with the 8-bit alpha
    source = [float(c) for c in color[:3]]
    destination = [c / 255.0 for c in before[:3]]
    result = [s * stored + d * (1.0 - stored) for s, d in zip(source, destination, strict=True)]
    return {"source": source, "alpha": alpha, "alpha8": int(round(stored * 255.0)), "destination": before[:3],
            "result": [int(np.floor(r * 255.0 + 0.5)) for r in result], "read_back": after[:3]}
