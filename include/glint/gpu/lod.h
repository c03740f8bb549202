// Atlas-aware texture LOD, the data half, written once for GLSL and C++: the query and atlas
// structs and their flags. The functions are in lod_impl.h (GLSL: include lod.glsl; C++: include
// <glint/gpu/lod_impl.h>, which supplies the few GLSL built-ins it uses from <cmath>). The
// derivation is in docs/LOD.md; the Vulkan specification's "LOD Operation" (texel-space scale
// factors, anisotropy, bias, clamps) is followed exactly, with the exact gradient length (the
// specification also allows approximations, which hardware uses).
#ifndef GLINT_GPU_LOD_H
#define GLINT_GPU_LOD_H
#include "types.h"

// GlintLodQuery::flags and GlintLodAtlas::flags bits.
#define GLINT_LOD_ANISOTROPIC 1u  // use the anisotropic LOD (eta = min(rho_max / rho_min, max_aniso))
#define GLINT_LOD_PADDING_CAP 2u  // cap the level so the footprint stays inside the padded tile

// One query: derivatives of the sub-texture's own UV (0..1 across the tile, unwrapped: REPEAT
// inside a tile must pass derivatives of the continuous UV, not of fract(uv)) and the tile.
struct GlintLodQuery {
  GLINT_FLOAT dudx;
  GLINT_FLOAT dvdx;
  GLINT_FLOAT dudy;
  GLINT_FLOAT dvdy;
  GLINT_FLOAT tex_w;  // sub-texture size in texels at level 0
  GLINT_FLOAT tex_h;
  GLINT_FLOAT off_x;  // sub-texture offset in the atlas, texels at level 0
  GLINT_FLOAT off_y;
};

// The atlas and the sampling settings shared by a batch of queries.
struct GlintLodAtlas {
  GLINT_FLOAT atlas_w;     // atlas size in texels at level 0
  GLINT_FLOAT atlas_h;
  GLINT_FLOAT levels;      // number of mip levels in the atlas (>= 1)
  GLINT_FLOAT bias;        // LOD bias (default 0), already clamped to the device's maxSamplerLodBias
  GLINT_FLOAT max_aniso;   // maxAnisotropy (>= 1), used with GLINT_LOD_ANISOTROPIC
  GLINT_FLOAT padding;     // texels of padding around every tile at level 0, with GLINT_LOD_PADDING_CAP
  GLINT_UINT flags;
  GLINT_UINT reserved;
};

#ifdef __cplusplus
static_assert(sizeof(GlintLodQuery) == 32 && offsetof(GlintLodQuery, tex_w) == 16 && offsetof(GlintLodQuery, off_y) == 28,
              "GlintLodQuery std430 layout (8 floats)");
static_assert(sizeof(GlintLodAtlas) == 32 && offsetof(GlintLodAtlas, padding) == 20 && offsetof(GlintLodAtlas, flags) == 24,
              "GlintLodAtlas std430 layout");
#endif

#endif
