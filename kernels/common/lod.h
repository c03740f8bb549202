// Atlas-aware texture LOD (issue 4, seed 002), written once for GLSL and C++ (STYLE rule 2):
// GLSL includes it through lod.glsl; C++ includes it through host/lod_math.h, which maps the few
// GLSL names it uses onto <cmath>. The derivation is in docs/LOD.md; the Vulkan specification's
// "LOD Operation" (texel-space scale factors, anisotropy, bias, clamps) is followed exactly, with
// the exact gradient length (the specification also allows approximations, which hardware uses).
#ifndef GLINT_LOD_H
#define GLINT_LOD_H
#include "glint_types.h"

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

#endif
