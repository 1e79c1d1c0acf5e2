"""Shared by the ray-tracing lessons: the course's Phong material and the demo scene.

Not a lesson (the leading underscore keeps it out of the registry): the
pieces ``ray_phong`` and ``ray_interactive`` both show.
"""

from __future__ import annotations

from glsandbox import Camera, Light, Material, Node, Scene, geometry, transforms

#: The course's first-half Phong: ka + kd + ks = 1 (course section "Phong boyama modeli").
KA, KD, KS = 0.2, 0.6, 0.2


def dx(p: tuple[float, float, float]) -> tuple[float, float, float]:
    """A course (DirectX) point in OpenGL coordinates."""
    return tuple(float(v) for v in transforms.from_directx_point(p))  # type: ignore[return-value]


def material(color: tuple[float, float, float], reflectivity: float = 0.0, shininess: float = 32.0) -> Material:
    return Material(color=(*color, 1.0), shading="phong", ambient=KA, diffuse=KD, specular=KS,
                    shininess=shininess, reflectivity=reflectivity)


def sphere(name: str, center: tuple[float, float, float], radius: float, mat: Material) -> Node:
    return Node(name, geometry.sphere(), transforms.translate(*center) @ transforms.scale(radius, radius, radius), mat)


def lamp(index: int, position: tuple[float, float, float], size: float, color=(1.0, 1.0, 1.0)) -> Node:
    """A light drawn as a small unlit cube around it (casts no shadow for its own light)."""
    return Node(f"lamp{index}", geometry.cube(), transforms.translate(*position) @ transforms.scale(size, size, size),
                Material(color=(*color, 1.0)))


def demo_scene(name: str) -> Scene:
    floor = Node("floor", geometry.plane(16.0), transforms.translate(0.0, -1.0, 0.0),
                 material((0.55, 0.55, 0.6), reflectivity=0.35))
    box = Node("box", geometry.cube24(), transforms.translate(1.8, -0.4, -1.2) @ transforms.rotate_y(0.5)
               @ transforms.scale(0.6, 0.6, 0.6), material((0.9, 0.75, 0.2)))
    lights = (Light((3.0, 4.0, 3.0)), Light((-4.0, 3.0, 1.0), (0.5, 0.5, 0.7)))
    nodes = (floor, box,
             sphere("mirror", (-0.6, 0.0, -0.5), 1.0, material((0.9, 0.9, 0.95), reflectivity=0.6)),
             sphere("red", (0.9, -0.55, 1.2), 0.45, material((0.9, 0.15, 0.1))),
             sphere("green", (-2.2, -0.6, 1.0), 0.4, material((0.2, 0.8, 0.3))),
             *(lamp(i, l.position, 0.1, l.color) for i, l in enumerate(lights)))
    camera = Camera(eye=(0.0, 1.6, 6.0), target=(0.0, -0.2, 0.0), fov_y=45.0)
    return Scene(name, nodes=nodes, camera=camera, lights=lights, clear_color=(0.45, 0.6, 0.85, 1.0))
