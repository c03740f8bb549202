// HDR bloom: soft-knee bright-pass, mip-pyramid downsample, upsample with accumulation by gather,
// composite. All compute. The exact algorithm (taps, edge rules, mapping between levels) is in
// docs/BLOOM.md; tools/reference/bloom_reference.h implements it in float64.
#pragma once

#include <glint/glint.h>

#include <array>
#include <memory>

namespace glint {

namespace detail {
struct BloomAccess;  // benchmarks' and tests' switch of the dispatch structure (not installed)
}

/// The filter used between pyramid levels.
enum class BloomFilter : uint32_t {
  cod13 = 0,   //!< 13-tap downsample, 3x3 tent upsample (Jimenez 2014). Default.
  dual = 1,    //!< dual filter: 5-tap down, 8-tap up (Bjørge 2015). Cheapest; not a Gaussian.
  gauss9 = 2,  //!< area downsample + a separable 9-tap Gaussian per level.
};

/// How the first downsample keeps isolated bright pixels ("fireflies") from dominating the bloom
/// (docs/BLOOM.md "Karis guard"; docs/STABILITY.md measures each).
enum class FireflyGuard : uint32_t {
  off = 0,           //!< plain weighted mean
  karis = 1,         //!< Karis average of raw 2x2 boxes (Jimenez 2014): strongest suppression, but a
                     //!< point moving by sub-pixel steps flickers (44 to 94 % energy variation)
  karis_smooth = 2,  //!< Karis average of boxes of a binomially prefiltered source (sigma 1.58 px):
                     //!< steady under sub-pixel motion (under 2 %), milder suppression. Default.
};

/// Bloom settings. Defaults are given per field; ranges are checked by validate(), which throws.
/// Shape fields (iterations, filter, firefly_guard, precision) decide images and pipelines: changing them through
/// Bloom::set_config() rebuilds those. The other fields are per-frame push constants.
struct BloomConfig {
  float threshold = 1.0f;                   //!< luminance where bloom starts (0 to 65504)
  float soft_knee = 0.5f;                   //!< knee width as a fraction of threshold (0 to 1)
  float intensity = 0.3f;                   //!< weight of the bloom added to the scene (0 to 100); 0 = off
  uint32_t iterations = 5;                  //!< pyramid levels (1 to 8); reduced at small sizes [shape]
  float radius = 1.0f;                      //!< scales the upsample (or Gaussian) footprint (0.25 to 4)
  BloomFilter filter = BloomFilter::cod13;  //!< [shape]
  FireflyGuard firefly_guard = FireflyGuard::karis_smooth;  //!< on the first downsample [shape]
  float max_brightness = 1000.0f;                           //!< per-channel clamp of pyramid level 0 (1e-3 to 8000):
                                                            //!< bounds the light any small area adds, keeps fp16
                                                            //!< levels finite. Source texels are first clamped to
                                                            //!< 65504 (what +Inf and 1e9 become).
  Precision precision = Precision::fp16;                    //!< intermediate storage [shape]
  /// 0: level 0 is half the input (the 1920x1080 chain of docs/BLOOM.md; the glow is a fixed size in pixels). Else
  /// level 0 is this many rows (at most the input's height) with the input's aspect, reached through 2:1 steps and one
  /// step of ratio 1 to 2, so the glow is the same fraction of the image at every resolution down to this height
  /// (docs/STABILITY.md "Scale"). 0 or 8 to 16384. [shape]
  uint32_t level0_height = 0;

  /// Throws Error(invalid_argument) naming the first field that is out of range or NaN.
  void validate() const;
};

/// "cod13", "dual" or "gauss9" ("?" for a value outside BloomFilter).
const char* bloom_filter_name(BloomFilter filter);
/// "off", "karis" or "karis_smooth" ("?" for a value outside FireflyGuard).
const char* firefly_guard_name(FireflyGuard guard);

/// The mip chain a bloom of `input` size with `iterations` uses (docs/BLOOM.md, "Mip chain").
/// Returns at most `iterations` levels; fewer when a level would be under 2 pixels on a side.
std::vector<LevelSize> bloom_mip_chain(VkExtent2D input, uint32_t iterations, uint32_t level0_height = 0);

/// The images the first downsample steps through before level 0 (2:1 each; not part of the
/// bloom): empty unless level0_height asks for a level 0 under half the input (docs/BLOOM.md).
std::vector<LevelSize> bloom_pre_levels(VkExtent2D input, uint32_t level0_height);

/// One bloom effect. Make it once; call record() every frame.
///
/// Input: a float colour image with SAMPLED usage whose format the device can sample; output: one
/// with STORAGE usage whose format it can store (docs/FORMATS.md: RGBA16F, RGBA32F and
/// B10G11R11_UFLOAT on every device that stores them; RGB16F, RGB32F and E5B9G9R9 where the device
/// stores them without a format), same extent. Formats are chosen from the device's format
/// features; any other is refused with an Error naming it. After record(), the input is in SHADER_READ_ONLY_OPTIMAL
/// (GENERAL if it is also the output) and the output in GENERAL, both last used by the compute shader stage. Input and
/// output may be the same image (in place).
///
/// Per size and config shape, images and pipelines are made once: by prepare(), or by the first
/// record() at that size. A record() at a prepared size, into an output of a prepared format
/// (RGBA16F and RGBA32F always; others by prepare(extent, format)), creates no Vulkan object. Descriptors are
/// pushed with each dispatch (VK_KHR_push_descriptor) and nothing keeps the caller's views: a view
/// may be destroyed once the command buffers it was recorded into are done, and a new view (even
/// one with the old handle) needs nothing before the next record().
///
/// Several sizes (dynamic resolution, several views): one Bloom may be recorded at different
/// extents, in one command buffer or in consecutive frames. Each size keeps its own pyramid; the
/// pyramid of a size is destroyed only when no submitted work can use it: by a later record(),
/// prepare() or release_unused() once the size was unused for Context::frames_in_flight() frames
/// (the caller calls Context::begin_frame() once per frame), or once the run_once() it was recorded
/// in has returned. At most kMaxCachedSizes sizes are kept (glint.h).
class Bloom {
 public:
  /// Throws Error(invalid_argument) if config is invalid.
  Bloom(const Context& context, const BloomConfig& config = {});
  Bloom(const Bloom&) = delete;
  Bloom& operator=(const Bloom&) = delete;
  Bloom(Bloom&&) noexcept;
  Bloom& operator=(Bloom&&) noexcept;
  ~Bloom();

  /// Replaces the config. Per-frame fields take effect at the next record(); changed shape fields
  /// make new pyramids (here for the current size, else at the next record()). The pyramids of the
  /// old shape are retired like unused sizes, so frames in flight may still use them.
  void set_config(const BloomConfig& config);
  const BloomConfig& config() const;

  /// Makes everything a frame of this size needs, so record() allocates nothing. Optional.
  /// Throws Error(unsupported_size) for a zero extent or one above the device's maximum.
  /// The pipelines that write an RGBA16F or RGBA32F output are made with the others; those of
  /// another output format (B10G11R11_UFLOAT_PACK32, or a format written without a format
  /// qualifier) are made by the overload below or by the first record() into it.
  void prepare(VkExtent2D extent);

  /// prepare(extent), and the pipelines that write `output_format`, so that record() into an
  /// output of that format at this size creates no Vulkan object. They are kept for the Bloom's
  /// lifetime, and a set_config() that changes the shape makes them again for the new shape.
  /// Checks both before making anything: Error(unsupported_size) as prepare(extent);
  /// Error(unsupported_format) naming the format when it is not a float colour format the device
  /// can store (the check record() makes of its output). Otherwise throws as prepare(extent) does.
  void prepare(VkExtent2D extent, VkFormat output_format);

  /// Records the bloom of `input` into `output` on `cmd` (which must be in the recording state,
  /// on a queue family with compute). Updates the state fields of both images. An extent not seen
  /// (or retired) makes its pyramid; the pyramids of other sizes stay as the class comment says.
  /// `profiler` (may be null) gets a mark after each stage.
  /// Throws Error before recording anything if an image has the wrong format, usage or extent, or
  /// (invalid_argument) if a new size is needed while kMaxCachedSizes sizes may all still be in use.
  void record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler = nullptr);

  /// Destroys the pyramid of every size other than the last one prepared or recorded that no
  /// submitted work can use (Context::begin_frame() says which), without waiting for them to age.
  /// After Context::wait_idle() or mark_idle() that is every other size. Creates nothing.
  void release_unused();
  /// Sizes (with config shapes) whose pyramids are kept now: at most kMaxCachedSizes, and with one
  /// size per frame and begin_frame() every frame at most Context::frames_in_flight().
  uint32_t cached_sizes() const;

  /// Levels the current size (the last one prepared or recorded) uses (after the small-size clamp),
  /// and whether iterations were reduced to get there. Valid after prepare() or record().
  uint32_t levels() const;
  bool clamped() const;
  std::vector<LevelSize> level_sizes() const;

  /// Bytes the GPU must move at least for one frame at the prepared size (each image read and
  /// written once): the floor that benchmarks report against.
  uint64_t min_bytes_moved(VkFormat input_format, VkFormat output_format) const;

  struct Impl;

 private:
  friend struct detail::BloomAccess;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint
