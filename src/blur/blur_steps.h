// The step machinery both blur drivers run (docs/BLUR.md): a size's program is a list of steps
// (pipeline, push constants, image in, image out) planned once, which record() walks, writing the
// barriers between them and pushing each step's descriptors. BlurPyramid (blur_pyramid.cpp) and
// GaussianBlur (gaussian_blur.cpp) plan their own steps from these parts. Internal.
#pragma once

#include <glint/blur.h>

#include <map>
#include <string>
#include <vector>

#include "blur/blur_plan.h"
#include "blur/shaders/blur_params.h"
#include "core/pipeline.h"
#include "core/resources.h"

namespace glint::blur_steps {

constexpr VkImageLayout kGeneral = VK_IMAGE_LAYOUT_GENERAL;
constexpr VkImageLayout kReadOnly = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;

/// The format of the owned images at `p`: RGBA16F or RGBA32F.
VkFormat precision_format(Precision p);

// The fused kernel's tile: workgroup (x, y) with `rows` outputs per invocation along y.
struct FusedShape {
  detail::Workgroup2D workgroup{8, 8};
  uint32_t rows = 1;
};

// The largest tile whose shared memory fits the device (CONTRIBUTING.md, "Device limits"): larger tiles re-read less
// apron. CPU devices (lavapipe) get 8-row-high tiles, which keep their per-thread groups small.
FusedShape fused_shape(const DeviceInfo& info, uint32_t radius, bool half_shared = false);

// Largest value a texel may hold so that every image of the chain stays finite (docs/BLUR.md):
// fp32 keeps headroom for the 4-texel sums the kernels form before scaling.
float max_value_for(VkFormat a, VkFormat b);

// The kernel variant that stores `format`: its GLSL qualifier's, else "noformat" (which
// detail::check_color_write() accepted for the caller's output before any pipeline is made).
std::string store_variant(VkFormat format);

/// Checks a caller image before anything is recorded: non-null handles, one layer, a float colour
/// format the device reads (or, when `need` has STORAGE, writes), its extent, and the usage `need`
/// (named `need_name` in the message).
void check_image(const Context& context, const Image& img, const char* where, const char* role, VkImageUsageFlags need,
                 const char* need_name);

// Which image a step reads or writes: the caller's input or output, or an owned image.
constexpr int kInput = -1;
constexpr int kOutput = -2;

struct Step {
  const detail::ComputePipeline* pipeline = nullptr;
  int src = kInput;
  int dst = kOutput;
  BlurPush push{};
  uint32_t invocations_x = 0;  // dispatch covers these (the pipeline divides by its workgroup)
  uint32_t invocations_y = 0;
  // Output rows per invocation row of the dispatch: invocations_y = ceil(rows of output / this); 0
  // where that does not hold (the separable streamed kernel's invocation rows walk its bands).
  uint32_t rows = 1;
  bool sampler = false;  // binding 0 is a combined image sampler
  // Runs a streamed kernel (blur_stream.comp, blur_down_stream.comp, blur_upsample_stream.comp).
  bool streamed = false;
  // Loads in the order chosen for GPUs (gpu_order()): blur_down_stream.comp's shuffle variant (the
  // taps gathered through subgroup shuffles) or blur_stream.comp's 2:1 mean as column means.
  bool gpu_order = false;
  const detail::OwnedBuffer* taps = nullptr;  // binding 2
  std::string label;
};

// Pipelines keyed by what specializes them, shared by every size of one effect (a std::map, so the
// steps' pointers stay valid while the effect lives).
using PipelineMap = std::map<std::string, detail::ComputePipeline>;

// The program of one size: owned images and steps. Each step pushes its descriptors when recorded.
struct StepProgram {
  const Context* context = nullptr;
  PipelineMap* pipelines = nullptr;
  std::vector<detail::OwnedImage> images;
  std::vector<detail::OwnedBuffer> tap_buffers;
  std::vector<Step> steps;
  VkSampler sampler = VK_NULL_HANDLE;  // bilinear, for the linear-sampling variant (owned by the context)

  /// The pipeline of `kernel` storing `dst_format` with workgroup `wg` and specialization `spec`,
  /// made at its first use and shared through `pipelines`.
  const detail::ComputePipeline& pipeline(const std::string& kernel, VkFormat dst_format, detail::Workgroup2D wg,
                                          std::vector<uint32_t> spec, std::vector<VkDescriptorType> bindings);

  /// Steps that run a streamed kernel (blur_stream.comp, blur_down_stream.comp, blur_upsample_stream.comp).
  uint32_t streamed_steps() const;
  /// Steps marked Step::gpu_order.
  uint32_t gpu_order_steps() const;

  // Owned images can also be copied from (BlurPyramid hands its levels to the caller).
  int add_image(VkExtent2D e, VkFormat f);

  /// A host-visible storage buffer holding `values` (a step's tap weights), owned by the program.
  const detail::OwnedBuffer* add_taps(const std::vector<float>& values);

  // The descriptors of step `s`: source (with the bilinear sampler for the linear-sampling
  // variant), destination, and the tap weights when the step has them.
  detail::Bindings bindings_of(const Step& s, const Image& src, const Image& dst) const;

  /// Records every step, with the barriers between them; `output` is the caller's output image
  /// (null for BlurPyramid, whose steps write owned images only).
  void record(VkCommandBuffer cmd, Image& input, Image* output, Profiler* profiler);
};

/// The push constants of a step from `src` to `dst` texels.
BlurPush make_push(VkExtent2D src, VkExtent2D dst, uint32_t flags, float max_value);

VkExtent2D half_extent(VkExtent2D e);

/// Which kernel runs a level-blur step that reads its source at the same size or at an exact 2:1
/// mean (docs/BLUR.md "Streamed separable"): the streamed kernel (src/blur/shaders/blur_stream.comp)
/// or the tiled one (src/blur/shaders/blur_level.comp, which also takes the other reads).
/// `device`, the default: the streamed kernel where one of its strips fits the device's shared
/// memory and, on GPUs, the image makes at least kStreamMinGroups workgroups
/// (stream_fills_device()); else the tiles. `stream` drops the second condition and `tiles` forces
/// the tiled kernel (tests and benchmarks, through detail::BlurAccess). The pyramid's downsamples
/// (down_step) and upsample (upsample_step) take the same choice: streamed unless `tiles`; under
/// `device` a GPU's loads take the order of a copy (gpu_order()): the downsamples fetch each row
/// in copy order and gather their taps through subgroup shuffles where it has them
/// (blur_down_stream.comp's shuffle variants, which down_shuffles_supported() checks), and the
/// streamed level blur loads a 2:1 mean as two column means (blur_stream.comp, SPLIT_MEAN); CPU
/// devices keep four fetches a texel, where the other orders measured slower
/// (docs/perf/blur_down_stream_ab.txt). `gpu_order` is `stream` with those loads on every device,
/// CPU devices included, and `stream` keeps the four fetches everywhere, so that the tests run
/// both forms on every device.
enum class SeparableKernel : uint32_t { device, stream, tiles, gpu_order };

/// Whether a step under `kernel` on `info`'s device takes the loads ordered for GPUs: `gpu_order`,
/// or `device` on a device that is not a CPU.
bool gpu_order(const DeviceInfo& info, SeparableKernel kernel);

/// Whether `context`'s device can run blur_down_stream.comp's shuffle variants: it shuffles and
/// broadcasts in compute, and every subgroup size it may pick divides the kernel's 64-wide
/// workgroups, so that under SPIR-V 1.6 its subgroups are full (the Vulkan spec,
/// SubgroupLocalInvocationId) and tile the workgroup's columns.
bool down_shuffles_supported(const Context& context);

/// The streamed kernel's workgroup (STRIP_W / 4 invocations across, STEP rows) of the widest strip
/// whose shared memory (twice the source rows where the 2:1 mean is loaded as column means,
/// `split_mean`) and invocations fit the device, or none (false) where no strip fits.
bool stream_shape(const DeviceInfo& info, uint32_t radius, bool half_shared, bool split_mean,
                  detail::Workgroup2D& workgroup);

/// Rows each workgroup of the streamed kernel writes for an image `width` x `height` with strips
/// of `strip_width` columns: bands of at least kStreamMinBand rows (at most 2 RADIUS / band of the
/// rows are filtered twice), enough of them for about kStreamGroups workgroups.
uint32_t stream_band_rows(uint32_t width, uint32_t height, uint32_t strip_width);
inline constexpr uint32_t kStreamMinBand = 32;
inline constexpr uint32_t kStreamGroups = 2048;

/// Whether the streamed kernel's strips of `strip_width` columns make at least kStreamMinGroups
/// workgroups for a `size` output; always true on CPU devices. A few long walks leave a GPU's SMs
/// idle where many short tiles would not (docs/BLUR.md "Streamed separable": on the H100 the
/// 3-level BlurPyramid at 1920x1080, whose 240x135 level makes 20 groups, took 44.5 us with every
/// level streamed, 43.9 tiled and 38.6 with this floor).
bool stream_fills_device(const DeviceInfo& info, VkExtent2D size, uint32_t strip_width);
inline constexpr uint32_t kStreamMinGroups = 64;

// A fused level-blur step B(src -> dst, sigma) (docs/BLUR.md); sigma 0 is the area downsample alone.
// The source is read at the same size, as the exact 2:1 mean or as the area average of any
// ratio. The shared copies are fp16 where dst_format is RGBA16F, unless `fp32_shared`. A step that reads its
// source at the same size or as the exact 2:1 mean runs on the kernel `kernel` picks.
Step fused_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
                VkFormat dst_format, double sigma, double truncation, uint32_t flags, float max_value,
                std::string label, bool fp32_shared = false, SeparableKernel kernel = SeparableKernel::device);

// The pyramid's B-spline upsample from `src` to `dst`, magnifying 2x or more on each axis: the
// streamed kernel (src/blur/shaders/blur_upsample_stream.comp: workgroups of kUpWorkgroup, each
// invocation one output column and every kUpWorkgroup.y-th row of a band of kUpBandRows rows,
// marked Step::streamed) unless `kernel` is tiles, which forces the tiled one
// (src/blur/shaders/blur_upsample.comp, its tile shape from the device: the largest whose shared
// footprint and invocations fit) for the tests and benchmarks that compare them.
Step upsample_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size,
                   VkExtent2D dst_size, VkFormat dst_format, float max_value, std::string label,
                   SeparableKernel kernel = SeparableKernel::device);
inline constexpr detail::Workgroup2D kUpWorkgroup{16, 2};
inline constexpr uint32_t kUpBandRows = 64;
// The pyramid's binomial downsample of an exact 2:1 step from `src` to `dst`: the streamed kernel
// (src/blur/shaders/blur_down_stream.comp: one destination column and kDownBandRows rows per
// invocation, marked Step::streamed; with subgroup shuffles and kDownShuffleBandRows rows, marked
// Step::gpu_order, under `device` on GPUs and under `gpu_order`, as SeparableKernel says) unless `kernel` is tiles,
// which forces the tiled one (src/blur/shaders/blur_down.comp, its tile shape from the device as upsample_step's) for
// the tests and benchmarks that compare them.
Step down_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
               VkFormat dst_format, uint32_t flags, float max_value, std::string label,
               SeparableKernel kernel = SeparableKernel::device);
// Rows of a band, measured on the H100 (docs/perf/blur_down_stream_ab.txt): in one device call the
// shuffled form took 156.8 / 123.0 / 140.2 us for the sigma 4 / 16 / 64 pyramid with bands of 4,
// 159.4 / 125.9 / 143.4 with 8, 162.7 / 138.0 / 161.6 with 16 and 158.2 / 150.0 / 195.5 with 32
// (shorter bands re-read 2 of each band's 2 n + 2 source rows but make more workgroups for the
// small levels); the four-fetch form's first downsample at sigma 4 took 80.9 us with 8 and 87.8
// with 4, in two calls.
inline constexpr uint32_t kDownBandRows = 8;
inline constexpr uint32_t kDownShuffleBandRows = 4;
// A plain per-texel step (dual down/up) with 2D workgroups.
Step simple_step(StepProgram& prog, const char* kernel, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
                 VkFormat dst_format, uint32_t flags, float max_value, std::string label,
                 std::vector<VkDescriptorType> bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
                                                           VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});

}  // namespace glint::blur_steps

namespace glint::detail {

/// Tests' and benchmarks' switch of the kernel the level-blur steps of GaussianBlur and
/// BlurPyramid, and GaussianBlur's pyramid downsamples, run on (blur_steps::SeparableKernel).
struct BlurAccess {
  /// Selects the kernel of `blur`'s (`pyramid`'s) level-blur and downsample steps and plans the
  /// current size again. Call it while no recorded frame of it is pending.
  static void select_separable(GaussianBlur& blur, blur_steps::SeparableKernel kernel);
  static void select_separable(BlurPyramid& pyramid, blur_steps::SeparableKernel kernel);
  /// How many steps of the program of the last prepare() or record() run a streamed kernel (the
  /// level blur's or the downsample's).
  static uint32_t streamed(const GaussianBlur& blur);
  static uint32_t streamed(const BlurPyramid& pyramid);
  /// How many steps load in the order chosen for GPUs (Step::gpu_order).
  static uint32_t gpu_ordered(const GaussianBlur& blur);
  static uint32_t gpu_ordered(const BlurPyramid& pyramid);
};

}  // namespace glint::detail
