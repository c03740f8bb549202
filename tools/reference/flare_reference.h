// Float64 CPU reference of glint's lens flares (the drawing half, docs/FLARE.md): the element
// atlas (every level) and the composite of instances into an image, written from docs/FLARE.md
// independently of the GLSL (src/flare/shaders/flare_elements.glsl, flare_look.glsl), sharing only
// the constants of src/flare/shaders/flare_params.h. The sampler is modelled as the Vulkan
// specification's bilinear + linear-mipmap filter with exact weights; every sample also returns a
// bound on how far a conformant device may be from it (docs/FLARE.md "Tolerance"). CPU only.
#pragma once

#include <glint/flare.h>
#include <glint/gpu/flare_types.h>
#include <glint/gpu/lod.h>

#include <array>
#include <cstdint>
#include <vector>

#include "core/cpu_image.h"

namespace glint::reference {

/// One atlas level: width * height * 4 doubles (premultiplied RGBA), row-major.
struct FlareAtlasLevel {
  uint32_t width = 0, height = 0;
  std::vector<double> rgba;
  double* at(uint32_t x, uint32_t y) { return &rgba[(size_t(y) * width + x) * 4]; }
  const double* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};
using FlareAtlas = std::vector<FlareAtlasLevel>;

/// Element `element` (GLINT_FLARE_ELEMENT_*) at the tile-normalized coordinate q in (-1, 1)^2.
std::array<double, 4> flare_element(uint32_t element, double qx, double qy);
/// Tile rectangle (x, y, w, h) of an element in level-0 texels.
std::array<uint32_t, 4> flare_tile(uint32_t element);
/// Level 0: every tile texel evaluates its element at its centre, every other texel is 0.
FlareAtlasLevel flare_atlas_level0();
/// The 2x2 box average of `finer` (whose sides are even).
FlareAtlasLevel flare_atlas_reduce(const FlareAtlasLevel& finer);
/// Every level (GLINT_FLARE_ATLAS_LEVELS), each reduced from the float64 level above.
FlareAtlas flare_atlas();
/// The atlas as the LOD function sees it (docs/FLARE.md): its size, levels, padding and the
/// padding cap; bias 0, anisotropy 1.
GlintLodAtlas flare_lod_atlas();

/// One sprite of one instance, as docs/FLARE.md defines it (size 0: nothing drawn).
struct FlareSprite {
  double lo_x = 0, lo_y = 0, width = 0, height = 0;
  double rgb[3] = {0, 0, 0};
  uint32_t tile = GLINT_FLARE_ELEMENT_GLOW;
  double lod = 0;
};
FlareSprite flare_sprite(const GlintFlareInstance& instance, uint32_t slot, const FlareConfig& config,
                         uint32_t viewport_w, uint32_t viewport_h);

/// The device's filtering precision (VkPhysicalDeviceLimits): bits of the bilinear weights and of
/// the mipmap blend weight.
struct SamplerPrecision {
  uint32_t subtexel_bits = 4;  // the specification's minimum
  uint32_t mipmap_bits = 4;
};

/// Trilinear, clamp-to-edge sample of `atlas` at normalized (u, v) and level `lod`, with a bound on a
/// conformant device's deviation (weights quantized to the precision above, fp32 coordinates).
struct FlareSample {
  double rgba[4] = {0, 0, 0, 0};
  double bound[4] = {0, 0, 0, 0};
};
FlareSample flare_sample(const FlareAtlas& atlas, double u, double v, double lod, SamplerPrecision precision);

/// `dst` plus the flares of the first `count` instances, with a per-channel bound and the number
/// of sprites that touched each pixel. Alpha is dst's. Sprites are tested at pixel centres with
/// [lo, lo + size); a centre within 2e-3 px of an edge (where fp32 may decide either way) adds its
/// contribution to the bound instead of deciding. Disabled or intensity-0 configs return dst.
struct FlareComposite {
  uint32_t width = 0, height = 0;
  std::vector<double> rgba;     // width * height * 4
  std::vector<double> bound;    // width * height * 4: sampling + coverage bound (no output rounding)
  std::vector<uint32_t> count;  // width * height: sprites that added light
};
FlareComposite flare_composite(const CpuImage& dst, const std::vector<GlintFlareInstance>& instances, uint32_t count,
                               const FlareConfig& config, const FlareAtlas& atlas, SamplerPrecision precision);

}  // namespace glint::reference
