"""glsandbox.geometry: the course's cube and its winding through the DirectX conversion, and the
quad as a strip and as a list. No GL."""

from __future__ import annotations

import numpy as np

from glsandbox import geometry


def outward(triangles: np.ndarray) -> np.ndarray:
    """Per triangle: does the counter-clockwise normal point away from the origin?"""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    normal = np.cross(b - a, c - a)
    return np.einsum("ij,ij->i", normal, (a + b + c) / 3) > 0


def test_course_cube_has_8_vertices_and_36_indices() -> None:
    cube = geometry.cube()
    assert cube.positions.shape == (8, 3)
    assert cube.indices.shape == (36,)
    assert sorted(set(cube.indices.tolist())) == list(range(8))


def test_course_cube_is_clockwise_in_directx_and_counter_clockwise_after_conversion() -> None:
    # In the course's left-handed frame every triangle's algebraic normal
    # (b-a)x(c-a) points outward, which a left-handed viewer sees clockwise.
    course = geometry.COURSE_CUBE_VERTICES[geometry.COURSE_CUBE_INDICES.reshape(-1, 3)]
    assert outward(course).all()
    # After the one conversion (mirror z, swap two indices) they are
    # counter-clockwise as seen from outside in OpenGL: all front faces.
    assert outward(geometry.cube().triangles()).all()


def test_mirror_alone_would_make_every_face_a_back_face() -> None:
    mirrored = geometry.COURSE_CUBE_VERTICES * np.array([1, 1, -1])
    tri = mirrored[geometry.COURSE_CUBE_INDICES.reshape(-1, 3)]
    assert not outward(tri).any()


def test_strip_and_list_quads_cover_the_same_triangles_with_the_same_winding() -> None:
    def canonical(tris: np.ndarray) -> list:
        out = []
        for t in tris:  # rotate each triangle so its smallest vertex is first: keeps winding
            k = min(range(3), key=lambda i: tuple(t[i]))
            out.append(tuple(map(tuple, np.roll(t, -k, axis=0))))
        return sorted(out)

    strip, quad_list = geometry.quad_strip(), geometry.quad_list()
    assert strip.vertex_count == 4 and quad_list.vertex_count == 6
    assert canonical(strip.triangles()) == canonical(quad_list.triangles())
    swapped = geometry.quad_list_swapped().triangles()
    normals_z = np.cross(swapped[:, 1] - swapped[:, 0], swapped[:, 2] - swapped[:, 0])[:, 2]
    assert normals_z[0] > 0 > normals_z[1]
