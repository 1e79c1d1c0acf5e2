// The 4-wide BVH's traversal (common/bvh.glsl includes it when BVH_WIDE is
// 1, in place of the binary one; the same functions, bvh_closest_at and
// bvh_any_at). The host (glsandbox/raytrace/bvh_wide.py collapses the binary
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

BvhHit bvh_closest_at(int root, vec3 o, vec3 d, float t_max, bool cull) {
    BvhHit hit = BvhHit(t_max, -1, vec2(0.0), false, 0);
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    float stack_near[BVH_STACK];
    int sp = 0;
    vec4 near;
    ivec4 entry;
    int node = root;  // the root's four boxes: the first iteration's visit
    int waiting = -1;
    int tri = 0;
    int tri_end = 0;
    bool finished = false;
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
        }
        if (waiting == -1) {  // the walk: one node further
            if (node == -1 && sp > 0) {  // pop the next subtree, skipped if it starts beyond the best hit
                --sp;
                node = stack_near[sp] <= hit.t ? stack[sp] : -1;
            }
            if (node >= 0) {  // an inner node: its four children's boxes, the nearest taken, the rest pushed
                bvh4_visit(r, node, hit.t, near, entry);
                bvh4_sort(near, entry);
                if (sp + 3 > BVH_STACK) { hit.overflow = true; break; }  // never drop a subtree silently
#define BVH4_PUSH(c) if (entry.c != -1) { stack[sp] = entry.c; stack_near[sp] = near.c; ++sp; }
                BVH4_PUSH(w) BVH4_PUSH(z) BVH4_PUSH(y)  // far to near: the nearest pushed is popped first
#undef BVH4_PUSH
                node = entry[0];  // a child hit has a finite near (some axis of d is not 0): never after a miss
            }
            if (node < -1) {
                waiting = node;
                node = -1;
            }
        }
        if (waiting != -1 && tri >= tri_end) {  // the waiting leaf's triangles from the next iteration
            bvh_leaf(waiting, tri, tri_end);
            waiting = -1;
        }
        finished = tri >= tri_end && waiting == -1 && node == -1 && sp == 0;
    }
    if (!finished) hit.overflow = true;
    return hit;
}

// Any hit with 0 < t < t_max: the same walk, unordered, ending at the first hit.
bool bvh_any_at(int root, vec3 o, vec3 d, float t_max, bool cull, out bool overflow) {
    BvhRay r = bvh_ray(o, d);
    int stack[BVH_STACK];
    int sp = 0;
    vec4 near;
    ivec4 entry;
    int node = root;  // the root's four boxes: the first iteration's visit
    int waiting = -1;
    int tri = 0;
    int tri_end = 0;
    bool finished = false;
    bool found = false;
    overflow = false;
    for (int step = 0; step < BVH_MAX_STEPS && !finished; ++step) {
        if (tri < tri_end) {
            int index;
            vec2 uv;
            float t = bvh_triangle(r, tri, cull, index, uv);
            found = t > 0.0 && t < t_max && BVH_ANY_ACCEPT(index, t, uv);
            ++tri;
        }
        if (waiting == -1) {
            if (node == -1 && sp > 0) node = stack[--sp];
            if (node >= 0) {
                bvh4_visit(r, node, t_max, near, entry);
                if (sp + 3 > BVH_STACK) { overflow = true; break; }
                node = -1;
#define BVH4_TAKE(c) if (entry.c != -1) { if (node == -1) node = entry.c; else stack[sp++] = entry.c; }
                BVH4_TAKE(x) BVH4_TAKE(y) BVH4_TAKE(z) BVH4_TAKE(w)  // the first child hit taken, the others pushed
#undef BVH4_TAKE
            }
            if (node < -1) {
                waiting = node;
                node = -1;
            }
        }
        if (waiting != -1 && tri >= tri_end) {
            bvh_leaf(waiting, tri, tri_end);
            waiting = -1;
        }
        finished = found || (tri >= tri_end && waiting == -1 && node == -1 && sp == 0);
    }
    if (!finished) overflow = true;
    return found;
}
