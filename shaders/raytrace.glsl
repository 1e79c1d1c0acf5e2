#version 400 core
// The ray tracer as one fragment shader (glsandbox.raytrace.gpu): one
// fragment = one pixel = one primary ray, with its shadow rays and
// reflection bounces. The same algorithm as the float64 numpy engine
// (glsandbox/raytrace/numpy_engine.py; render.py's docstring gives the course
// sections), in float32. A fragment shader, not a compute shader: on llvmpipe it
// measured about 5x faster for this.
//
// Data (uploaded by glsandbox/raytrace/gpu.py), flat arrays of vec4 records:
// TRI_RECORDS per triangle and NODE_RECORDS per node, each field at the
// offset glsandbox/raytrace/gpu_records.py defines (TRI_V0, NODE_INVERSE...,
// with what each float holds); the node's kind code (NODE_BOX_MIN's w) is a
// KIND_<NAME> define from glsandbox.raytrace.world.NodeKind. Mesh nodes
// first (u_mesh_count of them), then the analytic nodes (u_shape_count).
// A small scene has them in a uniform block (SceneData: u_node, u_tri), a
// larger one in RGBA32F textures read with texelFetch (u_nodes, u_tris).
//
// Variants: NUM_LIGHTS (the light loop), NUM_TEXTURES (0..4 samplers),
// SHADOWS (shadow rays; CUTOUT_SHADOWS: some textured cut-out, whose shadow
// rays read its texels), REFLECT (reflection bounces and passes through
// see-through surfaces: some node reflects, is a cut-out or is blended, and
// max_depth > 0), HAS_MESHES, HAS_SHAPES (some analytic node) and
// HAS_<KIND> per analytic kind (HAS_SPHERE, HAS_CYLINDER; their cases in
// shape_t and shape_surface), TWO_SIDED (a node is lit
// on both sides), SEE_THROUGH (a node is a cut-out or blended), SIMPLE_OFFSET
// (the teaching variant of the secondary rays' offset), VERTEX_COLORS (a node uses
// them); SCENE_NODES (the scene's node list, see nearest()) with
// NODE_COUNT and TRI_COUNT for a small scene, whose records are in the
// uniform block.
//
// Why variants: llvmpipe runs a fragment shader on 8 lanes (pixels) at
// once with execution masks. An `if` whose lanes are all off still executes
// (masked); only a loop can skip work, and only iterations after the first:
// it runs while any lane is still in it. So code a scene cannot reach
// (shadow rays with shadows off, the sphere test in a scene without
// spheres, vertex colours nobody uses) is compiled out instead of branched
// around, and the AABB test decides how many iterations a node's triangle
// loop runs. Data read with an index the compiler can see is constant (a
// node's records in an unrolled node list) is one load for all 8 lanes; an
// index that varies per lane is 8 loads, and texelFetch costs more again.
// Ties keep the course's min_indis rule exactly: the first node in scene
// order, then the first triangle, wins.

#define TEX_WIDTH 1024
// INF (no hit), FLT_MIN_NORMAL and the error bounds come from
// glsandbox/raytrace/constants.py's glsl_defines().

#if defined(VERTEX_SHADER)
#include "common/fullscreen_vertex.glsl"

#elif defined(FRAGMENT_SHADER)
uniform int u_mesh_count;    // mesh nodes: records 0 .. u_mesh_count-1
uniform int u_shape_count;  // analytic nodes (spheres, cylinders): the next u_shape_count records
uniform vec2 u_size;        // the image in pixels
uniform vec3 u_eye;         // camera position (world)
uniform mat3 u_basis;       // view space -> world (right, up, back)
uniform vec2 u_half;        // image plane half-size at distance 1: tan(fov/2)*aspect, tan(fov/2)
uniform vec3 u_background;  // the viewport's clear colour
uniform int u_max_depth;    // reflection bounces (REFLECT: > 0)
uniform int u_cull;         // -1: per node (as the rasterizer), 0: never, 1: always
uniform bool u_aabb;
uniform float u_offset;     // SIMPLE_OFFSET (the teaching variant): offset u_offset * max(1, max|P|), not the error bound
uniform vec3 u_offset_origin;  // SIMPLE_OFFSET: the anchor, so |P| is the world position's, as in the numpy engine
#if NUM_LIGHTS > 0
uniform vec3 u_light_pos[NUM_LIGHTS];
uniform vec3 u_light_color[NUM_LIGHTS];
#endif
#if NUM_TEXTURES > 0
uniform sampler2D u_tex0;
uniform int u_wrap[NUM_TEXTURES];
#endif
#if NUM_TEXTURES > 1
uniform sampler2D u_tex1;
#endif
#if NUM_TEXTURES > 2
uniform sampler2D u_tex2;
#endif
#if NUM_TEXTURES > 3
uniform sampler2D u_tex3;
#endif
out vec4 frag_color;

// The general program's node counts: literals from the host (gpu.py), so a
// scene of one mesh node (a model) runs its node loop as straight code: a
// loop whose bound is a uniform cost about 15% of a primary frame of a
// 1,000-triangle model on llvmpipe, before any BVH work.
#ifndef MESH_NODES
#define MESH_NODES u_mesh_count
#endif
#ifndef SHAPE_NODES
#define SHAPE_NODES u_shape_count
#endif

#if defined(SCENE_NODES)
layout(std140) uniform SceneData {
    vec4 u_node[NODE_COUNT * NODE_RECORDS];
    vec4 u_tri[TRI_COUNT * TRI_RECORDS];
};
vec4 node_rec(int k, int r) { return u_node[k * NODE_RECORDS + r]; }
vec4 tri_rec(int k, int r) { return u_tri[k * TRI_RECORDS + r]; }
#else
uniform sampler2D u_tris;
uniform sampler2D u_nodes;
// Record i's texel (i >= 0: unsigned row and column, a mask and a shift; see bvh_at).
vec4 record(sampler2D s, int i) {
    uint u = uint(i);
    return texelFetch(s, ivec2(int(u % uint(TEX_WIDTH)), int(u / uint(TEX_WIDTH))), 0);
}
vec4 node_rec(int k, int r) { return record(u_nodes, k * NODE_RECORDS + r); }
vec4 tri_rec(int k, int r) { return record(u_tris, k * TRI_RECORDS + r); }
#endif

#define WT_DOUBLE_EDGES 0  // see common/watertight.glsl: watertight without, and cheaper
#include "common/watertight.glsl"

#ifndef BVH
#define BVH 0
#endif
#ifndef CUTOUT_SHADOWS
#define CUTOUT_SHADOWS 0
#endif
#if SHADOWS && CUTOUT_SHADOWS
// A textured cut-out blocks a shadow ray only on a drawn texel (shadow_texel,
// below); the BVH's any-hit walk asks it for the node g_shadow_node.
bool shadow_texel(int k, int j, float t, vec2 bary, vec3 o, vec3 d);
int g_shadow_node = -1;
#define BVH_ANY_ACCEPT(index, t, uv) shadow_texel(g_shadow_node, index, t, uv, o, d)
#else
#define shadow_texel(k, j, t, bary, o, d) true
#endif
#if BVH
// Mesh nodes traced through their BVHs (gpu.py packs one per mesh node into
// one texture pair; u_bvh_roots texel k holds mesh slot k's root node). A
// ray that runs out of BVH_MAX_STEPS sets g_overflow; main writes alpha 0
// and the host raises instead of showing the picture.
#include "common/bvh.glsl"
uniform sampler2D u_bvh_roots;
bool g_overflow = false;
int bvh_root(int k) { return int(texelFetch(u_bvh_roots, ivec2(k, 0), 0).x); }
#endif

// Hızlandırma: AABB. The slab test: the ray is inside the box between the
// largest entry and the smallest exit; skip the node unless that interval
// is non-empty, ends after 0 and starts before the best hit so far.
bool slab(vec3 o, vec3 inv_d, vec3 lo, vec3 hi, float best) {
    vec3 ta = (lo - o) * inv_d;
    vec3 tb = (hi - o) * inv_d;
    vec3 tn = min(ta, tb);
    vec3 tf = max(ta, tb);
    float near = max(max(tn.x, tn.y), tn.z);
    float far = min(min(tf.x, tf.y), tf.z);
    return near <= far && far > 0.0 && near < best;
}

// The watertight triangle test (common/watertight.glsl, the one the BVH
// traversal uses too): a ray through a shared edge or vertex hits one of its
// triangles, never none. `uv` gets the hit's barycentric (u, v), which the
// shading needs (so it is not solved again there). Backface culling
// (course "Hızlandırma: backface culling") keeps the front faces only.
float triangle_t(int k, WtRay r, bool cull, out vec2 uv) {
    float t = wt_triangle(r, tri_rec(k, TRI_V0).xyz, tri_rec(k, TRI_V1).xyz, tri_rec(k, TRI_V2).xyz, cull, uv);
    return t > 0.0 ? t : INF;
}

// triangle_t for the unrolled scan: INF for a miss (wt_hit accepts only
// t above its error bound, which is >= 0, so that is t > 0.0 too) and the
// undivided barycentrics vwd (uv = vwd.xy / vwd.z, divided once per ray).
float triangle_hit(int k, WtRay r, bool cull, out vec3 vwd) {
    return wt_hit(r, tri_rec(k, TRI_V0).xyz, tri_rec(k, TRI_V1).xyz, tri_rec(k, TRI_V2).xyz, cull, INF, vwd);
}

const float PI = 3.14159265358979;

// --- the analytic kinds (glsandbox/raytrace/shapes/, one GLSL file each): a hit
// test <kind>_t and a surface <kind>_surface (own-space normal, uv) per kind.
// SHAPE_T_CASES and SHAPE_SURFACE_CASES (shapes.glsl_dispatch) hold one case per
// kind the scene has; there is no default case: a kind code with none flags the
// pixel (g_bad_kind, alpha 0.25) and the host raises.
#include "shapes/sphere.glsl"
#include "shapes/cylinder.glsl"

bool g_bad_kind = false;

float shape_t(int kind, vec3 o, vec3 d, bool cull) {
    SHAPE_T_CASES
    g_bad_kind = true;
    return INF;
}

// q: the hit in the kind's own space; n: its own-space normal.
void shape_surface(int kind, vec3 q, out vec3 n, out vec2 uv) {
    SHAPE_SURFACE_CASES
    g_bad_kind = true;
    n = vec3(0.0);
    uv = vec2(0.0);
}
// --- end of the analytic kinds

vec3 to_object(int k, vec3 p, float w) {
    vec4 h = vec4(p, w);
    return vec3(dot(node_rec(k, NODE_INVERSE), h), dot(node_rec(k, NODE_INVERSE + 1), h),
                dot(node_rec(k, NODE_INVERSE + 2), h));
}

bool node_cull(vec4 r1) { return u_cull < 0 ? r1.w > 0.5 : u_cull == 1; }

// How many of mesh node k's triangles a ray tests: all of them, or none
// when the ray misses the node's box (or meets it only beyond `best`).
// Lanes with 0 leave the triangle loop at once, and when all 8 lanes of a
// block miss, the loop ends after one masked pass instead of one per
// triangle. The count is read from the node's record, not written into the
// source: with a known bound Mesa unrolls the loop into a test per
// triangle, each behind its own exit (measured on 8 and 16 mesh nodes:
// slower, and 1.5 to 1.7 times the compile time).
int box_count(int k, vec3 o, vec3 inv_d, float best) {
    return !u_aabb || slab(o, inv_d, node_rec(k, NODE_BOX_MIN).xyz, node_rec(k, NODE_BOX_MAX).xyz, best)
        ? int(node_rec(k, NODE_RANGE).y) : 0;
}

// The nearest hit with t > 0 (tDistances / min_indis): its t, node `k`,
// triangle `j` (-1 for a sphere) and barycentric `uv` (meshes).
float nearest(vec3 o, vec3 d, out int hit_node, out int hit_tri, out vec2 hit_uv) {
    float best = INF;
    hit_node = -1;
    hit_tri = -1;
    hit_uv = vec2(0.0);
    WtRay wr = wt_ray(o, d);
    vec3 inv_d = wr.inv_d;
    vec2 uv;
#if defined(SCENE_NODES)
    // The node list unrolled, in scene order: SCENE_NODES is a sequence of
    // MESH(k, start, count, cull, lamps) (a loop over the node's triangles from
    // `start`), TRI(k, j, cull, lamps) (one triangle of a node too small to
    // be worth a loop, gpu.UNROLL_TRIS) and SHAPE(k, kind, cull, lamps) (an
    // analytic node, its KIND_* a literal), with the
    // record slot, triangles, one-sidedness and lamp bits as literals, so
    // node records are read at constant indices, and a strict `<` gives
    // ties to the earlier node and triangle (min_indis).
    vec3 vwd, hit_vwd = vec3(0.0, 0.0, 1.0);
#define MESH(k, start, count, cull, lamps) { \
        int stop = start + box_count(k, o, inv_d, best); \
        for (int j = start; j < stop; ++j) { \
            float t = triangle_hit(j, wr, cull != 0, vwd); \
            if (t < best) { best = t; hit_node = k; hit_tri = j; hit_vwd = vwd; } \
        } \
    }
    // RUN_BEGIN RUN_NODE(..)... RUN_LOOP RUN_PICK(..)... RUN_END: a run of
    // consecutive looped nodes whose triangles follow each other
    // (gpu.py's scene_nodes), one loop over the triangles from the first
    // node whose box the ray meets to the end of the last. llvmpipe runs a
    // loop's first pass for all 8 lanes even when none is in it, so a group
    // that misses every box pays one masked pass for the run, not one per
    // node. The loop runs in triangle order, which is scene order, so a
    // strict `<` still gives ties to the earlier node and triangle; the
    // triangles of a node between two met ones are tested too (a superset:
    // the nearest hit is the same).
#define RUN_BEGIN { int lo = TRI_COUNT, hi = 0;
#define RUN_NODE(k, start, count, cull, lamps) \
        if (box_count(k, o, inv_d, best) > 0) { lo = min(lo, start); hi = start + count; }
#define RUN_LOOP for (int j = lo; j < hi; ++j) { int node = -1; bool one_sided = false;
#define RUN_PICK(k, start, count, cull, lamps) if (j >= start) { node = k; one_sided = cull != 0; }
#define RUN_END \
            float t = triangle_hit(j, wr, one_sided, vwd); \
            if (t < best) { best = t; hit_node = node; hit_tri = j; hit_vwd = vwd; } \
        } \
    }
#define TRI(k, j, cull, lamps) { \
        float t = triangle_hit(j, wr, cull != 0, vwd); \
        if (t < best) { best = t; hit_node = k; hit_tri = j; hit_vwd = vwd; } \
    }
    // PAIR(k, j, cull, lamps, s0, s1, s2, fresh): triangles j and j + 1 of a
    // node (a quad) sharing two corners: j + 1's corner m is j's corner s_m,
    // or (s_m == 3) its own record TRI_V0 + fresh. Shared corners are the
    // same floats, so transforming them once gives the same test.
#define PAIR(k, j, cull, lamps, s0, s1, s2, fresh) { \
        vec3 c[4] = vec3[4](wt_corner(wr, tri_rec(j, TRI_V0).xyz), wt_corner(wr, tri_rec(j, TRI_V1).xyz), \
                            wt_corner(wr, tri_rec(j, TRI_V2).xyz), wt_corner(wr, tri_rec(j + 1, TRI_V0 + fresh).xyz)); \
        float t = wt_hit_corners(c[0], c[1], c[2], cull != 0, INF, vwd); \
        if (t < best) { best = t; hit_node = k; hit_tri = j; hit_vwd = vwd; } \
        t = wt_hit_corners(c[s0], c[s1], c[s2], cull != 0, INF, vwd); \
        if (t < best) { best = t; hit_node = k; hit_tri = j + 1; hit_vwd = vwd; } \
    }
#define SHAPE(k, kind, cull, lamps) { \
        float t = shape_t(kind, to_object(k, o, 1.0), to_object(k, d, 0.0), cull != 0); \
        if (t < best) { best = t; hit_node = k; hit_tri = -1; } \
    }
    SCENE_NODES
#undef TRI
#undef PAIR
#undef MESH
#undef SHAPE
#undef RUN_BEGIN
#undef RUN_NODE
#undef RUN_LOOP
#undef RUN_PICK
#undef RUN_END
    hit_uv = hit_vwd.xy / hit_vwd.z;  // a sphere's is unused
#else
    // Any number of nodes: mesh nodes, then sphere nodes, in two loops over
    // the records; an equal t goes to the node first in scene order (r2.z),
    // and within a node to the first triangle.
    float best_order = 1e9;
#if HAS_MESHES && BVH
    for (int k = 0; k < MESH_NODES; ++k) {
        BvhHit h = bvh_closest_at(bvh_root(k), o, d, best, node_cull(node_rec(k, NODE_BOX_MAX)));
        if (h.overflow) g_overflow = true;
        if (h.index >= 0 && h.t < best) {
            best = h.t; best_order = node_rec(k, NODE_RANGE).z; hit_node = k; hit_tri = h.index; hit_uv = h.uv;
        }
    }
#elif HAS_MESHES
    for (int k = 0; k < MESH_NODES; ++k) {
        vec4 r0 = node_rec(k, NODE_BOX_MIN);
        vec4 r1 = node_rec(k, NODE_BOX_MAX);
        if (u_aabb && !slab(o, inv_d, r0.xyz, r1.xyz, best)) continue;
        bool cull = node_cull(r1);
        vec4 r2 = node_rec(k, NODE_RANGE);
        int start = int(r2.x);
        int stop = start + int(r2.y);
        for (int j = start; j < stop; ++j) {
            float t = triangle_t(j, wr, cull, uv);
            if (t < best || (t == best && t < INF && r2.z < best_order)) {
                best = t; best_order = r2.z; hit_node = k; hit_tri = j; hit_uv = uv;
            }
        }
    }
#endif
#if HAS_SHAPES
    for (int k = MESH_NODES; k < MESH_NODES + SHAPE_NODES; ++k) {
        vec4 r0 = node_rec(k, NODE_BOX_MIN);
        vec4 r1 = node_rec(k, NODE_BOX_MAX);
        if (u_aabb && !slab(o, inv_d, r0.xyz, r1.xyz, best)) continue;
        float t = shape_t(int(r0.w), to_object(k, o, 1.0), to_object(k, d, 0.0), node_cull(r1));
        float order = node_rec(k, NODE_RANGE).z;
        if (t < best || (t == best && t < INF && order < best_order)) {
            best = t; best_order = order; hit_node = k; hit_tri = -1;
        }
    }
#endif
#endif
    return best;
}

#if SHADOWS
// The shadow query for light `light`: is anything hit with 0 < t < 1? Any
// hit answers it, so a lane stops testing at its first; the light's lamp
// is skipped.
bool occluded(vec3 o, vec3 d, int light) {
    WtRay wr = wt_ray(o, d);
    vec3 inv_d = wr.inv_d;
    vec2 uv;
#if defined(SCENE_NODES)
    bool hit = false;
    vec3 vwd;
    // The lamp bits are literals: the lamp test is one comparison per node,
    // none where the compiler unrolls the light loop.
#define MESH(k, start, count, cull, lamps) if (((lamps >> light) & 1) == 0) { \
        int stop = start + box_count(k, o, inv_d, 1.0); \
        for (int j = start; j < stop && !hit; ++j) { \
            float t = triangle_hit(j, wr, cull != 0, vwd); \
            hit = t < 1.0 && shadow_texel(k, j, t, vwd.xy / vwd.z, o, d); \
        } \
    }
    // A run (see nearest()) without the light's own lamp: its box counts as
    // missed, and its triangles, where the loop passes through them, do not block.
#define RUN_BEGIN { int lo = TRI_COUNT, hi = 0;
#define RUN_NODE(k, start, count, cull, lamps) \
        if (((lamps >> light) & 1) == 0 && box_count(k, o, inv_d, 1.0) > 0) { lo = min(lo, start); hi = start + count; }
#define RUN_LOOP for (int j = lo; j < hi && !hit; ++j) { int node = -1; bool one_sided = false; bool lamp = false;
#define RUN_PICK(k, start, count, cull, lamps) \
        if (j >= start) { node = k; one_sided = cull != 0; lamp = ((lamps >> light) & 1) != 0; }
#define RUN_END \
            float t = triangle_hit(j, wr, one_sided, vwd); \
            hit = !lamp && t < 1.0 && shadow_texel(node, j, t, vwd.xy / vwd.z, o, d); \
        } \
    }
#define TRI(k, j, cull, lamps) if (((lamps >> light) & 1) == 0 && !hit) { \
        float t = triangle_hit(j, wr, cull != 0, vwd); \
        hit = t < 1.0 && shadow_texel(k, j, t, vwd.xy / vwd.z, o, d); \
    }
#define PAIR(k, j, cull, lamps, s0, s1, s2, fresh) if (((lamps >> light) & 1) == 0 && !hit) { \
        vec3 c[4] = vec3[4](wt_corner(wr, tri_rec(j, TRI_V0).xyz), wt_corner(wr, tri_rec(j, TRI_V1).xyz), \
                            wt_corner(wr, tri_rec(j, TRI_V2).xyz), wt_corner(wr, tri_rec(j + 1, TRI_V0 + fresh).xyz)); \
        float t = wt_hit_corners(c[0], c[1], c[2], cull != 0, INF, vwd); \
        hit = t < 1.0 && shadow_texel(k, j, t, vwd.xy / vwd.z, o, d); \
        if (!hit) { \
            t = wt_hit_corners(c[s0], c[s1], c[s2], cull != 0, INF, vwd); \
            hit = t < 1.0 && shadow_texel(k, j + 1, t, vwd.xy / vwd.z, o, d); \
        } \
    }
#define SHAPE(k, kind, cull, lamps) if (((lamps >> light) & 1) == 0) { \
        hit = hit || shape_t(kind, to_object(k, o, 1.0), to_object(k, d, 0.0), cull != 0) < 1.0; \
    }
    SCENE_NODES
#undef TRI
#undef PAIR
#undef MESH
#undef SHAPE
#undef RUN_BEGIN
#undef RUN_NODE
#undef RUN_LOOP
#undef RUN_PICK
#undef RUN_END
    return hit;
#else
#if HAS_MESHES && BVH
    for (int k = 0; k < MESH_NODES; ++k) {
        if (((int(node_rec(k, NODE_EXTRA).z) >> light) & 1) != 0) continue;
#if CUTOUT_SHADOWS
        g_shadow_node = k;
#endif
        bool overflow;
        bool blocked = bvh_any_at(bvh_root(k), o, d, 1.0, node_cull(node_rec(k, NODE_BOX_MAX)), overflow);
        if (overflow) g_overflow = true;
        if (blocked) return true;
    }
#elif HAS_MESHES
    for (int k = 0; k < MESH_NODES; ++k) {
        vec4 r0 = node_rec(k, NODE_BOX_MIN);
        vec4 r1 = node_rec(k, NODE_BOX_MAX);
        if (((int(node_rec(k, NODE_EXTRA).z) >> light) & 1) != 0) continue;
        if (u_aabb && !slab(o, inv_d, r0.xyz, r1.xyz, 1.0)) continue;
        bool cull = node_cull(r1);
        vec4 r2 = node_rec(k, NODE_RANGE);
        int start = int(r2.x);
        int stop = start + int(r2.y);
        for (int j = start; j < stop; ++j) {
            float t = triangle_t(j, wr, cull, uv);
            if (t < 1.0 && shadow_texel(k, j, t, uv, o, d)) return true;
        }
    }
#endif
#if HAS_SHAPES
    for (int k = MESH_NODES; k < MESH_NODES + SHAPE_NODES; ++k) {
        vec4 r0 = node_rec(k, NODE_BOX_MIN);
        vec4 r1 = node_rec(k, NODE_BOX_MAX);
        if (((int(node_rec(k, NODE_EXTRA).z) >> light) & 1) != 0) continue;
        if (u_aabb && !slab(o, inv_d, r0.xyz, r1.xyz, 1.0)) continue;
        if (shape_t(int(r0.w), to_object(k, o, 1.0), to_object(k, d, 0.0), node_cull(r1)) < 1.0) return true;
    }
#endif
    return false;
#endif
}
#endif

#if NUM_TEXTURES > 0
int wrap_index(int i, int size, int mode) {
    if (mode == 0) return i - size * int(floor(float(i) / float(size)));  // repeat
    if (mode == 1) {  // mirrored repeat
        int m = i - 2 * size * int(floor(float(i) / float(2 * size)));
        return m < size ? m : 2 * size - 1 - m;
    }
    return clamp(i, 0, size - 1);  // clamp to edge
}

vec4 fetch_texel(int slot, ivec2 ij) {
#if NUM_TEXTURES > 1
    if (slot == 1) return texelFetch(u_tex1, ij, 0);
#endif
#if NUM_TEXTURES > 2
    if (slot == 2) return texelFetch(u_tex2, ij, 0);
#endif
#if NUM_TEXTURES > 3
    if (slot == 3) return texelFetch(u_tex3, ij, 0);
#endif
    return texelFetch(u_tex0, ij, 0);
}

ivec2 texture_size(int slot) {
#if NUM_TEXTURES > 1
    if (slot == 1) return textureSize(u_tex1, 0);
#endif
#if NUM_TEXTURES > 2
    if (slot == 2) return textureSize(u_tex2, 0);
#endif
#if NUM_TEXTURES > 3
    if (slot == 3) return textureSize(u_tex3, 0);
#endif
    return textureSize(u_tex0, 0);
}

// Bilinear in the base level, the wrap mode done by hand (as the numpy engine).
vec4 sample_texture(int slot, vec2 uv) {
    ivec2 size = texture_size(slot);
    int mode = u_wrap[slot];
    vec2 xy = uv * vec2(size) - 0.5;
    vec2 base = floor(xy);
    vec2 f = xy - base;
    int x0 = int(base.x), y0 = int(base.y);
    int xa = wrap_index(x0, size.x, mode), xb = wrap_index(x0 + 1, size.x, mode);
    int ya = wrap_index(y0, size.y, mode), yb = wrap_index(y0 + 1, size.y, mode);
    vec4 top = mix(fetch_texel(slot, ivec2(xa, ya)), fetch_texel(slot, ivec2(xb, ya)), f.x);
    vec4 bottom = mix(fetch_texel(slot, ivec2(xa, yb)), fetch_texel(slot, ivec2(xb, yb)), f.x);
    return mix(top, bottom, f.y);
}
#endif

// Point, unit normal, base colour and alpha (the colour's times the
// texture's) of a hit; `bary` is the (u, v) the triangle test found.
void surface(int k, int j, float t, vec2 bary, vec3 o, vec3 d, out vec3 p, out vec3 n, out vec3 base,
             out float alpha) {
    vec4 look = node_rec(k, NODE_LOOK);  // alpha, alpha mode, cutoff, flags
    int flags = int(look.w);
    p = o + t * d;
    vec2 uv = vec2(0.0);
    vec3 colors = vec3(1.0);
#if HAS_SHAPES && HAS_MESHES
    if (j < 0) {
#endif
#if HAS_SHAPES
        vec3 q;  // the hit's own-space normal, through the normal matrix
        shape_surface(int(node_rec(k, NODE_BOX_MIN).w), to_object(k, p, 1.0), q, uv);
        n = vec3(dot(node_rec(k, NODE_NORMAL).xyz, q), dot(node_rec(k, NODE_NORMAL + 1).xyz, q),
                 dot(node_rec(k, NODE_NORMAL + 2).xyz, q));
#endif
#if HAS_SHAPES && HAS_MESHES
    } else {
#endif
#if HAS_MESHES
        // Barycentric weights of the hit: t(u,v) = V0 + u(V1−V0) + v(V2−V0).
        vec3 w = vec3(1.0 - bary.x - bary.y, bary.x, bary.y);
        vec4 a = tri_rec(j, TRI_NORMAL), b = tri_rec(j, TRI_NORMAL + 1), c = tri_rec(j, TRI_NORMAL + 2);
        n = w.x * a.xyz + w.y * b.xyz + w.z * c.xyz;
#if TWO_SIDED
        // Two-sided: a back face seen (the ray along the face normal (V1-V0) x (V2-V0), the
        // rasterizer's !gl_FrontFacing) is lit as its other side. Compiled out where no node
        // is: on llvmpipe its mere presence cost 6% of a phong frame, run or not.
        vec3 v0 = tri_rec(j, TRI_V0).xyz;
        if ((flags & 2) != 0 && dot(cross(tri_rec(j, TRI_V1).xyz - v0, tri_rec(j, TRI_V2).xyz - v0), d) > 0.0) n = -n;
#endif
#if VERTEX_COLORS || NUM_TEXTURES > 0
        vec4 ca = tri_rec(j, TRI_COLOR), cb = tri_rec(j, TRI_COLOR + 1), cc = tri_rec(j, TRI_COLOR + 2);
        uv = w.x * vec2(a.w, b.w) + w.y * vec2(c.w, ca.w) + w.z * vec2(cb.w, cc.w);
        colors = w.x * ca.xyz + w.y * cb.xyz + w.z * cc.xyz;
#endif
#endif
#if HAS_SHAPES && HAS_MESHES
    }
#endif
    n = normalize(n);
    vec4 m = node_rec(k, NODE_COLOR);
    base = m.rgb;
#if VERTEX_COLORS
    if (int(m.w) == 1 || (flags & 1) != 0) base *= colors;  // vertex colours (unlit, or tinting a lit colour)
#endif
    alpha = look.x;
#if NUM_TEXTURES > 0
    int slot = int(node_rec(k, NODE_EXTRA).y);
    if (slot >= 0) {
        vec4 texel = sample_texture(slot, uv);
        base *= texel.rgb;
        alpha *= texel.a;
    }
#endif
}

// How much of a hit surface covers what lies behind it (numpy_engine's coverage):
// opaque 1, a cut-out 1 or 0 by its cutoff, a blended surface its alpha.
float coverage(int k, float alpha) {
    vec4 look = node_rec(k, NODE_LOOK);
    int mode = int(look.y);
    return mode == 1 ? (alpha >= look.z ? 1.0 : 0.0) : mode == 2 ? alpha : 1.0;
}

#if SHADOWS && CUTOUT_SHADOWS
// Whether shadow ray o + t d (0 < t < 1) meeting node k's triangle j at `bary`
// is blocked there (numpy_engine._drawn_texels): anywhere on an opaque node,
// on a cut-out only where it is drawn, its alpha (surface's: the colour's
// times the texel's) at or above the cutoff. The rasterizer's planar shadow
// and shadow map discard the same texels.
bool shadow_texel(int k, int j, float t, vec2 bary, vec3 o, vec3 d) {
    vec4 look = node_rec(k, NODE_LOOK);  // alpha, alpha mode, cutoff, flags
    if (int(look.y) != 1) return true;
    vec3 p, n, base;
    float alpha;
    surface(k, j, t, bary, o, d, p, n, base, alpha);
    return alpha >= look.z;
}
#endif

// Where secondary rays start (pbrt-v4, "Robust spawned ray origins"): the
// hit point with a bound `err` on its rounding error per component, and the
// geometric normal `ng`. A triangle's point is recomputed from its
// barycentrics, P = b0 V0 + b1 V1 + b2 V2, off the plane by at most
// TRIANGLE_POINT_ERROR * (|b0 V0| + |b1 V1| + |b2 V2|); a sphere's, O + t D,
// by SPHERE_POINT_ERROR * (|O| + |t D|) (constants.py gives both).
struct Spawn {
    vec3 p;
    vec3 err;
    vec3 ng;
};

Spawn spawn_at(int j, float t, vec2 bary, vec3 o, vec3 d, vec3 n) {
    Spawn s;
#if HAS_MESHES
    if (j >= 0) {
        vec3 v0 = tri_rec(j, TRI_V0).xyz, v1 = tri_rec(j, TRI_V1).xyz, v2 = tri_rec(j, TRI_V2).xyz;
        vec3 a = (1.0 - bary.x - bary.y) * v0, b = bary.x * v1, c = bary.y * v2;
        s.p = a + b + c;
        s.err = TRIANGLE_POINT_ERROR * (abs(a) + abs(b) + abs(c));
        vec3 g = cross(v1 - v0, v2 - v0);
        s.ng = dot(g, g) > 0.0 ? normalize(g) : n;
        return s;
    }
#endif
    s.p = o + t * d;
    s.err = SPHERE_POINT_ERROR * (abs(o) + abs(t * d));
    s.ng = n;
    return s;
}

// x moved one float away from zero's side given by `dir` (pbrt's NextFloatUp/Down).
float next_float(float x, float dir) {
    if (dir == 0.0) return x;
    if (x == 0.0) return dir > 0.0 ? FLT_MIN_NORMAL : -FLT_MIN_NORMAL;
    int bits = floatBitsToInt(x);
    return intBitsToFloat((x > 0.0) == (dir > 0.0) ? bits + 1 : bits - 1);
}

// A secondary ray's origin: the point moved along the geometric normal by the
// error bound's reach along it, then rounded away (so the move itself cannot
// round back onto the surface), to the side the shading normal `n` puts
// `towards` on (as the numpy engine's _offset, which says why).
vec3 offset_point(Spawn s, vec3 n, vec3 towards) {
    vec3 offset;
#if SIMPLE_OFFSET
    // |P| of the world position (s.p is relative to the anchor): the knob means one
    // thing in both engines, a share of where the point sits in the world.
    vec3 world = s.p + u_offset_origin;
    offset = u_offset * max(1.0, max(max(abs(world.x), abs(world.y)), abs(world.z))) * s.ng;
#else
    offset = dot(abs(s.ng), s.err) * s.ng;
#endif
    if ((dot(n, towards) < 0.0) != (dot(s.ng, n) < 0.0)) offset = -offset;
    vec3 q = s.p + offset;
    return vec3(next_float(q.x, offset.x), next_float(q.y, offset.y), next_float(q.z, offset.z));
}

#include "common/course_light.glsl"

// The rasterizer's per-light Phong (common/lighting.glsl), with shadow rays.
vec3 shade(int k, vec3 p, vec3 n, vec3 mesh, vec3 d, Spawn at) {
    int mode = int(node_rec(k, NODE_COLOR).w);
    if (mode < 2) return mesh;  // solid, vertex colours: unlit
    vec3 color = vec3(0.0);
#if NUM_LIGHTS > 0
    vec4 coef = node_rec(k, NODE_PHONG);
    vec3 to_eye = -normalize(d);
    for (int i = 0; i < NUM_LIGHTS; ++i) {
        vec3 diffuse, specular;
        course_light(n, normalize(u_light_pos[i] - p), to_eye, mesh, u_light_color[i], coef.w, mode == 3,
                     diffuse, specular);
        float visible = 1.0;
#if SHADOWS
        vec3 start = offset_point(at, n, u_light_pos[i] - at.p);
        if (occluded(start, u_light_pos[i] - start, i)) visible = 0.0;
#endif
        color += min(coef.x * mesh + visible * (coef.y * diffuse + coef.z * specular), vec3(1.0));
    }
#endif
    return color;
}

void main() {
    vec2 ndc = 2.0 * gl_FragCoord.xy / u_size - 1.0;  // pixel centres, as the rasterizer samples
    vec3 o = u_eye;
    vec3 d = u_basis * vec3(ndc * u_half, -1.0);
    vec3 color = vec3(0.0);
#if REFLECT
    float weight = 1.0;
    for (int depth = 0; depth <= u_max_depth; ++depth) {
        int k, j;
        vec2 bary;
        float t = nearest(o, d, k, j, bary);
        if (k < 0) {
            color += weight * u_background;
            break;
        }
        vec3 p, n, base;
        float alpha;
        surface(k, j, t, bary, o, d, p, n, base, alpha);
        Spawn at = spawn_at(j, t, bary, o, d, n);
        vec3 local = shade(k, p, n, base, d, at);
        bool last = depth >= u_max_depth;
#if SEE_THROUGH
        // A see-through surface passes the ray on straight, weighted 1 - a; it does not
        // also reflect (numpy_engine._trace). At the last bounce its own colour stands in.
        float a = last ? 1.0 : coverage(k, alpha);
        float r = (last || a < 1.0) ? 0.0 : node_rec(k, NODE_EXTRA).x;
        color += weight * a * (1.0 - r) * local;
        if (a < 1.0) {
            o = offset_point(at, n, d);  // just behind the surface
            weight *= 1.0 - a;
            continue;
        }
#else  // every surface opaque: coverage 1
        float r = last ? 0.0 : node_rec(k, NODE_EXTRA).x;
        color += weight * (1.0 - r) * local;
#endif
        if (r <= 0.0) break;
        vec3 reflected = d - 2.0 * dot(d, n) * n;  // Yansıma vektörü
        o = offset_point(at, n, -d);
        d = reflected;
        weight *= r;
    }
#else
    int k, j;
    vec2 bary;
    float t = nearest(o, d, k, j, bary);
    if (k < 0) {
        color = u_background;
    } else {
        vec3 p, n, base;
        float alpha;
        surface(k, j, t, bary, o, d, p, n, base, alpha);
        color = shade(k, p, n, base, d, spawn_at(j, t, bary, o, d, n));
    }
#endif
#if BVH
    frag_color = vec4(clamp(color, 0.0, 1.0), g_overflow ? 0.0 : (g_bad_kind ? 0.25 : 1.0));
#else
    frag_color = vec4(clamp(color, 0.0, 1.0), g_bad_kind ? 0.25 : 1.0);
#endif
}
#endif
