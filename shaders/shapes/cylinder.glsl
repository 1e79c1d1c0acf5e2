// The capped unit cylinder x² + z² <= 1, |y| <= 1 in its own space
// (glsandbox/raytrace/shapes/cylinder.py). Needs INF and PI (shaders/raytrace.glsl).

// The side is the sphere's stable quadratic (Ray Tracing Gems ch. 7) in the
// xz-plane, its roots kept where |y| <= 1; each cap the plane y = ±1 (course
// "Işın-Düzlem kesim testi"), kept where x² + z² <= 1.
float cylinder_t(vec3 o, vec3 d, bool cull) {
    if (cull && dot(o.xz, o.xz) < 1.0 && abs(o.y) < 1.0) return INF;  // from inside
    float best = INF;
    float a = dot(d.xz, d.xz);
    vec2 l = -o.xz;
    float b = dot(l, d.xz);
    vec2 h = l - (b / a) * d.xz;
    float disc = a * (1.0 - dot(h, h));
    if (a > 0.0 && disc >= 0.0) {
        float q = b + (b >= 0.0 ? sqrt(disc) : -sqrt(disc));
        if (q != 0.0) {
            float l_len = length(l);
            float c = (l_len - 1.0) * (l_len + 1.0);
            float t0 = c / q, t1 = q / a;
            if (t0 > 0.0 && t0 < best && abs(o.y + t0 * d.y) <= 1.0) best = t0;
            if (t1 > 0.0 && t1 < best && abs(o.y + t1 * d.y) <= 1.0) best = t1;
        }
    }
    if (d.y != 0.0) {
        float tb = (-1.0 - o.y) / d.y, tt = (1.0 - o.y) / d.y;
        vec2 pb = o.xz + tb * d.xz, pt = o.xz + tt * d.xz;
        if (tb > 0.0 && tb < best && dot(pb, pb) <= 1.0) best = tb;
        if (tt > 0.0 && tt < best && dot(pt, pt) <= 1.0) best = tt;
    }
    return best;
}

// As geometry.cylinder() lays them out: on a cap (the hit nearer |y| = 1 than
// x² + z² = 1) the cap's normal and (½ + x/2, ½ + z/2); on the side the radial
// normal and (azimuth/2π, (1 − y)/2).
void cylinder_surface(vec3 q, out vec3 n, out vec2 uv) {
    float r = length(q.xz);
    float phi = atan(q.x, q.z);
    if (abs(abs(q.y) - 1.0) < abs(r - 1.0)) {  // a cap
        n = vec3(0.0, sign(q.y), 0.0);
        uv = 0.5 + 0.5 * q.xz;
    } else {
        n = vec3(q.x, 0.0, q.z) / r;
        uv = vec2((phi < 0.0 ? phi + 2.0 * PI : phi) / (2.0 * PI), 0.5 * (1.0 - q.y));
    }
}
