// The course's per-light Phong (section "Lighting", the DirectX lighting
// tutorial's pixel shader), in world space. For each light i:
//
//   toLight   L = normalize(vLightPos[i] - Posw)
//   diffuse   D = max(N·L, 0) · mesh · lightColor          ("N * toLight": 0.8 × (255,0,0) = (204,0,0))
//   reflected R = fromLight - 2 (fromLight·N) N,  fromLight = -L
//   specular  S = max(R·toEye, 0)^32 · lightColor          (peak where R points at the eye)
//   colour   += min(0.1·mesh + 0.4·D + 0.3·S, 1)           (clamped per light, then summed)
//
// Two deliberate differences from the notes, both invisible with the
// course's white light: the light colour multiplies the diffuse term too (a
// yellow light cannot light a blue surface), and the specular term is zero
// where the light is behind the surface (N·L <= 0), which the notes' shader
// does not check, so no highlight appears on the dark side.
// BLINN replaces R·toEye by N·H with the half vector H = normalize(L + toEye).

uniform vec4 u_color;      // vMeshColor
uniform vec3 u_eye;        // vEyePos
uniform float u_ambient;   // 0.1
uniform float u_diffuse;   // 0.4
uniform float u_specular;  // 0.3
uniform float u_shininess; // 32
#if NUM_LIGHTS > 0
uniform vec3 u_light_pos[NUM_LIGHTS];    // vLightPos[]
uniform vec3 u_light_color[NUM_LIGHTS];  // vLightColor[]
#endif

#include "common/course_light.glsl"

vec3 shade(vec3 position, vec3 normal, vec3 mesh) {
    vec3 color = vec3(0.0);
#if NUM_LIGHTS > 0
    vec3 to_eye = normalize(u_eye - position);
#ifdef BLINN
    const bool blinn = true;
#else
    const bool blinn = false;
#endif
    for (int i = 0; i < NUM_LIGHTS; ++i) {
        vec3 diffuse, specular;
        course_light(normal, normalize(u_light_pos[i] - position), to_eye, mesh, u_light_color[i], u_shininess,
                     blinn, diffuse, specular);
        color += min(u_ambient * mesh + u_diffuse * diffuse + u_specular * specular, vec3(1.0));
    }
#endif
    return color;
}
