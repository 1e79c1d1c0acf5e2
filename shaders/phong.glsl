#version 330 core
// Lit surfaces (course section "Lighting"): the per-light Phong formula of
// common/lighting.glsl. Variants, set by the plan:
//   NUM_LIGHTS n   the light loop's size: only the lights in the scene
//   PER_VERTEX     Gouraud: the formula at the vertices, colours interpolated
//                  (highlights smaller than a triangle get lost)
//   BLINN          Blinn-Phong half vector instead of the reflection vector
//   NAIVE_NORMALS  the course's Output.Norm = mul(Input.Norm, world); wrong
//                  under non-uniform scale. Otherwise the normal matrix, the
//                  inverse transpose of the model's 3x3 (m_normal).
//   TEXTURED       the mesh colour is the texture (unit 0) times u_color
//   VERTEX_COLOR   the mesh colour is also multiplied by the vertex colours
//                  (a model file's, e.g. a PLY's red green blue)
//   TWO_SIDED      back faces are lit as seen: with the normal reversed
//                  (glTF doubleSided; culling is off for them)
//   ALPHA_MASK     a fragment whose alpha (u_color.a times the texture's) is
//                  below u_alpha_cutoff is discarded: a cut-out

#include "common/lighting.glsl"

#if defined(VERTEX_SHADER)
#include "common/transform.glsl"
uniform mat3 m_normal;
in vec3 in_position;
in vec3 in_normal;
#ifdef TEXTURED
in vec2 in_uv;
out vec2 v_uv;
#endif
#ifdef VERTEX_COLOR
in vec3 in_color;
#endif
#ifdef PER_VERTEX
out vec3 v_color;
#ifdef TWO_SIDED
out vec3 v_back_color;  // the same vertex lit from behind; the fragment picks by gl_FrontFacing
#endif
#else
out vec3 v_world;
out vec3 v_normal;
#ifdef VERTEX_COLOR
out vec3 v_tint;
#endif
#endif

vec3 world_normal(vec3 n) {
#ifdef NAIVE_NORMALS
    // A normal is not a position: a scale (a, b, c) must shrink it by
    // (1/a, 1/b, 1/c), not stretch it. This tilts it towards the long axis.
    return mat3(m_model) * n;
#else
    return m_normal * n;
#endif
}

void main() {
    vec4 world = m_model * vec4(in_position, 1.0);
    gl_Position = m_proj * m_view * world;
    vec3 normal = normalize(world_normal(in_normal));
#ifdef TEXTURED
    v_uv = in_uv;
#endif
    vec3 mesh = u_color.rgb;
#ifdef VERTEX_COLOR
    mesh *= in_color;
#endif
#ifdef PER_VERTEX
    v_color = shade(world.xyz, normal, mesh);
#ifdef TWO_SIDED
    v_back_color = shade(world.xyz, -normal, mesh);
#endif
#else
    v_world = world.xyz;
    v_normal = normal;
#ifdef VERTEX_COLOR
    v_tint = in_color;
#endif
#endif
}

#elif defined(FRAGMENT_SHADER)
#ifdef TEXTURED
uniform sampler2D u_texture;
in vec2 v_uv;
#endif
#ifdef PER_VERTEX
in vec3 v_color;
#ifdef TWO_SIDED
in vec3 v_back_color;
#endif
#else
in vec3 v_world;
in vec3 v_normal;
#ifdef VERTEX_COLOR
in vec3 v_tint;
#endif
#endif
#ifdef ALPHA_MASK
uniform float u_alpha_cutoff;
#endif
layout(location = 0) out vec4 frag_color;
#include "common/primitive_id.glsl"

void main() {
    WRITE_PRIMITIVE_ID();
    vec4 texel = vec4(1.0);
#ifdef TEXTURED
    texel = texture(u_texture, v_uv);
#endif
    float alpha = u_color.a * texel.a;
#ifdef ALPHA_MASK
    if (alpha < u_alpha_cutoff) discard;
#endif
#ifdef PER_VERTEX
    // Gouraud lit the vertices with u_color; the texture tints the result.
    vec3 lit = v_color;
#ifdef TWO_SIDED
    if (!gl_FrontFacing) lit = v_back_color;
#endif
    vec3 color = lit * texel.rgb;
#else
    // Interpolation shortens normals: normalise again per pixel.
    vec3 normal = normalize(v_normal);
#ifdef TWO_SIDED
    if (!gl_FrontFacing) normal = -normal;  // a back face seen: its outside is the other way
#endif
    vec3 mesh = u_color.rgb * texel.rgb;
#ifdef VERTEX_COLOR
    mesh *= v_tint;
#endif
    vec3 color = shade(v_world, normal, mesh);
#endif
    frag_color = vec4(color, alpha);
}
#endif
