"""Matrices: model transforms by order string, camera, projection, conversions.

Conventions
-----------

=====================  ==========================  ===============================
                       the course (DirectX 11)     glsandbox (OpenGL)
=====================  ==========================  ===============================
handedness             left-handed, +z into screen right-handed, camera looks -z
vectors                row vectors, ``v * M``      column vectors, ``M @ v``
composition            ``S * T * R``: S first      ``R @ T @ S``: S first
front faces            clockwise on screen         counter-clockwise on screen
clip-space depth       0 .. 1                      -1 .. 1
=====================  ==========================  ===============================

The conversion happens in exactly one place, :func:`from_directx_mesh` and its
helpers below: mirror z (``F = diag(1, 1, -1)``) and swap two indices of every
triangle. Mirroring z maps the course's view space onto OpenGL's view space
with the *same* picture on screen, so a triangle that looked clockwise in
DirectX still looks clockwise; swapping two indices turns it counter-clockwise,
OpenGL's default front face. A DirectX matrix ``M`` (row-vector form) becomes
``F @ M.T @ F``: transposed for column vectors, conjugated by the mirror
(which, for a rotation about y, flips the sign of the angle).

Order strings
-------------
A transform order string lists transforms in the order they are *applied to a
vertex*: ``"STR"`` scales, then translates, then rotates. That is the course's
``mScale * mTranslate * mRotate`` (row vectors apply left to right) and the
column-vector matrix ``R @ T @ S``.

pyrr
----
pyrr stores matrices for row vectors (translation in the last row) and its
``Matrix44 * Matrix44`` applies the *right* operand first (a trap the
transform-order lesson's tests show). :func:`look_at` and :func:`perspective`
build pyrr's ``create_look_at`` and ``create_perspective_projection`` here
with the same operations, transposed into column-vector form, bit for bit (a
test compares them): importing pyrr cost every start-up about 6 ms.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence

import numpy as np

from glsandbox.errors import SandboxError, plain

Matrix = np.ndarray  # a (4, 4) float64 array acting on column vectors

#: Every permutation of S, T and R, the valid transform order strings.
ORDERS: tuple[str, ...] = tuple("".join(p) for p in itertools.permutations("STR"))

#: Mirror z: the change of basis between the course's left-handed coordinates
#: and OpenGL's right-handed ones. It is its own inverse.
MIRROR_Z: Matrix = np.diag([1.0, 1.0, -1.0, 1.0])


def _vec3(value: Sequence[float] | np.ndarray, name: str = "vector") -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise SandboxError(f"{name} must be three finite numbers, got {plain(value)}")
    return arr


# --- model transforms -------------------------------------------------------


def identity() -> Matrix:
    """The 4x4 identity."""
    return np.eye(4)


#: The 4x4 identity the model transforms below start from (copied: a fresh array each).
_IDENTITY = np.eye(4)
_IDENTITY.flags.writeable = False


def translate(x: float, y: float, z: float) -> Matrix:
    """Translation by (x, y, z): the last column carries the offset."""
    # The identity copied and three entries set: half the cost of np.array on nested lists
    # (lessons move nodes every frame).
    m = _IDENTITY.copy()
    m[0, 3] = x
    m[1, 3] = y
    m[2, 3] = z
    return m


def scale(x: float, y: float, z: float) -> Matrix:
    """Non-uniform scale along the axes."""
    m = _IDENTITY.copy()  # (as translate; np.diag is Python around several numpy calls)
    m[0, 0] = x
    m[1, 1] = y
    m[2, 2] = z
    return m


def rotate_x(angle: float) -> Matrix:
    """Right-handed rotation about +x by ``angle`` radians (y turns towards z)."""
    c, s = math.cos(angle), math.sin(angle)
    m = _IDENTITY.copy()
    m[1, 1], m[1, 2], m[2, 1], m[2, 2] = c, -s, s, c
    return m


def rotate_y(angle: float) -> Matrix:
    """Right-handed rotation about +y by ``angle`` radians (z turns towards x)."""
    c, s = math.cos(angle), math.sin(angle)
    m = _IDENTITY.copy()
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def rotate_y_stack(angles: np.ndarray) -> np.ndarray:
    """:func:`rotate_y` for many angles at once: an (N, 4, 4) stack, which ``@``
    broadcasts against single matrices (a whole animation path in one product)."""
    angles = np.asarray(angles, dtype=np.float64)
    c, s = np.cos(angles), np.sin(angles)
    stack = np.zeros((len(angles), 4, 4))
    stack[:, 0, 0], stack[:, 0, 2], stack[:, 2, 0], stack[:, 2, 2] = c, s, -s, c
    stack[:, 1, 1] = stack[:, 3, 3] = 1.0
    return stack


def rotate_z(angle: float) -> Matrix:
    """Right-handed rotation about +z by ``angle`` radians (x turns towards y)."""
    c, s = math.cos(angle), math.sin(angle)
    m = _IDENTITY.copy()
    m[0, 0], m[0, 1], m[1, 0], m[1, 1] = c, -s, s, c
    return m


def parse_order(order: str) -> str:
    """Validate a transform order string; return it upper-cased.

    Raises :class:`SandboxError` listing the valid strings when ``order`` is
    not a permutation of S, T and R.
    """
    text = str(order).strip().upper()
    if text not in ORDERS:
        raise SandboxError(
            f"order {order!r} is not a permutation of S, T, R; valid orders: {', '.join(ORDERS)}"
        )
    return text


def compose(order: str, *, S: Matrix, T: Matrix, R: Matrix) -> Matrix:
    """Compose S, T and R in the order they are applied to a vertex.

    ``compose("STR", ...)`` is ``R @ T @ S``, the course's
    ``mScale * mTranslate * mRotate``: each later transform multiplies from the
    left, because with column vectors the matrix nearest the vertex acts first.
    """
    parts = {"S": S, "T": T, "R": R}
    m = np.eye(4)
    for letter in parse_order(order):
        m = parts[letter] @ m
    return m


def normal_matrix(model: Matrix) -> np.ndarray:
    """The 3x3 inverse transpose of the model matrix's upper-left block.

    Normals are covectors: under a non-uniform scale ``diag(a, b, c)`` a
    tangent stretches by (a, b, c) but the normal must shrink by (1/a, 1/b,
    1/c) to stay perpendicular. The course's ``mul(Input.Norm, world)`` is
    only right for rotations and uniform scales: under any other scale its
    normals lean off the surface (the ``phong`` lesson's ``normals=naive``).
    """
    block = np.asarray(model, dtype=np.float64)[:3, :3]
    # The determinant by cofactors on nine Python floats (numpy's det costs more than the
    # inverse on a 3x3, and a moving lit node asks every frame); it only tells singular apart.
    (a, b, c), (d, e, f), (g, h, i) = block.tolist()
    if abs(a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)) < 1e-300:
        raise SandboxError("model matrix is singular: its normal matrix does not exist")
    return np.linalg.inv(block).T


def smallest_scale(model: Matrix) -> float:
    """How much the model matrix shrinks some direction the most: the smallest
    singular value of its upper-left 3x3 block (0 for a scale of 0 along an
    axis, which flattens the mesh; its inverse, and the normal matrix, then
    do not exist, and grow as 1 / this value near it)."""
    return float(np.linalg.svd(np.asarray(model, dtype=np.float64)[:3, :3], compute_uv=False)[-1])


def scales_at_least(model: Matrix, bound: float) -> bool:
    """Whether :func:`smallest_scale` of ``model`` is at least ``bound``, cheaply.

    For the 3x3 block A with singular values s1 >= s2 >= s3:
    s3 = |det A| / (s1 s2) and s1 s2 <= (s1² + s2²) / 2 <= |A|²_F / 2, so
    s3 >= 2 |det A| / |A|²_F. When that lower bound clears ``bound`` (every
    ordinary model matrix) no singular value decomposition is needed."""
    # Nine Python floats: cheaper than numpy's det and einsum on a 3x3 (lessons move nodes
    # every frame, and each moved lit node is checked).
    if least_scale_bound(*np.asarray(model, dtype=np.float64)[:3, :3].ravel().tolist()) >= bound:
        return True
    return smallest_scale(model) >= bound


def least_scale_bound(a: float, b: float, c: float, d: float, e: float, f: float, g: float, h: float,
                      i: float) -> float:
    """2 |det A| / |A|²_F for the 3x3 block A = ((a, b, c), (d, e, f), (g, h, i)) given row by row:
    a lower bound of its smallest singular value (see :func:`scales_at_least`; 0 for a zero block)."""
    frobenius2 = a * a + b * b + c * c + d * d + e * e + f * f + g * g + h * h + i * i
    if not frobenius2 > 0.0:
        return 0.0
    return 2.0 * abs(a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)) / frobenius2


def transform_points(m: Matrix, points: np.ndarray) -> np.ndarray:
    """Apply a 4x4 matrix to an (N, 3) array of points (w = 1), with the divide."""
    pts = np.asarray(points, dtype=np.float64)
    homo = np.empty((len(pts), 4))  # (x, y, z, 1) rows, filled in place (hstack's wrappers cost more on 8 points)
    homo[:, :3] = pts
    homo[:, 3] = 1.0
    homo = homo @ np.asarray(m, dtype=np.float64).T
    return homo[:, :3] / homo[:, 3:4]


# --- camera and projection --------------------------------------------------


def _unit(v: np.ndarray) -> np.ndarray:
    """``v / |v|``, the length summed as pyrr's ``vector.normalize`` sums it (same bits)."""
    return v / np.sqrt(np.sum(v**2))


def look_at(eye: Sequence[float], target: Sequence[float], up: Sequence[float]) -> Matrix:
    """A right-handed view matrix (see :func:`_look_at`); cached by value,
    since a camera usually stays put for many frames. Returns a fresh copy."""
    key = (tuple(map(float, eye)), tuple(map(float, target)), tuple(map(float, up)))
    return _look_at_cached(*key).copy()


@functools.lru_cache(maxsize=256)
def _look_at_cached(eye: tuple, target: tuple, up: tuple) -> Matrix:
    return _look_at(eye, target, up)


def _look_at(eye: Sequence[float], target: Sequence[float], up: Sequence[float]) -> Matrix:
    """A right-handed view matrix: the camera at ``eye`` looks at ``target``.

    The view direction ``f = normalize(target - eye)`` and the up vector span
    the camera's vertical plane; their cross product is the camera's right
    axis. When ``up`` is parallel to ``f`` that cross product is zero and no
    camera exists (the course's up (0,0,1) looking along z): that is refused
    here with a clear message instead of silently producing NaNs.
    """
    e, t, u = _vec3(eye, "eye"), _vec3(target, "target"), _vec3(up, "up")
    forward = t - e
    f_len = float(np.linalg.norm(forward))
    u_len = float(np.linalg.norm(u))
    if f_len == 0.0:
        raise SandboxError(f"camera eye and target are the same point {plain(tuple(e))}")
    if u_len == 0.0:
        raise SandboxError("camera up vector is zero")
    # sin of the angle between up and the view direction.
    sin_angle = float(np.linalg.norm(np.cross(forward / f_len, u / u_len)))
    if sin_angle < 1e-9:
        raise SandboxError(
            f"camera up {plain(tuple(u))} is parallel to the view direction {plain(tuple(forward / f_len))}: "
            "no camera orientation exists; choose an up vector not along the view"
        )
    # gluLookAt: the camera's axes as the rows of the rotation, f = forward, s = f x up
    # (right), u = s x f (true up); the camera looks down -z. The last column moves the
    # eye to the origin: -R @ eye, one dot product per axis.
    f = _unit(t - e)
    s = _unit(np.cross(f, u))
    u = _unit(np.cross(s, f))
    return np.array(((s[0], s[1], s[2], -np.dot(s, e)),
                     (u[0], u[1], u[2], -np.dot(u, e)),
                     (-f[0], -f[1], -f[2], np.dot(f, e)),
                     (0.0, 0.0, 0.0, 1.0)), dtype=np.float64)


def perspective(fovy_degrees: float, aspect: float, near: float, far: float) -> Matrix:
    """OpenGL perspective projection (see :func:`_perspective`), cached by value."""
    return _perspective_cached(float(fovy_degrees), float(aspect), float(near), float(far)).copy()


@functools.lru_cache(maxsize=256)
def _perspective_cached(fovy_degrees: float, aspect: float, near: float, far: float) -> Matrix:
    return _perspective(fovy_degrees, aspect, near, far)


def _perspective(fovy_degrees: float, aspect: float, near: float, far: float) -> Matrix:
    """OpenGL perspective projection (clip-space depth -1..1).

    The course's ``XMMatrixPerspectiveFovLH(XM_PIDIV4, w/h, 0.01, 100)`` maps
    depth to 0..1 instead; the picture (x and y) is the same.
    """
    if not 0.0 < fovy_degrees < 180.0:
        raise SandboxError(f"field of view must be between 0 and 180 degrees, got {fovy_degrees}")
    if not 0.0 < near < far:
        raise SandboxError(f"need 0 < near < far, got near={near}, far={far}")
    if aspect <= 0.0:
        raise SandboxError(f"aspect ratio must be positive, got {aspect}")
    # gluPerspective: the near plane spans [-x, x] by [-y, y] with y = near * tan(fovy / 2);
    # x and y map to -1..1 at the near plane (2 near / width), and depth -near..-far maps to
    # -1..1 through clip w = -z. The frustum is symmetric, so the off-centre terms are 0.
    ymax = near * np.tan(fovy_degrees * np.pi / 360.0)
    xmax = ymax * aspect
    return np.array(((2.0 * near / (xmax + xmax), 0.0, 0.0, 0.0),
                     (0.0, 2.0 * near / (ymax + ymax), 0.0, 0.0),
                     (0.0, 0.0, -(far + near) / (far - near), -2.0 * far * near / (far - near)),
                     (0.0, 0.0, -1.0, 0.0)), dtype=np.float64)


# --- the one DirectX -> OpenGL conversion -----------------------------------


def from_directx_point(p: Sequence[float]) -> np.ndarray:
    """A point or direction given in the course's left-handed coordinates."""
    x, y, z = _vec3(p, "point")
    return np.array([x, y, -z])


#: ``F @ M @ F`` for the diagonal ``F = MIRROR_Z`` just flips the signs of
#: row 2 and column 2 (their crossing twice, so it keeps its sign).
_MIRROR_SIGNS = np.outer(np.diag(MIRROR_Z), np.diag(MIRROR_Z))


def from_directx_matrix(m_row: np.ndarray) -> Matrix:
    """A DirectX (row-vector, left-handed) 4x4 matrix in OpenGL form:
    ``MIRROR_Z @ m_row.T @ MIRROR_Z``, done as a sign flip."""
    return np.asarray(m_row, dtype=np.float64).T * _MIRROR_SIGNS


def from_directx_mesh(positions: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Convert course vertex and index buffers: mirror z, swap two indices per triangle.

    The clockwise-front triangle ``(a, b, c)`` of the course becomes
    ``(a, c, b)``, counter-clockwise-front, OpenGL's default.
    """
    pos = np.asarray(positions, dtype=np.float64).copy()
    pos[:, 2] = -pos[:, 2]
    tri = np.asarray(indices, dtype=np.int64).reshape(-1, 3)[:, [0, 2, 1]]
    return pos, tri.reshape(-1).copy()


# --- upload -----------------------------------------------------------------


def gl_bytes(m: np.ndarray) -> bytes:
    """Bytes for a GLSL ``mat3``/``mat4`` uniform: float32, column-major."""
    return np.asarray(m, dtype=np.float32).tobytes(order="F")


# --- planes, mirrors, planar shadows, reverse-Z (course section "The stencil Test") ---

Plane = tuple[float, float, float, float]


def normalize_plane(plane: Sequence[float]) -> np.ndarray:
    """A plane ``a*x + b*y + c*z + d = 0`` scaled so that (a, b, c) has length 1.

    The course's ``XMPlaneNormalize``: after it, ``n·p + d`` is the signed
    distance of a point p from the plane, positive on the side n points to.
    Dividing all four numbers by |n| keeps the same plane. A zero normal is no
    plane and is refused.
    """
    arr = np.asarray(plane, dtype=np.float64).reshape(-1)
    if arr.shape != (4,) or not np.all(np.isfinite(arr)):
        raise SandboxError(f"a plane must be four finite numbers (a, b, c, d), got {plain(plane)}")
    length = float(np.linalg.norm(arr[:3]))
    if length < 1e-12:
        raise SandboxError(f"plane {plain(tuple(arr))} has a zero normal (a, b, c): it is not a plane")
    return arr / length


def from_directx_plane(plane: Sequence[float]) -> np.ndarray:
    """A plane given in the course's left-handed coordinates, in OpenGL's.

    With z mirrored, a point (x, y, z) becomes (x, y, -z); the plane
    ``a x + b y + c z + d = 0`` therefore becomes ``a x + b y - c z + d = 0``:
    the course's mirror plane (0, 0, 1, -6), z = 6, is OpenGL's z = -6.
    """
    a, b, c, d = np.asarray(plane, dtype=np.float64).reshape(4)
    return np.array([a, b, -c, d])


def reflection_matrix(plane: Sequence[float]) -> Matrix:
    """The mirror image through a plane (the course's ``XMMatrixReflect``).

    With the plane normalized to (n, d), a point p is at signed distance
    ``s = n·p + d``; its image is ``p - 2 s n``. As a matrix (column vectors)::

        R = | I - 2 n nᵀ   -2 d n |
            |     0          1    |

    R² = I (reflecting twice gives the point back) and det R = -1: a
    reflection turns counter-clockwise triangles clockwise, so the reflected
    pass must flip the front-face rule (the course's ``CullClockwise``).
    """
    p = normalize_plane(plane)
    n, d = p[:3], p[3]
    m = np.eye(4)
    m[:3, :3] -= 2.0 * np.outer(n, n)
    m[:3, 3] = -2.0 * d * n
    return m


#: Below this |P·L| (plane normalized, light direction unit length) a light is
#: treated as parallel to the plane (directional) or lying in it (point).
SHADOW_EPSILON = 1e-9


def light_vector(light: Sequence[float]) -> np.ndarray:
    """A homogeneous light (x, y, z, w): w = 1 a point light at (x, y, z),
    w = 0 a directional light shining *from* direction (x, y, z) (the
    course's ``toMainLight = -lightDir``). Directions are normalized."""
    arr = np.asarray(light, dtype=np.float64).reshape(-1)
    if arr.shape != (4,) or not np.all(np.isfinite(arr)) or arr[3] not in (0.0, 1.0):
        raise SandboxError(f"a light must be (x, y, z, w) with w = 1 (point) or 0 (direction), got {plain(light)}")
    if arr[3] == 0.0:
        length = float(np.linalg.norm(arr[:3]))
        if length < 1e-12:
            raise SandboxError("a directional light needs a non-zero direction, got (0, 0, 0)")
        arr = np.array([*(arr[:3] / length), 0.0])
    return arr


def shadow_matrix(plane: Sequence[float], light: Sequence[float]) -> Matrix:
    """Flatten geometry onto a plane along the rays from a light (the course's ``XMMatrixShadow``).

    With P the normalized plane and L the homogeneous light (w = 1 point, w = 0
    direction), ``S = (P·L) I - L Pᵀ``. For a point X (w = 1)::

        S X = (P·L) X - (P·X) L

    a combination of X and L, so S X lies on the line through X and the light;
    and ``P·(S X) = (P·L)(P·X) - (P·X)(P·L) = 0``, so it lies on the plane.
    The homogeneous w of S X is ``P·L - P·X`` for a point light (the light's
    height above the plane minus the vertex's) and ``P·L`` for a directional
    one. w = 0 means the ray never meets the plane: a directional light
    parallel to it (refused here), or a vertex at the light's height; w < 0, a
    vertex above a point light, projects to the wrong side (the planner culls
    such casters, see :func:`glsandbox.planar.shadow_casters`). A point light
    lying in the plane gives a rank-1 matrix and is refused too.
    """
    p = normalize_plane(plane)
    l = light_vector(light)
    dot = float(p @ l)
    if abs(dot) < SHADOW_EPSILON:
        what = "parallel to" if l[3] == 0.0 else "in"
        raise SandboxError(
            f"light {plain(tuple(l))} lies {what} the shadow plane {plain(tuple(p))}: "
            "no planar shadow exists (P·L = 0)")
    return dot * np.eye(4) - np.outer(l, p)


def offset_along_normal(plane: Sequence[float], distance: float) -> Matrix:
    """A translation by ``distance`` along the plane's unit normal: the course's
    ``shadowOffsetY = XMMatrixTranslation(0, 0.005, 0)`` for any plane."""
    n = normalize_plane(plane)[:3]
    return translate(*(float(distance) * n))


#: Clip z' = (w - z) / 2: maps OpenGL's clip depth (near -1, far +1) to
#: reverse-Z (near 1, far 0) in the 0..1 range that ``glClipControl(...,
#: GL_ZERO_TO_ONE)`` keeps as is.
_REVERSE_Z = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -0.5, 0.5], [0.0, 0.0, 0.0, 1.0]])


def reverse_z(projection: Matrix) -> Matrix:
    """A projection remapped to reverse-Z: near plane at depth 1, far at 0.

    Depth d = z_ndc after the perspective divide is ``A + B/z`` (z the view
    distance): hyperbolic, so most of the 0..1 range is spent close to the
    near plane. A 24-bit integer buffer has the same step 2^-24 everywhere,
    which leaves few steps far away: with near 0.01 and far 100 two surfaces
    0.005 apart fall on one step beyond a distance of about 29. A float buffer
    has steps proportional to the value; mapping far to 0 puts the float's
    fine steps where the hyperbola is flat, which nearly cancels out: the
    relative depth precision becomes about uniform in distance. Needs
    ``glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)`` (else GL maps -1..1 to
    0..1 and halves the precision again), a float depth buffer, clear depth 0
    and the depth test ``GREATER``.
    """
    return _REVERSE_Z @ np.asarray(projection, dtype=np.float64)
