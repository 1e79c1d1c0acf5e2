// World, view, projection (the course's "World, View, Projection" constant
// buffer). Column vectors: the matrix nearest the vertex acts first.
uniform mat4 m_model;
uniform mat4 m_view;
uniform mat4 m_proj;

vec4 to_clip(vec3 position) {
    return m_proj * m_view * m_model * vec4(position, 1.0);
}
