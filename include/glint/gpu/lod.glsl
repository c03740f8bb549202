// glint's atlas-aware LOD for any GLSL shader: compile with glslangValidator -I<prefix>/include
// (GL_GOOGLE_include_directive), #include "glint/gpu/lod.glsl", then call glint_lod(query, atlas)
// with a GlintLodQuery and a GlintLodAtlas. The functions live in lod_impl.h, which is also the C++
// twin (glint::lod_math) and the source of glint's own LOD kernels. docs/LOD.md derives them.
#include "lod.h"
#include "lod_impl.h"
