"""Textures: the course's uv, mip levels read back, filters and wrap modes, bad input.

Course section "Texture Mapping". The probes put a textured square straight
in front of the camera so that it fills the frame exactly: the 2x2 square at
distance 1/tan(22.5°) under a 45° field of view. Then a 256-texel texture
with uv 0..k across a 64-pixel frame has 4k texels per pixel: mip level
log2(4k).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from PIL import Image
from support import assert_user_error, run_cli

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.images import MIP_COLORS, QUADRANT_COLORS, labels, load_image, mip_levels
from glsandbox.plan import plan
from glsandbox.scene import Camera, Material, Node, Scene, Texture
from glsandbox.lessons.texture import TextureLesson, course_uv_table

FILL_DISTANCE = 1.0 / math.tan(math.radians(22.5))


def facing_square(texture: Texture, uv_scale: float = 1.0, uv_offset: float = 0.0) -> Scene:
    """A 2x2 textured square facing the camera and filling the frame."""
    mesh = geometry.plane(2.0)
    mesh = replace(mesh, name="probe_square", uvs=mesh.uvs * uv_scale + uv_offset)
    model = transforms.rotate_x(math.radians(90))  # the xz plane turned to face +z
    camera = Camera(eye=(0.0, 0.0, FILL_DISTANCE), target=(0.0, 0.0, 0.0))
    return Scene("probe", nodes=(Node("square", mesh, model, Material(texture=texture)),), camera=camera)


def render(gl, scene: Scene, size: int = 64) -> np.ndarray:
    return gl.render_scene(scene, (size, size)).image[:, :, :3].astype(int)


# --- uv of the 24-vertex cube -------------------------------------------------


def cube_uv_at(mesh: geometry.Mesh, position: np.ndarray, normal: np.ndarray) -> np.ndarray:
    match = np.all(np.isclose(mesh.positions, position), axis=1) & np.all(np.isclose(mesh.normals, normal), axis=1)
    (index,) = np.flatnonzero(match)
    return mesh.uvs[index]


@pytest.mark.parametrize("face, dx_normal", [("front", (0, 0, -1)), ("top", (0, 1, 0))])
def test_cube24_has_the_course_uv(face, dx_normal):
    mesh = geometry.cube24()
    assert mesh.vertex_count == 24 and mesh.element_count == 36
    normal = transforms.from_directx_point(dx_normal)
    for dx_position, uv in course_uv_table()[face]:
        got = cube_uv_at(mesh, transforms.from_directx_point(dx_position), normal)
        assert tuple(got) == uv, (face, dx_position)


def test_no_face_shows_its_image_mirrored():
    # Seen from outside a front face is counter-clockwise; with v pointing
    # down the image, an unmirrored picture makes the uv triangle clockwise.
    mesh = geometry.cube24()
    for tri in mesh.indices.reshape(-1, 3):
        p, t = mesh.positions[tri], mesh.uvs[tri]
        assert np.dot(np.cross(p[1] - p[0], p[2] - p[0]), mesh.normals[tri[0]]) > 0
        e1, e2 = t[1] - t[0], t[2] - t[0]
        assert e1[0] * e2[1] - e1[1] * e2[0] < 0


def face_views() -> list[tuple[np.ndarray, np.ndarray]]:
    """(outward normal, image-up direction) of each cube24 face, from its uv."""
    mesh = geometry.cube24()
    views = []
    for base in range(0, 24, 4):
        corners = range(base, base + 4)
        top = next(i for i in corners if tuple(mesh.uvs[i]) == (0.0, 0.0))
        bottom = next(i for i in corners if tuple(mesh.uvs[i]) == (0.0, 1.0))
        up = mesh.positions[top] - mesh.positions[bottom]
        views.append((mesh.normals[base], up / np.linalg.norm(up)))
    return views


@pytest.mark.parametrize("face", range(6))
def test_each_face_shows_the_labels_upright(gl, face):
    # Look at each face head-on with the image's up as the camera's up: the
    # quadrant colours must sit where the picture has them (uv (0,0) top left).
    normal, up = face_views()[face]
    camera = Camera(eye=tuple(3.0 * normal), target=(0.0, 0.0, 0.0), up=tuple(up))
    texture = Texture("labels", filter="nearest")
    scene = Scene("face", nodes=(Node("cube", geometry.cube24(), np.eye(4), Material(texture=texture)),),
                  camera=camera)
    image = render(gl, scene)
    half = 1.0 / (2.0 * math.tan(math.radians(22.5)))  # the face's half width in frame halves at distance 2
    for (u, v), color in QUADRANT_COLORS.items():
        x = 32 + (2 * u - 1) * 0.8 * half * 32
        y = 32 + (2 * v - 1) * 0.8 * half * 32
        assert tuple(image[int(y), int(x)]) == color, (face, (u, v))


# --- mip levels -----------------------------------------------------------------


@pytest.mark.parametrize("uv_scale, level", [(0.125, 0), (1.0, 2), (2.0, 3), (4.0, 4), (16.0, 6)])
def test_the_sampled_mip_level_is_read_back(gl, uv_scale, level):
    # 4k texels per pixel: level log2(4k); below one texel per pixel, level 0.
    image = render(gl, facing_square(Texture("mip_levels", filter="mip_nearest"), uv_scale))
    assert tuple(image[32, 32]) == MIP_COLORS[level]
    assert (image == np.array(MIP_COLORS[level])).all()  # the whole square: one level


def test_grazing_ground_climbs_the_mip_chain(gl):
    lesson = TextureLesson(ground="mip_levels", filter="mip_nearest")
    image = gl.render(lesson, (128, 128)).image[:, :, :3].astype(int)
    palette = np.array(MIP_COLORS)
    column = image[40:, 3]  # the ground's left edge, from the horizon towards the camera
    levels = [int(np.argmin(np.abs(palette - px).sum(axis=1))) for px in column]
    assert levels == sorted(levels, reverse=True)  # farther rows sample smaller levels
    assert levels[0] - levels[-1] >= 3


def test_anisotropic_reads_finer_levels_at_a_grazing_angle(gl):
    # Trilinear picks the level from the footprint's long axis (blurry far
    # away); anisotropic from the short one, sampling along the long axis.
    palette = np.array(MIP_COLORS)

    def levels(name: str) -> np.ndarray:
        image = gl.render(TextureLesson(ground="mip_levels", filter=name), (128, 128)).image[:, :, :3].astype(int)
        return np.array([int(np.argmin(np.abs(palette - px).sum(axis=1))) for px in image[40:128:4, 3]])

    trilinear, anisotropic = levels("mip_linear"), levels("anisotropic")
    assert (anisotropic <= trilinear).all() and (anisotropic < trilinear).sum() > len(trilinear) // 2


def test_non_mip_filters_ignore_the_levels(gl):
    for name in ("nearest", "linear"):
        image = render(gl, facing_square(Texture("mip_levels", filter=name), 4.0))
        assert tuple(image[32, 32]) == MIP_COLORS[0]


# --- filters --------------------------------------------------------------------

MIP_FILTERS = ("linear", "mip_nearest", "mip_linear")


def test_filters_agree_under_magnification_except_nearest(gl):
    # 16 texels over 64 pixels: the mag filter decides, and every filter
    # but nearest magnifies bilinearly from level 0. (llvmpipe's anisotropic
    # path samples magnified texels its own way, so it is left out here.)
    images = {f: render(gl, facing_square(Texture("checker", filter=f), 1 / 16)) for f in
              ("nearest", *MIP_FILTERS)}
    for name in MIP_FILTERS[1:]:
        assert np.array_equal(images[name], images["linear"]), name
    assert (np.abs(images["nearest"] - images["linear"]).max(axis=2) > 30).sum() > 50


def test_nearest_and_linear_agree_one_texel_per_pixel(gl):
    # Pixel centres land on texel centres: bilinear weights are (1, 0).
    a = render(gl, facing_square(Texture("labels", filter="nearest"), 0.25))
    b = render(gl, facing_square(Texture("labels", filter="linear"), 0.25))
    assert np.abs(a - b).max() <= 2


@pytest.mark.parametrize("uv_scale, level", [(1.0, 2), (2.0, 3), (4.0, 4)])
def test_isotropic_minification_trilinear_and_anisotropic_pick_the_same_level(gl, uv_scale, level):
    # A face-on square has a round footprint: at an exact level trilinear
    # reads that level alone, and anisotropic filtering has nothing to
    # stretch along: its centre pixel reads the same level. (llvmpipe's
    # anisotropic path rounds the level per 2x2 pixel quad, so some quads read
    # the next finer level; none reads a coarser one.)
    probe = (slice(24, 40), slice(24, 40))
    trilinear = render(gl, facing_square(Texture("mip_levels", filter="mip_linear"), uv_scale))
    assert np.abs(trilinear[probe] - np.array(MIP_COLORS[level])).max() <= 1
    anisotropic = render(gl, facing_square(Texture("mip_levels", filter="anisotropic"), uv_scale))
    assert tuple(anisotropic[32, 32]) == MIP_COLORS[level]
    allowed = [np.array(MIP_COLORS[level]), np.array(MIP_COLORS[level - 1])]
    pixels = anisotropic[probe].reshape(-1, 3)
    assert all(any((px == c).all() for c in allowed) for px in pixels)


def test_filters_differ_on_the_grazing_ground(gl):
    def far_rows(name: str) -> np.ndarray:
        image = gl.render(TextureLesson(filter=name), (128, 128)).image[:, :, :3].astype(int)
        return image[70:80, :32]  # near the horizon, left of the cube

    rows = {name: far_rows(name) for name in ("nearest", "mip_nearest", "mip_linear", "anisotropic")}
    for a in rows:
        for b in rows:
            if a < b:
                assert not np.array_equal(rows[a], rows[b]), (a, b)
    # Without mipmaps the far checker aliases into full contrast; trilinear
    # averages it towards the mean colour.
    assert rows["nearest"].std() > rows["mip_linear"].std()


# --- wrap modes ------------------------------------------------------------------


def test_wrap_modes_agree_inside_and_differ_outside(gl):
    # uv from -1 to 2: the middle third is the texture itself in every mode.
    images = {w: render(gl, facing_square(Texture("labels", filter="nearest", wrap=w), 3.0, -1.0), 96)
              for w in ("repeat", "mirrored", "clamp")}
    inner = (slice(34, 62), slice(34, 62))
    outer = (slice(0, 30), slice(0, 30))  # uv (-1..0, -1..0)
    for w in ("mirrored", "clamp"):
        assert np.array_equal(images[w][inner], images["repeat"][inner])
    for a, b in (("repeat", "mirrored"), ("repeat", "clamp"), ("mirrored", "clamp")):
        assert not np.array_equal(images[a][outer], images[b][outer]), (a, b)
    # Repeat shows the (1,1) quadrant just above-left of the middle, mirrored
    # the (0,0) one again, clamp the border's white.
    assert tuple(images["repeat"][28, 28]) == QUADRANT_COLORS[(1, 1)]
    assert tuple(images["mirrored"][28, 28]) == QUADRANT_COLORS[(0, 0)]
    assert tuple(images["clamp"][5, 5]) == (255, 255, 255)


# --- the lesson ------------------------------------------------------------------


def test_texture_plan_is_pinned():
    assert plan(TextureLesson().scene()).describe() == "\n".join([
        "plan for texture",
        "buffers: colour RGBA8, depth 24, no MSAA",
        "programs:",
        "  basic[SOLID_COLOR,TEXTURED]",
        "passes:",
        "  1. clear viewport 0: colour (0.55, 0.7, 0.9, 1) + depth",
        "  2. draw viewport 0 (depth test): ground with basic[SOLID_COLOR,TEXTURED] + texture unit 0: "
        "checker (mip_linear, repeat); cube with basic[SOLID_COLOR,TEXTURED] + texture unit 0: labels "
        "(mip_linear, repeat)",
    ])


def test_sampler_settings_are_scene_data():
    scene = TextureLesson(filter="anisotropic", wrap="clamp").scene()
    assert {n.material.texture.filter for n in scene.nodes} == {"anisotropic"}
    assert {n.material.texture.wrap for n in scene.nodes} == {"clamp"}


TEXTURE_VARIANTS = {
    **{f: {"filter": f} for f in ("nearest", "linear", "mip_nearest", "mip_linear", "anisotropic")},
    "mirrored": {"wrap": "mirrored", "ground": "labels"},
    "clamp": {"wrap": "clamp"},
}


@pytest.mark.parametrize("variant", sorted(TEXTURE_VARIANTS))
def test_texture_goldens(gl, golden, variant):
    frame = gl.render(TextureLesson(**TEXTURE_VARIANTS[variant]), (256, 256))
    golden(frame.image, f"texture/{variant}")


# --- the images --------------------------------------------------------------------


def test_project_images():
    image = labels()
    assert image.shape == (256, 256, 4)
    for (u, v), color in QUADRANT_COLORS.items():
        assert tuple(image[20 + 200 * v, 20 + 200 * u, :3]) == color
    levels = mip_levels()
    assert [lv.shape[0] for lv in levels] == [256 >> k for k in range(9)]


def test_user_image_file_is_used(gl, tmp_path):
    path = tmp_path / "mine.png"
    Image.new("RGB", (8, 8), (10, 200, 30)).save(path)
    image = render(gl, facing_square(Texture(str(path), filter="nearest")))
    assert tuple(image[32, 32]) == (10, 200, 30)


# --- bad input ---------------------------------------------------------------------


def bad_files(tmp_path):
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(b"this is not an image at all")
    truncated = tmp_path / "truncated.png"
    Image.new("RGB", (64, 64), (1, 2, 3)).save(truncated)
    truncated.write_bytes(truncated.read_bytes()[:60])
    huge = tmp_path / "huge.png"
    Image.new("L", (20000, 1)).save(huge)  # wider than GL_MAX_TEXTURE_SIZE (16384 on llvmpipe)
    return {
        "missing": (tmp_path / "nope.png", "not found"),
        "folder": (tmp_path, "is a folder"),
        "corrupt": (corrupt, "not an image"),
        "truncated": (truncated, "corrupt or unreadable"),
        "huge": (huge, "larger than this context allows"),
    }


@pytest.mark.parametrize("case", ["missing", "folder", "corrupt", "truncated", "huge"])
def test_bad_texture_files_raise_one_line_naming_the_file(gl, tmp_path, case):
    path, reason = bad_files(tmp_path)[case]
    with pytest.raises(SandboxError) as error:
        gl.render(TextureLesson(image=str(path)), (32, 32))
    message = str(error.value)
    assert "\n" not in message and str(path) in message and reason in message, message


def test_cli_bad_texture_file_exits_2_and_writes_nothing(tmp_path):
    out = tmp_path / "out.png"
    missing = tmp_path / "nope.png"
    proc = run_cli("render", "texture", "--set", f"image={missing}", "--size", "32x32", "--out", str(out),
                   unchanged=tmp_path)  # nothing half-written
    assert_user_error(proc, str(missing), "not found")


def test_unknown_sampler_and_wrap_names():
    with pytest.raises(SandboxError, match="unknown texture filter 'bilinear'"):
        Texture("checker", filter="bilinear")
    with pytest.raises(SandboxError, match="unknown texture wrap 'tile'"):
        Texture("checker", wrap="tile")
    with pytest.raises(SandboxError, match="texture file .*nope.png not found"):
        load_image("nope.png")


def test_cli_unknown_filter_is_a_one_line_error(tmp_path):
    proc = run_cli("render", "texture", "--set", "filter=bilinear", "--out", str(tmp_path / "x.png"))
    assert_user_error(proc, "bilinear")
