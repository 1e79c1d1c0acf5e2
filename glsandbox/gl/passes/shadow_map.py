"""The ``shadow_map`` pass's runner: the casters' depth into the light's depth texture
(:mod:`glsandbox.gl.shadow_textures`). It binds the frame's framebuffer again after, which sets
its write masks; it fits its light's frustum to the casters and receivers at the frame's models
and draws them there, so a frame moved only by time is drawn without the moved scene."""

from __future__ import annotations

from glsandbox.gl.passes import Runner, touches_nothing
from glsandbox.gl.shadow_textures import run_shadow_map_pass

RUNNER = Runner("shadow_map", run_shadow_map_pass, touches_nothing, moved=True)
