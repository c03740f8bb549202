// Visibility of lens-flare lights, kept on the GPU: a Hi-Z depth pyramid built in two
// dispatches (HiZPyramid), and a cull (LightCuller) that projects the lights, culls them against the
// frustum, tests their occlusion on an N x N grid read from the pyramid, and compacts the visible
// ones, in increasing light index (so every run gives the same order), into an instance buffer for an indirect draw or
// dispatch. docs/OCCLUSION.md derives the fold rule, the level choice, the error bound and the
// compaction; tools/reference/occlusion_reference.h holds the float64 references.
//
// Conventions (Vulkan): clip = view_proj * (position, 1); ndc = clip.xyz / clip.w;
// pixel = (ndc.xy * 0.5 + 0.5) * depth size, so ndc.y = -1 is the first row; depth = ndc.z in
// [0, 1], 0 near for standard Z, 1 near for reversed Z. A light is occluded where the stored depth
// is nearer than the light's.
//
// A frame:
//   hiz.record(cmd, depth);                          // after the depth pass
//   culler.record(cmd, hiz, depth, lights, count, frame, outputs);  // instances in light order
//   ... draw: vkCmdDrawIndirect(outputs.indirect, offset 0) or vkCmdDispatchIndirect(offset 16),
//       reading outputs.instances; the caller's barrier starts from the state fields record() left.
#pragma once

#include <glint/glint.h>
#include <glint/gpu/flare_types.h>

#include <cstdint>
#include <memory>

namespace glint {

namespace detail {
struct HiZAccess;        // benchmarks' and tests' switch of the stream pass (src/visibility/hiz_internal.h)
struct LightCullAccess;  // benchmarks' and tests' switch of the cull's path (src/visibility/light_cull_internal.h)
}  // namespace detail

/// Creation-time settings of a Hi-Z pyramid. Checked by validate().
struct HiZConfig {
  VkExtent2D extent{0, 0};  //!< depth image size in pixels (1 to 16384 on a side, and at most the
                            //!< device's maxImageDimension2D)
  /// The depth image's format: VK_FORMAT_D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT,
  /// D32_SFLOAT_S8_UINT (read through a depth-aspect view; UNORM depth reads as d / (2^bits - 1)) or
  /// R32_SFLOAT. The constructor also refuses, by name, a format the device cannot sample (Vulkan
  /// guarantees only D16_UNORM and D32_SFLOAT; D24S8 is absent on some GPUs).
  VkFormat format = VK_FORMAT_D32_SFLOAT;
  bool reversed_z = false;  //!< true: depth 1 is near, the pyramid keeps the minimum (farthest);
                            //!< false: 0 is near, it keeps the maximum
  /// The largest grid cell (light size_px / grid) that needs one texel per cell, in pixels
  /// (0 = no limit, else 1 to 16384). Levels coarser than ceil(log2(max_cell_px)) are not built;
  /// a larger cell reads several texels of the last level instead (still conservative).
  uint32_t max_cell_px = 0;

  /// Throws Error(invalid_argument / unsupported_format / unsupported_size) naming the field.
  void validate() const;
};

/// Number of Hi-Z levels above level 0 (the depth image) that a config builds: floor(log2 of the
/// larger side), capped by max_cell_px. Level k is max(1, extent >> k) on a side.
uint32_t hiz_level_count(const HiZConfig& config);

/// The Hi-Z depth pyramid of one depth image size. Owns an R32_SFLOAT image whose mip m holds Hi-Z
/// level m + 1 (level 0 is the caller's depth image, never copied). Each texel holds the farthest
/// depth of every source pixel it covers (fold rule in docs/OCCLUSION.md).
class HiZPyramid {
 public:
  /// Throws Error if config is invalid or larger than the device allows, and Error(no_device) if
  /// the pyramid has more than 2 levels and the device's maxComputeSharedMemorySize is below the
  /// 20484 bytes its kernels declare (Vulkan guarantees 16384; cap the levels with
  /// HiZConfig::max_cell_px <= 4 there).
  HiZPyramid(const Context& context, const HiZConfig& config);
  HiZPyramid(const HiZPyramid&) = delete;
  HiZPyramid& operator=(const HiZPyramid&) = delete;
  HiZPyramid(HiZPyramid&&) noexcept;
  HiZPyramid& operator=(HiZPyramid&&) noexcept;
  ~HiZPyramid();

  /// Records the build of every level from `depth`: one dispatch where the pyramid has at most 6
  /// levels (2 on CPU devices), a second for the levels above, after a barrier.
  /// `depth`: config.format and config.extent, SAMPLED usage, `view` a 2D view with the depth aspect
  /// alone (a depth format; barriers cover depth and stencil of a combined format) or a
  /// colour (R32) view of mip 0. Afterwards `depth` is in SHADER_READ_ONLY_OPTIMAL, last read by
  /// the compute shader stage, and the pyramid was last written by it. The first record() also
  /// clears the pyramid's internal counter (once per object); later frames need no clearing.
  /// `profiler` (may be null) gets one mark. Throws Error before recording on a wrong image.
  void record(VkCommandBuffer cmd, Image& depth, Profiler* profiler = nullptr);

  const HiZConfig& config() const;
  /// Levels built above level 0 (0 for a 1x1 depth image).
  uint32_t levels() const;
  /// The pyramid image: a view of all its mips (mip m = level m + 1), with its last use. Readers
  /// outside glint (samplers, other services) transition it through this state with
  /// `level_count = levels()`; LightCuller does this itself.
  Image& image();
  const Image& image() const;
  /// Bytes one record() reads and writes at least (depth once, every level once).
  uint64_t min_bytes_moved() const;

  struct Impl;

 private:
  friend struct detail::HiZAccess;
  std::unique_ptr<Impl> impl_;
};

/// Where LightCuller's N x N occlusion samples read the Hi-Z pyramid (docs/OCCLUSION.md).
enum class OcclusionPattern : uint32_t {
  /// One sample per cell at multi-jittered positions (distinct x and y over all N^2 samples), each
  /// reading a one-cell footprint centred on it: an occluder edge sliding across a light moves the
  /// fraction by 1/N^2 at a time.
  multi_jittered = 0,
  /// Each cell reads the texels under the cell itself: never below the true fraction, but an
  /// axis-aligned edge flips a whole column of N cells at once (steps of 1/N). For comparison.
  regular = 1,
};

/// Creation-time settings of a LightCuller. Checked by validate().
struct LightCullConfig {
  uint32_t capacity = 1024;  //!< GlintFlareInstance slots in the instance buffer (1 to 16777216)
  uint32_t grid = 4;         //!< N: N x N occlusion cells per light (1 to 16)
  float margin_ndc = 1.2f;   //!< frustum margin: lights with |ndc.x| or |ndc.y| above it are
                             //!< culled (1 to 8; 1.2, a margin that keeps the ghosts of lights just off screen)
  float depth_bias =
      0.0f;  //!< NDC depth tolerance: a light up to this much behind a surface
             //!< still counts as visible there (0 to 0.1; 0.01 hides depth-precision noise on coplanar lights)
  uint32_t max_lights = 1u << 20;  //!< most lights per record() (1 to 4194240 = 65535 x 64); the
                                   //!< culler keeps 16 bytes per light (and 16 per 64) for it, and
                                   //!< 4 per sample up to 65535 samples (max_lights x N^2) for the
                                   //!< depth-image cull
  OcclusionPattern pattern = OcclusionPattern::multi_jittered;  //!< where the N x N samples read

  void validate() const;
};

/// Per-frame inputs of LightCuller::record().
struct LightCullFrame {
  float view_proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  //!< column-major (GLM)
  uint32_t vertex_count = 54;        //!< written to GlintFlareIndirect::vertex_count (0 to 2^20);
                                     //!< the default is LensFlare::vertices_per_instance()
  uint32_t groups_per_instance = 1;  //!< the dispatch arguments cover instances x this
                                     //!< workgroups (0 to LightCuller::max_groups_per_instance())
};

/// The buffers one cull writes. The caller owns them; their state fields are updated.
struct LightCullOutputs {
  Buffer instances;  //!< GlintFlareInstance[capacity]; STORAGE usage. The visible lights in increasing
                     //!< light index; when more are visible than capacity, the lowest indices.
  Buffer indirect;   //!< one GlintFlareIndirect (32 bytes): VkDrawIndirectCommand at 0,
                     //!< VkDispatchIndirectCommand at 16; STORAGE | INDIRECT usage
  Buffer stats;      //!< one GlintFlareStats (32 bytes); STORAGE usage. Read it when you want:
                     //!< glint never waits on it.
  Buffer results;    //!< optional: GlintFlareLightResult[count] in input order (STORAGE usage);
                     //!< buffer == VK_NULL_HANDLE writes none (saves 8 bytes per light)
};

/// Cull + occlusion grid test + compaction of a light list (GlintFlareLight, <glint/gpu/flare_types.h>).
class LightCuller {
 public:
  /// Throws Error if config is invalid or asks for a path the device lacks.
  LightCuller(const Context& context, const LightCullConfig& config = {});
  LightCuller(const LightCuller&) = delete;
  LightCuller& operator=(const LightCuller&) = delete;
  LightCuller(LightCuller&&) noexcept;
  LightCuller& operator=(LightCuller&&) noexcept;
  ~LightCuller();

  /// Records the cull of `count` lights from `lights` (GlintFlareLight[count], STORAGE usage)
  /// against `hiz` (built from `depth` earlier on this command buffer or before, unless
  /// needs_pyramid() says the cull does not read it) into `outputs`.
  /// Up to one_group_lights() lights, one dispatch: one workgroup culls, tests and compacts
  /// them; when needs_pyramid() is false, the samples' windows are read from `depth` itself by a
  /// workgroup each and the last of them culls and compacts. More lights, four dispatches: the
  /// cull and grid test in workgroups of 64 lights; the
  /// two-level scan (the second, one workgroup, gives every workgroup its first instance slot,
  /// writes the indirect arguments and statistics and resets the counters); the scatter of the
  /// visible lights into their slots. All give the same outputs (bit for bit on every device
  /// tested), the same bits on every run.
  /// A light with enabled == 0 or a non-finite float field is GLINT_FLARE_DISABLED.
  /// count == 0 is allowed (zero instances). Afterwards the
  /// outputs were last written by the compute shader stage: a draw needs a barrier to
  /// DRAW_INDIRECT / INDIRECT_COMMAND_READ for `indirect` and to VERTEX_SHADER (or COMPUTE) /
  /// SHADER_STORAGE_READ for `instances`. The first four-dispatch record() clears the internal
  /// counters once, and so does the first record() that reads the depth image; submit the command
  /// buffers they were recorded into (a culler whose first such record() was never submitted is
  /// left with uncleared counters: make a new one).
  /// Throws Error before recording if a buffer is null, too small or lacks a usage, if `depth`
  /// does not match `hiz`, or if count or `frame` is out of range.
  void record(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, Buffer& lights, uint32_t count,
              const LightCullFrame& frame, LightCullOutputs& outputs, Profiler* profiler = nullptr);

  const LightCullConfig& config() const;

  /// Whether record() of `count` lights against a pyramid made as `hiz` reads the pyramid. False
  /// when the lights are few (count <= one_group_lights()), the pyramid has at most 5 levels (a
  /// HiZConfig::max_cell_px of at most 32, as LensFlarePass sets for lights of up to 128 px at
  /// N = 4) and the samples' windows, estimated as 2x2 texels of the last level each, hold at most
  /// twice the depth image's pixels (count x N^2 x 4^(levels + 1) <= 2 x width x height; so also
  /// for no light): record() then reads the pixels under the windows' texels from the depth image
  /// itself, with the pyramid's answers (docs/OCCLUSION.md, "Few lights from the depth image"), and
  /// the caller may skip HiZPyramid::record() for this cull. A fact of the configs, the device and
  /// `count`.
  bool needs_pyramid(const HiZPyramid& hiz, uint32_t count) const;

  /// The largest LightCullFrame::groups_per_instance this culler's capacity allows on this device:
  /// capacity x groups_per_instance workgroups must fit maxComputeWorkGroupCount[0] x [1] (the
  /// dispatch arguments are rows of at most [0] groups; see GlintFlareIndirect) and 32 bits.
  /// At least 1 for every capacity the config accepts. Composite effects check it at construction.
  uint32_t max_groups_per_instance() const;

  /// The most lights record() culls in one dispatch of one workgroup: min(W, 16384 / N^2) for
  /// an N x N grid, with W = min(1024, maxComputeWorkGroupInvocations, maxComputeWorkGroupSize[0])
  /// on GPUs and 64 on CPU devices, which run a workgroup's invocations one after another and a
  /// cull's workgroups in parallel (docs/OCCLUSION.md, "One workgroup for few lights").
  uint32_t one_group_lights() const;

  struct Impl;

 private:
  friend struct detail::LightCullAccess;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint
