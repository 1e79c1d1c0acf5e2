// The vertex stage of a full-viewport pass (overlays, the GLSL ray tracer):
// a 4-vertex triangle strip made from the vertex number alone, no buffers:
// 0 -> (-1,-1), 1 -> (1,-1), 2 -> (-1,1), 3 -> (1,1).
void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
