"""Benchmark: each lesson's frame through glsandbox vs a hand-written raw-ModernGL frame.

Run with every other benchmark by ``glsandbox bench``. Every raster lesson
has a raw class here (the indexed cube's case lives in ``cube_frame.py``).
Each draws the lesson's default frame at 800x600 with plain ModernGL calls:
its own shaders (the same formulas as ``shaders/``), matrices by hand
(``_raw.py``), state set directly, and the few GL calls moderngl lacks
(stencil, write masks, clip control) through ctypes (``_raw.gl_calls``).
Mesh and image data come from glsandbox.geometry / glsandbox.images, and the
numbers of a scene (sizes, colours, camera) from the lesson module: arrays and
constants, read and uploaded once, not per-frame work. Where a lesson's
picture needs more than GL every frame (the transform-order lesson's matrix
panel is text whose numbers change), the raw side does that work too, with its
own code; what never changes (a constant text panel) is made once, like a mesh.
The table's last column says whether both draw the same picture; the tests
(``tests/measure/test_tradeoffs_bench.py``) check each pixel for pixel at 160x120.
Goals: glsandbox <= 1.05x raw, and at most 50 us of extra main-thread
CPU per frame (the bench's "extra CPU" column).
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from _raw import (COLOR_MASK, clear, eye_relative, from_eye, GL_ALWAYS, GL_EQUAL, GL_INVERT, GL_KEEP, GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE,
                  GL_REPLACE, GL_STENCIL_BUFFER_BIT, GL_STENCIL_TEST, GL_ZERO_TO_ONE, VERTEX_COLOR_FS, VERTEX_COLOR_VS,
                  depth_stencil_framebuffer, framebuffer, gl, gl_calls, look_at, perspective, read, reverse_z, rotate_x,
                  rotate_y, rotate_z, scale, translate)

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
# Prefixed with "#version 330 core" and "#define LIGHTS n" by phong_fs(n).
PHONG_FS_BODY = """
uniform vec4 u_color; uniform vec3 u_eye; uniform vec3 u_light_pos[LIGHTS]; uniform vec3 u_light_color[LIGHTS];
in vec3 v_world; in vec3 v_normal; out vec4 frag_color;
void main() {
    vec3 n = normalize(v_normal), mesh = u_color.rgb, color = vec3(0.0);
    vec3 to_eye = normalize(u_eye - v_world);
    for (int i = 0; i < LIGHTS; ++i) {
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


def phong_fs(lights: int) -> str:
    """The per-pixel Phong fragment shader with its light loop sized to ``lights``."""
    return f"#version 330 core\n#define LIGHTS {lights}\n{PHONG_FS_BODY}"


# An image copied onto the frame texel for pixel: the viewport is the image's rectangle, the quad
# covers it (corners from the vertex number), each fragment fetches its texel (row 0: the top row).
IMAGE_VS = """#version 330 core
void main() { gl_Position = vec4(vec2(gl_VertexID % 2, gl_VertexID / 2) * 2.0 - 1.0, 0.0, 1.0); }
"""
IMAGE_FS = """#version 330 core
uniform sampler2D u_image; uniform ivec2 u_origin; out vec4 frag_color;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) - u_origin;
    frag_color = texelFetch(u_image, ivec2(p.x, textureSize(u_image, 0).y - 1 - p.y), 0);
}
"""


def _vao(ctx: moderngl.Context, program: moderngl.Program, mesh, with_normals: bool = False,
         with_uv: bool = False, with_colors: bool = False) -> moderngl.VertexArray:
    content = [(ctx.buffer(np.asarray(mesh.positions, "f4").tobytes()), "3f", "in_position")]
    if with_normals:
        content.append((ctx.buffer(np.asarray(mesh.normals, "f4").tobytes()), "3f", "in_normal"))
    if with_uv:
        content.append((ctx.buffer(np.asarray(mesh.uvs, "f4").tobytes()), "2f", "in_uv"))
    if with_colors:
        content.append((ctx.buffer(np.asarray(mesh.colors, "f4").tobytes()), "3f", "in_color"))
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
            clear(self.fbo, *color[:3], viewport=rect)
        return read(self.fbo, self.size)


class RawTriangle:
    """triangle: the quad as a 4-vertex strip (left viewport) and a 6-vertex list (right), culled.

    Lean: the model (identity), view and colour are written once at set-up; per frame only each
    viewport's projection (one program serves both, their aspects differ), prepared as bytes once.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry

        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size, depth=False)
        self.program = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        self.strip = _vao(ctx, self.program, geometry.quad_strip())
        self.list = _vao(ctx, self.program, geometry.quad_list())
        half = round(size[0] / 2)
        self.rects = ((0, 0, half, size[1]), (half, 0, size[0] - half, size[1]))
        projs = [gl(perspective(45.0, r[2] / r[3], 0.01, 100.0)) for r in self.rects]
        self.passes = tuple(zip(self.rects, projs, (self.strip, self.list),
                                (moderngl.TRIANGLE_STRIP, moderngl.TRIANGLES)))
        self.program["m_model"].write(gl(np.eye(4)))
        self.program["m_view"].write(gl(look_at((0, 0, 3), (0, 0, 0))))
        self.program["u_color"].value = (1.0, 0.55, 0.1, 1.0)
        self.proj = self.program["m_proj"]

    def frame(self, k: int) -> np.ndarray:
        ctx, fbo = self.ctx, self.fbo
        fbo.use()
        ctx.enable(moderngl.CULL_FACE)
        for rect, proj, vao, mode in self.passes:
            clear(fbo, 0.0, 0.125, 0.6, viewport=rect)
            fbo.viewport = rect
            self.proj.write(proj)
            vao.render(mode)
        fbo.viewport = (0, 0, *self.size)
        ctx.disable(moderngl.CULL_FACE)
        return read(fbo, self.size)


class RawPhong:
    """phong: lit ground and ellipsoid (two lights, per-pixel Phong), two unlit light cubes.

    Lean, as a careful hand-written program: the camera (view, projection, eye), the light
    colours, and the ground's and ellipsoid's model and normal matrices ((M^-1)^T, which never
    move) are converted, inverted and written once at set-up; the draws that share a program keep
    what they wrote. Per frame: the two orbiting lights (positions and their cubes' models) and
    the model, normal matrix and colour that differ between the two lit draws.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry

        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size)
        self.lit = ctx.program(vertex_shader=PHONG_VS, fragment_shader=phong_fs(2))
        self.solid = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        ground = _vao(ctx, self.lit, geometry.plane(12.0), with_normals=True)
        sphere = _vao(ctx, self.lit, geometry.sphere(), with_normals=True)
        self.cube = _vao(ctx, self.solid, geometry.cube())
        self.eye = np.array((0.0, 2.5, 8.0))
        # Camera-relative, as glsandbox draws: the view without its translation, models and
        # lights relative to the eye (formed in float64), the eye at 0.
        view = gl(eye_relative(look_at(self.eye, (0, 0, 0)), self.eye))
        proj = gl(perspective(45.0, size[0] / size[1], 0.01, 100.0))
        for program in (self.lit, self.solid):
            program["m_view"].write(view)
            program["m_proj"].write(proj)
        self.lit["u_eye"].value = (0.0, 0.0, 0.0)
        self.light_colors = np.array([(1, 1, 1), (1, 1, 0)], "f4")
        self.lit["u_light_color"].write(self.light_colors.tobytes())
        self.cube_colors = tuple((*map(float, c), 1.0) for c in self.light_colors)
        models = [translate(0, -1.2, 0), rotate_y(math.radians(30)) @ scale(1.8, 0.7, 0.9)]
        colors = [(0.6, 0.6, 0.6, 1.0), (1.0, 0.25, 0.2, 1.0)]
        self.draws = tuple((vao, gl(from_eye(m, self.eye)), _normal(m), c)
                           for vao, m, c in zip((ground, sphere), models, colors))
        self.cube_scale = scale(0.15, 0.15, 0.15)
        self.uniforms = tuple(self.lit[n] for n in ("m_model", "m_normal", "u_color"))
        self.light_pos, self.solid_model, self.solid_color = (
            self.lit["u_light_pos"], self.solid["m_model"], self.solid["u_color"])

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        angles = (math.pi / 3 + 0.8 * t, math.pi - math.pi / 3 - 0.8 * t)
        lights = np.array([(3.0 * math.cos(a), 1.5, 3.0 * math.sin(a)) for a in angles])
        ctx, fbo = self.ctx, self.fbo
        fbo.use()
        clear(fbo, 0.0, 0.125, 0.6, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        relative = lights - self.eye
        self.light_pos.write(relative.astype("f4").tobytes())
        model, normal, color = self.uniforms
        for vao, model_bytes, normal_bytes, rgba in self.draws:
            model.write(model_bytes)
            normal.write(normal_bytes)
            color.value = rgba
            vao.render(moderngl.TRIANGLES)
        for position, rgba in zip(relative, self.cube_colors):  # T(-eye) T(p) S = T(p - eye) S
            self.solid_model.write(gl(translate(*position) @ self.cube_scale))
            self.solid_color.value = rgba
            self.cube.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(fbo, self.size)


class RawTexture:
    """texture: the checkered ground (grazing) and the labelled cube24, trilinear, repeat.

    Lean: the camera, the colour, the sampler's unit and the ground's model matrix (it never
    moves) are written or converted once at set-up; per frame the turning cube's model only.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry
        from glsandbox.images import builtin_levels
        from glsandbox.lessons.texture import ground

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
        self.eye = (0.0, 1.9, 5.5)
        p = self.program
        p["m_view"].write(gl(eye_relative(look_at(self.eye, (0.0, -0.3, 0.0)), self.eye)))  # camera-relative
        p["m_proj"].write(gl(perspective(45.0, size[0] / size[1], 0.01, 100.0)))
        p["u_color"].value = (1.0, 1.0, 1.0, 1.0)
        p["u_texture"].value = 0
        self.ground_model = gl(from_eye(translate(0.0, -1.0, 0.0), self.eye))
        self.model = p["m_model"]

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        ctx, fbo = self.ctx, self.fbo
        fbo.use()
        clear(fbo, 0.55, 0.7, 0.9, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        cube_model = gl(from_eye(rotate_y(math.radians(30) + 0.5 * t), self.eye))
        for vao, model, texture in zip((self.ground, self.cube), (self.ground_model, cube_model), self.textures):
            self.model.write(model)
            texture.use(0)
            vao.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(fbo, self.size)


class RawTransformOrder:
    """transform_order (order STR, overlay on): the centre cube spinning, the second cube under
    R @ T @ S orbiting the origin, the trail of its top corner, and two text panels on top.

    Per frame, as any program showing this picture must: the trail's 64 points (numpy, all at
    once) written into one buffer, and the matrix panel, whose numbers change every frame, drawn
    with Pillow (the lesson's font and layout: 3 px padding, 2 px between lines, the matrix's
    columns right-aligned 8 px apart, white on black at alpha 150) and uploaded. The figures
    panel never changes: it is made once by the lesson's own function (data, like the meshes).
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from PIL import Image, ImageDraw, ImageFont

        from glsandbox import geometry
        from glsandbox.lessons import transform_order as lesson

        defaults = {p.name: p.default for p in lesson.TransformOrder.all_params()}
        assert defaults["order"] == "STR" and defaults["view"] == "single" and defaults["overlay"]
        self.speed, self.spin, self.span = defaults["speed"], defaults["spin"], defaults["trail"]
        self.ctx, self.size, self.fbo = ctx, size, framebuffer(ctx, size)
        self.colored = ctx.program(vertex_shader=VERTEX_COLOR_VS, fragment_shader=VERTEX_COLOR_FS)
        self.solid = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        self.image = ctx.program(vertex_shader=IMAGE_VS, fragment_shader=IMAGE_FS)
        self.cube = _vao(ctx, self.colored, geometry.cube(), with_colors=True)
        self.samples = lesson.TRAIL_SAMPLES
        self.trail_buffer = ctx.buffer(reserve=self.samples * 12)
        self.trail = ctx.vertex_array(self.solid, [(self.trail_buffer, "3f", "in_position")])
        self.quad = ctx.vertex_array(self.image, [])
        camera = lesson.CAMERA
        self.eye = camera.eye
        self.view = gl(eye_relative(look_at(camera.eye, camera.target, camera.up), self.eye))  # camera-relative (RawPhong)
        self.proj = gl(perspective(camera.fov_y, size[0] / size[1], camera.near, camera.far))
        self.ts = translate(*lesson.OFFSET) @ scale(*lesson.SCALE)  # S, then T
        self.corner = (self.ts @ (*lesson.TRAIL_POINT, 1.0))[:3]  # the trail's point after S and T
        self.trail_color = lesson.TRAIL_COLOR
        # The matrix panel's font, measure and fixed lines.
        self.font = ImageFont.load_default()
        measure = ImageDraw.Draw(Image.new("RGBA", (1, 1))).textlength
        self.width = lambda text: math.ceil(measure(text, font=self.font))
        ascent, descent = self.font.getmetrics()
        self.step = ascent + descent + 2
        self.lines = ("mScale * mTranslate * mRotate", "M = R @ T @ S =",
                      f"orbits the origin, radius {np.linalg.norm(lesson.OFFSET):.1f}")
        self.lines_width = max(self.width(text) for text in self.lines)
        self.panel_height = 8 * self.step - 2 + 6  # 8 rows; the width changes with the numbers
        self.panel: moderngl.Texture | None = None
        # The panels are laid out as the lesson's overlays are (glsandbox.overlay: scaled with the
        # frame, capped to a share of it), so the raw picture is the lesson's at any size.
        from glsandbox.overlay import Overlay

        self.region = (0, 0, *size)
        figures = Overlay("figures", np.ascontiguousarray(lesson.figures_panel()), None, (4, -4))
        drawn = np.ascontiguousarray(figures.drawn_image(self.region))
        self.figures = self._texture(drawn.shape[1], drawn.shape[0], drawn.tobytes())
        self.figures_at = figures.placement(self.region)[:2]

    def _texture(self, width: int, height: int, data: bytes) -> moderngl.Texture:
        texture = self.ctx.texture((width, height), 4, data, alignment=1)
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        return texture

    def _matrix_panel(self, angle: float, model: np.ndarray) -> tuple[int, bytes]:
        """The panel's width and RGBA bytes (top row first): order, products, the matrix, the motion."""
        from PIL import Image, ImageDraw

        cells = [["0.00" if text == "-0.00" else text for text in (f"{v:.2f}" for v in row)] for row in model]
        columns = [max(self.width(row[c]) for row in cells) for c in range(4)]
        header = f"STR: scale, translate, rotate (R {math.degrees(angle):.0f} deg)"
        width = max(self.width(header), self.lines_width, sum(columns) + 3 * 8) + 6
        panel = Image.new("RGBA", (width, self.panel_height), (0, 0, 0, 150))
        draw = ImageDraw.Draw(panel)
        white = (255, 255, 255, 255)
        for row, text in zip((0, 1, 2, 7), (header, *self.lines)):
            draw.text((3, 3 + row * self.step), text, font=self.font, fill=white)
        for row, numbers in enumerate(cells, start=3):
            x = 3
            for column, text in zip(columns, numbers):
                draw.text((x + column - self.width(text), 3 + row * self.step), text, font=self.font, fill=white)
                x += column + 8
        return width, panel.tobytes()

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        angle = self.speed * t
        ctx, colored, solid = self.ctx, self.colored, self.solid
        second = rotate_y(-angle) @ self.ts  # the course's XMMatrixRotationY(angle) is rotate_y(-angle) here
        turns = -np.linspace(angle - self.span, angle, self.samples)
        c, s = np.cos(turns), np.sin(turns)
        x, y, z = self.corner
        self.trail_buffer.write(np.stack([c * x + s * z, np.full_like(c, y), c * z - s * x], 1).astype("f4"))
        from glsandbox.overlay import Overlay

        width, pixels = self._matrix_panel(angle, second)
        matrix = Overlay("matrix", np.frombuffer(pixels, np.uint8).reshape(self.panel_height, width, 4), None, (4, 4))
        drawn = np.ascontiguousarray(matrix.drawn_image(self.region))
        top_left = matrix.placement(self.region)[:2]
        if self.panel is None or self.panel.size != (drawn.shape[1], drawn.shape[0]):
            if self.panel is not None:
                self.panel.release()
            self.panel = self._texture(drawn.shape[1], drawn.shape[0], drawn.tobytes())
        else:
            self.panel.write(drawn.tobytes(), alignment=1)

        self.fbo.use()
        clear(self.fbo, 0.0, 0.125, 0.6, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        colored["m_view"].write(self.view)
        colored["m_proj"].write(self.proj)
        for model in (rotate_y(-self.spin * t), second):
            colored["m_model"].write(gl(from_eye(model, self.eye)))
            self.cube.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.CULL_FACE)
        solid["m_model"].write(gl(from_eye(np.eye(4), self.eye)))
        solid["m_view"].write(self.view)
        solid["m_proj"].write(self.proj)
        solid["u_color"].value = self.trail_color
        self.trail.render(moderngl.LINE_STRIP)
        # The panels: straight alpha over the frame (whose alpha is not written: it stays opaque).
        ctx.disable(moderngl.DEPTH_TEST)
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        for texture, origin in ((self.panel, top_left), (self.figures, self.figures_at)):
            texture.use(0)
            self.image["u_origin"].value = origin
            self.fbo.viewport = (*origin, *texture.size)
            self.quad.render(moderngl.TRIANGLE_STRIP, vertices=4)
        self.fbo.viewport = (0, 0, *self.size)
        ctx.disable(moderngl.BLEND)
        ctx.blend_func = moderngl.DEFAULT_BLENDING
        return read(self.fbo, self.size)


def _lit_draw(vao: moderngl.VertexArray, model: np.ndarray, color: tuple, eye: np.ndarray) -> tuple:
    """A lit draw's vertex array, model matrix (relative to ``eye``), normal matrix ((M^-1)^T,
    column-major) and colour."""
    return vao, gl(from_eye(model, eye)), _normal(model), color


class RawMirror:
    """mirror (stencil mirror, stencil shadow, point light, reverse-Z, polygon offset): the room, the
    glass marked in the stencil, the reflection where it is marked, the glass blended, the cube's
    planar shadow darkening each pixel once.

    moderngl has no stencil, write-mask or clip-control calls and no depth-stencil renderbuffer:
    those go through ctypes from the context's own loader (``_raw.gl_calls``, not glsandbox's
    rawgl), the rest is moderngl. Every state changed is put back at the end of the frame (the
    bench shares one context with glsandbox). The room's dimensions, the camera's and light's
    numbers are read from the lesson module once (data); R, the shadow matrix and the reverse-Z
    projection are written out here. Matrices of what does not move are made once.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry
        from glsandbox.lessons import mirror as lesson

        v = {p.name: p.default for p in lesson.MirrorLesson.params}
        assert (v["mirror"], v["shadow"], v["light"], v["depth"], v["offset"]) == \
            ("stencil", "on", "point", "reverse_z", True)
        self.ctx, self.size, self.gl = ctx, size, gl_calls(ctx)
        self.fbo = depth_stencil_framebuffer(ctx, self.gl, size)
        self.lit = ctx.program(vertex_shader=PHONG_VS, fragment_shader=phong_fs(1))
        self.solid = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        plane, cube24 = geometry.plane(1.0), geometry.cube24()
        lit_plane, self.lit_cube = (_vao(ctx, self.lit, m, with_normals=True) for m in (plane, cube24))
        self.glass, self.shadow_cube = _vao(ctx, self.solid, plane), _vao(ctx, self.solid, cube24)
        light_cube = _vao(ctx, self.solid, geometry.cube())

        # The room: a floor, the left wall, the back wall as four pieces round the glass's hole.
        half, back, front, high = lesson.HALF_WIDTH, lesson.BACK, lesson.FRONT, lesson.WALL_HEIGHT
        glass_half, glass_low, glass_high = lesson.GLASS_HALF, lesson.GLASS_BOTTOM, lesson.GLASS_TOP
        middle, deep, side = (front + back) / 2, front - back, half - glass_half
        to_z, to_x = rotate_x(math.radians(90.0)), rotate_z(math.radians(-90.0))  # the plane (+y) facing +z, +x

        def back_piece(width: float, height: float, x: float, y: float) -> np.ndarray:
            return translate(x, y, back) @ to_z @ scale(width, 1.0, height)

        floor = translate(0.0, 0.0, middle) @ scale(2 * half, 1.0, deep)
        wall_left = translate(-half, high / 2, middle) @ to_x @ scale(high, 1.0, deep)
        wall = (0.6, 0.55, 0.7, 1.0)
        room = [(floor, (0.75, 0.72, 0.65, 1.0)), (wall_left, (0.45, 0.6, 0.5, 1.0)),
                (back_piece(side, high, -(glass_half + side / 2), high / 2), wall),
                (back_piece(side, high, glass_half + side / 2, high / 2), wall),
                (back_piece(2 * glass_half, glass_low, 0.0, glass_low / 2), wall),
                (back_piece(2 * glass_half, high - glass_high, 0.0, (glass_high + high) / 2), wall)]
        direction = np.asarray(lesson.EYE_DIRECTION) / np.linalg.norm(lesson.EYE_DIRECTION)
        eye = self.eye = np.asarray(lesson.TARGET) + v["distance"] * direction
        self.glass_model = gl(from_eye(back_piece(2 * glass_half, glass_high - glass_low, 0.0,
                                                  (glass_low + glass_high) / 2), eye))
        self.glass_color = lesson.GLASS_COLOR

        # R: the reflection through the glass's plane n·p + d = 0 (|n| = 1): p - 2 (n·p + d) n.
        mirror = np.asarray(lesson.MIRROR_PLANE, dtype=np.float64)
        mirror /= np.linalg.norm(mirror[:3])
        self.reflect = np.eye(4)
        self.reflect[:3, :3] -= 2.0 * np.outer(mirror[:3], mirror[:3])
        self.reflect[:3, 3] = -2.0 * mirror[3] * mirror[:3]
        # The shadow: S = (P·L) I - L Pᵀ flattens onto the floor P along the rays from the point L,
        # then lifted by ``lift`` along the floor's normal.
        light = np.array([v["lx"], v["ly"], v["lz"], 1.0])
        floor_plane = np.asarray(lesson.FLOOR_PLANE, dtype=np.float64)
        floor_plane /= np.linalg.norm(floor_plane[:3])
        self.flatten = translate(*(v["lift"] * floor_plane[:3])) @ (
            float(floor_plane @ light) * np.eye(4) - np.outer(light, floor_plane))
        self.shadow_color = lesson.SHADOW_COLOR
        self.lights = tuple(np.asarray(p[:3] - eye, "f4").tobytes() for p in (light, self.reflect @ light))

        # The draws that do not move, their matrices made once: seen and reflected.
        light_model = translate(*light[:3]) @ scale(*(lesson.LIGHT_CUBE_SCALE,) * 3)
        self.room = [_lit_draw(lit_plane, model, color, eye) for model, color in room]
        self.reflected_room = [_lit_draw(lit_plane, self.reflect @ model, color, eye) for model, color in room[:2]]
        self.light_draws = [(light_cube, gl(from_eye(m, eye))) for m in (light_model, self.reflect @ light_model)]
        self.cube_color = (1.0, 0.5, 0.15, 1.0)
        self.cube_at, self.cube_half, self.speed = lesson.CUBE_CENTRE, lesson.CUBE_HALF, v["speed"]

        view = gl(eye_relative(look_at(eye, lesson.TARGET), eye))  # camera-relative, as glsandbox draws (RawPhong)
        proj = gl(reverse_z(perspective(v["fov"], size[0] / size[1], v["near"], v["far"])))
        for program in (self.lit, self.solid):  # the camera never moves: set once
            program["m_view"].write(view)
            program["m_proj"].write(proj)
        self.lit["u_eye"].value = (0.0, 0.0, 0.0)
        self.lit["u_light_color"].write(np.ones(3, "f4").tobytes())

    def _lit(self, draws: list) -> None:
        lit = self.lit
        for vao, model, normal, color in draws:
            lit["m_model"].write(model)
            lit["m_normal"].write(normal)
            lit["u_color"].value = color
            vao.render(moderngl.TRIANGLES)

    def _stencil(self, write_mask: int, test: int, ref: int, compare_mask: int, on_pass: int) -> None:
        """Which bits a pass writes, its test (``ref & compare_mask`` against the buffer's), and what
        a fragment passing stencil and depth does to the written bits (failing ones keep them)."""
        self.gl.StencilMask(write_mask)
        self.gl.StencilFunc(test, ref, compare_mask)
        self.gl.StencilOp(GL_KEEP, GL_KEEP, on_pass)

    def _solid(self, vao: moderngl.VertexArray, model: bytes, color: tuple) -> None:
        self.solid["m_model"].write(model)
        self.solid["u_color"].value = color
        vao.render(moderngl.TRIANGLES)

    def frame(self, k: int) -> np.ndarray:
        t = 0.01 * k
        ctx, raw, lit = self.ctx, self.gl, self.lit
        h = self.cube_half
        cube = translate(*self.cube_at) @ rotate_y(0.5 + self.speed * t) @ scale(h, h, h)
        seen, mirrored = (_lit_draw(self.lit_cube, m, self.cube_color, self.eye) for m in (cube, self.reflect @ cube))

        self.fbo.use()
        raw.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)  # reverse-Z: depth 0..1 as is, near 1, far 0
        ctx.depth_func = ">"
        clear(self.fbo, 0.08, 0.08, 0.12, depth=0.0)
        raw.ClearStencil(0)
        raw.Clear(GL_STENCIL_BUFFER_BIT)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        lit["u_light_pos"].write(self.lights[0])
        self._lit([*self.room, seen])
        self._solid(*self.light_draws[0], (1.0, 1.0, 0.85, 1.0))
        # Mark the glass's visible pixels with stencil bit 1; no colour or depth writes.
        raw.Enable(GL_STENCIL_TEST)
        self._stencil(1, GL_ALWAYS, 1, 0xFF, GL_REPLACE)
        raw.ColorMask(0, 0, 0, 0)
        raw.DepthMask(0)
        self._solid(self.glass, self.glass_model, self.glass_color)
        # The reflection where bit 1 is set: R @ model, the light through R, clockwise fronts (det R = -1).
        # Colour writes back on but alpha (the frame stays opaque under the blended glass and shadow).
        self._stencil(0, GL_EQUAL, 1, 1, GL_KEEP)
        raw.ColorMask(*COLOR_MASK)
        raw.DepthMask(1)
        ctx.front_face = "cw"
        lit["u_light_pos"].write(self.lights[1])
        self._lit([*self.reflected_room, mirrored])
        self._solid(*self.light_draws[1], (1.0, 1.0, 0.85, 1.0))
        # The glass blended over its reflection.
        raw.Disable(GL_STENCIL_TEST)
        ctx.front_face = "ccw"
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self._solid(self.glass, self.glass_model, self.glass_color)
        # The shadow: darken a pixel only while its bit 2 is clear, then set it; no depth writes,
        # no culling, pulled towards the camera by polygon offset (+1, +1: nearer is larger here).
        raw.Enable(GL_STENCIL_TEST)
        self._stencil(2, GL_EQUAL, 0, 2, GL_INVERT)
        raw.DepthMask(0)
        ctx.polygon_offset = (1.0, 1.0)
        ctx.disable(moderngl.CULL_FACE)
        self._solid(self.shadow_cube, gl(from_eye(self.flatten @ cube, self.eye)), self.shadow_color)
        # OpenGL's defaults again.
        raw.Disable(GL_STENCIL_TEST)
        self._stencil(0xFF, GL_ALWAYS, 0, 0xFF, GL_KEEP)
        raw.DepthMask(1)
        ctx.polygon_offset = (0.0, 0.0)
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
        ctx.blend_func = moderngl.DEFAULT_BLENDING
        ctx.depth_func = "<"
        raw.ClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE)
        raw.ClearDepth(1.0)
        return read(self.fbo, self.size)


# The lit pass of the shadow-map lesson: one light, its map sampled with a comparison sampler.
SHADOW_PHONG_FS = """#version 330 core
uniform vec4 u_color; uniform vec3 u_eye; uniform vec3 u_light_pos; uniform vec3 u_light_color;
uniform sampler2DShadow u_map; uniform mat4 u_light_matrix; uniform float u_texel;
in vec3 v_world; in vec3 v_normal; out vec4 frag_color;
float lit_share(vec3 p, vec3 n, vec3 l) {
    float c = clamp(dot(n, l), 0.05, 1.0);
    vec4 clip = u_light_matrix * vec4(p + l * (0.02 + 0.02 * sqrt(1.0 - c * c) / c), 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 q = clip.xyz / clip.w * 0.5 + 0.5;
    if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q, vec3(1.0)))) return 1.0;
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) sum += texture(u_map, vec3(q.xy + vec2(x, y) * u_texel, q.z));
    return sum / 9.0;
}
void main() {
    vec3 n = normalize(v_normal), mesh = u_color.rgb;
    vec3 to_eye = normalize(u_eye - v_world), l = normalize(u_light_pos - v_world);
    float nl = dot(n, l), s = 0.0;
    if (nl > 0.0) { s = pow(max(dot(to_eye, 2.0 * nl * n - l), 0.0), 32.0); }
    float visible = lit_share(v_world, n, l);
    frag_color = vec4(min(0.1 * mesh + visible * (0.4 * (max(nl, 0.0) * mesh * u_light_color)
                                                  + 0.3 * (s * u_light_color)), vec3(1.0)), u_color.a);
}
"""


class RawShadowMap:
    """shadow_map (show=map): the two passes by hand. The casters' depth from the light into a
    1024² depth texture (a perspective frustum from the light at the centre of the casters' bounds,
    near and far around every corner), then the lit pass comparing each pixel with it, 3x3 PCF.

    Lean: the camera, the light, the map's unit and texel, and the floor's, sphere's and panel's
    model and normal matrices and world-space box corners (they never move) are made and written
    once at set-up. Per frame: the turning cube's model, the light's frustum (it bounds the cube
    too, so it follows it) and the uniforms that differ between draws of one program.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]) -> None:
        from glsandbox import geometry
        from glsandbox.lessons import shadow_map as lesson

        self.ctx, self.size, self.fbo, self.lesson = ctx, size, framebuffer(ctx, size), lesson
        self.depth = ctx.program(vertex_shader=SOLID_VS, fragment_shader=SOLID_FS)
        self.lit = ctx.program(vertex_shader=PHONG_VS, fragment_shader=SHADOW_PHONG_FS)
        self.map = ctx.depth_texture((1024, 1024))
        self.map.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.map.repeat_x = self.map.repeat_y = False
        self.map.compare_func = "<="
        self.map_fbo = ctx.framebuffer(depth_attachment=self.map)
        meshes = {"floor": geometry.plane(1.0), "cube": geometry.cube24(), "sphere": geometry.sphere(),
                  "panel": geometry.cube24()}
        self.names = tuple(meshes)
        lit_vaos = {k: _vao(ctx, self.lit, m, with_normals=True) for k, m in meshes.items()}
        depth_vaos = {k: _vao(ctx, self.depth, m) for k, m in meshes.items()}
        # Each mesh's bounding box corners (model space), for the light's frustum.
        corners = {k: np.c_[np.array([[(m.positions.min(0), m.positions.max(0))[i >> a & 1][a] for a in range(3)]
                                      for i in range(8)]), np.ones(8)] for k, m in meshes.items()}
        self.cube_corners = corners["cube"]
        h = lesson.CUBE_HALF
        self.cube_place = (translate(*lesson.CUBE_AT), scale(h, h, h))
        fixed = {"floor": scale(lesson.FLOOR_SIZE, 1.0, lesson.FLOOR_SIZE),
                 "sphere": translate(*lesson.SPHERE[0]) @ scale(*(lesson.SPHERE[1],) * 3),
                 "panel": translate(*lesson.PANEL[0]) @ scale(*lesson.PANEL[1])}
        # The world-space corners of what never moves, in draw order round the cube's.
        self.points_before = [(corners[k] @ fixed[k].T)[:, :3] for k in self.names[:self.names.index("cube")]]
        self.points_after = [(corners[k] @ fixed[k].T)[:, :3] for k in self.names[self.names.index("cube") + 1:]]
        self.light = np.asarray(lesson.LIGHT, dtype=np.float64)
        # Each draw: its vertex arrays, then (None for the cube: per frame) its model and normal bytes.
        self.draws = tuple((depth_vaos[k], lit_vaos[k], *((gl(fixed[k]), _normal(fixed[k])) if k in fixed else
                                                          (None, None)), (*lesson.COLORS[k], 1.0))
                           for k in self.names)
        self.depth["m_view"].write(gl(np.eye(4)))
        lit = self.lit
        lit["u_map"].value = 1
        lit["u_texel"].value = 1.0 / 1024
        eye, target = lesson.SINGLE_VIEW
        lit["m_view"].write(gl(look_at(eye, target)))
        lit["m_proj"].write(gl(perspective(lesson.FOV, size[0] / size[1], lesson.NEAR, lesson.FAR)))
        lit["u_eye"].value = eye
        lit["u_light_pos"].value = lesson.LIGHT
        lit["u_light_color"].value = (1.0, 1.0, 1.0)

    def light_matrix(self, points: np.ndarray) -> np.ndarray:
        light = self.light
        target = points.mean(axis=0)
        forward = (target - light) / np.linalg.norm(target - light)
        view = look_at(light, target, (0.0, 0.0, 1.0) if abs(forward[1]) > 0.9 else (0.0, 1.0, 0.0))
        depths = -(np.c_[points, np.ones(len(points))] @ view.T)[:, 2]
        far = max(float(depths.max()), 1e-3) * 1.01
        near = max(float(depths.min()) * 0.99, far * 1e-3)
        return perspective(self.lesson.MAP_FOV, 1.0, near, far) @ view

    def frame(self, k: int) -> np.ndarray:
        ctx, depth, lit = self.ctx, self.depth, self.lit
        at, size = self.cube_place
        t = 0.01 * k
        cube = at @ rotate_y(0.4 + 0.5 * t) @ size
        points = np.concatenate([*self.points_before, (self.cube_corners @ cube.T)[:, :3], *self.points_after])
        light_matrix = gl(self.light_matrix(points))
        cube_model, cube_normal = gl(cube), _normal(cube)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        self.map_fbo.use()  # pass 1: depth only, from the light
        self.map_fbo.clear(depth=1.0)
        depth["m_proj"].write(light_matrix)
        for depth_vao, _, model, _, _ in self.draws:
            depth["m_model"].write(cube_model if model is None else model)
            depth_vao.render(moderngl.TRIANGLES)
        self.fbo.use()  # pass 2: lit, each pixel compared with the map
        clear(self.fbo, *self.lesson.CLEAR[:3], depth=1.0)  # every channel, then the draws' mask (_raw.clear)
        self.map.use(1)
        lit["u_light_matrix"].write(light_matrix)
        for _, lit_vao, model, normal, color in self.draws:
            lit["m_model"].write(cube_model if model is None else model)
            lit["m_normal"].write(cube_normal if normal is None else normal)
            lit["u_color"].value = color
            lit_vao.render(moderngl.TRIANGLES)
        ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        return read(self.fbo, self.size)


def _normal(model: np.ndarray) -> bytes:
    """The normal matrix's bytes: (M^-1)^T in column-major is M^-1 in row-major."""
    return np.linalg.inv(model[:3, :3]).astype("f4").tobytes()


RAW_BASELINES = {"clear_and_swap": RawClear, "triangle": RawTriangle, "phong": RawPhong, "texture": RawTexture,
                 "transform_order": RawTransformOrder, "mirror": RawMirror, "shadow_map": RawShadowMap}
#: The lesson settings a baseline draws (the default where not listed): the shadow-map lesson's
#: technique alone, its two passes (the side-by-side default also ray-traces a tile).
RAW_SETTINGS: dict[str, dict[str, str]] = {"shadow_map": {"show": "map"}}


def cases(env) -> list:
    """One case per lesson with a raw baseline: the lesson's default frame, animated by ``time``."""
    from glsandbox.lesson import find_lesson
    from glsandbox.measure.bench import LESSON_FRAME_CPU_GOAL_US, LESSON_FRAME_GOAL, Case, Side, same_pixels

    renderer, size = env.renderer, env.size
    found = []
    for name, raw_class in RAW_BASELINES.items():
        raw = raw_class(renderer.host.ctx, size)
        lesson = find_lesson(name)(**RAW_SETTINGS.get(name, {}))

        def ours(k: int, lesson=lesson) -> np.ndarray:
            return renderer.render(lesson.at(0.01 * k), size).image

        found.append(Case("frame vs raw ModernGL", name, Side("raw ModernGL", raw.frame), Side("glsandbox", ours),
                          repeat=30, goal=LESSON_FRAME_GOAL,
                 cpu_goal_us=LESSON_FRAME_CPU_GOAL_US, compare=same_pixels))
    return found
