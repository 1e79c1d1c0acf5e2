"""Everything that talks to OpenGL: contexts, shaders, targets, the executor."""
