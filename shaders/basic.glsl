#version 330 core
// Unlit geometry: a flat colour (SOLID_COLOR) or the mesh's per-vertex
// colours interpolated across each triangle (VERTEX_COLOR, the course's
// Tutorial 04 cube).

#if defined(VERTEX_SHADER)
#include "common/transform.glsl"

in vec3 in_position;
#ifdef VERTEX_COLOR
in vec3 in_color;
out vec3 v_color;
#endif

void main() {
    gl_Position = to_clip(in_position);
#ifdef VERTEX_COLOR
    v_color = in_color;
#endif
}

#elif defined(FRAGMENT_SHADER)
uniform vec4 u_color;
#ifdef VERTEX_COLOR
in vec3 v_color;
#endif
out vec4 frag_color;

void main() {
#ifdef VERTEX_COLOR
    frag_color = vec4(v_color, 1.0) * u_color;
#else
    frag_color = u_color;
#endif
}
#endif
