// The built-in demo scene: an HDR starfield and sun generated on the GPU
// (tools/demo/shaders/demo_starfield.comp), and for the lens flares a depth buffer with occluders
// and a light list in front of and behind them, generated on the CPU (make_flare_scene).
#pragma once

#include <glint/glint.h>
#include <glint/gpu/flare_types.h>

#include <array>
#include <vector>

namespace glint::demo {

struct StarfieldParams {
  uint32_t stars = 6000;         //!< about this many stars (1 to 1e6)
  float min_brightness = 0.05f;  //!< dimmest star (> 0)
  float max_brightness = 50.0f;  //!< brightest star (>= min_brightness)
  float sun_brightness = 60.0f;  //!< sun disc brightness (10 to 100)
  uint32_t variant = 1;          //!< which random starfield (any value; the same value gives the same stars)
};

/// Records the starfield and sun into `target` (RGBA16F or RGBA32F with STORAGE usage) and
/// updates its state. Makes its pipeline on first use per context and format.
void record_starfield(const Context& context, VkCommandBuffer cmd, Image& target, const StarfieldParams& params,
                      Profiler* profiler = nullptr);

/// The flare half of the demo scene, in Vulkan's conventions (docs/OCCLUSION.md): a camera at the
/// origin looking down -z (60 degree vertical field of view, near 0.1, far 100, standard Z), a
/// depth buffer of three box occluders ("towers" and a "pillar") over the far plane, and lights in
/// the sky, in front of the occluders, wholly and partly behind them, behind the camera, off
/// screen and disabled, so that every visibility outcome appears. One light sits on the
/// starfield's sun. Sizes scale with the image (their values at 1080 lines).
struct FlareScene {
  std::vector<float> depth;           //!< width * height, row-major, top row first; 1 = far plane
  std::array<float, 16> view_proj{};  //!< column-major (GLM)
  std::vector<GlintFlareLight> lights;
  std::vector<VkRect2D> occluders;  //!< the boxes' pixel rectangles (the demo paints them dark)
};

/// Builds the flare scene for an image of `extent` (any size from 1x1).
FlareScene make_flare_scene(VkExtent2D extent);

}  // namespace glint::demo
