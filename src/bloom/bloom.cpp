// Bloom driver: validates, owns the pyramid and pipelines, records the passes of docs/BLOOM.md.
#include <glint/bloom.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bloom/bloom_internal.h"
#include "bloom/shaders/bloom_params.h"
#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/formats.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "core/size_cache.h"

namespace glint {

using detail::concat;

// The GLSL push-constant block must match byte for byte (CONTRIBUTING.md, "Shared structs").
static_assert(sizeof(BloomPush) == 48, "BloomPush layout changed: update src/bloom/shaders/bloom_params.h users");
static_assert(offsetof(BloomPush, threshold) == 16);
static_assert(offsetof(BloomPush, composite_scale) == 32);
static_assert(offsetof(BloomPush, flags) == 36);
static_assert(offsetof(BloomPush, next_width) == 40);
static_assert(sizeof(BloomTailPush) == 16 + 8 * GLINT_BLOOM_MAX_LEVELS);
static_assert(offsetof(BloomTailPush, sizes) == 16);
static_assert(static_cast<uint32_t>(BloomFilter::cod13) == GLINT_BLOOM_COD13);
static_assert(static_cast<uint32_t>(BloomFilter::dual) == GLINT_BLOOM_DUAL);
static_assert(static_cast<uint32_t>(BloomFilter::gauss9) == GLINT_BLOOM_GAUSS9);
static_assert(GLINT_BLOOM_SOURCE_MAX == 65504.0, "docs/BLOOM.md and bloom.h state the source clamp");

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kSampled = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
constexpr VkAccessFlags2 kStorageWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr VkAccessFlags2 kStorageRead = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;

// Shared memory the tiled kernels declare for a workgroup g, per kind (64-bit: set_path() checks
// shapes a caller chose). The downsamples (src/bloom/shaders/bloom_down_tiled.glsl: vec4 windows of
// the source and of its box means).
uint64_t down_shared_bytes(detail::Workgroup2D g) {
  const uint64_t x = g.x, y = g.y;
  return ((2 * x + 4) * (2 * y + 4) + (2 * x + 3) * (2 * y + 3)) * 16;
}
// The tiled upsample and composite (bloom_up_tiled.glsl: vec4 windows of the smaller level and of
// the horizontal pass).
uint64_t up_tiled_shared_bytes(detail::Workgroup2D g) {
  const uint64_t x = g.x, y = g.y;
  return ((x + 10) * (y + 10) + x * (y + 10)) * 16;
}
// The 2:1 upsample and composite (src/bloom/shaders/bloom_up_2x.glsl: a vec3 per output of the
// workgroup's 2 g.x x 2 g.y tile, counted at 16 bytes).
uint64_t two_to_one_shared_bytes(detail::Workgroup2D g) { return 4 * uint64_t(g.x) * g.y * 16; }

// Shared memory of the kernels that run in the bloom's own workgroup: the above, and
// bloom_composite_up.comp, src/bloom/shaders/bloom_prefilter_smooth.comp (vec4 windows of the
// source) and src/bloom/shaders/bloom_prefilter_boxes.comp (three floats per texel of a window for a
// 2 g.y row tile, at an odd row stride with 4 texels of slack, and of its horizontal results).
uint64_t bloom_shared_bytes(detail::Workgroup2D g) {
  const uint64_t x = g.x, y = g.y;
  // bloom_composite_up.comp: the up tiles plus the window of level 1.
  const uint64_t composite_up = up_tiled_shared_bytes(g) + ((x + 9) / 2 + 12) * ((y + 9) / 2 + 12) * 16;
  const uint64_t apron = 2 * GLINT_BLOOM_SMOOTH_RADIUS;
  const uint64_t smooth = ((2 * x + 6 + apron) * (2 * y + 6 + apron) + (2 * y + 6 + apron) * (2 * x + 6)) * 16;
  // The window's row stride is odd: 2 g.x + 4 + apron is even, so one more.
  const uint64_t boxes = ((2 * x + 5 + apron + 2 * x + 3) * (4 * y + 4 + apron) + 4) * 12;
  return std::max({down_shared_bytes(g), composite_up, smooth, boxes, two_to_one_shared_bytes(g)});
}

// Whether src/bloom/shaders/bloom_prefilter_boxes.comp can serve this configuration: the
// karis_smooth guard with a filter that reads 2x2 box means (cod13, dual), on a GPU, or on any
// device whose workgroup the caller chose (ContextOptions::workgroup_2d, the tuning option, which
// selects the GPU kernels so they can be tuned and tested anywhere). The kernel trades arithmetic
// and shared memory per output, which bound a GPU's occupancy, for two more barriers with live
// registers across them; lavapipe runs a barrier as a coroutine switch that saves those registers,
// and with its default 8x8 workgroups measured the kernel 1.6x slower than the general one, so
// CPU devices keep the general kernel by default.
bool smooth_boxes_kernel(const Context& context, const BloomConfig& config) {
  const bool gpu_kernels =
      context.info().type != VK_PHYSICAL_DEVICE_TYPE_CPU || context.state().workgroup_2d.width != 0;
  return config.firefly_guard == FireflyGuard::karis_smooth && config.filter != BloomFilter::gauss9 && gpu_kernels;
}

// Whether `big` is exactly twice `small` on both axes (an exact 2:1 step, which the box-means
// first step and the 2:1 upsample and composite kernels need).
bool exactly_twice(LevelSize big, LevelSize small) {
  return big.width == 2 * small.width && big.height == 2 * small.height;
}

// Whether the first downsample runs that kernel: it needs an exact 2:1 step. Every other case
// runs the general src/bloom/shaders/bloom_prefilter_smooth.comp.
bool smooth_boxes_apply(const Context& context, const BloomConfig& config, VkExtent2D full, LevelSize first) {
  return smooth_boxes_kernel(context, config) && exactly_twice({full.width, full.height}, first);
}

// The device's preferred workgroup if its shared memory holds the tiles, else 8x8 (12 KiB).
detail::Workgroup2D bloom_workgroup(const Context& context) {
  const DeviceInfo& info = context.info();
  detail::Workgroup2D g = detail::choose_workgroup_2d(context);
  if (bloom_shared_bytes(g) > info.max_shared_memory_bytes) g = {8, 8};
  if (bloom_shared_bytes(g) > info.max_shared_memory_bytes) {
    throw Error(ErrorCode::no_device, concat("bloom needs ", bloom_shared_bytes(g), " bytes of shared memory; device '",
                                             info.name, "' has ", info.max_shared_memory_bytes));
  }
  return g;
}

// The small-levels dispatch (src/bloom/shaders/bloom_tail.comp) runs one workgroup: on a GPU as
// many invocations as the device allows up to 1024 (every one of them works on each level; a
// 32-wide x keeps within maxComputeWorkGroupSize, at least 128 x 128 x 64), on a CPU device 8x8
// (lavapipe runs a workgroup on one thread, SIMD 8 wide: more invocations add no parallelism).
detail::Workgroup2D tail_workgroup(const Context& context) {
  const DeviceInfo& info = context.info();
  if (info.type == VK_PHYSICAL_DEVICE_TYPE_CPU) return {8, 8};
  const uint32_t n = std::min(1024u, std::max(128u, info.max_workgroup_invocations));
  return {32, n / 32};
}

// Floats of shared memory the small-levels dispatch declares (3 per texel): the device's
// maxComputeSharedMemorySize (at least 16 KiB), at most 64 KiB so that one workgroup's work stays
// small: with 48 KiB (NVIDIA) the levels below T hold at most 4096 texels, so level T, which
// the workgroup accumulates into, has at most about 4 x 4096 / (4/3) = 12288 texels.
uint32_t tail_floats(const Context& context) {
  const uint32_t bytes = std::min(context.info().max_shared_memory_bytes, 65536u);
  return bytes / 12 * 3;
}

}  // namespace

struct Bloom::Impl {
  const Context* context;
  BloomConfig config;
  detail::Workgroup2D workgroup;
  detail::BloomPath path;  // which dispatches are fused (bloom_internal.h)
  detail::Workgroup2D tail_group;
  uint32_t tail_capacity = 0;  // floats of shared memory of the small-levels dispatch

  // Pipelines for the current shape (filter, precision); composite and copy per output format.
  detail::ComputePipeline prefilter_down, down, blur, up;
  // bloom_up_2x for the separable filters (cod13, gauss9), run where level k is exactly twice
  // level k+1 on both axes; else empty.
  detail::ComputePipeline up_2x;
  // karis_smooth at an exact 2:1 first step with cod13 or dual (smooth_boxes_apply()); else empty.
  detail::ComputePipeline prefilter_boxes;
  // The small levels in one dispatch (path.fuse_small_levels); else empty.
  detail::ComputePipeline tail;
  // Composite and copy per output variant (core/formats.h, check_color_write()): rgba16f and
  // rgba32f are made with the others, r11f_g11f_b10f and noformat by prepare(extent, format) or
  // on first use, and made again by a shape change. The composite is
  // bloom_composite_up (path.fuse_last_up) or bloom_composite; composite_2x holds
  // bloom_composite_2x for the separable filters (cod13, gauss9), which record() runs where the
  // output is exactly twice level 0 on both axes.
  std::map<std::string, detail::ComputePipeline> composite, composite_2x, copy;

  // The pyramid of one input extent (and config generation). Kept per size in `cache` until no
  // submitted work can use it (core/size_cache.h), so one Bloom may be recorded at several sizes.
  struct Pyramid {
    VkExtent2D extent{0, 0};
    std::vector<LevelSize> chain;
    bool was_clamped = false;
    std::vector<LevelSize> pre_chain;  // level0_height's 2:1 steps before level 0
    bool boxes_first = false;          // the first step runs prefilter_boxes (smooth_boxes_apply())
    std::vector<detail::OwnedImage> pre_levels;
    std::vector<detail::OwnedImage> levels;
    std::vector<detail::OwnedImage> temps;  // gauss9 horizontal pass, one per level
  };
  detail::SizeCache<Pyramid> cache;
  Pyramid* cur = nullptr;   // the pyramid of the last prepare() or record()
  uint32_t generation = 0;  // bumped by a shape change: older pyramids are never found again

  VkFormat level_format() const {
    return config.precision == Precision::fp32 ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
  }

  detail::PipelineDesc desc(const std::string& kernel, std::vector<VkDescriptorType> bindings,
                            detail::Workgroup2D shape = {0, 0}) const {
    detail::PipelineDesc d;
    d.kernel_id = kernel;
    d.bindings = std::move(bindings);
    d.push_constant_bytes = sizeof(BloomPush);
    d.workgroup = shape.x != 0 ? shape : workgroup;
    // Constant 3: prefetch the tiled loads on GPUs only (src/bloom/shaders/bloom.glsl, PREFETCH).
    const uint32_t prefetch = context->info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0u : 1u;
    d.specialization = {static_cast<uint32_t>(config.filter), prefetch};
    return d;
  }

  // desc() of the 2:1 upsample and composite kernels, with constant 4: their outputs stored in copy
  // order through shared memory, on GPUs unless the path says otherwise
  // (src/bloom/shaders/bloom_up_2x.glsl, COPY_ORDER).
  detail::PipelineDesc desc_2x(const std::string& kernel, std::vector<VkDescriptorType> bindings,
                               detail::Workgroup2D shape) const {
    detail::PipelineDesc d = desc(kernel, std::move(bindings), shape);
    using Order = detail::BloomPath::CopyOrder;
    const bool on = path.copy_order_2x == Order::device ? detail::copy_order_by_default(context->info())
                                                        : path.copy_order_2x == Order::on;
    d.specialization.push_back(on ? 1u : 0u);
    return d;
  }

  void make_pipelines() {
    const std::string lv = detail::format_variant(level_format());
    const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    const auto W = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    const char* first =
        config.firefly_guard == FireflyGuard::karis_smooth ? "bloom_prefilter_smooth_" : "bloom_prefilter_down_";
    prefilter_down = detail::ComputePipeline(*context, desc(first + lv, {S, W}));
    prefilter_boxes = smooth_boxes_kernel(*context, config)
                          ? detail::ComputePipeline(*context, desc("bloom_prefilter_boxes_" + lv, {S, W}))
                          : detail::ComputePipeline();
    down = detail::ComputePipeline(*context, desc("bloom_down_" + lv, {S, W}, path.down_workgroup));
    blur = config.filter == BloomFilter::gauss9 ? detail::ComputePipeline(*context, desc("bloom_blur_" + lv, {S, W}))
                                                : detail::ComputePipeline();
    up = detail::ComputePipeline(*context, desc("bloom_up_" + lv, {S, W}, path.up_workgroup));
    up_2x = path.up_2x && config.filter != BloomFilter::dual
                ? detail::ComputePipeline(*context, desc_2x("bloom_up_2x_" + lv, {S, W}, path.up_workgroup))
                : detail::ComputePipeline();
    if (path.fuse_small_levels) {
      detail::PipelineDesc d = desc("bloom_tail_" + lv, {S, W});
      d.push_constant_bytes = sizeof(BloomTailPush);
      d.workgroup = tail_group;
      d.specialization.push_back(tail_capacity);  // constant 4: TAIL_FLOATS
      tail = detail::ComputePipeline(*context, d);
    } else {
      tail = detail::ComputePipeline();
    }
    // The output variants made so far (prepared or recorded) are made again for the new shape, so
    // that a prepared output format stays prepared.
    std::vector<std::string> variants = {"rgba16f", "rgba32f"};
    for (const auto& [v, pipeline] : composite) {
      if (std::find(variants.begin(), variants.end(), v) == variants.end()) variants.push_back(v);
    }
    composite.clear();
    composite_2x.clear();
    copy.clear();
    for (const std::string& v : variants) output_pipelines(v);
  }

  // The pipelines that write an output of kernel variant `v`: the composite, the 2:1 composite
  // (null where it does not apply: dual, or the composite with the last upsample fused) and the copy.
  struct OutputPipelines {
    detail::ComputePipeline* composite;
    detail::ComputePipeline* composite_2x;
    detail::ComputePipeline* copy;
  };
  OutputPipelines output_pipelines(const std::string& v) {
    const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    const auto W = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    auto c = composite.find(v);
    if (c == composite.end()) {
      detail::PipelineDesc d = path.fuse_last_up ? desc("bloom_composite_up_" + v, {S, S, W, S})
                                                 : desc("bloom_composite_" + v, {S, S, W}, path.composite_workgroup);
      c = composite.emplace(v, detail::ComputePipeline(*context, d)).first;
    }
    detail::ComputePipeline* c2 = nullptr;
    if (!path.fuse_last_up && path.composite_2x && config.filter != BloomFilter::dual) {
      auto it = composite_2x.find(v);
      if (it == composite_2x.end()) {
        it = composite_2x
                 .emplace(v, detail::ComputePipeline(
                                 *context, desc_2x("bloom_composite_2x_" + v, {S, S, W}, path.composite_workgroup)))
                 .first;
      }
      c2 = &it->second;
    }
    auto k = copy.find(v);
    if (k == copy.end()) k = copy.emplace(v, detail::ComputePipeline(*context, desc("image_copy_" + v, {S, W}))).first;
    return {&c->second, c2, &k->second};
  }

  // The pyramid for `size`, from the cache or made now; it becomes `cur`. Throws (before anything
  // is recorded) when the cache is full of pyramids that submitted work may still use.
  Pyramid& pyramid_for(VkExtent2D size, const char* who) {
    cur = &cache.get({size, VK_FORMAT_UNDEFINED, generation}, cur, who, [&] { return make_pyramid(size); });
    return *cur;
  }

  std::unique_ptr<Pyramid> make_pyramid(VkExtent2D size) const {
    auto made = std::make_unique<Pyramid>();
    Pyramid& P = *made;
    std::vector<LevelSize>& chain = P.chain;
    std::vector<LevelSize>& pre_chain = P.pre_chain;
    std::vector<detail::OwnedImage>& pre_levels = P.pre_levels;
    std::vector<detail::OwnedImage>& levels = P.levels;
    std::vector<detail::OwnedImage>& temps = P.temps;
    chain = bloom_mip_chain(size, config.iterations, config.level0_height);
    pre_chain = bloom_pre_levels(size, config.level0_height);
    P.was_clamped = chain.size() < config.iterations;
    P.boxes_first = smooth_boxes_apply(*context, config, size, pre_chain.empty() ? chain[0] : pre_chain[0]);
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    const bool gauss = config.filter == BloomFilter::gauss9;
    for (const LevelSize& l : pre_chain)
      pre_levels.emplace_back(*context, VkExtent2D{l.width, l.height}, level_format(), usage);
    for (const LevelSize& l : chain) {
      levels.emplace_back(*context, VkExtent2D{l.width, l.height}, level_format(), usage);
      if (gauss) temps.emplace_back(*context, VkExtent2D{l.width, l.height}, level_format(), usage);
    }
    P.extent = size;
    return made;
  }

  // T of the small-levels dispatch for `chain` (bloom_internal.h, small_levels_top()): the first
  // level whose levels below (and for gauss9 the blur's scratch of the largest of them) fit its
  // shared memory. -1: not run.
  int small_levels_top(const std::vector<LevelSize>& chain) const {
    if (!path.fuse_small_levels) return -1;
    const size_t n = chain.size();
    for (size_t t = 0; t + 1 < n; ++t) {
      uint64_t floats = 0;
      for (size_t k = t + 1; k < n; ++k) floats += 3ull * chain[k].width * chain[k].height;
      if (config.filter == BloomFilter::gauss9) floats += 3ull * chain[t + 1].width * chain[t + 1].height;
      if (floats <= tail_capacity) return static_cast<int>(t);
    }
    return -1;
  }

  BloomPush push(const Pyramid& P, LevelSize src, LevelSize dst, uint32_t flags = 0) const {
    BloomPush p{};
    p.src_width = static_cast<int32_t>(src.width);
    p.src_height = static_cast<int32_t>(src.height);
    p.dst_width = static_cast<int32_t>(dst.width);
    p.dst_height = static_cast<int32_t>(dst.height);
    p.threshold = config.threshold;
    p.knee = config.threshold * config.soft_knee;
    p.max_brightness = config.max_brightness;
    p.radius = config.radius;
    p.composite_scale = config.intensity / static_cast<float>(P.chain.size());
    p.flags = flags;
    return p;
  }

  // Whether two caller images are the same layer of the same image (bloom in place).
  static bool same_subresource(const Image& a, const Image& b) {
    return a.image == b.image && a.base_array_layer == b.base_array_layer;
  }

  // Checks both images; returns the kernel variant that writes the output.
  const char* check_images(const Image& in, const Image& out) const {
    auto check_one = [&](const Image& img, const char* role, VkImageUsageFlags need, const char* need_name) {
      if (!img.image || !img.view) {
        throw Error(ErrorCode::invalid_argument, concat("Bloom::record: ", role, " image and view must be non-null"));
      }
      detail::check_layers(img, "Bloom::record", role);
      detail::check_extent(*context, img.extent, "Bloom::record", role);
      if ((img.usage & need) != need) {
        throw Error(ErrorCode::missing_usage, concat("Bloom::record: ", role, " image lacks ", need_name, " usage"));
      }
    };
    const bool in_place = same_subresource(in, out);
    check_one(in, "input", VK_IMAGE_USAGE_SAMPLED_BIT, "VK_IMAGE_USAGE_SAMPLED_BIT");
    check_one(out, "output", VK_IMAGE_USAGE_STORAGE_BIT, "VK_IMAGE_USAGE_STORAGE_BIT");
    detail::check_color_read(*context, in.format, "Bloom::record", "input");
    const char* variant = detail::check_color_write(*context, out.format, "Bloom::record", "output");
    if (in.extent.width != out.extent.width || in.extent.height != out.extent.height) {
      throw Error(ErrorCode::invalid_argument,
                  concat("Bloom::record: output extent ", out.extent.width, "x", out.extent.height,
                         " differs from input extent ", in.extent.width, "x", in.extent.height));
    }
    if (in_place && in.format != out.format) {
      throw Error(ErrorCode::invalid_argument,
                  concat("Bloom::record: in-place input and output must have the same format; input is ",
                         detail::format_name(in.format), ", output ", detail::format_name(out.format)));
    }
    return variant;
  }

  void record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler);
};

void Bloom::Impl::record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler) {
  const char* out_variant = check_images(input, output);
  const bool in_place = same_subresource(input, output);
  if (config.intensity == 0.0f) {
    // Nothing to add: the output is the input. In place that is no work at all.
    if (in_place) return;
    Pyramid& P = pyramid_for(input.extent, "Bloom::record");
    const detail::ComputePipeline* copy_pipeline = output_pipelines(out_variant).copy;
    cache.recorded(&P, cmd);
    detail::Barriers b;
    b.use(input, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kSampled);
    b.use(output, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kStorageWrite);
    b.flush(cmd);
    const LevelSize full{input.extent.width, input.extent.height};
    copy_pipeline->dispatch(
        cmd, {{input.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, {output.view, VK_IMAGE_LAYOUT_GENERAL}},
        push(P, full, full), full.width, full.height);
    if (profiler) profiler->mark(cmd, "bloom copy (intensity 0)");
    return;
  }
  Pyramid& P = pyramid_for(input.extent, "Bloom::record");
  const OutputPipelines out_pipelines = output_pipelines(out_variant);
  cache.recorded(&P, cmd);
  const std::vector<LevelSize>& chain = P.chain;
  const std::vector<LevelSize>& pre_chain = P.pre_chain;
  std::vector<detail::OwnedImage>& levels = P.levels;
  std::vector<detail::OwnedImage>& temps = P.temps;
  std::vector<detail::OwnedImage>& pre_levels = P.pre_levels;

  // In place, one state tracks the one image; it is copied back to `input` at the end.
  Image& scene = in_place ? output : input;
  const VkImageLayout scene_layout = in_place ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  const uint32_t n = static_cast<uint32_t>(chain.size());
  const LevelSize full{input.extent.width, input.extent.height};
  const VkImageLayout G = VK_IMAGE_LAYOUT_GENERAL;
  const bool gauss = config.filter == BloomFilter::gauss9;
  detail::Barriers b;

  auto blur_level = [&](uint32_t k) {
    b.use(levels[k].state, G, kCompute, kSampled);
    b.use(temps[k].state, G, kCompute, kStorageWrite);
    b.flush(cmd);
    blur.dispatch(cmd, {{levels[k].state.view, G}, {temps[k].state.view, G}}, push(P, chain[k], chain[k]),
                  chain[k].width, chain[k].height);
    b.use(temps[k].state, G, kCompute, kSampled);
    b.use(levels[k].state, G, kCompute, kStorageWrite);
    b.flush(cmd);
    blur.dispatch(cmd, {{temps[k].state.view, G}, {levels[k].state.view, G}},
                  push(P, chain[k], chain[k], GLINT_BLOOM_FLAG_VERTICAL), chain[k].width, chain[k].height);
  };

  // 1. Bright-pass fused into the first downsample; with level0_height, 2:1 steps to level 0.
  const uint32_t karis = config.firefly_guard == FireflyGuard::karis ? GLINT_BLOOM_FLAG_KARIS : 0u;
  const auto m = static_cast<uint32_t>(pre_chain.size());
  Image& first = m ? pre_levels[0].state : levels[0].state;
  const LevelSize first_size = m ? pre_chain[0] : chain[0];
  b.use(scene, scene_layout, kCompute, kSampled);
  b.use(first, G, kCompute, kStorageWrite);
  b.flush(cmd);
  const detail::Bindings prefilter_bindings{{input.view, scene_layout}, {first.view, G}};
  if (P.boxes_first) {
    // A workgroup of W x H invocations writes W x 2H texels (two rows per invocation).
    prefilter_boxes.dispatch(cmd, prefilter_bindings, push(P, full, first_size), first_size.width,
                             (first_size.height + 1) / 2);
  } else {
    prefilter_down.dispatch(cmd, prefilter_bindings, push(P, full, first_size, karis), first_size.width,
                            first_size.height);
  }
  for (uint32_t k = 0; k < m; ++k) {
    Image& next = k + 1 < m ? pre_levels[k + 1].state : levels[0].state;
    const LevelSize next_size = k + 1 < m ? pre_chain[k + 1] : chain[0];
    b.use(pre_levels[k].state, G, kCompute, kSampled);
    b.use(next, G, kCompute, kStorageWrite);
    b.flush(cmd);
    down.dispatch(cmd, {{pre_levels[k].state.view, G}, {next.view, G}}, push(P, pre_chain[k], next_size),
                  next_size.width, next_size.height);
  }
  if (gauss) blur_level(0);
  if (profiler) profiler->mark(cmd, "bloom bright-pass + down 0");

  // 2. Progressive downsample, down to level T of the small-levels dispatch (docs/BLOOM.md "Dispatches").
  const int top = small_levels_top(chain);
  const uint32_t last_down = top >= 0 ? static_cast<uint32_t>(top) : n - 1;
  for (uint32_t k = 1; k <= last_down; ++k) {
    b.use(levels[k - 1].state, G, kCompute, kSampled);
    b.use(levels[k].state, G, kCompute, kStorageWrite);
    b.flush(cmd);
    down.dispatch(cmd, {{levels[k - 1].state.view, G}, {levels[k].state.view, G}}, push(P, chain[k - 1], chain[k]),
                  chain[k].width, chain[k].height);
    if (gauss) blur_level(k);
  }
  if (profiler && last_down > 0) profiler->mark(cmd, "bloom downsample");

  // 2b. The levels below T in one workgroup: their downsamples and upsamples, A(T) over level T.
  if (top >= 0) {
    const auto t = static_cast<uint32_t>(top);
    BloomTailPush tp{};
    tp.count = static_cast<int32_t>(n - 1 - t);
    tp.radius = config.radius;
    for (uint32_t k = t; k < n; ++k) {
      tp.sizes[2 * (k - t)] = static_cast<int32_t>(chain[k].width);
      tp.sizes[2 * (k - t) + 1] = static_cast<int32_t>(chain[k].height);
    }
    b.use(levels[t].state, G, kCompute, kSampled | kStorageRead | kStorageWrite);
    b.flush(cmd);
    tail.dispatch(cmd, {{levels[t].state.view, G}, {levels[t].state.view, G}}, tp, tail_group.x, tail_group.y);
    if (profiler) profiler->mark(cmd, "bloom small levels");
  }

  // 3. Upsample with accumulation by gather, smallest level first, from the level that holds its
  // A(k) (T, or the last level) down to level 1 (0 when the composite does not evaluate A(0)).
  const uint32_t have = top >= 0 ? static_cast<uint32_t>(top) : n - 1;
  const uint32_t up_to = path.fuse_last_up ? std::min(1u, have) : 0u;
  for (uint32_t k = have; k-- > up_to;) {
    b.use(levels[k + 1].state, G, kCompute, kSampled);
    b.use(levels[k].state, G, kCompute, kStorageRead | kStorageWrite);
    b.flush(cmd);
    const detail::Bindings bindings{{levels[k + 1].state.view, G}, {levels[k].state.view, G}};
    if (up_2x && exactly_twice(chain[k], chain[k + 1])) {
      // One invocation per 2x2 block of level k (bloom_up_2x.comp).
      up_2x.dispatch(cmd, bindings, push(P, chain[k + 1], chain[k]), chain[k].width / 2, chain[k].height / 2);
    } else {
      up.dispatch(cmd, bindings, push(P, chain[k + 1], chain[k]), chain[k].width, chain[k].height);
    }
  }
  if (profiler && have > up_to) profiler->mark(cmd, "bloom upsample");

  // 4. The composite, with the last upsample (Up(A(0)) to full resolution) and, fused, the one
  // before it (A(0) = level 0 + Up(A(1))) evaluated inside.
  if (path.fuse_last_up) {
    const bool level0_done = have == 0;  // one level, or T = 0: level 0 holds A(0)
    BloomPush cp = push(P, chain[0], full, level0_done ? GLINT_BLOOM_FLAG_LEVEL0_DONE : 0u);
    Image& next = level0_done ? levels[0].state : levels[1].state;
    if (!level0_done) {
      cp.next_width = static_cast<int32_t>(chain[1].width);
      cp.next_height = static_cast<int32_t>(chain[1].height);
      b.use(next, G, kCompute, kSampled);
    }
    b.use(levels[0].state, G, kCompute, kSampled);
    b.use(scene, scene_layout, kCompute, kSampled);
    b.use(output, G, kCompute, in_place ? (kSampled | kStorageWrite) : kStorageWrite);
    b.flush(cmd);
    out_pipelines.composite->dispatch(
        cmd, {{input.view, scene_layout}, {levels[0].state.view, G}, {output.view, G}, {next.view, G}}, cp, full.width,
        full.height);
  } else {
    b.use(levels[0].state, G, kCompute, kSampled);
    b.use(scene, scene_layout, kCompute, kSampled);
    b.use(output, G, kCompute, in_place ? (kSampled | kStorageWrite) : kStorageWrite);
    b.flush(cmd);
    const detail::Bindings bindings{{input.view, scene_layout}, {levels[0].state.view, G}, {output.view, G}};
    if (out_pipelines.composite_2x && exactly_twice(full, chain[0])) {
      // One invocation per 2x2 block of outputs (bloom_composite_2x.comp).
      out_pipelines.composite_2x->dispatch(cmd, bindings, push(P, chain[0], full), full.width / 2, full.height / 2);
    } else {
      out_pipelines.composite->dispatch(cmd, bindings, push(P, chain[0], full), full.width, full.height);
    }
  }
  if (profiler) profiler->mark(cmd, "bloom composite");
  if (in_place) input = output;
}

Bloom::Bloom(const Context& context, const BloomConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  impl_->context = &context;
  impl_->config = config;
  impl_->workgroup = bloom_workgroup(context);
  impl_->tail_group = tail_workgroup(context);
  impl_->tail_capacity = tail_floats(context);
  // One dispatch per level by default (BloomPath): both fusions measured slower on the H100
  // and on lavapipe (docs/BLOOM.md "Dispatches").
  impl_->cache.bind(context);
  impl_->make_pipelines();
}

Bloom::Bloom(Bloom&&) noexcept = default;
Bloom& Bloom::operator=(Bloom&&) noexcept = default;
Bloom::~Bloom() = default;

void Bloom::set_config(const BloomConfig& config) {
  config.validate();
  const BloomConfig old = impl_->config;
  impl_->config = config;
  const bool smooth_changed =
      (old.firefly_guard == FireflyGuard::karis_smooth) != (config.firefly_guard == FireflyGuard::karis_smooth);
  const bool pipelines_changed = old.filter != config.filter || old.precision != config.precision || smooth_changed;
  const bool shape_changed =
      old.iterations != config.iterations || old.level0_height != config.level0_height || pipelines_changed;
  if (!shape_changed) return;
  // Pyramids of the old shape stay cached, never found again, until no submitted work uses them.
  ++impl_->generation;
  if (pipelines_changed) impl_->make_pipelines();
  if (impl_->cur) impl_->pyramid_for(impl_->cur->extent, "Bloom::set_config");
}

const BloomConfig& Bloom::config() const { return impl_->config; }

void Bloom::prepare(VkExtent2D extent) {
  detail::check_extent(*impl_->context, extent, "Bloom::prepare");
  impl_->pyramid_for(extent, "Bloom::prepare");
}

void Bloom::prepare(VkExtent2D extent, VkFormat output_format) {
  detail::check_extent(*impl_->context, extent, "Bloom::prepare");
  const char* variant = detail::check_color_write(*impl_->context, output_format, "Bloom::prepare", "output");
  impl_->pyramid_for(extent, "Bloom::prepare");
  impl_->output_pipelines(variant);
}

void Bloom::record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler) {
  detail::check_command_buffer("Bloom::record", cmd);
  detail::check_image_layout("Bloom::record", "input", input);
  detail::check_image_layout("Bloom::record", "output", output);
  impl_->record(cmd, input, output, profiler);
}

void Bloom::release_unused() { impl_->cache.release_unused(impl_->cur); }
uint32_t Bloom::cached_sizes() const { return impl_->cache.size(); }

uint32_t Bloom::levels() const { return impl_->cur ? static_cast<uint32_t>(impl_->cur->chain.size()) : 0u; }
bool Bloom::clamped() const { return impl_->cur && impl_->cur->was_clamped; }
std::vector<LevelSize> Bloom::level_sizes() const { return impl_->cur ? impl_->cur->chain : std::vector<LevelSize>{}; }

uint64_t Bloom::min_bytes_moved(VkFormat input_format, VkFormat output_format) const {
  if (!impl_->cur) return 0;
  const Impl::Pyramid& p = *impl_->cur;
  const uint64_t pixels = uint64_t(p.extent.width) * p.extent.height;
  const uint64_t in_bytes = detail::texel_bytes(input_format);
  const uint64_t out_bytes = detail::texel_bytes(output_format);
  const uint64_t level_bytes = impl_->config.precision == Precision::fp32 ? 16 : 8;
  uint64_t total = pixels * (in_bytes + out_bytes);
  for (const LevelSize& l : p.chain) total += 2 * uint64_t(l.width) * l.height * level_bytes;
  for (const LevelSize& l : p.pre_chain) total += 2 * uint64_t(l.width) * l.height * level_bytes;
  return total;
}

namespace detail {

void BloomAccess::set_path(Bloom& bloom, const BloomPath& path) {
  // The shared memory of each kind's kernels at its shape (down_shared_bytes() and the others above):
  // bloom_down's tiles; bloom_up's (and bloom_composite's) tiles and the 2:1 kernels' output tile.
  const DeviceInfo& info = bloom.impl_->context->info();
  auto check = [&](const char* kind, Workgroup2D g, uint64_t bytes) {
    if (g.x == 0 && g.y == 0) return;
    if (g.x == 0 || g.y == 0 || uint64_t(g.x) * g.y > info.max_workgroup_invocations ||
        bytes > info.max_shared_memory_bytes) {
      throw Error(ErrorCode::invalid_argument,
                  concat("BloomPath::", kind, " = ", g.x, "x", g.y, ": needs ", uint64_t(g.x) * g.y,
                         " invocations and ", bytes, " bytes of shared memory; device '", info.name, "' has ",
                         info.max_workgroup_invocations, " and ", info.max_shared_memory_bytes));
    }
  };
  auto up_bytes = [](Workgroup2D g) { return std::max(up_tiled_shared_bytes(g), two_to_one_shared_bytes(g)); };
  check("down_workgroup", path.down_workgroup, down_shared_bytes(path.down_workgroup));
  check("up_workgroup", path.up_workgroup, up_bytes(path.up_workgroup));
  check("composite_workgroup", path.composite_workgroup, up_bytes(path.composite_workgroup));
  bloom.impl_->path = path;
  bloom.impl_->make_pipelines();
}

BloomPath BloomAccess::path(const Bloom& bloom) { return bloom.impl_->path; }

int BloomAccess::small_levels_top(const Bloom& bloom) {
  const Bloom::Impl& impl = *bloom.impl_;
  return impl.cur ? impl.small_levels_top(impl.cur->chain) : -1;
}

}  // namespace detail

}  // namespace glint
