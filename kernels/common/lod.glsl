// glint's atlas-aware LOD for any kernel: #include "lod.glsl", then call glint_lod(query, atlas).
// The functions live in lod_impl.h, shared with the C++ twin (host/lod_math.h).
#include "lod.h"
#include "lod_impl.h"
