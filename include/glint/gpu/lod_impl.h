// The LOD functions, in the common subset of GLSL and C++ (scalars, sqrt, log2, floor, min, max,
// clamp, floatBitsToUint). GLSL: include "glint/gpu/lod.glsl" (or this file) and call
// glint_lod(query, atlas). C++: include <glint/gpu/lod_impl.h>; the functions are in namespace
// glint::lod_math, next to the GLSL built-ins they use, mapped onto <cmath>. glint's own
// glint::lod_level() and LodBatch kernel are this source. Every path ends in
// clamp(.., 0, levels - 1). docs/LOD.md derives it.
#ifndef GLINT_GPU_LOD_IMPL_H
#define GLINT_GPU_LOD_IMPL_H
#include "lod.h"

#ifdef __cplusplus
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
namespace glint {
namespace lod_math {
// The GLSL built-ins used below, for float.
inline float sqrt(float x) { return std::sqrt(x); }
inline float log2(float x) { return std::log2(x); }
inline float floor(float x) { return std::floor(x); }
inline float min(float a, float b) { return std::min(a, b); }
inline float max(float a, float b) { return std::max(a, b); }
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }
inline uint32_t floatBitsToUint(float x) {
  uint32_t u;
  std::memcpy(&u, &x, sizeof u);
  return u;
}
#define GLINT_LOD_FN inline
#else
#define GLINT_LOD_FN
#endif

// Below any real level: log2 of a zero footprint (magnification without limit) lands here.
#define GLINT_LOD_MIN_LAMBDA (-64.0)

// Texel-space scale factor along screen x (Vulkan spec, LOD Operation: m_ux = |du/dx| * w,
// m_vx = |dv/dx| * h; rho_x is the exact length of (m_ux, m_vx)). u scales by the sub-texture's
// width and v by its height. The atlas size does not appear: atlas level 0 stores the tile texel
// for texel, so atlas-space derivatives (du/dx * w / W) times the atlas width W give the same
// texel-space factor (chain rule, docs/LOD.md).
GLINT_LOD_FN float glint_lod_rho_x(GlintLodQuery q) {
  float mu = q.dudx * q.tex_w;
  float mv = q.dvdx * q.tex_h;
  return sqrt(mu * mu + mv * mv);
}

GLINT_LOD_FN float glint_lod_rho_y(GlintLodQuery q) {
  float mu = q.dudy * q.tex_w;
  float mv = q.dvdy * q.tex_h;
  return sqrt(mu * mu + mv * mv);
}

// Not NaN, not +-Inf, tested on the bits: the exponent field is all ones only for those. Written as
// a float test (x == x && x - x == 0), a compiler that assumes floats are finite folds it to true
// (lavapipe did in a flare shader). floatBitsToUint is GLSL's; src/lod/lod_math.h supplies it for C++.
GLINT_LOD_FN bool glint_lod_finite(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }

// Valid tile and atlas: finite numbers, a tile of at least 1x1 inside the atlas, levels >= 1.
GLINT_LOD_FN bool glint_lod_valid(GlintLodQuery q, GlintLodAtlas a) {
  bool finite = glint_lod_finite(q.dudx) && glint_lod_finite(q.dvdx) && glint_lod_finite(q.dudy) &&
                glint_lod_finite(q.dvdy) && glint_lod_finite(q.tex_w) && glint_lod_finite(q.tex_h) &&
                glint_lod_finite(q.off_x) && glint_lod_finite(q.off_y) && glint_lod_finite(a.atlas_w) &&
                glint_lod_finite(a.atlas_h) && glint_lod_finite(a.levels) && glint_lod_finite(a.bias);
  return finite && q.tex_w >= 1.0 && q.tex_h >= 1.0 && a.levels >= 1.0 && q.off_x >= 0.0 && q.off_y >= 0.0 &&
         q.off_x + q.tex_w <= a.atlas_w && q.off_y + q.tex_h <= a.atlas_h;
}

// lambda_base + bias before any clamp (spec: isotropic rho = max(rho_x, rho_y); anisotropic
// eta = min(rho_max / rho_min, max_aniso), 1 when both are 0, max_aniso when only rho_min is 0,
// lambda_base = log2(rho_max / eta)).
GLINT_LOD_FN float glint_lod_unclamped(GlintLodQuery q, GlintLodAtlas a) {
  float rx = glint_lod_rho_x(q);
  float ry = glint_lod_rho_y(q);
  float rho_max = max(rx, ry);
  float rho_min = min(rx, ry);
  float eta = 1.0;
  if ((a.flags & GLINT_LOD_ANISOTROPIC) != 0u && rho_max > 0.0) {
    // min(rho_max / rho_min, max_aniso), written as a comparison so that it never divides inf by
    // inf: when both scale factors overflow float to +inf that gave NaN, and the level fell to 0
    // instead of levels - 1. rho_min == 0 gives 0 * max_aniso = 0, not above rho_max: max_aniso.
    eta = rho_max < rho_min * a.max_aniso ? rho_max / rho_min : a.max_aniso;
  }
  float rho = rho_max / eta;
  float lambda = rho > 0.0 ? log2(rho) : GLINT_LOD_MIN_LAMBDA;
  return lambda + a.bias;
}

// The finest level that still keeps the footprint inside the tile's padding: at level L a
// bilinear tap reaches up to 1.5 level-L texels, that is under 2^(L+1) level-0 texels, beyond the
// sample point; an anisotropic footprint adds rho_max / 2 along its major axis. So the cap is the
// largest L with 2^(L+1) + reach <= padding, and 0 when even level 0 does not fit.
GLINT_LOD_FN float glint_lod_padding_cap(GlintLodQuery q, GlintLodAtlas a) {
  float reach = 0.0;
  if ((a.flags & GLINT_LOD_ANISOTROPIC) != 0u) reach = 0.5 * max(glint_lod_rho_x(q), glint_lod_rho_y(q));
  float room = a.padding - reach;
  return room >= 2.0 ? floor(log2(room)) - 1.0 : 0.0;
}

// The level a sampler uses for this query: lambda, then the padding cap, then [0, levels - 1].
// Invalid input (NaN, a tile outside the atlas, levels < 1) falls back to level 0, also clamped.
GLINT_LOD_FN float glint_lod(GlintLodQuery q, GlintLodAtlas a) {
  float top = max(a.levels - 1.0, 0.0);
  if (!glint_lod_valid(q, a)) return clamp(0.0, 0.0, top);
  float lambda = glint_lod_unclamped(q, a);
  if ((a.flags & GLINT_LOD_PADDING_CAP) != 0u) lambda = min(lambda, glint_lod_padding_cap(q, a));
  return clamp(lambda, 0.0, top);
}

#ifdef __cplusplus
}  // namespace lod_math
}  // namespace glint
#endif
#undef GLINT_LOD_FN

#endif
