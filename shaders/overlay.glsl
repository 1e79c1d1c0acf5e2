#version 330 core
// Overlays (labels, the composed matrix, figures): an RGBA image copied onto
// the frame texel for pixel. The executor sets the GL viewport to the image's
// rectangle and the scissor to its region; the quad covers that viewport and
// each fragment fetches exactly one texel, so text is never resampled.

#if defined(VERTEX_SHADER)
#include "common/fullscreen_vertex.glsl"

#elif defined(FRAGMENT_SHADER)
uniform sampler2D u_image;
uniform ivec2 u_origin;  // the frame pixel of the image's bottom-left corner
layout(location = 0) out vec4 frag_color;
#include "common/primitive_id.glsl"

void main() {
    WRITE_PRIMITIVE_ID();
    ivec2 size = textureSize(u_image, 0);
    ivec2 p = ivec2(gl_FragCoord.xy) - u_origin;
    // Texture row 0 is the image's top row (images are stored top first).
    frag_color = texelFetch(u_image, ivec2(p.x, size.y - 1 - p.y), 0);
}
#endif
