#version 400 core
// A test and benchmark harness for common/bvh.glsl (glsandbox.raytrace.gpu_bvh):
// one fragment per ray. The rays come in two RGBA32F textures laid out like
// the target, origin + t_max and direction + cull flag; the results go to two
// RGBA32F targets:
//   location 0: (t, caller's triangle index (-1: miss), u, v)
//   location 1: (overflow 0/1, loop iterations used, any-hit 0/1, 0)
// BVH_ANY (defined to 1) traces shadow queries (bvh_any) instead of the nearest hit.
// BVH_CAMERA (defined to 1) makes the rays here instead, as shaders/raytrace.glsl
// does: primary rays through the pixel centres of a perspective camera (no
// ray textures; what the ray tracer's fragment shader will do).

#if defined(VERTEX_SHADER)
#include "common/fullscreen_vertex.glsl"

#elif defined(FRAGMENT_SHADER)
#include "common/bvh.glsl"

#if defined(BVH_CAMERA) && BVH_CAMERA
uniform vec2 u_size;    // the image in pixels
uniform vec3 u_eye;     // camera position (world)
uniform mat3 u_basis;   // view space -> world (right, up, back)
uniform vec2 u_half;    // image plane half-size at distance 1
uniform float u_t_max;
uniform bool u_cull;
#else
uniform sampler2D u_ray_origins;  // xyz origin, w t_max
uniform sampler2D u_ray_dirs;     // xyz direction, w 1.0 to cull back faces
#endif
layout(location = 0) out vec4 out_hit;
layout(location = 1) out vec4 out_info;

void main() {
#if defined(BVH_CAMERA) && BVH_CAMERA
    vec2 ndc = 2.0 * gl_FragCoord.xy / u_size - 1.0;  // pixel centres, row 0 at the bottom
    vec4 o = vec4(u_eye, u_t_max);
    vec4 d = vec4(u_basis * vec3(ndc * u_half, -1.0), u_cull ? 1.0 : 0.0);
#else
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 o = texelFetch(u_ray_origins, pixel, 0);
    vec4 d = texelFetch(u_ray_dirs, pixel, 0);
#endif
#if defined(BVH_ANY) && BVH_ANY
    bool overflow;
    bool found = bvh_any(o.xyz, d.xyz, o.w, d.w > 0.5, overflow);
    out_hit = vec4(0.0, -1.0, 0.0, 0.0);
    out_info = vec4(overflow ? 1.0 : 0.0, 0.0, found ? 1.0 : 0.0, 0.0);
#else
    BvhHit hit = bvh_closest(o.xyz, d.xyz, o.w, d.w > 0.5);
    out_hit = vec4(hit.t, float(hit.index), hit.uv);
    out_info = vec4(hit.overflow ? 1.0 : 0.0, float(hit.steps), 0.0, 0.0);
#endif
}
#endif
