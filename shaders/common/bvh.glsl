// BVH traversal for a fragment (or compute) shader: the course's "Hızlandırma:
// AABB" taken to its conclusion. #include it, then call bvh_closest() or
// bvh_any(). The host side (glsandbox/raytrace/gpu_bvh.py) packs a
// glsandbox.raytrace.bvh.BVH into two RGBA32F textures read with texelFetch,
// texel i at (i % BVH_TEX_WIDTH, i / BVH_TEX_WIDTH):
//
//   u_bvh_nodes  4 texels per record r: its two children, each as
//                (box min xyz, ref), (box max xyz, count):
//                count == 0: an inner child, whose own children are in record ref;
//                count >  0: a leaf of stored triangles ref .. ref+count-1.
//                Record 0 holds the root in its first two texels. A visit of an
//                inner node reads both children's boxes (4 fetches) and a leaf
//                is never visited on its own: its range comes with its box.
//                Boxes are rounded outwards to float32.
//                (BVH_WIDE 1: 8 texels a record of four children, common/bvh_wide.glsl.)
//   u_bvh_tris   3 texels per stored triangle k: 3k = (v0 xyz, caller's index),
//                3k+1 = (v1 xyz, 0), 3k+2 = (v2 xyz, 0).
// Integers are stored as floats: exact up to 2^24 (the host checks).
//
// Defines (with defaults): BVH_TEX_WIDTH (4096), BVH_STACK (64: at least
// the tree's depth; the host sets it), BVH_MAX_STEPS (8192), BVH_PAD (2^-18),
// BVH_WIDE (0; 1: the 4-wide tree of common/bvh_wide.glsl, its own record
// layout, traversed by the same two functions).
//
// The loop budget. llvmpipe ends a shader invocation's loops after 65,535
// iterations IN TOTAL, silently: sequential loops and nested loops share one
// counter (measured: two loops of 40,000 ran 40,000 and 25,534). A ray that
// needed more would just lose triangles. So the traversal is ONE loop whose
// every iteration is one unit of work (taking the next subtree off the stack
// and visiting it: its two children's boxes; or testing one triangle of a
// leaf), bounded by
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
#ifndef BVH_WIDE
#define BVH_WIDE 0
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

// Texel i's place. Indices are never negative, so the row and column are taken
// unsigned: by a power-of-two width a mask and a shift, where int's % and / need
// sign fix-ups (measured: 3-5% of a model frame's CPU time on llvmpipe).
ivec2 bvh_at(int i) {
    uint u = uint(i);
    return ivec2(int(u % uint(BVH_TEX_WIDTH)), int(u / uint(BVH_TEX_WIDTH)));
}

vec4 bvh_texel(sampler2D s, int i) {
    return texelFetch(s, bvh_at(i), 0);
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

// The slab test against child `side` (0 or 1) of record `rec` (Hızlandırma: AABB):
// the ray is in the box between the largest entry and the smallest exit. `near`
// is the entry; `entry` what the traversal holds for the child (bvh_entry).
bool bvh_child(BvhRay r, int rec, int side, float limit, out float near, out int entry) {
    ivec2 at = bvh_at(4 * rec + 2 * side);  // even, and the width is: the max texel is the next one in its row
    vec4 lo = texelFetch(u_bvh_nodes, at, 0);
    vec4 hi = texelFetch(u_bvh_nodes, at + ivec2(1, 0), 0);
    vec3 ta = (lo.xyz - r.pad - r.w.o) * r.w.inv_d;
    vec3 tb = (hi.xyz + r.pad - r.w.o) * r.w.inv_d;
    vec3 tn = min(ta, tb);
    vec3 tf = max(ta, tb);
    near = max(max(tn.x, tn.y), tn.z);
    float far = min(min(tf.x, tf.y), tf.z);
    int count = int(hi.w);
    // An inner child: its record (>= 0). A leaf: -2 - (first * 64 + count - 1)
    // (leaves hold 1..64 triangles, first < 2^24: within an int). -1: nothing.
    entry = count > 0 ? -2 - (int(lo.w) * 64 + count - 1) : int(lo.w);
    return near <= far && far >= 0.0 && near <= limit;
}

// A leaf entry's triangle range.
void bvh_leaf(int entry, out int first, out int stop) {
    uint code = uint(-2 - entry);  // >= 0
    first = int(code / 64u);
    stop = first + int(code % 64u) + 1;
}

// The watertight test against stored triangle k: t (or -1.0 for a miss),
// the caller's index and the barycentrics.
float bvh_triangle(BvhRay r, int k, bool cull, out int index, out vec2 uv) {
    vec4 t0 = bvh_texel(u_bvh_tris, 3 * k);
    index = int(t0.w);
    return wt_triangle(r.w, t0.xyz, bvh_texel(u_bvh_tris, 3 * k + 1).xyz, bvh_texel(u_bvh_tris, 3 * k + 2).xyz,
                       cull, uv);
}

// The steps of the loop below (both tree shapes). One triangle of the current leaf, if any is left, folded into the
// nearest hit by the tie rule.
void bvh_closest_triangle(BvhRay r, bool cull, float t_max, inout int tri, int tri_end, inout BvhHit hit) {
    if (tri < tri_end) {
        int index;
        vec2 uv;
        float t = bvh_triangle(r, tri, cull, index, uv);
        if (t > 0.0 && t < t_max && (t < hit.t || (t == hit.t && index < hit.index))) {
            hit.t = t;
            hit.index = index;
            hit.uv = uv;
        }
        ++tri;
    }
}

// One triangle of the current leaf for an any-hit ray: whether it counts
// (`o`, `d`: the ray, by the names BVH_ANY_ACCEPT reads).
bool bvh_any_triangle(BvhRay r, vec3 o, vec3 d, bool cull, float t_max, inout int tri, int tri_end) {
    bool found = false;
    if (tri < tri_end) {
        int index;
        vec2 uv;
        float t = bvh_triangle(r, tri, cull, index, uv);
        found = t > 0.0 && t < t_max && BVH_ANY_ACCEPT(index, t, uv);
        ++tri;
    }
    return found;
}

// The walk came to a leaf (`node` < -1): it waits for the current leaf to be done.
void bvh_wait(inout int node, inout int waiting) {
    if (node < -1) {
        waiting = node;
        node = -1;
    }
}

// The waiting leaf's triangles from the next iteration, once the current leaf is done.
void bvh_next_leaf(inout int waiting, inout int tri, inout int tri_end) {
    if (waiting != -1 && tri >= tri_end) {
        bvh_leaf(waiting, tri, tri_end);
        waiting = -1;
    }
}

#if BVH_WIDE
#include "common/bvh_wide.glsl"
#endif

// The nearest hit with 0 < t < t_max: an ordered, stackful traversal (the
// nearer child first, the other pushed with its entry distance so it can be
// skipped once a nearer hit is known). On 8-wide SIMD every loop iteration
// runs all of its code under masks, so each iteration does two things at
// once: it tests one triangle of the current leaf, and it takes the walk one
// node further (pops the next subtree, skipped if it starts beyond the best
// hit, and visits it: both children's boxes). A leaf the walk comes to waits
// (one at most: the walk pauses meanwhile) until the current one is done. The
// walk may so run one leaf ahead of the best hit, which only skips less.
// bvh_closest_at / bvh_any_at start at record `root` (several BVHs concatenated
// in one texture pair, their indices offset); bvh_closest / bvh_any at record 0.
BvhHit bvh_closest_at(int root, vec3 o, vec3 d, float t_max, bool cull) {
    BvhHit hit = BvhHit(t_max, -1, vec2(0.0), false, 0);
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    float stack_near[BVH_STACK];
    int sp = 0;
#if BVH_WIDE
    vec4 near;
    ivec4 entry;
    int node = root;  // the root record's four boxes: the first iteration's visit
#else
    float near;
    int node;
    if (!bvh_child(r, root, 0, t_max, near, node)) node = -1;
#endif
    int waiting = -1;  // a leaf entry waiting for the current leaf to be done
    int tri = 0;
    int tri_end = 0;
    bool finished = node == -1;
    for (int step = 0; step < BVH_MAX_STEPS && !finished; ++step) {
        hit.steps = step + 1;
        bvh_closest_triangle(r, cull, t_max, tri, tri_end, hit);  // one triangle of the current leaf
        if (waiting == -1) {  // the walk: one node further
            if (node == -1 && sp > 0) {  // pop the next subtree, skipped if it starts beyond the best hit
                --sp;
                node = stack_near[sp] <= hit.t ? stack[sp] : -1;
            }
#if BVH_WIDE
            if (node >= 0) {  // an inner node: its four children's boxes, the nearest taken, the rest pushed
                bvh4_visit(r, node, hit.t, near, entry);
                bvh4_sort(near, entry);
                if (sp + 3 > BVH_STACK) { hit.overflow = true; break; }  // never drop a subtree silently
#define BVH4_PUSH(c) if (entry.c != -1) { stack[sp] = entry.c; stack_near[sp] = near.c; ++sp; }
                BVH4_PUSH(w) BVH4_PUSH(z) BVH4_PUSH(y)  // far to near: the nearest pushed is popped first
#undef BVH4_PUSH
                node = entry.x;  // a child hit has a finite near (some axis of d is not 0): never after a miss
            }
#else
            if (node >= 0) {  // an inner node: both children's boxes
                float near_l, near_r;
                int left, right;
                bool hit_l = bvh_child(r, node, 0, hit.t, near_l, left);
                bool hit_r = bvh_child(r, node, 1, hit.t, near_r, right);
                if (hit_l && hit_r) {
                    if (sp == BVH_STACK) { hit.overflow = true; break; }  // never drop a subtree silently
                    bool left_first = near_l <= near_r;
                    stack[sp] = left_first ? right : left;
                    stack_near[sp] = left_first ? near_r : near_l;
                    ++sp;
                    node = left_first ? left : right;
                } else {
                    node = hit_l ? left : (hit_r ? right : -1);
                }
            }
#endif
            bvh_wait(node, waiting);
        }
        bvh_next_leaf(waiting, tri, tri_end);
        finished = tri >= tri_end && waiting == -1 && node == -1 && sp == 0;
    }
    if (!finished) hit.overflow = true;
    return hit;
}

// Whether anything is hit with 0 < t < t_max (a shadow ray): the same walk,
// unordered, ending at the first hit. Unfinished rays set `overflow`.
bool bvh_any_at(int root, vec3 o, vec3 d, float t_max, bool cull, out bool overflow) {
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    int sp = 0;
#if BVH_WIDE
    vec4 near;
    ivec4 entry;
    int node = root;
#else
    float near;
    int node;
    if (!bvh_child(r, root, 0, t_max, near, node)) node = -1;
#endif
    int waiting = -1;
    int tri = 0;
    int tri_end = 0;
    bool finished = node == -1;
    bool found = false;
    overflow = false;
    for (int step = 0; step < BVH_MAX_STEPS && !finished; ++step) {
        found = bvh_any_triangle(r, o, d, cull, t_max, tri, tri_end);
        if (waiting == -1) {
            if (node == -1 && sp > 0) node = stack[--sp];
#if BVH_WIDE
            if (node >= 0) {
                bvh4_visit(r, node, t_max, near, entry);
                if (sp + 3 > BVH_STACK) { overflow = true; break; }
                node = -1;
#define BVH4_TAKE(c) if (entry.c != -1) { if (node == -1) node = entry.c; else stack[sp++] = entry.c; }
                BVH4_TAKE(x) BVH4_TAKE(y) BVH4_TAKE(z) BVH4_TAKE(w)  // the first child hit taken, the others pushed
#undef BVH4_TAKE
            }
#else
            if (node >= 0) {
                float near_l, near_r;
                int left, right;
                bool hit_l = bvh_child(r, node, 0, t_max, near_l, left);
                bool hit_r = bvh_child(r, node, 1, t_max, near_r, right);
                if (hit_l && hit_r) {
                    if (sp == BVH_STACK) { overflow = true; break; }
                    stack[sp++] = right;
                    node = left;
                } else {
                    node = hit_l ? left : (hit_r ? right : -1);
                }
            }
#endif
            bvh_wait(node, waiting);
        }
        bvh_next_leaf(waiting, tri, tri_end);
        finished = found || (tri >= tri_end && waiting == -1 && node == -1 && sp == 0);
    }
    if (!finished) overflow = true;
    return found;
}

BvhHit bvh_closest(vec3 o, vec3 d, float t_max, bool cull) { return bvh_closest_at(0, o, d, t_max, cull); }
bool bvh_any(vec3 o, vec3 d, float t_max, bool cull, out bool overflow) {
    return bvh_any_at(0, o, d, t_max, cull, overflow);
}
