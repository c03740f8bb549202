// The blur family: a three-level cumulative blur pyramid whose levels are
// handed to the caller's shaders, and a Gaussian blur of any sigma with a choice of methods.
// The exact algorithms are in docs/BLUR.md; tools/reference/blur_reference.h implements them in
// float64.
#pragma once

#include <glint/glint.h>

#include <array>
#include <memory>

namespace glint {

namespace detail {
struct BlurAccess;  // tests' and benchmarks' switch of the separable kernel (src/blur/blur_steps.h)
}

/// Settings of a BlurPyramid. All fields are shape fields: set_config() rebuilds what they decide.
struct BlurPyramidConfig {
  /// Gaussian sigma of each level's blur, in texels of that level (0.3 to 4; taps
  /// 2 ceil(3 sigma) + 1, so the default 1.2 gives 9 taps). Level k reads level k-1, so the
  /// effective sigma in input pixels grows as the square root of the sum of squares, scaled by
  /// the level size (effective_sigma_px()).
  std::array<float, 3> sigma_texels{1.2f, 1.2f, 1.2f};
  Precision precision = Precision::fp16;  //!< storage of the three levels

  /// Throws Error(invalid_argument) naming the first field that is out of range or NaN.
  void validate() const;
};

/// Effective standard deviation of a blur, per axis, in input pixels.
struct EffectiveSigma {
  double x_px = 0;
  double y_px = 0;
};

/// Three cumulative blur levels: level k (1 to 3) is level k-1 (level 0 = the input)
/// area-downsampled to half size (floor, at least 1) and blurred by one separable Gaussian, in
/// one dispatch per level (docs/BLUR.md, "Blur pyramid").
///
/// Input: a float colour format the device samples (docs/FORMATS.md: RGBA16F, RGBA32F,
/// B10G11R11_UFLOAT, ...) with SAMPLED usage; after record() it is in SHADER_READ_ONLY_OPTIMAL,
/// last read by the compute stage. The levels are images the pyramid owns, with SAMPLED, STORAGE
/// and TRANSFER_SRC usage; after record() they are in GENERAL, last written by the compute stage (so the
/// caller's next barrier starts from level(k).stage/access). A shader samples all three with the
/// same normalized UV as the input.
///
/// Per input size, images and pipelines are made once (prepare(), or the first record() at that
/// size); record() at a prepared size creates no Vulkan object. Descriptors are pushed with each
/// dispatch: nothing keeps the caller's views past the command buffers they were recorded into.
///
/// Several sizes: one pyramid may be recorded at different input extents, in one command buffer
/// or in consecutive frames. Each size keeps its own levels; level(k) is the level of the size of
/// the last prepare() or record(), so read (or copy) it before recording another size. A size's
/// levels are destroyed only when no submitted work can use them: by a later record(), prepare()
/// or release_unused() once the size was unused for Context::frames_in_flight() frames (the
/// caller calls Context::begin_frame() once per frame), or once the run_once() it was recorded in
/// has returned. At most kMaxCachedSizes sizes are kept (glint.h).
class BlurPyramid {
 public:
  /// Throws Error(invalid_argument) if config is invalid, Error(no_device) if the device's shared
  /// memory cannot hold the tile of the largest sigma.
  BlurPyramid(const Context& context, const BlurPyramidConfig& config = {});
  BlurPyramid(const BlurPyramid&) = delete;
  BlurPyramid& operator=(const BlurPyramid&) = delete;
  BlurPyramid(BlurPyramid&&) noexcept;
  BlurPyramid& operator=(BlurPyramid&&) noexcept;
  ~BlurPyramid();

  /// Replaces the config; makes new levels here for the current size if one is prepared, else at
  /// the next record(). The levels of the old config are retired like unused sizes, so frames in
  /// flight may still use them.
  void set_config(const BlurPyramidConfig& config);
  const BlurPyramidConfig& config() const;

  /// Makes everything a frame of this input size needs. Throws Error(unsupported_size) for a zero
  /// extent or one above the device's maximum.
  void prepare(VkExtent2D input_extent);

  /// Records the three levels of `input` into `cmd`. Throws before recording anything if the
  /// image has the wrong format, usage or extent, or (invalid_argument) if a new size is needed
  /// while kMaxCachedSizes sizes may all still be in use. `profiler` (may be null) gets a mark per
  /// level.
  void record(VkCommandBuffer cmd, Image& input, Profiler* profiler = nullptr);

  /// Destroys the levels of every size other than the current one that no submitted work can use
  /// (Context::begin_frame() says which), without waiting for them to age. Creates nothing.
  void release_unused();
  /// Sizes (with configs) whose levels are kept now: at most kMaxCachedSizes, and with one size
  /// per frame and begin_frame() every frame at most Context::frames_in_flight().
  uint32_t cached_sizes() const;

  /// Level k = 1, 2, 3 (Blur1 .. Blur3) with its current state. Valid after prepare()/record().
  /// Throws Error(invalid_argument) for another k. A caller that transitions or uses a level
  /// updates its layout/stage/access here (as for its own images), so the next record() starts
  /// its barrier from there.
  Image& level(uint32_t k);
  const Image& level(uint32_t k) const;
  LevelSize level_size(uint32_t k) const;
  /// Effective sigma of level k in input pixels (docs/BLUR.md variance bookkeeping).
  EffectiveSigma effective_sigma_px(uint32_t k) const;

  /// Bytes the GPU must move at least per frame at the prepared size (input read once, each
  /// level written once and read once by the next).
  uint64_t min_bytes_moved(VkFormat input_format) const;

  struct Impl;

 private:
  friend struct detail::BlurAccess;
  std::unique_ptr<Impl> impl_;
};

/// How GaussianBlur computes the blur (docs/BLUR.md, "Gaussian blur of any sigma").
enum class BlurMethod : uint32_t {
  automatic = 0,  //!< the fastest method whose modelled error is under max_relative_error
  separable = 1,  //!< direct separable Gaussian in shared memory (the accurate one)
  pyramid = 2,    //!< binomial downsample k levels, blur there, cubic B-spline back up
  dual = 3,       //!< dual filter down/up (Bjørge 2015), tap offset tuned to the sigma
};

/// The per-device constants of the cost model by which `automatic` ranks the methods that meet
/// the error bound (docs/BLUR.md "Cost model"): estimated microseconds = us_per_dispatch x
/// dispatches + us_per_byte x image bytes + us_per_shared_tap x taps read from shared memory +
/// us_per_fetch_tap x taps fetched from images. All zero (the default) means "this device's":
/// measured once per standalone Context at the first automatic plan (measure_blur_cost_model()),
/// and built-in constants fitted on an H100 for an adopted Context, which never submits; an engine
/// can measure on a standalone Context of the same device once and pass the result here.
struct BlurCostModel {
  double us_per_dispatch = 0;
  double us_per_byte = 0;
  double us_per_shared_tap = 0;
  double us_per_fetch_tap = 0;
};

/// Measures the cost model of `context`'s device: times a few small blurs of each method with
/// timestamps (wall clock where the queue has no timestamps) and fits the constants to them; about
/// 1 s on lavapipe, mostly compiling pipelines. Cached: later calls on the same Context return the
/// first result. Standalone contexts only (Error(invalid_argument) for an adopted one).
BlurCostModel measure_blur_cost_model(const Context& context);

/// Settings of a GaussianBlur. All fields are shape fields (they decide levels and taps).
struct GaussianBlurConfig {
  float sigma_px = 4.0f;                      //!< standard deviation in input pixels (0.5 to 64)
  BlurMethod method = BlurMethod::automatic;  //!< see BlurMethod
  float max_relative_error = 1e-2f;           //!< automatic and pyramid: bound on the modelled relative L2
                                              //!< error against the exact Gaussian (1e-4 to 1)
  bool linear_sampling = false;               //!< separable only: two passes that pair taps into bilinear
                                              //!< fetches through the sampler (9 taps in 5 fetches). The
                                              //!< sampler filters before any shader code sees a texel, so
                                              //!< this variant does not sanitize: the input must be finite
                                              //!< and within the output format's range (NaN and Inf reach
                                              //!< the output; every other method maps them, docs/BLUR.md)
  Precision precision = Precision::fp16;      //!< intermediate images
  /// automatic: the device's cost constants; all zero = measured (see BlurCostModel). Each is
  /// finite and >= 0, and all are zero or all > 0.
  BlurCostModel cost_model{};

  /// Throws Error(invalid_argument) naming the first field that is out of range or NaN.
  void validate() const;
};

/// What GaussianBlur decided for the current size (valid after prepare()/record()).
struct BlurChoice {
  BlurMethod method = BlurMethod::separable;  //!< never automatic
  bool linear_sampling = false;
  uint32_t radius = 0;                 //!< separable: taps 2 radius + 1
  uint32_t levels = 0;                 //!< pyramid, dual: levels below the input
  double level_sigma = 0;              //!< pyramid: sigma in texels of the smallest level
  double dual_offset = 0;              //!< dual: tap offset o in texels
  double effective_sigma_px = 0;       //!< sigma of the method's impulse response, input pixels
  double expected_relative_error = 0;  //!< modelled relative L2 against the exact Gaussian over the whole
                                       //!< image (borders included), storage rounding included
  uint32_t dispatches = 0;
  double estimated_us = 0;  //!< the cost model's estimate for this plan (what automatic compared)
};

/// A same-size Gaussian blur of input into output.
///
/// Input: a float colour format the device samples (and filters linearly with linear_sampling),
/// with SAMPLED usage, left in SHADER_READ_ONLY_OPTIMAL. Output: a float colour format it stores
/// (docs/FORMATS.md: RGBA16F, RGBA32F, B10G11R11_UFLOAT, ...) with STORAGE usage, same extent, a
/// different image (or another layer of the same one), left in GENERAL; both last used by the
/// compute stage. Per size and output format, everything is made once; record() at a prepared
/// size and output format (prepare(extent, format)) creates no Vulkan object, and keeps no
/// reference to the caller's views.
///
/// Several sizes: one blur may be recorded at different extents and output formats, in one
/// command buffer or in consecutive frames; each (size, output format) keeps its own plan, images
/// and steps, destroyed as BlurPyramid's levels are (Context::begin_frame()).
class GaussianBlur {
 public:
  /// Throws Error(invalid_argument) if config is invalid.
  GaussianBlur(const Context& context, const GaussianBlurConfig& config = {});
  GaussianBlur(const GaussianBlur&) = delete;
  GaussianBlur& operator=(const GaussianBlur&) = delete;
  GaussianBlur(GaussianBlur&&) noexcept;
  GaussianBlur& operator=(GaussianBlur&&) noexcept;
  ~GaussianBlur();

  /// Replaces the config; plans again here for the current size and output format if one is
  /// prepared, else at the next record(). The old config's resources retire like unused sizes.
  void set_config(const GaussianBlurConfig& config);
  const GaussianBlurConfig& config() const;

  /// Plans the method for this size and makes its images and pipelines, for an output of the
  /// format last prepared or recorded (RGBA16F before any). Throws Error(unsupported_size) for a
  /// zero extent or one above the device's maximum.
  void prepare(VkExtent2D extent);

  /// The same for an output of `output_format`, so that record() into an output of that format at
  /// this size creates no Vulkan object. set_config() plans again the current (size, format)
  /// alone; another one prepared before is planned again by its next prepare() or record(). Checks
  /// both before making anything: Error(unsupported_size) as prepare(extent);
  /// Error(unsupported_format) naming the format when it is not a float colour format the device
  /// can store (the check record() makes of its output). Otherwise throws as prepare(extent) does.
  void prepare(VkExtent2D extent, VkFormat output_format);

  /// Records the blur. Throws before recording anything on a wrong format, usage or extent, when
  /// input and output are the same image, or (invalid_argument) if a new size is needed while
  /// kMaxCachedSizes sizes may all still be in use.
  void record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler = nullptr);

  /// Destroys the resources of every (size, output format) other than the current one that no
  /// submitted work can use, without waiting for them to age. Creates nothing.
  void release_unused();
  /// (Size, output format, config) entries kept now (see BlurPyramid::cached_sizes()).
  uint32_t cached_sizes() const;

  /// The plan of the last prepare() or record() (a default BlurChoice before either).
  const BlurChoice& choice() const;

  /// Bytes the GPU must move at least per frame (input read once, output written once, each
  /// intermediate written and read once).
  uint64_t min_bytes_moved(VkFormat input_format, VkFormat output_format) const;

  struct Impl;

 private:
  friend struct detail::BlurAccess;
  std::unique_ptr<Impl> impl_;
};

/// Name of a method ("auto", "separable", "pyramid", "dual"); "unknown" for a value outside the enum.
/// Named like bloom_filter_name() and firefly_guard_name().
const char* blur_method_name(BlurMethod method);

/// The same as blur_method_name(). Kept working for existing callers; the name clashed in style with
/// the other enum names and, unqualified, with std::to_string.
[[deprecated("use blur_method_name")]] const char* to_string(BlurMethod method);

}  // namespace glint
