// The built-in demo scene, generated on the GPU (kernels/demo_starfield.comp).
#pragma once

#include <glint/glint.h>

namespace glint::demo {

struct StarfieldParams {
  uint32_t stars = 6000;          //!< about this many stars (1 to 1e6)
  float min_brightness = 0.05f;   //!< dimmest star (> 0)
  float max_brightness = 50.0f;   //!< brightest star (>= min_brightness)
  float sun_brightness = 60.0f;   //!< sun disc brightness (10 to 100)
  uint32_t seed = 1;
};

/// Records the starfield and sun into `target` (RGBA16F or RGBA32F with STORAGE usage) and
/// updates its state. Makes its pipeline on first use per context and format.
void record_starfield(const Context& context, VkCommandBuffer cmd, Image& target, const StarfieldParams& params,
                      Profiler* profiler = nullptr);

}  // namespace glint::demo
