// The watertight ray-triangle test (Woop, Benthin & Wald 2013) in float32, as
// glsandbox/raytrace/watertight.py does in float64: permute the axes so d's
// largest component is z, shear so the ray is the +z axis, and test the 2D
// edge functions. Two triangles sharing an edge form the same products for
// it, subtracted in the opposite order, so a ray can never slip between them.
// Used by the ray tracer's scan (shaders/raytrace.glsl) and by the BVH
// traversal (common/bvh.glsl), so every path a render takes is watertight.
//
// `precise` (GLSL 4.00) keeps the compiler from fusing a*b - c*d into an fma,
// which would break the exact antisymmetry; an edge function that rounds to 0
// is recomputed in double (exact for float inputs) where doubles exist and
// WT_DOUBLE_EDGES is not defined to 0. That only decides the side of a ray
// passing exactly through an edge; a 0 counts on both sides, so the test is
// watertight without it. The ray tracer leaves it out: llvmpipe runs a branch
// for all 8 lanes whenever one takes it, and the doubles cost per triangle.
//
// t is accepted only above its own rounding-error bound (pbrt-v4's deltaT):
// a shadow ray that starts a bounded distance off its surface (see
// glsandbox/raytrace/constants.py) can then never hit that surface again,
// however large the triangle. GAMMA2/3/5 (gamma(n) of float32) come as
// defines from constants.py (glsl_defines()); the fallbacks are the same values.
#ifndef WATERTIGHT_GLSL
#define WATERTIGHT_GLSL
#ifndef GAMMA2
#define GAMMA2 1.1920930376163766e-07
#endif
#ifndef GAMMA3
#define GAMMA3 1.788139663006007e-07
#endif
#ifndef GAMMA5
#define GAMMA5 2.9802331269482156e-07
#endif
#ifndef DIRECTION_TINY
#define DIRECTION_TINY 1e-30
#endif
#if __VERSION__ >= 400
#define WT_PRECISE precise
#ifndef WT_DOUBLE_EDGES
#define WT_DOUBLE_EDGES 1
#endif
#else
#define WT_PRECISE
#undef WT_DOUBLE_EDGES
#define WT_DOUBLE_EDGES 0
#endif

// What the test needs per ray (steps 1 and 2 of the paper), made once per ray.
struct WtRay {
    vec3 o;
    vec3 inv_d;     // for slab tests (zero components made tiny: no NaN)
    // The permutation and the shear (steps 1 and 2): a corner V becomes
    // (x - sx z, y - sy z, sz z) of P = V - O taken on the axes kx, ky, kz.
    bvec3 pick0;    // (kx, ky, kz) == 0
    bvec3 pick1;    // (kx, ky, kz) == 1
    vec3 s;         // sx, sy, sz
};

WtRay wt_ray(vec3 o, vec3 d) {
    WtRay r;
    r.o = o;
    vec3 ad = abs(d);
    int kz = ad.x >= ad.y ? (ad.x >= ad.z ? 0 : 2) : (ad.y >= ad.z ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0) { int k = kx; kx = ky; ky = k; }  // keep the winding
    r.s = vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    // The permutation as two masks, so a triangle's corners need no per-lane
    // vector indexing (slow on llvmpipe), only selects. A corner shared by
    // two triangles still gets the same numbers in both, which is all the
    // watertight argument needs of them.
    r.pick0 = equal(ivec3(kx, ky, kz), ivec3(0));
    r.pick1 = equal(ivec3(kx, ky, kz), ivec3(1));
    vec3 safe = mix(d, mix(vec3(-DIRECTION_TINY), vec3(DIRECTION_TINY), greaterThanEqual(d, vec3(0.0))),
                    lessThan(ad, vec3(DIRECTION_TINY)));
    r.inv_d = 1.0 / safe;
    return r;
}

// A corner in ray space: P = V - O permuted to (P[kx], P[ky], P[kz]) by
// selects, then sheared. (The same floats as the permutation-and-shear
// matrix this replaced, whose rows add 1 P[kx], -sx P[kz] and 0 P[ky]: the
// 1 and 0 products and the sum with 0 are exact; the selects are cheaper.)
vec3 wt_corner(WtRay r, vec3 v) {
    vec3 p = v - r.o;
    vec3 q = mix(mix(vec3(p.z), vec3(p.y), r.pick1), vec3(p.x), r.pick0);
    return vec3(q.x - r.s.x * q.z, q.y - r.s.y * q.z, r.s.z * q.z);
}

// E(p, q) = px qy - py qx, recomputed exactly when it rounds to 0.
float wt_edge(float px, float py, float qx, float qy) {
    WT_PRECISE float e = px * qy - py * qx;
#if WT_DOUBLE_EDGES
    if (e == 0.0) e = float(double(px) * double(qy) - double(py) * double(qx));
#endif
    return e;
}

// The test against the triangle whose corners a, b, c are already in ray
// space (wt_corner; two triangles sharing a vertex can transform it once):
// t (or `miss` for a miss) and vwd = (v, w, det), the barycentrics before
// their division: uv = vwd.xy / vwd.z (P = V0 + u (V1 - V0) + v (V2 - V0)).
// A scan keeps the nearest hit's vwd and divides once at the end: the same
// floats as dividing per triangle, without two divisions in every test.
float wt_hit_corners(vec3 a, vec3 b, vec3 c, bool cull, float miss, out vec3 vwd) {
    float u = wt_edge(c.x, c.y, b.x, b.y);  // the weight of V0
    float v = wt_edge(a.x, a.y, c.x, c.y);  // of V1
    float w = wt_edge(b.x, b.y, a.x, a.y);  // of V2
    bool negative = u < 0.0 || v < 0.0 || w < 0.0;
    bool positive = u > 0.0 || v > 0.0 || w > 0.0;
    float det = u + v + w;
    vwd = vec3(v, w, det);
    if ((cull ? negative : (negative && positive)) || det == 0.0) return miss;
    float t = (u * a.z + v * b.z + w * c.z) / det;
    // pbrt-v4's bound on t's rounding error: accept only t above it.
    float max_z = max(max(abs(a.z), abs(b.z)), abs(c.z));
    float max_x = max(max(abs(a.x), abs(b.x)), abs(c.x));
    float max_y = max(max(abs(a.y), abs(b.y)), abs(c.y));
    float delta_z = GAMMA3 * max_z;
    float delta_x = GAMMA5 * (max_x + max_z);
    float delta_y = GAMMA5 * (max_y + max_z);
    float delta_e = 2.0 * (GAMMA2 * max_x * max_y + delta_y * max_x + delta_x * max_y);
    float max_e = max(max(abs(u), abs(v)), abs(w));
    float delta_t = 3.0 * (GAMMA3 * max_e * max_z + delta_e * max_z + delta_z * max_e) / abs(det);
    return t > delta_t ? t : miss;
}

// The same against the triangle v0 v1 v2.
float wt_hit(WtRay r, vec3 v0, vec3 v1, vec3 v2, bool cull, float miss, out vec3 vwd) {
    return wt_hit_corners(wt_corner(r, v0), wt_corner(r, v1), wt_corner(r, v2), cull, miss, vwd);
}

// wt_hit with the barycentrics divided out: t (or -1.0 for a miss) and uv.
float wt_triangle(WtRay r, vec3 v0, vec3 v1, vec3 v2, bool cull, out vec2 uv) {
    vec3 vwd;
    float t = wt_hit(r, v0, v1, v2, cull, -1.0, vwd);
    uv = vwd.xy / vwd.z;
    return t;
}
#endif
