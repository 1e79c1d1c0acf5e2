// The unit sphere |p| = 1 in its own space (glsandbox/raytrace/shapes/sphere.py).
// Needs INF, PI (shaders/raytrace.glsl) and SPHERE_C_ERROR (raytrace/constants.py).

// Işın-Küre kesim testi, the numerically stable form (Ray Tracing Gems ch. 7):
// discriminant from the vector h = l − (b/a)d, roots q/a and c/q without cancellation.
float sphere_t(vec3 o, vec3 d, bool cull) {
    if (cull && dot(o, o) < 1.0) return INF;  // from inside, every front face faces away
    vec3 l = -o;
    float a = dot(d, d);
    float b = dot(l, d);
    vec3 h = l - (b / a) * d;
    float disc = a * (1.0 - dot(h, h));
    if (disc < 0.0) return INF;
    float q = b + (b >= 0.0 ? sqrt(disc) : -sqrt(disc));
    if (q == 0.0) return INF;
    float l_len = length(l);
    float c = (l_len - 1.0) * (l_len + 1.0);
    // The sphere's error bound (derived in glsandbox/raytrace/sphere.py's intersect_many,
    // here r = 1 and the centre the origin): |c| <= γ·(|l| + 1 + |o|)·(|l| + 1), |o| = |l|,
    // means the origin is on the surface to within the arithmetic: the root c/q is 0,
    // the surface the ray leaves, and the other root (the far side, or behind) answers.
    if (abs(c) <= SPHERE_C_ERROR * (2.0 * l_len + 1.0) * (l_len + 1.0)) c = 0.0;
    float t1 = q / a;
    float t0 = c / q;
    float near = min(t0, t1);
    float far = max(t0, t1);
    return near > 0.0 ? near : (far > 0.0 ? far : INF);
}

// q: the hit; n: the own-space normal (the point itself); uv as geometry.sphere()
// lays it out: u the azimuth/2π from +z towards +x, v the polar angle/π from +y.
void sphere_surface(vec3 q, out vec3 n, out vec2 uv) {
    n = normalize(q);
    float phi = atan(n.x, n.z);
    uv = vec2((phi < 0.0 ? phi + 2.0 * PI : phi) / (2.0 * PI), acos(clamp(n.y, -1.0, 1.0)) / PI);
}
