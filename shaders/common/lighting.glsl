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

#ifdef SHADOW_LIGHT
// Shadow map of light SHADOW_LIGHT (glsandbox/shadowmap.py). The receiver
// point p, moved towards the light by the bias, is projected by the light's
// projection @ view: its depth in 0..1 is compared with the map's (the
// comparison sampler returns 1 where p is at most as far as the nearest
// caster: lit). The bias is constant + slope · tan(angle between N and L)
// texels: a texel at distance d from the light is d · u_shadow_footprint
// wide (2·tan(fov/2)/size), and a surface seen at angle θ from the light
// spans tan θ texels of depth per texel of width, so a bias counted in
// texels stops acne at any scale and distance (a scene 1e-4 the size gets
// 1e-4 the world bias). Percentage-
// closer filtering averages a SHADOW_PCF x SHADOW_PCF grid of comparisons
// (1, 3, 5 or 7), one texel apart: edges get soft steps instead of stairs.
// Outside the light's frustum a point counts as lit.
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_matrix;
uniform float u_shadow_bias;
uniform float u_shadow_slope_bias;
uniform float u_shadow_texel;      // 1 / map size
uniform float u_shadow_footprint;  // a texel's width at unit distance from the light

float shadow_visibility(vec3 position, vec3 normal, vec3 to_light, float distance) {
    float cosine = clamp(dot(normal, to_light), 0.05, 1.0);
    float slope = sqrt(1.0 - cosine * cosine) / cosine;  // tan of the angle, at most about 20
    float texel = distance * u_shadow_footprint;  // the map's texel, in world units, here
    vec3 moved = position + to_light * texel * (u_shadow_bias + u_shadow_slope_bias * slope);
    vec4 clip = u_shadow_matrix * vec4(moved, 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 ndc = clip.xyz / clip.w;
    vec3 coord = ndc * 0.5 + 0.5;
    if (any(lessThan(coord, vec3(0.0))) || any(greaterThan(coord, vec3(1.0)))) return 1.0;
    // Constant bounds (a define, one variant per width): the compiler unrolls the loop.
    const int half_width = SHADOW_PCF / 2;
    float lit = 0.0;
    for (int y = -half_width; y <= half_width; ++y) {
        for (int x = -half_width; x <= half_width; ++x) {
            lit += texture(u_shadow_map, vec3(coord.xy + vec2(x, y) * u_shadow_texel, coord.z));
        }
    }
    float side = float(2 * half_width + 1);
    return lit / (side * side);
}
#endif

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
        vec3 light_offset = u_light_pos[i] - position;
        vec3 to_light = normalize(light_offset);
        course_light(normal, to_light, to_eye, mesh, u_light_color[i], u_shininess, blinn, diffuse, specular);
        float visible = 1.0;
#ifdef SHADOW_LIGHT
        // In shadow only the ambient term stays (the ray tracer's rule).
        if (i == SHADOW_LIGHT) visible = shadow_visibility(position, normal, to_light, length(light_offset));
#endif
        color += min(u_ambient * mesh + visible * (u_diffuse * diffuse + u_specular * specular), vec3(1.0));
    }
#endif
    return color;
}
