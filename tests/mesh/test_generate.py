"""Generated models: triangle counts, closed spheres facing out, the same mesh for the same seed."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.mesh.generate import icosphere, rock, terrain, terrain_cells_for


def triangles(mesh) -> np.ndarray:
    return mesh.positions[mesh.indices.reshape(-1, 3).astype(int)]


def edge_uses(mesh) -> dict[tuple[int, ...], int]:
    """How many triangles use each edge, vertices matched by position (split normals share one)."""
    _, vertex = np.unique(np.round(mesh.positions, 9), axis=0, return_inverse=True)
    faces = vertex.reshape(-1)[mesh.indices.reshape(-1, 3).astype(int)]
    uses: dict[tuple[int, ...], int] = {}
    for a, b, c in faces:
        for edge in ((a, b), (b, c), (c, a)):
            key = tuple(sorted(edge))
            uses[key] = uses.get(key, 0) + 1
    return uses


@pytest.mark.parametrize("subdivisions", [0, 1, 2])
def test_icosphere_is_a_closed_unit_sphere_of_20_4s_triangles_facing_out(subdivisions: int) -> None:
    mesh = icosphere(subdivisions)
    tris = triangles(mesh)
    assert len(tris) == 20 * 4 ** subdivisions
    np.testing.assert_allclose(np.linalg.norm(mesh.positions, axis=1), 1.0)
    np.testing.assert_allclose(mesh.normals, mesh.positions)  # the unit sphere's normal is its point
    outward = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    assert (np.einsum("ij,ij->i", outward, tris.mean(axis=1)) > 0).all()  # counter-clockwise from outside
    assert set(edge_uses(mesh).values()) == {2}  # closed: every edge shared by two triangles


def test_rock_is_closed_lumpy_within_its_roughness_and_the_same_for_a_seed() -> None:
    stone = rock(2, seed=3, roughness=0.2)
    radius = np.linalg.norm(stone.positions, axis=1)
    assert len(triangles(stone)) == 320
    assert radius.min() >= 0.8 - 1e-12 and radius.max() <= 1.2 + 1e-12 and np.ptp(radius) > 0.05
    assert set(edge_uses(stone).values()) == {2}
    np.testing.assert_allclose(np.linalg.norm(stone.normals, axis=1), 1.0)
    again, other = rock(2, seed=3, roughness=0.2), rock(2, seed=4, roughness=0.2)
    np.testing.assert_array_equal(again.positions, stone.positions)
    assert not np.array_equal(np.sort(np.linalg.norm(other.positions, axis=1)), np.sort(radius))


def test_terrain_has_2_cells_squared_triangles_facing_up_with_uv_across_it() -> None:
    ground = terrain(8, size=2.0, height=0.25)
    tris = triangles(ground)
    assert len(tris) == 2 * 8 * 8
    up = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])[:, 1]
    assert (up > 0).all()  # counter-clockwise seen from +y
    np.testing.assert_allclose(ground.positions[:, [0, 2]].min(axis=0), (-1.0, -1.0))
    np.testing.assert_allclose(ground.positions[:, [0, 2]].max(axis=0), (1.0, 1.0))
    heights = ground.positions[:, 1]
    assert np.ptp(heights) > 0.1 and np.abs(heights).max() < 2 * 0.25  # "within about ±height"
    np.testing.assert_array_equal(np.unique(terrain(8, height=0.5).positions[:, 1]), 2 * np.unique(heights))
    np.testing.assert_allclose(ground.uvs.min(axis=0), (0.0, 0.0))
    np.testing.assert_allclose(ground.uvs.max(axis=0), (1.0, 1.0))


def test_terrain_cells_for_comes_near_the_benchmark_counts() -> None:
    for wanted in (1_000, 10_000, 100_000, 1_000_000):
        assert abs(2 * terrain_cells_for(wanted) ** 2 - wanted) / wanted < 0.035  # 1k: 968, the nearest grid
    assert terrain_cells_for(0) == 1


@pytest.mark.parametrize("call", [lambda: icosphere(10), lambda: icosphere(1.5), lambda: rock(-1),
                                  lambda: terrain(0), lambda: terrain(4097)])
def test_out_of_range_sizes_are_refused(call) -> None:
    with pytest.raises(ValueError, match="must be an integer in"):
        call()
