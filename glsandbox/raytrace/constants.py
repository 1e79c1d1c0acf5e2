"""Numbers both ray tracing engines read, so they trace the same picture.

The numpy engine (:mod:`glsandbox.raytrace.numpy_engine`, float64) and the
GLSL engine (:mod:`glsandbox.raytrace.gpu`, float32, which passes them to
``shaders/raytrace.glsl`` as uniforms) import them from here and from
nowhere else; this module imports nothing.
"""

from __future__ import annotations

__all__ = ["SHADOW_OFFSET"]

#: Relative offset of secondary-ray origins (Gölge testi's shadow rays and
#: Yansıma vektörü's reflected rays): ``SHADOW_OFFSET·max(1, max|P_i|)``
#: along the normal, towards the side the ray leaves on. 2⁻¹⁶ is about 256
#: float32 ulps of the point's largest coordinate, so the GLSL engine uses
#: the same value as the float64 reference
#: (:data:`glsandbox.raytrace.SHADOW_EPSILON`, 2⁻³², suits float64 only; the
#: reasoning is in :mod:`glsandbox.raytrace.trace`).
SHADOW_OFFSET: float = 2.0**-16
