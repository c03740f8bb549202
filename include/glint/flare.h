// Light-entity anamorphic lens flares, the drawing half: an element atlas
// generated on the GPU, and two ways to draw every visible light's flare into an HDR image — one
// instanced vkCmdDrawIndirect (raster path) or a per-screen-tile gather (compute path) that
// gives the same image within a stated tolerance. The visibility half (Hi-Z, cull, occlusion,
// compaction) writes the two buffers this class reads: GlintFlareInstance[] and GlintFlareIndirect
// (<glint/gpu/flare_types.h>, installed). docs/FLARE.md describes the look, the atlas and the tolerance;
// tools/reference/flare_reference.h is the float64 twin.
#pragma once

#include <glint/glint.h>
#include <glint/gpu/flare_types.h>

#include <array>
#include <cstdint>
#include <memory>

namespace glint {

namespace detail {
struct LensFlareAccess;  // benchmarks' and tests' switch of the compute draw's path (src/flare/flare_internal.h)
}

/// Named looks (docs/FLARE.md, "The look"): each sets only the anamorphic ratio and the intensity.
enum class FlarePreset : uint32_t {
  retro_subtle = 0,   //!< anamorphic ratio 1.8, intensity 0.6
  retro_intense = 1,  //!< anamorphic ratio 2.5, intensity 1.2
  cinematic = 2,      //!< anamorphic ratio 2.0, intensity 0.8
  disabled = 3,       //!< enabled = false, ratio 1.0, intensity 0.0: records nothing
};

/// Lens-flare look. Every field is a per-frame setting (push constants): changing it never rebuilds
/// anything. Defaults: ratio 2, global intensity 1, and the element
/// weights of docs/FLARE.md. validate() throws Error(invalid_argument) naming the field, the value
/// and the range.
struct FlareConfig {
  bool enabled = true;             //!< false: record_*() record nothing (the image is left bit-identical)
  float anamorphic_ratio = 2.0f;   //!< horizontal stretch of every sprite (1 to 3)
  float intensity = 1.0f;          //!< global brightness multiplier (0 to 2; 0 records nothing)
  float main_weight = 1.0f;        //!< the light's own element (GlintFlareInstance::element, the
                                   //!< central glow by default) at the light (0 to 10)
  float streak_weight = 0.6f;      //!< horizontal streak at the light (0 to 10)
  float streak_length = 4.0f;      //!< streak width in units of size_px, before the ratio (1 to 10:
                                   //!< an anamorphic streak spans 2 to 10 times the light's size)
  float halo_weight = 0.25f;       //!< ring around the light (0 to 10)
  float starburst_weight = 0.35f;  //!< radial spikes at the light (0 to 10)
  float ghost_weight = 0.5f;       //!< the five ghosts along the light-to-centre line (0 to 10)
  /// Ghost positions along light -> screen centre: 0 at the light, 1 at the centre, beyond 1 past
  /// it (each -2 to 3). Default 0, 0.3, 0.7, 1.0, 1.5.
  std::array<float, 5> ghost_positions = {0.0f, 0.3f, 0.7f, 1.0f, 1.5f};
  bool tint = true;  //!< tint the streak and the ghosts (lens-coating colour); false: untinted
  std::array<float, 3> tint_color = {0.55f, 0.8f, 1.0f};  //!< blue-cyan, linear RGB (each 0 to 1)

  /// The preset's ratio and intensity on top of the defaults above.
  static FlareConfig preset(FlarePreset preset);

  /// Throws Error(invalid_argument) naming the first field that is out of range or NaN.
  void validate() const;
};

/// The element atlas as created (for tools and tests): RGBA16F, premultiplied alpha, `levels` mips,
/// in SHADER_READ_ONLY_OPTIMAL once generated. Owned by the LensFlare.
struct FlareAtlasInfo {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  //!< all levels
  VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  uint32_t width = 0, height = 0, levels = 0;
  uint32_t padding_texels = 0;  //!< zeros around every tile at level 0
  bool generated = false;       //!< false until the generation has been recorded (adopted contexts)
};

/// Draws lens flares. Make it once per colour format and extent; record every frame.
///
/// Inputs of record_raster() / record_compute():
/// - `color`: the HDR image flares are added to (VK_FORMAT_R16G16B16A16_SFLOAT or
///   R32G32B32A32_SFLOAT, the format and extent given at creation). Raster: COLOR_ATTACHMENT usage;
///   left in COLOR_ATTACHMENT_OPTIMAL, last used by COLOR_ATTACHMENT_OUTPUT (read + write).
///   Compute: STORAGE usage; left in GENERAL, last used by COMPUTE_SHADER (storage read + write).
///   RGB gains the flares; alpha is never written.
/// - `instances`: GlintFlareInstance[] (48 bytes each) with STORAGE_BUFFER usage. Only the first
///   instance_count (from `indirect`) are drawn; an index past the buffer's range is skipped.
/// - `indirect`: one GlintFlareIndirect (32 bytes) with INDIRECT_BUFFER usage; `offset` a multiple
///   of 4. The raster path reads its VkDrawIndirectCommand (vertex_count must be
///   vertices_per_instance(), first_vertex and first_instance 0); the compute path reads
///   group_count_x / groups_per_instance() as the instance count from a shader (the cull writes
///   group_count_x = instance_count * groups_per_instance()), so for it the buffer also needs
///   STORAGE_BUFFER usage.
/// Both buffers' state fields say what last wrote them (the cull's COMPUTE_SHADER / SHADER_WRITE,
/// or a transfer); glint records the barrier to the reads (raster: DRAW_INDIRECT /
/// INDIRECT_COMMAND_READ and the vertex shader's storage read; compute: the compute shader's storage
/// read of both) and updates the state fields.
///
/// Recording creates no Vulkan object: the descriptors are pushed with each draw or dispatch
/// (VK_KHR_push_descriptor), so nothing keeps the caller's buffers or views past the command
/// buffers they were recorded into.
class LensFlare {
 public:
  /// Creates the pipelines and the atlas for drawing into `color_format` images of `extent`.
  /// Standalone contexts generate the atlas here (one submit); adopted contexts record its
  /// generation in the first record_*() (or in record_setup()). The compute path owns a 32-byte
  /// launch buffer and, made at the first record_compute() with an instances buffer larger than any
  /// before, a sprite buffer of 304 bytes per instance (its pre-pass's output, for at most
  /// maxStorageBufferRange / 304 instances) that lives as long as the LensFlare.
  /// Throws Error(unsupported_format) for other formats or a format the device cannot blend
  /// (raster) / store (compute), Error(unsupported_size) for a zero or too large extent.
  LensFlare(const Context& context, VkFormat color_format, VkExtent2D extent);
  LensFlare(const LensFlare&) = delete;
  LensFlare& operator=(const LensFlare&) = delete;
  LensFlare(LensFlare&&) noexcept;
  LensFlare& operator=(LensFlare&&) noexcept;
  ~LensFlare();

  /// What the compaction must write into GlintFlareIndirect: vertex_count (the draw) and, per
  /// instance, groups_per_instance into group_count_x (read by the compute path). Constant for
  /// this LensFlare (1 since the compute path gathers per screen tile).
  static constexpr uint32_t vertices_per_instance() { return 9 * 6; }
  uint32_t groups_per_instance() const;
  /// The most instances the compute path can read through one storage-buffer descriptor on this
  /// device (maxStorageBufferRange / 48); record_compute() refuses an instance buffer whose range
  /// holds more.
  uint32_t max_compute_instances() const;
  /// The most instances an instances buffer may hold for record_compute() to draw in one dispatch
  /// (each of the gather's invocations evaluates one sprite, with no pre-pass and no launch
  /// arguments to write): the gather's workgroup size / 9 on GPUs (28), 0 on CPU devices, where
  /// the pre-pass is faster. A larger buffer takes three dispatches (docs/FLARE.md,
  /// "Compute (record_compute)").
  uint32_t one_dispatch_instances() const;

  /// Records the atlas generation if it has not been recorded yet (adopted contexts; a no-op on
  /// standalone ones). record_*() call it themselves; call it earlier to keep the first frame short.
  void record_setup(VkCommandBuffer cmd);

  /// Raster path: one vkCmdDrawIndirect of all instances inside vkCmdBeginRendering (dynamic
  /// rendering, load and store, no depth), additive ONE/ONE blending of premultiplied colour.
  /// `cmd` must be recording outside a render pass on a queue family with graphics.
  /// Throws Error before recording anything for a bad config, image or buffer.
  void record_raster(VkCommandBuffer cmd, Image& color, Buffer& instances, Buffer& indirect, const FlareConfig& config,
                     Profiler* profiler = nullptr);

  /// Compute path: a dispatch of flare_gather, a workgroup per screen tile, that reads the
  /// instance count from `indirect`, bins the sprites that touch its tile, sums their light in fp32
  /// and adds it to the lit pixels of `color`; before it, for an instances buffer of more than
  /// one_dispatch_instances(), a sprite pre-pass and the two dispatches' launch arguments. Same
  /// image as record_raster within docs/FLARE.md's tolerance. Throws Error before recording
  /// anything for a bad argument.
  void record_compute(VkCommandBuffer cmd, Image& color, Buffer& instances, Buffer& indirect, const FlareConfig& config,
                      Profiler* profiler = nullptr);

  FlareAtlasInfo atlas() const;
  VkFormat color_format() const;
  VkExtent2D extent() const;

  struct Impl;

 private:
  friend struct detail::LensFlareAccess;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint
