"""What one analytic shape kind is made of (:class:`ShapeKind`); the kinds are in
:mod:`glsandbox.raytrace.shapes`, one module each."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from glsandbox.geometry import Mesh

__all__ = ["Array", "ShapeKind", "glsl_path"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeKind:
    """One analytic kind's parts (see the module docstring)."""

    #: The kind's name: ``Mesh.analytic``, the ``NodeKind`` value, the GLSL file's and functions' stem.
    name: str
    #: ``hit(o, d, one_sided) -> t``: rays ``o + t·d`` (``(N, 3)`` each, in the kind's own
    #: space) against the unit shape, the nearest ``t > 0`` or inf; ``one_sided`` culls
    #: the back faces (an origin inside sees none of the front faces).
    hit: Callable[[Array, Array, bool], Array]
    #: ``surface(q) -> (normal, uv)``: at own-space hit points ``q`` ``(N, 3)``, the
    #: own-space normal (the node's normal matrix takes it to the world) and the texture coordinates.
    surface: Callable[[Array], tuple[Array, Array]]
    #: ``holds(positions) -> bool``: every point lies on the unit shape.
    holds: Callable[[Array], bool]
    #: The unit shape's box in its own space, ``(2, 3)`` min and max.
    own_box: Array
    #: The node-record fields (``gpu_records.NODE``) the kind's GLSL reads.
    record: tuple[str, ...]
    #: The raster mesh generator (``geometry.<kind>``) whose triangles tessellate the shape.
    mesh: Callable[..., Mesh]


def glsl_path(kind: ShapeKind) -> Path:
    """``shaders/shapes/<kind>.glsl``, the kind's GLSL, relative to the shader root."""
    return Path("shapes") / f"{kind.name}.glsl"
