"""Benchmark: each lesson's frame through glsandbox vs a hand-written raw-ModernGL frame.

Run with every other benchmark by ``glsandbox bench`` (the indexed cube's
case lives in ``cube_frame.py``). Each raw class draws the lesson's default
frame at 800x600 with plain ModernGL calls: its own shaders (the same
formulas as ``shaders/``), matrices by hand (``_raw.py``), state set
directly. Mesh and image data come from glsandbox.geometry / glsandbox.images
(arrays, uploaded once; not per-frame work). The table's last column says
whether both draw the same picture. Goal (issue 7): glsandbox <= 1.10x raw.
``transform_order`` has no raw baseline yet (its trail and overlays).
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from _raw import framebuffer, gl, look_at, perspective, read, rotate_y, scale, translate

SOLID_VS = """#version 330 core
uniform mat4 m_model; uniform mat4 m_view; uniform mat4 m_proj;
in vec3 in_position;
void main() { gl_Position = m_proj * m_view * m_model * vec4(in_position, 1.0); }
"""
SOLID_FS = """#version 330 core
uniform vec4 u_color; out vec4 frag_color;
void main() { frag_color = u_color; }
"""
TEXTURED_VS = """#version 330 core
uniform mat4 m_model; uniform mat4 m_view; uniform mat4 m_proj;
in vec3 in_position; in vec2 in_uv; out vec2 v_uv;
void main() { gl_Position = m_proj * m_view * m_model * vec4(in_position, 1.0); v_uv = in_uv; }
"""
TEXTURED_FS = """#version 330 core
uniform vec4 u_color; uniform sampler2D u_texture; in vec2 v_uv; out vec4 frag_color;
void main() { frag_color = u_color * texture(u_texture, v_uv); }
"""
PHONG_VS = """#version 330 core
uniform mat4 m_model; uniform mat4 m_view; uniform mat4 m_proj; uniform mat3 m_normal;
in vec3 in_position; in vec3 in_normal; out vec3 v_world; out vec3 v_normal;
void main() {
    vec4 world = m_model * vec4(in_position, 1.0);
    gl_Position = m_proj * m_view * world;
    v_world = world.xyz; v_normal = normalize(m_normal * in_normal);
}
"""
PHONG_FS = """#version 330 core
uniform vec4 u_color; uniform vec3 u_eye; uniform vec3 u_light_pos[2]; uniform vec3 u_light_color[2];
in vec3 v_world; in vec3 v_normal; out vec4 frag_color;
void main() {
    vec3 n = normalize(v_normal), mesh = u_color.rgb, color = vec3(0.0);
    vec3 to_eye = normalize(u_eye - v_world);
    for (int i = 0; i < 2; ++i) {
        vec3 l = normalize(u_light_pos[i] - v_world);
        float nl = dot(n, l);
        float s = 0.0;
        if (nl > 0.0) { vec3 r = -l - 2.0 * dot(-l, n) * n; s = pow(max(dot(to_eye, r), 0.0), 32.0); }
        color += min(0.1 * mesh + 0.4 * max(nl, 0.0) * mesh * u_light_color[i] + 0.3 * s * u_light_color[i],
                     vec3(1.0));
    }
    frag_color = vec4(color, u_color.a);
}
"""


def _vao(ctx: moderngl.Context, program: moderngl.Program, mesh, with_normals: bool = False,
         with_uv: bool = False) -> moderngl.VertexArray:
    content = [(ctx.buffer(np.asarray(mesh.positions, "f4").tobytes()), "3f", "in_position")]
    if with_normals:
        content.append((ctx.buffer(np.asarray(mesh.normals, "f4").tobytes()), "3f", "in_normal"))
    if with_uv:
        content.append((ctx.buffer(np.asarray(mesh.uvs, "f4").tobytes()), "2f", "in_uv"))
    index = ctx.buffer(np.asarray(mesh.indices, "u4").tobytes()) if mesh.indices is not None else None
    return ctx.vertex_array(program, content, index_buffer=index)


class RawClear:
    """clear_and_swap: two viewports, each cleared to its colour (scissored clear)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        self.size, self.fbo = size, framebuffer(ctx, size, depth=False)
        half = round(size[0] / 2)
        self.rects = (((0, 0, half, size[1]), (0.0, 0.125, 0.6, 1.0)),
                      ((half, 0, size[0] - half, size[1]), (0.6, 0.125, 0.0, 1.0)))

    def frame(self, k: int) -> np.ndarray:
        self.fbo.use()
        for rect, color in self.rects:
            self.fbo.clear(*color, viewport=rect)
        return read(self.fbo, self.size)


class RawTriangle:
    """triangle: the quad as a 4-vertex strip (left viewport) and a 6-vertex list (right), culled."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry

        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size, depth=False)
        self.program = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        self.strip = _vao(ctx, self.program, geometry.quad_strip())
        self.list = _vao(ctx, self.program, geometry.quad_list())
        half = round(size[0] / 2)
        self.rects = ((0, 0, half, size[1]), (half, 0, size[0] - half, size[1]))
        self.view = gl(look_at((0, 0, 3), (0, 0, 0)))
        self.projs = [gl(perspective(45.0, r[2] / r[3], 0.01, 100.0)) for r in self.rects]

    def frame(self, k: int) -> np.ndarray:
        ctx, p = self.ctx, self.program
        self.fbo.use()
        ctx.enable(moderngl.CULL_FACE)
        for rect, proj, vao, mode in zip(self.rects, self.projs, (self.strip, self.list),
                                         (moderngl.TRIANGLE_STRIP, moderngl.TRIANGLES)):
            self.fbo.clear(0.0, 0.125, 0.6, 1.0, viewport=rect)
            self.fbo.viewport = rect
            p["m_model"].write(gl(np.eye(4)))
            p["m_view"].write(self.view)
            p["m_proj"].write(proj)
            p["u_color"].value = (1.0, 0.55, 0.1, 1.0)
            vao.render(mode)
        self.fbo.viewport = (0, 0, *self.size)
        return read(self.fbo, self.size)


class RawPhong:
    """phong: lit ground and ellipsoid (two lights, per-pixel Phong), two unlit light cubes."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry

        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size)
        self.lit = ctx.program(vertex_shader=PHONG_VS, fragment_shader=PHONG_FS)
        self.solid = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        self.ground = _vao(ctx, self.lit, geometry.plane(12.0), with_normals=True)
        self.sphere = _vao(ctx, self.lit, geometry.sphere(), with_normals=True)
        self.cube = _vao(ctx, self.solid, geometry.cube())
        self.eye = (0.0, 2.5, 8.0)
        self.view, self.proj = look_at(self.eye, (0, 0, 0)), perspective(45.0, size[0] / size[1], 0.01, 100.0)
        self.models = [translate(0, -1.2, 0), rotate_y(math.radians(30)) @ scale(1.8, 0.7, 0.9)]
        self.colors = [(0.6, 0.6, 0.6, 1.0), (1.0, 0.25, 0.2, 1.0)]

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        angles = (math.pi / 3 + 0.8 * t, math.pi - math.pi / 3 - 0.8 * t)
        lights = np.array([(3.0 * math.cos(a), 1.5, 3.0 * math.sin(a)) for a in angles], "f4")
        light_colors = np.array([(1, 1, 1), (1, 1, 0)], "f4")
        ctx, lit, solid = self.ctx, self.lit, self.solid
        self.fbo.use()
        self.fbo.clear(0.0, 0.125, 0.6, 1.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        lit["m_view"].write(gl(self.view))
        lit["m_proj"].write(gl(self.proj))
        lit["u_eye"].value = self.eye
        lit["u_light_pos"].write(lights.tobytes())
        lit["u_light_color"].write(light_colors.tobytes())
        for vao, model, color in zip((self.ground, self.sphere), self.models, self.colors):
            lit["m_model"].write(gl(model))
            lit["m_normal"].write(np.linalg.inv(model[:3, :3]).astype("f4").tobytes())  # (M^-1)^T, column-major
            lit["u_color"].value = color
            vao.render(moderngl.TRIANGLES)
        solid["m_view"].write(gl(self.view))
        solid["m_proj"].write(gl(self.proj))
        for position, color in zip(lights, light_colors):
            solid["m_model"].write(gl(translate(*position) @ scale(0.15, 0.15, 0.15)))
            solid["u_color"].value = (*color, 1.0)
            self.cube.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(self.fbo, self.size)


class RawTexture:
    """texture: the checkered ground (grazing) and the labelled cube24, trilinear, repeat."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry
        from glsandbox.images import builtin_levels
        from lessons.texture import ground

        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size)
        self.program = ctx.program(vertex_shader=TEXTURED_VS, fragment_shader=TEXTURED_FS)
        self.ground = _vao(ctx, self.program, ground(60.0, 3.0), with_uv=True)
        self.cube = _vao(ctx, self.program, geometry.cube24(), with_uv=True)
        self.textures = []
        for name in ("checker", "labels"):
            levels = builtin_levels(name)
            texture = ctx.texture(levels[0].shape[1::-1], 4, np.ascontiguousarray(levels[0]).tobytes())
            texture.build_mipmaps()
            for level, image in enumerate(levels[1:], start=1):
                texture.write(np.ascontiguousarray(image).tobytes(), level=level)
            texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            self.textures.append(texture)
        self.view = look_at((0.0, 1.9, 5.5), (0.0, -0.3, 0.0))
        self.proj = perspective(45.0, size[0] / size[1], 0.01, 100.0)

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        ctx, p = self.ctx, self.program
        self.fbo.use()
        self.fbo.clear(0.55, 0.7, 0.9, 1.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        p["m_view"].write(gl(self.view))
        p["m_proj"].write(gl(self.proj))
        p["u_color"].value = (1.0, 1.0, 1.0, 1.0)
        p["u_texture"].value = 0
        models = (translate(0.0, -1.0, 0.0), rotate_y(math.radians(30) + 0.5 * t))
        for vao, model, texture in zip((self.ground, self.cube), models, self.textures):
            p["m_model"].write(gl(model))
            texture.use(0)
            vao.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(self.fbo, self.size)


RAW_BASELINES = {"clear_and_swap": RawClear, "triangle": RawTriangle, "phong": RawPhong, "texture": RawTexture}


def cases(env) -> list:
    """One case per lesson with a raw baseline: the lesson's default frame, animated by ``time``."""
    from glsandbox.bench import Case, Side, same_pixels
    from glsandbox.lesson import find_lesson

    renderer, size = env.renderer, env.size
    found = []
    for name, raw_class in RAW_BASELINES.items():
        raw = raw_class(renderer.host.ctx, size)
        lesson = find_lesson(name)()

        def ours(k: int, lesson=lesson) -> np.ndarray:
            return renderer.render(lesson.at(0.01 * k), size).image

        found.append(Case("frame vs raw ModernGL", name, Side("raw ModernGL", raw.frame), Side("glsandbox", ours),
                          repeat=30, goal=1.10, compare=same_pixels))
    return found
