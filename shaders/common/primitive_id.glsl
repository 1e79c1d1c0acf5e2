// The X-ray's primitive-id target (glsandbox.story.xray): with PRIMITIVE_ID a fragment also
// writes which node made it (u_node_id: its place in the scene's nodes + 1; 0 is no node, as
// an overlay's fragments write) and which of its draw's triangles (gl_PrimitiveID, the
// triangle's index in the mesh's index list), into the integer colour attachment 1. Blending
// never reaches an integer attachment: the last fragment to pass the depth and stencil tests
// with colour writes on is the one recorded.
#ifdef PRIMITIVE_ID
uniform uint u_node_id;
layout(location = 1) out uvec2 frag_id;
#define WRITE_PRIMITIVE_ID() frag_id = uvec2(u_node_id, uint(gl_PrimitiveID))
#else
#define WRITE_PRIMITIVE_ID()
#endif
