// One light's diffuse and specular terms, the course's formula (section
// "Lighting"), shared by the rasterizer (common/lighting.glsl) and the GLSL
// ray tracer (raytrace.glsl) so both renderers light a surface identically:
//
//   diffuse   D = max(N·L, 0) · mesh · lightColor
//   reflected R = fromLight - 2 (fromLight·N) N = 2 (N·L) N - L,  fromLight = -L
//   specular  S = max(R·toEye, 0)^shininess · lightColor      (zero where N·L <= 0)
//   Blinn:    R·toEye is replaced by N·H, H = normalize(L + toEye)
//
// All vectors are unit length, in world space.
void course_light(vec3 normal, vec3 to_light, vec3 to_eye, vec3 mesh, vec3 light_color, float shininess,
                  bool blinn, out vec3 diffuse, out vec3 specular) {
    float n_dot_l = dot(normal, to_light);
    diffuse = max(n_dot_l, 0.0) * mesh * light_color;
    float highlight = 0.0;
    if (n_dot_l > 0.0) {
        float cosine = blinn ? dot(normal, normalize(to_light + to_eye))
                             : dot(to_eye, 2.0 * n_dot_l * normal - to_light);
        highlight = pow(max(cosine, 0.0), shininess);
    }
    specular = highlight * light_color;
}
