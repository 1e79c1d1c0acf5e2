#version 330 core
// Toon (cel) shading: the course's per-light formula (common/lighting.glsl,
// section "Lighting") with the smooth terms cut into flat tones.
//   diffuse   max(N·L, 0) rounded up to one of bands levels (1/b, 2/b, ..., 1)
//   specular  all or nothing: on where the course's highlight passes 0.5
//   outline   black where the surface turns away from the eye (N·E < outline)
// Uniforms of its own come from the scene file's [nodes.uniforms] table or
// --set u.NAME=value; the rest are the renderer's (README "Your own shader").

#include "common/lighting.glsl"   // u_color, u_eye, u_light_pos[], u_light_color[], the coefficients, course_light()

uniform float bands;     // how many tones the lit side gets
uniform float outline;   // N·E below this is outline (0: none)

#if defined(VERTEX_SHADER)
#include "common/transform.glsl"  // m_model, m_view, m_proj
uniform mat3 m_normal;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;

void main() {
    vec4 world = m_model * vec4(in_position, 1.0);
    gl_Position = m_proj * m_view * world;
    v_world = world.xyz;
    v_normal = m_normal * in_normal;
}

#elif defined(FRAGMENT_SHADER)
in vec3 v_world;
in vec3 v_normal;
out vec4 frag_color;

void main() {
    vec3 normal = normalize(v_normal);
    vec3 to_eye = normalize(u_eye - v_world);
    vec3 mesh = u_color.rgb;
    vec3 color = vec3(0.0);
#if NUM_LIGHTS > 0
    for (int i = 0; i < NUM_LIGHTS; ++i) {
        vec3 to_light = normalize(u_light_pos[i] - v_world);
        vec3 diffuse, specular;
        course_light(normal, to_light, to_eye, mesh, u_light_color[i], u_shininess, false, diffuse, specular);
        // diffuse = max(N·L, 0)·mesh·light: replace the smooth factor by its band.
        float tone = ceil(max(dot(normal, to_light), 0.0) * bands) / bands;
        vec3 banded = tone * mesh * u_light_color[i];
        vec3 shine = step(0.5, specular) * u_light_color[i];
        color += min(u_ambient * mesh + u_diffuse * banded + u_specular * shine, vec3(1.0));
    }
#endif
    if (dot(normal, to_eye) < outline) {
        color = vec3(0.0);
    }
    frag_color = vec4(color, u_color.a);
}
#endif
