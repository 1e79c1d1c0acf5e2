"""The numpy engine's fast paths give the same numbers as the plain ones, bit for bit.

Primary rays share one origin (the eye), so the kernels form the origin's
terms once per shape instead of once per ray; ray-triangle pairs are
processed in cache-sized blocks; the renderer traces an image block by block.
None of that may change a single bit of ``t`` or of a pixel.
"""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.lesson import find_lesson
from glsandbox.raytrace import AABB, Sphere, TriangleBatch, moller_trumbore_many, render
from glsandbox.raytrace import numpy_engine as render_module
from glsandbox.raytrace.shape_protocol import shared_origin
from glsandbox.raytrace.world import build_world, camera_basis, camera_rays

RNG = np.random.default_rng(7)
EYE = np.array([0.3, 1.7, 6.2])
#: Directions from the eye towards a cloud around the origin, plus axis-parallel and ±0 components.
DIRS = np.concatenate([
    RNG.normal(0.0, 1.5, (3000, 3)) - EYE,
    np.array([[0.0, 0.0, -1.0], [-0.0, 0.0, -1.0], [0.0, -0.0, -1.0], [1e-300, 0.0, -1.0], [0.0, 0.0, 0.0]]),
])
TRIANGLES = [RNG.normal(0.0, 1.0, (40, 3)) for _ in range(3)]


def per_ray(origin: np.ndarray) -> np.ndarray:
    """The shared origin as a real ``(N, 3)`` array: the kernels' per-ray path."""
    return np.tile(origin, (len(DIRS), 1))


def test_shared_origin_is_recognised_only_for_a_broadcast() -> None:
    broadcast = np.broadcast_to(EYE, DIRS.shape)
    assert shared_origin(broadcast).shape == (3,)
    assert shared_origin(per_ray(EYE)).shape == (len(DIRS), 3)
    assert shared_origin(np.broadcast_to(EYE, (0, 3))).shape == (0, 3)


@pytest.mark.parametrize("cull", [False, True])
def test_moller_trumbore_with_one_origin_equals_an_origin_per_ray(cull: bool) -> None:
    shared = moller_trumbore_many(EYE, DIRS, *TRIANGLES, cull_backfaces=cull)
    assert np.isfinite(shared).any()
    np.testing.assert_array_equal(shared, moller_trumbore_many(per_ray(EYE), DIRS, *TRIANGLES, cull_backfaces=cull))


@pytest.mark.parametrize("chunk", [1, 7, 64, 1000, 1 << 20])
def test_nearest_many_blocks_do_not_change_the_answer(chunk: int) -> None:
    """Rays and triangles in blocks of any size: the same ``t`` and index (ties: lower index)."""
    a, b, c = TRIANGLES
    batch = TriangleBatch(np.concatenate([a, a]), np.concatenate([b, b]), np.concatenate([c, c]))  # every hit tied
    t_all = moller_trumbore_many(EYE, DIRS, batch.v0, batch.v1, batch.v2)
    t, i = batch.nearest_many(EYE, DIRS, chunk_elements=chunk)
    np.testing.assert_array_equal(t, t_all.min(axis=1))
    np.testing.assert_array_equal(i, np.where(np.isfinite(t), np.argmin(t_all, axis=1), -1))
    assert (i < len(a)).all()  # the first copy wins every tie


def test_sphere_with_one_origin_equals_an_origin_per_ray() -> None:
    for sphere in (Sphere((0.2, -0.1, 0.3), 1.1), Sphere(EYE + (0.1, 0.0, 0.0), 0.5)):  # outside, then inside
        shared = sphere.intersect_many(EYE, DIRS)
        assert np.isfinite(shared).any()
        np.testing.assert_array_equal(shared, sphere.intersect_many(per_ray(EYE), DIRS))


def test_slabs_with_one_origin_equal_an_origin_per_ray() -> None:
    for box in (AABB((-1, -1, -1), (1, 1, 1)), AABB((-1, 1.7, -1), (1, 1.7, 1)), AABB(EYE - 0.5, EYE + 0.5)):
        near, far = box.slabs(EYE, DIRS)
        near_rows, far_rows = box.slabs(per_ray(EYE), DIRS)
        np.testing.assert_array_equal(near, near_rows)
        np.testing.assert_array_equal(far, far_rows)
        assert not (np.isnan(near).any() or np.isnan(far).any())


def test_camera_rays_in_blocks_are_every_pixel_times_the_basis() -> None:
    """camera_rays multiplies by the camera's basis a block of rows at a time: every row is done."""
    camera = find_lesson("ray_phong")(renderer="raster").scene().camera
    width, height = 331, 97  # 32107 rays: several blocks and a partial one
    eye, dirs = camera_rays(camera, width, height)
    origin, basis, half_w, half_h = camera_basis(camera, width / height)
    j, i = np.divmod(np.arange(width * height), width)
    view = np.stack([(2 * (i + 0.5) / width - 1) * half_w, (1 - 2 * (j + 0.5) / height) * half_h,
                     -np.ones(i.size)], axis=1)
    np.testing.assert_allclose(dirs, np.einsum("ij,nj->ni", basis, view), rtol=0, atol=1e-14)
    np.testing.assert_array_equal(eye, origin)


@pytest.mark.parametrize("lesson", ["ray_phong", "phong"])
def test_rendering_in_blocks_gives_the_same_image(lesson: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """Blocks of primary rays (shadow rays and bounces included) against one pass over the image."""
    scene = find_lesson(lesson)(renderer="raster").scene()
    world = build_world(scene)
    assert world.materials.lit.shape == (len(world.nodes),)
    images = []
    for block in (1 << 30, 97):
        monkeypatch.setattr(render_module, "RAY_BLOCK", block)
        stats = render_module.RenderStats()
        images.append((render(scene, (64, 48), max_depth=2, stats=stats), (stats.rays, stats.tests)))
    assert images[0][1] == images[1][1]
    np.testing.assert_array_equal(images[0][0], images[1][0])
