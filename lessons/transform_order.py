"""Lesson 4: transform order with two cubes.

Course section "Rotation, two cubes, transform order" (DirectX SDK Tutorial
05). The centre cube spins in place. The second cube is built from

* S = scale(0.3, 1, 0.3), a thin pillar,
* T = translate(4, 0, 0),
* R = a rotation about y by an angle that grows with time (the course's
  ``XMMatrixRotationY(t)``; converting it to OpenGL mirrors z, which flips the
  sign of the angle, so the cube turns the same way on screen),

composed in the order picked with ``--set order=...``. An order string lists
the transforms in the order they act on a vertex: ``STR`` is the course's
``mScale * mTranslate * mRotate`` (row vectors, applied left to right) and
OpenGL's ``R @ T @ S`` (column vectors: the matrix nearest the vertex acts
first). What the six orders show:

* T before R orbits the origin (R turns the already moved cube about the
  origin); R before T spins in place (R turns the cube about its own centre,
  then T moves it).
* T before S shrinks the distance too: the scale acts on the translated
  position, 4 × 0.3 = 1.2.
* S and R commute here: the scale is the same (0.3) along x and z, and the
  rotation about y only mixes x and z. So TRS looks like TSR and RST like
  SRT. At time 0 R is the identity and only the order of S and T matters:
  two classes of identical pictures; later, four.

The overlay labels the order, shows the composed matrix and what it does,
and the notes' camera constants (``glsandbox.camera``); the trail is the path
of the cube's top corner over the last seconds, so orbit and spin show in one
still image. ``--set overlay=off`` hides label, matrix and trail so renders of
different orders compare pixel for pixel. In the window, keys 1–6 pick an
order and Tab switches to the split view of all six (``--set view=split``).
"""

from __future__ import annotations

import functools
import math
import sys

import numpy as np

import glsandbox
from glsandbox import Camera, Lesson, Material, Motion, Node, Overlay, Param, Scene, Viewport, register, text_image
from glsandbox import camera as course_camera
from glsandbox import geometry, transforms

#: The course's second cube: S, T, and the rotation axis of R.
SCALE = (0.3, 1.0, 0.3)
OFFSET = (4.0, 0.0, 0.0)
#: The course's product for each letter, in DirectX's row-vector order.
COURSE_NAMES = {"S": "mScale", "T": "mTranslate", "R": "mRotate"}
WORDS = {"S": "scale", "T": "translate", "R": "rotate"}
#: The point whose path is the trail: the cube's top corner, in model space.
TRAIL_POINT = np.array([1.0, 1.0, 1.0])
TRAIL_COLOR = (1.0, 0.85, 0.1, 1.0)
TRAIL_SAMPLES = 64
#: Looking down at the orbit from the front, far enough back to see radius 4.
CAMERA = Camera(eye=(0.0, 7.0, 12.0), target=(0.0, 1.2, 0.0), up=(0.0, 1.0, 0.0), fov_y=45.0)
#: The split view's tiles are narrow: look from further back with a wider lens.
SPLIT_CAMERA = Camera(eye=(0.0, 8.0, 14.0), target=(0.0, 0.5, 0.0), up=(0.0, 1.0, 0.0), fov_y=60.0)
#: The split view's layout: three columns, two rows, orders in ORDERS order.
SPLIT_COLUMNS, SPLIT_ROWS = 3, 2


def rotation(angle: float) -> np.ndarray:
    """The course's ``XMMatrixRotationY(angle)`` in OpenGL form: ``rotate_y(-angle)``.

    Mirroring z (``F R^T F``) turns a rotation about y by ``a`` into one by ``-a``.
    """
    return transforms.rotate_y(-angle)


def second_cube_model(order: str, angle: float) -> np.ndarray:
    """The second cube's model matrix: S, T and R(angle) applied in ``order``."""
    return transforms.compose(order, S=transforms.scale(*SCALE), T=transforms.translate(*OFFSET),
                              R=rotation(angle))


def second_cube_models(order: str, angles: np.ndarray) -> np.ndarray:
    """:func:`second_cube_model` for many angles at once, an (N, 4, 4) stack:
    ``compose`` multiplies with ``@``, which broadcasts S and T over the stack of R."""
    return transforms.compose(order, S=transforms.scale(*SCALE), T=transforms.translate(*OFFSET),
                              R=transforms.rotate_y_stack(-np.asarray(angles)))  # rotation(a) is rotate_y(-a)


def order_classes(angle: float) -> list[list[str]]:
    """The six orders grouped by identical model matrices (exact float64 equality)."""
    groups: list[list[str]] = []
    matrices: list[np.ndarray] = []
    for order in transforms.ORDERS:
        m = second_cube_model(order, angle)
        for group, rep in zip(groups, matrices):
            if np.array_equal(m, rep):
                group.append(order)
                break
        else:
            groups.append([order])
            matrices.append(m)
    return groups


@functools.lru_cache(maxsize=len(transforms.ORDERS))
def motion(order: str) -> str:
    """What the cube does under ``order``, measured from the matrices: orbit or spin in place."""
    centre = [transforms.transform_points(second_cube_model(order, a), np.zeros((1, 3)))[0] for a in (0.0, 1.0)]
    if np.allclose(centre[0], centre[1], atol=1e-12):
        return f"spins in place at x = {centre[0][0]:.1f}"
    return f"orbits the origin, radius {np.linalg.norm(centre[0]):.1f}"


def course_product(order: str) -> str:
    """The course's DirectX product for ``order``, e.g. ``mScale * mTranslate * mRotate``."""
    return " * ".join(COURSE_NAMES[c] for c in order)


def gl_product(order: str) -> str:
    """OpenGL's column-vector product for ``order``, e.g. ``R @ T @ S``."""
    return " @ ".join(reversed(order))


def _fmt(value: float) -> str:
    text = f"{value:.2f}"
    return "0.00" if text == "-0.00" else text


def matrix_panel(order: str, angle: float) -> np.ndarray:
    """The overlay of the single view: order, products, motion and the matrix."""
    m = second_cube_model(order, angle)
    rows: list[str | tuple[str, ...]] = [
        f"{order}: " + ", ".join(WORDS[c] for c in order) + f" (R {math.degrees(angle):.0f} deg)",
        f"{course_product(order)}",
        f"M = {gl_product(order)} =",
        *[tuple(_fmt(v) for v in row) for row in m],
        motion(order),
    ]
    return text_image(rows)


def figures_panel() -> np.ndarray:
    """The notes' camera constants and what they do (course section "W A S D, Z X")."""
    return text_image([
        f"notes' 0.9666/0.259: r 10 -> {course_camera.course_drift(24):.2f} (24 turns),",
        f"{course_camera.course_drift(1000):.2f} (1000); rotateRight det {course_camera.course_right_determinant():.4f}",
    ])


def trail_points(order: str, angle: float, span: float) -> np.ndarray:
    """The top corner's positions while R went from ``angle - span`` to ``angle``, (N, 3)."""
    models = second_cube_models(order, np.linspace(angle - span, angle, TRAIL_SAMPLES))
    corner = models @ np.append(TRAIL_POINT, 1.0)  # (N, 4): the corner under each model
    return corner[:, :3] / corner[:, 3:]


def trail_mesh(order: str, angle: float, span: float) -> geometry.Mesh:
    """The top corner's path (:func:`trail_points`) as a line strip."""
    return geometry.Mesh(f"trail_{order}", trail_points(order, angle, span), mode="line_strip")


@register
class TransformOrder(Lesson):
    name = "transform_order"
    title = "Transform order: two cubes, six orders of S, T, R"
    course_section = "Rotation, two cubes, transform order"
    order = 35
    contrasts = (("the six orders of S, T and R", "order=STR,SRT,TSR,TRS,RST,RTS"),)
    animated = True
    params = (
        Param("order", "STR", "the order S, T, R act on the second cube (STR = mScale*mTranslate*mRotate)",
              choices=transforms.ORDERS, convert=transforms.parse_order),
        Param("speed", 1.0, "R's angle grows by this many radians per second"),
        Param("spin", 1.0, "the centre cube's spin in radians per second"),
        Param("trail", 2.0, "the trail covers the last this many radians of R", minimum=0.0, maximum=2 * math.pi),
        Param("view", "single", "one order, or all six side by side", choices=("single", "split")),
    )

    @property
    def angle(self) -> float:
        return float(self.values["speed"]) * self.time

    def on_key(self, key: str) -> bool:
        """1–6 pick an order (ORDERS order) in the single view; Tab toggles the split view."""
        if key in ("1", "2", "3", "4", "5", "6"):
            self.values["order"] = transforms.ORDERS[int(key) - 1]
            self.values["view"] = "single"
            return True
        if key == "tab":
            self.values["view"] = "split" if self.values["view"] == "single" else "single"
            return True
        return False

    def motion(self) -> Motion:
        """Time turns both cubes, moves the trail's points along (the trail keeps its vertex
        count, so its buffer is rewritten in place) and changes the matrix panel's numbers."""
        split = self.values["view"] == "split"
        orders = transforms.ORDERS if split else (transforms.parse_order(self.values["order"]),)
        span = float(self.values["trail"])
        trail = bool(self.values["overlay"]) and span > 0.0
        models, positions = {"centre": self._centre_model()}, {}
        for order in orders:
            suffix = f"_{order}" if split else ""
            models[f"second{suffix}"] = second_cube_model(order, self.angle)
            if trail:
                positions[f"trail{suffix}"] = trail_points(order, self.angle, span)
        overlays = {}
        if self.values["overlay"] and not split:
            overlays["matrix"] = matrix_panel(orders[0], self.angle)
        return Motion(models=models, positions=positions, overlays=overlays)

    def _centre_model(self) -> np.ndarray:
        return transforms.rotate_y(-float(self.values["spin"]) * self.time)

    def _centre_cube(self) -> Node:
        return Node("centre", geometry.cube(), self._centre_model(), Material(shading="vertex_color"))

    def _order_nodes(self, order: str, viewport: int | None) -> list[Node]:
        views = None if viewport is None else (viewport,)
        suffix = "" if viewport is None else f"_{order}"
        nodes = [Node(f"second{suffix}", geometry.cube(), second_cube_model(order, self.angle),
                      Material(shading="vertex_color"), viewports=views)]
        span = float(self.values["trail"])
        if self.values["overlay"] and span > 0.0:
            nodes.append(Node(f"trail{suffix}", trail_mesh(order, self.angle, span), material=Material(TRAIL_COLOR),
                              cull_back_faces=False, viewports=views))
        return nodes

    def build(self) -> Scene:
        order = transforms.parse_order(self.values["order"])
        if self.values["view"] == "split":
            return self._split()
        nodes = [self._centre_cube(), *self._order_nodes(order, None)]
        overlays = ()
        if self.values["overlay"]:
            overlays = (Overlay("matrix", matrix_panel(order, self.angle), 0, (4, 4)),
                        Overlay("figures", figures_panel(), 0, (4, -4)))
        return Scene(self.name, nodes=tuple(nodes), camera=CAMERA, overlays=overlays)

    def _split(self) -> Scene:
        """Six viewports, one per order, sharing the centre cube and the camera."""
        viewports, nodes, overlays = [], [self._centre_cube()], []
        w, h = 1.0 / SPLIT_COLUMNS, 1.0 / SPLIT_ROWS
        for i, order in enumerate(transforms.ORDERS):
            col, row = i % SPLIT_COLUMNS, i // SPLIT_COLUMNS
            viewports.append(Viewport(rect=(col * w, 1.0 - (row + 1) * h, w, h), label=order))
            nodes += self._order_nodes(order, i)
            if self.values["overlay"]:
                overlays.append(Overlay(f"label_{order}", text_image([f"{i + 1}: {order}"]), i, (2, 2)))
        return Scene(self.name, nodes=tuple(nodes), camera=SPLIT_CAMERA, viewports=tuple(viewports),
                     overlays=tuple(overlays))


if __name__ == "__main__":
    sys.exit(glsandbox.run(TransformOrder))
