// Lens flares end to end: the visibility half (occlusion.h: HiZPyramid, LightCuller) and
// the drawing half (flare.h: LensFlare) wired together with the buffers that connect them, so that
// one record() goes from a depth image and a light list to flares added to an HDR image, with no
// readback in between: Hi-Z build -> cull + occlusion grid + compaction -> vkCmdDrawIndirect
// (raster) or vkCmdDispatchIndirect (compute). Use the three classes directly when the engine
// owns the instance and indirect buffers or interleaves other work; this class is the short way.
//
//   glint::FlarePassConfig pc;  pc.extent = {1920, 1080};  pc.cull.capacity = 256;
//   glint::LensFlarePass pass(ctx, pc);
//   // per frame, after the depth pass; lights: GlintFlareLight[count] (<glint/gpu/flare_types.h>)
//   pass.record(cmd, hdr_color, depth, lights, count, view_proj, glint::FlareConfig::preset(...));
//   // pass.stats() holds GlintFlareStats of that frame, to read whenever the caller wants.
#pragma once

#include <glint/flare.h>
#include <glint/glint.h>
#include <glint/occlusion.h>

#include <cstdint>
#include <memory>

namespace glint {

/// How the flares are drawn.
enum class FlareDrawPath : uint32_t {
  raster = 0,   //!< one vkCmdDrawIndirect (needs a graphics queue and COLOR_ATTACHMENT usage)
  compute = 1,  //!< tile gather launched by vkCmdDispatchIndirect (needs STORAGE usage)
};

/// Creation-time settings of a LensFlarePass. Checked by validate() (and by the parts it makes).
struct FlarePassConfig {
  VkExtent2D extent{0, 0};                                //!< colour and depth size (1 to 16384 on a side)
  VkFormat color_format = VK_FORMAT_R16G16B16A16_SFLOAT;  //!< RGBA16F or RGBA32F
  VkFormat depth_format = VK_FORMAT_D32_SFLOAT;           //!< D32_SFLOAT or R32_SFLOAT
  bool reversed_z = false;                                //!< true: depth 1 is near (HiZConfig::reversed_z)
  /// Cull settings. capacity is the most flares drawn per frame; with the compute path it must be
  /// at most LensFlare::max_compute_instances() of the device (7281 on lavapipe), else the
  /// constructor throws Error(invalid_argument) naming it. Lights beyond it count as overflow.
  LightCullConfig cull{};
  /// The largest light size_px the caller will send, in pixels (0 = unknown, else 1 to 65536): the
  /// Hi-Z pyramid is built only to the level a grid cell of that size reads
  /// (HiZConfig::max_cell_px = ceil(max_size_px / grid)). Larger lights stay conservative.
  float max_size_px = 0.0f;
  FlareDrawPath draw = FlareDrawPath::raster;
  /// Compute path: true lowers cull.capacity to LensFlare::max_compute_instances() instead of
  /// throwing (config() then reports the capacity used); the raster path has no such limit.
  bool clamp_capacity = false;
  bool per_light_results = false;  //!< keep GlintFlareLightResult per input light (8 bytes each)

  /// Throws Error(invalid_argument / unsupported_format / unsupported_size) naming the field.
  void validate() const;
};

/// Hi-Z + cull + draw of lens flares in one record(). Owns the HiZPyramid, LightCuller and
/// LensFlare and the device-local instance, indirect, statistics and (optional) result buffers.
class LensFlarePass {
 public:
  /// Makes every part (pipelines, atlas, buffers), so
  /// that record() creates nothing. Throws Error for a bad config or one the device cannot run.
  LensFlarePass(const Context& context, const FlarePassConfig& config);
  LensFlarePass(const LensFlarePass&) = delete;
  LensFlarePass& operator=(const LensFlarePass&) = delete;
  LensFlarePass(LensFlarePass&&) noexcept;
  LensFlarePass& operator=(LensFlarePass&&) noexcept;
  ~LensFlarePass();

  /// Records the Hi-Z build from `depth`, the cull of `count` lights and the draw into `color`.
  /// The Hi-Z build is left out where the cull reads the depth image itself
  /// (culler().needs_pyramid(hiz(), count) is false: few lights and a pyramid capped by
  /// max_size_px); hiz() then holds an earlier frame's pyramid, or none. Build it with
  /// hiz().record() when something else reads it.
  /// `color`: config's format and extent (COLOR_ATTACHMENT usage for raster, STORAGE for compute);
  /// left as LensFlare::record_raster / record_compute leave it (unchanged and untouched when
  /// `look` is disabled or has intensity 0; the cull still runs and the statistics are written).
  /// `depth`: config's depth format and extent, SAMPLED usage; left in SHADER_READ_ONLY_OPTIMAL.
  /// `lights`: GlintFlareLight[count] with STORAGE usage (count 0 to cull.max_lights).
  /// `view_proj`: 16 floats, column-major (GLM). `profiler` (may be null) gets the parts' marks.
  /// Throws Error before recording anything if an argument is wrong.
  void record(VkCommandBuffer cmd, Image& color, Image& depth, Buffer& lights, uint32_t count,
              const float view_proj[16], const FlareConfig& look, Profiler* profiler = nullptr);

  /// GlintFlareStats of the last recorded frame (32 bytes; STORAGE | TRANSFER_SRC usage). Its state
  /// fields say what last wrote it (the cull's finalize kernel), for the caller's barrier.
  Buffer& stats();
  /// GlintFlareLightResult[cull.max_lights] in input order (STORAGE | TRANSFER_SRC), or an empty
  /// Buffer when per_light_results is false.
  Buffer& results();
  /// The instance (GlintFlareInstance[cull.capacity]) and indirect (GlintFlareIndirect) buffers.
  Buffer& instances();
  Buffer& indirect();

  HiZPyramid& hiz();
  LightCuller& culler();
  LensFlare& flare();
  const FlarePassConfig& config() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint
