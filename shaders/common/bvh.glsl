// BVH traversal for a fragment (or compute) shader: the course's "Hızlandırma:
// AABB" taken to its conclusion. #include it, then call bvh_closest() or
// bvh_any(). The host side (glsandbox/raytrace/gpu_bvh.py) packs a
// glsandbox.raytrace.bvh.BVH into two RGBA32F textures read with texelFetch,
// texel i at (i % BVH_TEX_WIDTH, i / BVH_TEX_WIDTH):
//
//   u_bvh_nodes  2 texels per node i:  2i   = (box min xyz, first)
//                                      2i+1 = (box max xyz, count)
//                count == 0: an inner node, children first and first + 1;
//                count >  0: a leaf of stored triangles first .. first+count-1.
//                Boxes are rounded outwards to float32. Node 0 is the root.
//   u_bvh_tris   3 texels per stored triangle k: 3k = (v0 xyz, caller's index),
//                3k+1 = (v1 xyz, 0), 3k+2 = (v2 xyz, 0).
// Integers are stored as floats: exact up to 2^24 (the host checks).
//
// Defines (with defaults): BVH_TEX_WIDTH (4096), BVH_STACK (64: at least
// the tree's depth; the host sets it), BVH_MAX_STEPS (8192), BVH_PAD (2^-18).
//
// The loop budget. llvmpipe ends a shader invocation's loops after 65,535
// iterations IN TOTAL, silently: sequential loops and nested loops share one
// counter (measured: two loops of 40,000 ran 40,000 and 25,534). A ray that
// needed more would just lose triangles. So the traversal is ONE loop whose
// every iteration is one unit of work (visiting an inner node: its two
// children's boxes; or testing one triangle of a leaf), bounded by
// BVH_MAX_STEPS, far below the limit. A ray that reaches the bound (or
// would overflow the stack) is not finished: the result says so
// (BvhHit.overflow) and the host raises instead of using it. A shader that
// traces several rays per invocation must keep the SUM of its loops' bounds
// under 65,535 (e.g. BVH_MAX_STEPS 8192 leaves room for 7 traversals).
//
// Tie rule: the course's min_indis, as the numpy engine: the smallest t with
// 0 < t < t_max wins; on an equal t the lower caller's triangle index wins.
// So a box entered at exactly the best t is still opened (near <= best).
//
// The triangle test is the watertight one (common/watertight.glsl), the
// same function the ray tracer's scan uses.

#ifndef BVH_TEX_WIDTH
#define BVH_TEX_WIDTH 4096
#endif
#ifndef BVH_STACK
#define BVH_STACK 64
#endif
#ifndef BVH_MAX_STEPS
#define BVH_MAX_STEPS 8192
#endif
#ifndef BVH_PAD
#define BVH_PAD 3.814697265625e-06
#endif
// BVH_ANY_ACCEPT(index, t, uv): whether bvh_any counts a hit (an any-hit
// filter, as Embree's; `o`, `d` are the ray's): every hit unless the
// includer defines it (the ray tracer's cut-out shadows).
#ifndef BVH_ANY_ACCEPT
#define BVH_ANY_ACCEPT(index, t, uv) true
#endif
#include "common/watertight.glsl"

uniform sampler2D u_bvh_nodes;
uniform sampler2D u_bvh_tris;

struct BvhHit {
    float t;        // t_max (and index -1) for a miss
    int index;      // the caller's triangle index, -1 for a miss
    vec2 uv;        // barycentrics: P = V0 + u (V1 - V0) + v (V2 - V0)
    bool overflow;  // the ray ran out of steps or stack: t and index are NOT to be trusted
    int steps;      // loop iterations used
};

vec4 bvh_texel(sampler2D s, int i) {
    return texelFetch(s, ivec2(i % BVH_TEX_WIDTH, i / BVH_TEX_WIDTH), 0);
}

// A ray as the traversal needs it: the watertight test's per-ray setup and
// the ray's part of the box padding, BVH_PAD * max|o|.
struct BvhRay {
    WtRay w;
    float pad;
};

BvhRay bvh_ray(vec3 o, vec3 d) {
    BvhRay r;
    r.w = wt_ray(o, d);
    r.pad = BVH_PAD * max(max(abs(o.x), abs(o.y)), abs(o.z));
    return r;
}

// The slab test against node `node`'s box (Hızlandırma: AABB): the ray is in
// the box between the largest entry and the smallest exit. `near` is the entry.
bool bvh_box(BvhRay r, int node, float limit, out float near) {
    vec3 lo = bvh_texel(u_bvh_nodes, 2 * node).xyz - r.pad;
    vec3 hi = bvh_texel(u_bvh_nodes, 2 * node + 1).xyz + r.pad;
    vec3 ta = (lo - r.w.o) * r.w.inv_d;
    vec3 tb = (hi - r.w.o) * r.w.inv_d;
    vec3 tn = min(ta, tb);
    vec3 tf = max(ta, tb);
    near = max(max(tn.x, tn.y), tn.z);
    float far = min(min(tf.x, tf.y), tf.z);
    return near <= far && far >= 0.0 && near <= limit;
}

// The watertight test against stored triangle k: t (or -1.0 for a miss),
// the caller's index and the barycentrics.
float bvh_triangle(BvhRay r, int k, bool cull, out int index, out vec2 uv) {
    vec4 t0 = bvh_texel(u_bvh_tris, 3 * k);
    index = int(t0.w);
    return wt_triangle(r.w, t0.xyz, bvh_texel(u_bvh_tris, 3 * k + 1).xyz, bvh_texel(u_bvh_tris, 3 * k + 2).xyz,
                       cull, uv);
}

// The nearest hit with 0 < t < t_max: an ordered, stackful traversal (the
// nearer child first, the other pushed with its entry distance so it can be
// skipped once a nearer hit is known), one unit of work per loop iteration.
// bvh_closest_at / bvh_any_at start at node `root` (several BVHs concatenated in
// one texture pair, their indices offset); bvh_closest / bvh_any at node 0.
BvhHit bvh_closest_at(int root, vec3 o, vec3 d, float t_max, bool cull) {
    BvhHit hit = BvhHit(t_max, -1, vec2(0.0), false, 0);
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    float stack_near[BVH_STACK];
    int sp = 0;
    float near;
    int node = bvh_box(r, root, t_max, near) ? root : -1;
    int tri = 0;
    int tri_end = 0;
    bool finished = node < 0;
    for (int step = 0; step < BVH_MAX_STEPS && !finished; ++step) {
        hit.steps = step + 1;
        if (tri < tri_end) {  // one triangle of the current leaf
            int index;
            vec2 uv;
            float t = bvh_triangle(r, tri, cull, index, uv);
            if (t > 0.0 && t < t_max && (t < hit.t || (t == hit.t && index < hit.index))) {
                hit.t = t;
                hit.index = index;
                hit.uv = uv;
            }
            ++tri;
            continue;
        }
        if (node < 0) {  // pop the next subtree still worth entering
            if (sp == 0) { finished = true; continue; }
            --sp;
            if (stack_near[sp] <= hit.t) node = stack[sp];
            continue;
        }
        vec4 lo = bvh_texel(u_bvh_nodes, 2 * node);
        int count = int(bvh_texel(u_bvh_nodes, 2 * node + 1).w);
        int first = int(lo.w);
        if (count > 0) {  // a leaf: its triangles in the next iterations
            tri = first;
            tri_end = first + count;
            node = -1;
            continue;
        }
        float near_l, near_r;
        bool hit_l = bvh_box(r, first, hit.t, near_l);
        bool hit_r = bvh_box(r, first + 1, hit.t, near_r);
        if (hit_l && hit_r) {
            if (sp == BVH_STACK) { hit.overflow = true; break; }  // never drop a subtree silently
            bool left_first = near_l <= near_r;
            stack[sp] = left_first ? first + 1 : first;
            stack_near[sp] = left_first ? near_r : near_l;
            ++sp;
            node = left_first ? first : first + 1;
        } else {
            node = hit_l ? first : (hit_r ? first + 1 : -1);
        }
    }
    if (!finished) hit.overflow = true;
    return hit;
}

// Whether anything is hit with 0 < t < t_max (a shadow ray): the same walk,
// ending at the first hit. Unfinished rays set `overflow`.
bool bvh_any_at(int root, vec3 o, vec3 d, float t_max, bool cull, out bool overflow) {
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    int sp = 0;
    float near;
    int node = bvh_box(r, root, t_max, near) ? root : -1;
    int tri = 0;
    int tri_end = 0;
    bool finished = node < 0;
    bool found = false;
    overflow = false;
    for (int step = 0; step < BVH_MAX_STEPS && !finished; ++step) {
        if (tri < tri_end) {
            int index;
            vec2 uv;
            float t = bvh_triangle(r, tri, cull, index, uv);
            if (t > 0.0 && t < t_max && BVH_ANY_ACCEPT(index, t, uv)) { found = true; finished = true; }
            ++tri;
            continue;
        }
        if (node < 0) {
            if (sp == 0) { finished = true; continue; }
            node = stack[--sp];
            continue;
        }
        vec4 lo = bvh_texel(u_bvh_nodes, 2 * node);
        int count = int(bvh_texel(u_bvh_nodes, 2 * node + 1).w);
        int first = int(lo.w);
        if (count > 0) {
            tri = first;
            tri_end = first + count;
            node = -1;
            continue;
        }
        float near_l, near_r;
        bool hit_l = bvh_box(r, first, t_max, near_l);
        bool hit_r = bvh_box(r, first + 1, t_max, near_r);
        if (hit_l && hit_r) {
            if (sp == BVH_STACK) { overflow = true; break; }
            stack[sp++] = first + 1;
            node = first;
        } else {
            node = hit_l ? first : (hit_r ? first + 1 : -1);
        }
    }
    if (!finished) overflow = true;
    return found;
}

BvhHit bvh_closest(vec3 o, vec3 d, float t_max, bool cull) { return bvh_closest_at(0, o, d, t_max, cull); }
bool bvh_any(vec3 o, vec3 d, float t_max, bool cull, out bool overflow) {
    return bvh_any_at(0, o, d, t_max, cull, overflow);
}
