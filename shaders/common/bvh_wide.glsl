// The 4-wide BVH's node visit (common/bvh.glsl includes it when BVH_WIDE is
// 1: its two traversals then visit 4 children a node instead of 2). The host (glsandbox/raytrace/bvh_wide.py collapses the binary
// SAH tree, gpu_bvh.pack_wide packs it) lays out 8 texels per record r, one
// plane of all four child boxes per texel, so one visit tests four boxes with
// vec4 arithmetic:
//
//   8r+0..2  box min x, y, z of children 0..3 (rounded outwards to float32)
//   8r+3..5  box max x, y, z
//   8r+6     ref:   an inner child's record, or a leaf's first stored triangle
//   8r+7     count: 0 an inner child, > 0 a leaf of that many triangles,
//                   -1 an empty slot (never entered)
//
// The loop is the binary one's (one unit of work an iteration: a triangle of
// the current leaf, and one node further), so the loop budget, the leaf that
// waits and the tie rule are as bvh.glsl describes; a visit pushes up to
// three children (the stack: 3 entries a wide level, the host sets it). The
// walk starts at the root record itself: its four boxes are the first visit
// (the binary walk tests the root's own box first; here that would be a
// visit more for every ray that enters it, measured slower on shadow rays).

// The slab test of the four children of record `rec`; `near` their entries
// (+inf where missed, so that they sort last), `entry` what the traversal
// holds for each (bvh_entry's code; -1 for a missed child).
void bvh4_visit(BvhRay r, int rec, float limit, out vec4 near, out ivec4 entry) {
    ivec2 at = bvh_at(8 * rec);  // 8 | BVH_TEX_WIDTH: the record's texels share a row
    vec3 lo = -r.pad - r.w.o;
    vec3 hi = r.pad - r.w.o;
    vec4 ax = (texelFetch(u_bvh_nodes, at, 0) + lo.x) * r.w.inv_d.x;
    vec4 ay = (texelFetch(u_bvh_nodes, at + ivec2(1, 0), 0) + lo.y) * r.w.inv_d.y;
    vec4 az = (texelFetch(u_bvh_nodes, at + ivec2(2, 0), 0) + lo.z) * r.w.inv_d.z;
    vec4 bx = (texelFetch(u_bvh_nodes, at + ivec2(3, 0), 0) + hi.x) * r.w.inv_d.x;
    vec4 by = (texelFetch(u_bvh_nodes, at + ivec2(4, 0), 0) + hi.y) * r.w.inv_d.y;
    vec4 bz = (texelFetch(u_bvh_nodes, at + ivec2(5, 0), 0) + hi.z) * r.w.inv_d.z;
    ivec4 ref = ivec4(texelFetch(u_bvh_nodes, at + ivec2(6, 0), 0));
    ivec4 count = ivec4(texelFetch(u_bvh_nodes, at + ivec2(7, 0), 0));
    vec4 n = max(max(min(ax, bx), min(ay, by)), min(az, bz));
    vec4 f = min(min(max(ax, bx), max(ay, by)), max(az, bz));
    // The four tests as vectors (no loop: a loop, even of constant bounds, may count towards
    // llvmpipe's 65,535 iterations). GLSL 3.30 has no integer mix: selects by arithmetic.
    uvec4 hit = uvec4(lessThanEqual(n, f)) & uvec4(greaterThanEqual(f, vec4(0.0)))
              & uvec4(lessThanEqual(n, vec4(limit))) & uvec4(greaterThanEqual(count, ivec4(0)));
    near = mix(vec4(1.0 / 0.0), n, bvec4(hit));
    ivec4 leaf = -2 - (ref * 64 + count - 1);
    ivec4 code = ref + (leaf - ref) * ivec4(greaterThan(count, ivec4(0)));
    entry = (code + 1) * ivec4(hit) - 1;
}

// Sorts the children nearest first (a 5-comparator network), misses last.
#define BVH4_SWAP(a, b) if (near[b] < near[a]) { \
    float tn = near[a]; near[a] = near[b]; near[b] = tn; \
    int te = entry[a]; entry[a] = entry[b]; entry[b] = te; }
void bvh4_sort(inout vec4 near, inout ivec4 entry) {
    BVH4_SWAP(0, 1) BVH4_SWAP(2, 3) BVH4_SWAP(0, 2) BVH4_SWAP(1, 3) BVH4_SWAP(1, 2)
}
#undef BVH4_SWAP
