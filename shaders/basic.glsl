#version 330 core
// Unlit geometry: a flat colour (SOLID_COLOR) or the mesh's per-vertex
// colours interpolated across each triangle (VERTEX_COLOR, the course's
// Tutorial 04 cube). TEXTURED multiplies by the texture on unit 0 at the
// mesh's uv (course section "Texture Mapping"). ALPHA_MASK discards a
// fragment whose alpha is below u_alpha_cutoff (a model file's cut-outs).
// CUTOUT_SHADOW (with TEXTURED and ALPHA_MASK): a cut-out's planar shadow
// (or its depth in a shadow map), the flat colour where the texture's alpha
// reaches the cutoff, nothing where the part is cut out.

#if defined(VERTEX_SHADER)
#include "common/transform.glsl"

in vec3 in_position;
#ifdef VERTEX_COLOR
uniform vec4 u_color;
in vec3 in_color;
out vec4 v_color;
#endif
#ifdef TEXTURED
in vec2 in_uv;
out vec2 v_uv;
#endif

void main() {
    gl_Position = to_clip(in_position);
#ifdef TEXTURED
    v_uv = in_uv;
#endif
#ifdef VERTEX_COLOR
    // The tint u is the same at every vertex, so it can be applied here:
    // interpolating c * u gives u times the interpolated c. One multiply per
    // vertex instead of one per pixel.
    v_color = vec4(in_color, 1.0) * u_color;
#endif
}

#elif defined(FRAGMENT_SHADER)
#ifdef VERTEX_COLOR
in vec4 v_color;
#else
uniform vec4 u_color;
#endif
#ifdef TEXTURED
uniform sampler2D u_texture;
in vec2 v_uv;
#endif
#ifdef ALPHA_MASK
uniform float u_alpha_cutoff;
#endif
layout(location = 0) out vec4 frag_color;
#include "common/primitive_id.glsl"

void main() {
    WRITE_PRIMITIVE_ID();
#ifdef VERTEX_COLOR
    frag_color = v_color;
#else
    frag_color = u_color;
#endif
#if defined(CUTOUT_SHADOW)
    if (texture(u_texture, v_uv).a < u_alpha_cutoff) discard;
#else
#ifdef TEXTURED
    frag_color *= texture(u_texture, v_uv);
#endif
#ifdef ALPHA_MASK
    if (frag_color.a < u_alpha_cutoff) discard;
#endif
#endif
}
#endif
