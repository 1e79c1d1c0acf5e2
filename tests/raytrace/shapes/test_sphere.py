"""The unit sphere kind's error bound, in both engines: a ray leaving a point on a sphere never
meets that surface again at ``t ≈ 0`` (outward: no hit; inward: the far side), at every radius.

The numpy engine's test is :meth:`Sphere.intersect_many` (the course API's sphere, which the
engine's unit sphere is); the gpu engine's is ``shaders/shapes/sphere.glsl``'s ``sphere_t``,
run here on the rays the engine would give it: world points relative to the sphere's centre in
float32, taken into its own space by the float32 inverse model matrix, as ``to_object`` does."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace.sphere import Sphere

RADII = (1e-3, 1.0, 10.0, 1e3, 1e5, 1e6)


def surface_rays(radius: float, centre: np.ndarray, count: int = 4000, seed: int = 0
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points on the sphere (rounded to float64, as any computed hit is), a random unit
    direction leaving each outwards, and the chord length ``2r·cos`` an inward ray crosses."""
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    cos = np.einsum("ij,ij->i", d, n)
    d *= np.sign(cos)[:, None]
    return centre + radius * n, d, 2.0 * radius * np.abs(cos)


@pytest.mark.parametrize("radius", RADII)
@pytest.mark.parametrize("where", ["origin", "offset", "far"])
def test_rays_leaving_a_sphere_never_meet_it_again_at_zero(radius: float, where: str) -> None:
    centre = {"origin": np.zeros(3), "offset": radius * np.array([0.3, -0.2, 0.5]),
              "far": np.array([1e5, -3e4, 2e4])}[where]
    sphere = Sphere(centre, radius)
    points, out, chord = surface_rays(radius, centre)
    t_out = np.array([sphere.intersect_many(p, d[None])[0] for p, d in zip(points, out)])
    assert np.count_nonzero(np.isfinite(t_out)) == 0  # outward: nothing to hit
    t_in = np.array([sphere.intersect_many(p, -d[None])[0] for p, d in zip(points, out)])
    # Inward: the far side, to within the rounding of the points (u·(|C| + r) each), never t ≈ 0.
    slack = 1e-12 * (np.linalg.norm(centre) + radius)
    crossing = chord > 8 * slack  # a chord shorter than the points' own error is no test
    assert crossing.mean() > 0.99
    np.testing.assert_allclose(t_in[crossing], chord[crossing], rtol=1e-9, atol=8 * slack)
    # Batched (one origin per ray) as the engines call it: the same.
    np.testing.assert_array_equal(sphere.intersect_many(points, -out), t_in)


def test_the_bound_keeps_hits_from_just_off_the_surface() -> None:
    """An origin a thousandth of the radius outside still sees the sphere in front of it, and one
    that far inside still leaves through the near wall: the bound is the arithmetic's, no wider."""
    for radius in (1.0, 1e6):
        sphere = Sphere((0.0, 0.0, 0.0), radius)
        out = sphere.intersect_many(np.array([0.0, 0.0, 1.001 * radius]), np.array([[0.0, 0.0, -1.0]]))[0]
        inside = sphere.intersect_many(np.array([0.0, 0.0, 0.999 * radius]), np.array([[0.0, 0.0, 1.0]]))[0]
        assert out == pytest.approx(1e-3 * radius, rel=1e-9)
        assert inside == pytest.approx(1e-3 * radius, rel=1e-9)


PROBE = """#version 400 core
#if defined(VERTEX_SHADER)
#include "common/fullscreen_vertex.glsl"
#elif defined(FRAGMENT_SHADER)
const float PI = 3.14159265358979;
#include "shapes/sphere.glsl"
uniform sampler2D u_origins;
uniform sampler2D u_directions;
uniform vec4 u_inverse[3];
out vec4 out_t;
void main() {
    ivec2 at = ivec2(gl_FragCoord.xy);
    vec4 o = vec4(texelFetch(u_origins, at, 0).xyz, 1.0);
    vec4 d = vec4(texelFetch(u_directions, at, 0).xyz, 0.0);
    vec3 oo = vec3(dot(u_inverse[0], o), dot(u_inverse[1], o), dot(u_inverse[2], o));
    vec3 dd = vec3(dot(u_inverse[0], d), dot(u_inverse[1], d), dot(u_inverse[2], d));
    out_t = vec4(sphere_t(oo, dd, false), 0.0, 0.0, 1.0);
}
#endif
"""


def gpu_sphere_t(ctx, tmp_path, radius: float, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """``sphere_t`` on the gpu for world rays at a sphere of ``radius`` (its centre the upload's
    anchor, as the gpu engine's for a lone sphere): ``t`` in world units of the direction."""
    import moderngl

    from glsandbox.gl.shaders import compile_program
    from glsandbox.plan import ProgramVariant
    from glsandbox.raytrace.constants import glsl_defines

    path = tmp_path / "probe.glsl"
    path.write_text(PROBE)
    program = compile_program(ctx, ProgramVariant(str(path), glsl_defines(), user=True))
    n = origins.shape[0]
    size = (n, 1)
    textures = []
    for unit, (name, rows) in enumerate((("u_origins", origins), ("u_directions", directions))):
        data = np.zeros((n, 4), dtype=np.float32)
        data[:, :3] = rows  # relative to the centre, float32, as gpu.py uploads them
        texture = ctx.texture(size, 4, data.tobytes(), dtype="f4")
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.use(unit)
        program[name].value = unit
        textures.append(texture)
    inverse = np.zeros((3, 4), dtype=np.float32)
    inverse[:, :3] = np.eye(3) / radius  # the inverse model matrix's rows (scale 1/r; the centre is 0)
    program["u_inverse"].write(inverse.tobytes())
    target = ctx.texture(size, 4, dtype="f4")
    frame = ctx.framebuffer(color_attachments=[target])
    vao = ctx.vertex_array(program, [])
    try:
        frame.use()
        frame.viewport = (0, 0, *size)
        vao.render(moderngl.TRIANGLE_STRIP, vertices=4)
        return np.frombuffer(frame.read(components=4, dtype="f4"), dtype=np.float32).reshape(n, 4)[:, 0].copy()
    finally:
        for thing in (vao, frame, target, program, *textures):
            thing.release()


@pytest.mark.parametrize("radius", RADII)
def test_the_gpu_sphere_test_never_meets_the_surface_it_leaves(gl, tmp_path, radius: float) -> None:
    from glsandbox.raytrace.constants import NO_HIT_F32

    points, out, chord = surface_rays(radius, np.zeros(3), count=2000)
    ctx = gl.host.ctx
    t_out = gpu_sphere_t(ctx, tmp_path, radius, points, out)
    assert np.count_nonzero(t_out < NO_HIT_F32) == 0
    t_in = gpu_sphere_t(ctx, tmp_path, radius, points, -out)
    crossing = chord > 1e-2 * radius  # float32: a grazing chord (cos < 0.005) is known to no better than its length
    assert crossing.mean() > 0.99
    # The far side, not t ≈ 0 (a t ≈ 0 is off by the whole chord); a grazing chord's float32
    # length is off by about u·r/cos, so the tolerance grows as the chord shortens.
    off = np.abs(t_in[crossing] - chord[crossing])
    assert np.all(off <= 0.1 * chord[crossing] + 1e-5 * radius), off.max()
    assert np.median(off / chord[crossing]) < 1e-5
