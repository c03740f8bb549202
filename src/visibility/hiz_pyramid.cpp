// Hi-Z pyramid: the conservative depth pyramid that LightCuller tests lights against
// (docs/OCCLUSION.md).
#include <glint/gpu/flare_types.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>
#include <vector>

#include "core/barriers.h"
#include "core/check.h"
#include "core/compaction.h"
#include "core/context_state.h"
#include "core/formats.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "visibility/hiz_internal.h"
#include "visibility/shaders/light_cull_params.h"  // push constants and buffer layouts shared with the kernels
#include "visibility/visibility_util.h"

namespace glint {

using detail::concat;
using namespace visibility_detail;

// The GLSL push-constant blocks must match byte for byte (CONTRIBUTING.md, "Shared structs").
static_assert(sizeof(GlintHiZPush) == 32);
static_assert(offsetof(GlintHiZPush, counter_index) == 20);

namespace {

uint32_t floor_log2(uint32_t v) {
  uint32_t k = 0;
  while (v >>= 1) ++k;
  return k;
}

uint32_t ceil_log2(uint32_t v) {
  uint32_t k = floor_log2(v);
  return (1u << k) < v ? k + 1 : k;
}

constexpr const char* kHiZFormats =
    "VK_FORMAT_D16_UNORM, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT, "
    "VK_FORMAT_D32_SFLOAT_S8_UINT or VK_FORMAT_R32_SFLOAT";

}  // namespace

void HiZConfig::validate() const {
  check_uint("HiZConfig::extent.width", extent.width, 1, 16384);
  check_uint("HiZConfig::extent.height", extent.height, 1, 16384);
  if (!detail::is_depth_format(format) && format != VK_FORMAT_R32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("HiZConfig::format = ", detail::format_name(format), " is not accepted: ", kHiZFormats));
  }
  if (max_cell_px != 0) check_uint("HiZConfig::max_cell_px", max_cell_px, 1, 16384);
}

uint32_t hiz_level_count(const HiZConfig& config) {
  config.validate();
  uint32_t levels = floor_log2(std::max(config.extent.width, config.extent.height));
  if (config.max_cell_px != 0) levels = std::min(levels, ceil_log2(config.max_cell_px));
  return levels;
}

struct HiZPyramid::Impl {
  const Context* context = nullptr;
  HiZConfig config;
  uint32_t levels = 0;
  // The pyramid: one R32F image with max(1, levels) mips, a sampling view of all mips and a storage
  // view per mip.
  detail::OwnedImage pyramid;
  detail::OwnedBuffer counters;  // the counter word of the tile dispatch (16 bytes)
  Buffer counter_state;
  bool counters_cleared = false;
  // Nearest, clamp-to-edge: the stream passes gather 2x2 depth texels per fetch.
  VkSampler sampler = VK_NULL_HANDLE;  // owned by the context
  // The two dispatches (docs/OCCLUSION.md, "Hi-Z pyramid"): the stream pass writes levels 1 to
  // stream_levels from the depth image, hiz_build.comp the levels above (made only when there are
  // any). On GPUs the stream pass is hiz_stream.comp (levels 1 to 6 by 64x64 blocks, through
  // shared memory), on CPU devices hiz_stream_texels.comp (levels 1 and 2, one invocation per
  // level-2 texel, no barrier: on lavapipe the other took 4.5x as long). Both push their
  // descriptors with every dispatch.
  detail::HiZStream stream = detail::HiZStream::blocks;
  uint32_t stream_levels = GLINT_HIZ_STREAM_LEVELS;
  detail::ComputePipeline stream_pipeline;
  detail::ComputePipeline tile_pipeline;

  GlintHiZPush stream_push{};                    // base = the depth image; tile_levels = levels it writes
  GlintHiZPush tile_push{};                      // base = level stream_levels
  uint32_t stream_width = 0, stream_height = 0;  // invocations of the stream dispatch
  uint32_t tile_groups_x = 0, tile_groups_y = 0;

  ~Impl() { release(); }

  void release() {
    VkDevice device = context ? context->device() : VK_NULL_HANDLE;
    if (!device) return;
    pyramid.reset();
  }

  void make_image() {
    const VkExtent2D e0{std::max(1u, config.extent.width >> 1), std::max(1u, config.extent.height >> 1)};
    // Transfer usage lets tools read the pyramid back and tests poison it.
    pyramid = detail::OwnedImage(*context, e0, VK_FORMAT_R32_SFLOAT,
                                 VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                 std::max(1u, levels));
  }

  // The two dispatches that build `levels` (>= 1) levels: the stream pass writes levels 1 to
  // stream_levels (by 64x64 blocks of the depth image, the last block of a row or column up to the
  // edge or, where stream_blocks() says so, the remainder a block of its own; or one invocation per
  // level-2 texel); the tile pass reduces level stream_levels by 64x64
  // tiles through up to 6 levels, and its last workgroup the rest. That level is at most
  // 16384 / 4 = 4096 = 64 tiles wide (after the texel stream pass; 256 = 4 tiles after the block
  // one), so the tail always fits one workgroup, and 2 + 6 + 6 = 14 levels cover the largest
  // pyramid.
  //
  // Blocks of the block stream pass along a side of `size` depth texels that builds levels 1 to
  // `built`: one per 64 texels, the last up to the edge (64 to 127 texels), except where the
  // remainder r = size % 64 is at least 2^built: then the remainder is a block of its own. It owns
  // the last texel of every level j <= built (size >> j > (size - r) >> j exactly when r >= 2^j,
  // the size less r being a multiple of 64), and its texels cover only depth texels of its own
  // (child c >= (size - r) >> j covers parents >= 2c), so the 64-texel block before it holds no
  // last texel and is built on the interior path; the edge path then runs over r rows or columns
  // instead of 64 + r.
  static uint32_t stream_blocks(uint32_t size, uint32_t built) {
    const uint32_t full = size >> 6, rest = size & 63;
    if (full == 0) return 1;
    return full + (rest >= (1u << built) ? 1 : 0);
  }

  void plan() {
    const uint32_t reversed = config.reversed_z ? 1u : 0u;
    const uint32_t first = stream_levels;
    stream_push.base_width = static_cast<int32_t>(config.extent.width);
    stream_push.base_height = static_cast<int32_t>(config.extent.height);
    stream_push.tile_levels = std::min(first, levels);
    stream_push.reversed_z = reversed;
    if (stream == detail::HiZStream::blocks) {  // a workgroup of 16x16 per 64x64 block
      stream_width = stream_blocks(config.extent.width, stream_push.tile_levels) * 16;
      stream_height = stream_blocks(config.extent.height, stream_push.tile_levels) * 16;
    } else {  // an invocation per level-2 texel (level 2's size even when only level 1 is built)
      stream_width = std::max(1u, config.extent.width >> 2);
      stream_height = std::max(1u, config.extent.height >> 2);
    }
    if (levels <= first) return;
    const uint32_t bw = std::max(1u, config.extent.width >> first);
    const uint32_t bh = std::max(1u, config.extent.height >> first);
    tile_push.base_width = static_cast<int32_t>(bw);
    tile_push.base_height = static_cast<int32_t>(bh);
    tile_push.tile_levels = std::min(GLINT_HIZ_TILE_LEVELS, levels - first);
    tile_groups_x = std::max(1u, bw >> 6);
    tile_groups_y = std::max(1u, bh >> 6);
    if (tile_groups_x > GLINT_HIZ_TILE || tile_groups_y > GLINT_HIZ_TILE ||
        levels > first + 2 * GLINT_HIZ_TILE_LEVELS) {
      throw Error(ErrorCode::vulkan_failure, concat("HiZPyramid: ", config.extent.width, "x", config.extent.height,
                                                    " does not fit the tile pass's tail"));
    }
    tile_push.tail_levels = levels - first - tile_push.tile_levels;
    tile_push.reversed_z = reversed;
    tile_push.counter_index = 0;
  }

  // Level k's storage view (k >= 1); levels not built alias the last built one: never accessed,
  // but every binding needs a view.
  VkImageView level_view(uint32_t k) const { return pyramid.level_view(std::min(k, std::max(1u, levels)) - 1); }

  // The stream pass's descriptors: the depth through the nearest sampler, levels 1 to stream_levels.
  detail::Bindings stream_bindings(const Image& depth) const {
    detail::Bindings b{{depth.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler}};
    for (uint32_t k = 1; k <= stream_levels; ++k) b.push_back({level_view(k), VK_IMAGE_LAYOUT_GENERAL});
    return b;
  }

  // Chooses the stream pass (`device`: by the device type), plans the dispatches and makes their
  // pipelines.
  void select(detail::HiZStream which) {
    const DeviceInfo& info = context->info();
    which = detail::hiz_resolve_stream(which, info.type, info.max_shared_memory_bytes, levels, info.name);
    stream = which;
    stream_levels = detail::hiz_stream_levels(which);
    plan();
    stream_pipeline.reset();
    tile_pipeline.reset();
    if (levels == 0) return;  // 1x1: nothing to build
    detail::PipelineDesc s;
    s.kernel_id = which == detail::HiZStream::blocks ? "hiz_stream_main" : "hiz_stream_texels_main";
    s.bindings = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
    for (uint32_t k = 0; k < stream_levels; ++k) s.bindings.push_back(VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    s.push_constant_bytes = sizeof(GlintHiZPush);
    // The kernels' fixed local sizes.
    s.workgroup = which == detail::HiZStream::blocks ? detail::Workgroup2D{16, 16} : detail::Workgroup2D{32, 4};
    stream_pipeline = detail::ComputePipeline(*context, s);
    if (levels <= stream_levels) return;
    detail::PipelineDesc d;
    d.kernel_id = "hiz_build_main";
    for (uint32_t k = 0; k < GLINT_HIZ_MAX_LEVELS; ++k) d.bindings.push_back(VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    d.bindings.push_back(VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    d.push_constant_bytes = sizeof(GlintHiZPush);
    d.workgroup = {256, 1};              // the kernel's local size is fixed at 256 (64x64 tiles)
    d.specialization = {stream_levels};  // constant 2: the level it starts from
    tile_pipeline = detail::ComputePipeline(*context, d);
  }

  // The tile pass's descriptors: a storage view per level 1..GLINT_HIZ_MAX_LEVELS, the counter.
  detail::Bindings tile_bindings() const {
    detail::Bindings b;
    for (uint32_t k = 1; k <= GLINT_HIZ_MAX_LEVELS; ++k) b.push_back({level_view(k), VK_IMAGE_LAYOUT_GENERAL});
    b.push_back(counter_state);
    return b;
  }
};

HiZPyramid::HiZPyramid(const Context& context, const HiZConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  const uint32_t limit = context.info().max_image_dimension_2d;
  if (config.extent.width > limit || config.extent.height > limit) {
    throw Error(ErrorCode::unsupported_size,
                concat("HiZConfig::extent = ", config.extent.width, "x", config.extent.height,
                       " is above the device's maxImageDimension2D = ", limit));
  }
  // The kernel gathers the depth through a sampler: the format needs SAMPLED_IMAGE, which Vulkan
  // guarantees for D16_UNORM and D32_SFLOAT only (X8_D24, D24S8 and D32S8 vary by device).
  if (!(detail::format_features(context, config.format) & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) {
    throw Error(ErrorCode::unsupported_format,
                concat("HiZConfig::format = ", detail::format_name(config.format), " cannot be sampled on device '",
                       context.info().name, "' (no VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT with optimal tiling)"));
  }
  Impl& m = *impl_;
  m.context = &context;
  m.config = config;
  m.levels = hiz_level_count(config);
  m.make_image();
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  m.counters = detail::OwnedBuffer(context, 16, usage, false);
  m.counter_state = view_of(m.counters, usage);
  m.sampler = detail::clamp_sampler(context, VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, 0.0f);
  m.select(detail::HiZStream::device);
}

HiZPyramid::HiZPyramid(HiZPyramid&&) noexcept = default;
HiZPyramid& HiZPyramid::operator=(HiZPyramid&&) noexcept = default;
HiZPyramid::~HiZPyramid() = default;

const HiZConfig& HiZPyramid::config() const { return impl_->config; }
uint32_t HiZPyramid::levels() const { return impl_->levels; }
Image& HiZPyramid::image() { return impl_->pyramid.state; }
const Image& HiZPyramid::image() const { return impl_->pyramid.state; }

uint64_t HiZPyramid::min_bytes_moved() const {
  const auto& c = impl_->config;
  uint64_t bytes = uint64_t(c.extent.width) * c.extent.height * 4;
  for (uint32_t k = 1; k <= impl_->levels; ++k) {
    bytes += uint64_t(std::max(1u, c.extent.width >> k)) * std::max(1u, c.extent.height >> k) * 4;
  }
  return bytes;
}

void HiZPyramid::record(VkCommandBuffer cmd, Image& depth, Profiler* profiler) {
  detail::check_command_buffer("HiZPyramid::record", cmd);
  detail::check_image_layout("HiZPyramid::record", "depth", depth);
  Impl& m = *impl_;
  const char* where = "HiZPyramid::record";
  if (!depth.image || !depth.view)
    throw Error(ErrorCode::invalid_argument, concat(where, ": depth image or view is null"));
  detail::check_layers(depth, where, "depth");
  if (depth.format != m.config.format) {
    throw Error(ErrorCode::unsupported_format,
                concat(where, ": depth format ", detail::format_name(depth.format),
                       " differs from HiZConfig::format = ", detail::format_name(m.config.format)));
  }
  if (depth.extent.width != m.config.extent.width || depth.extent.height != m.config.extent.height) {
    throw Error(ErrorCode::unsupported_size,
                concat(where, ": depth is ", depth.extent.width, "x", depth.extent.height, "; HiZConfig::extent is ",
                       m.config.extent.width, "x", m.config.extent.height));
  }
  if (!(depth.usage & VK_IMAGE_USAGE_SAMPLED_BIT)) {
    throw Error(ErrorCode::missing_usage, concat(where, ": depth image lacks VK_IMAGE_USAGE_SAMPLED_BIT usage"));
  }
  if (m.levels == 0) {  // 1x1: level 0 is the whole pyramid; only leave the depth readable
    detail::Barriers b;
    b.use(depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled);
    b.flush(cmd);
    if (profiler) profiler->mark(cmd, "hi-z");
    return;
  }
  detail::Barriers b;
  const bool tile_pass = m.levels > m.stream_levels;
  if (tile_pass && !m.counters_cleared) {  // once per object: the kernel resets the counter after each use
    detail::record_zero_fill(cmd, b, m.counter_state);
    m.counters_cleared = true;
  }
  b.use(depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled);
  b.use(m.pyramid.state, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageRead | kStorageWrite, std::max(1u, m.levels));
  if (tile_pass) b.use(m.counter_state, kCompute, kStorageRead | kStorageWrite);
  b.flush(cmd);
  m.stream_pipeline.dispatch(cmd, m.stream_bindings(depth), m.stream_push, m.stream_width, m.stream_height);
  if (tile_pass) {  // the tile pass reads the stream pass's last level
    if (profiler) profiler->mark(cmd, "hi-z stream");
    b.use(m.pyramid.state, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageRead | kStorageWrite, std::max(1u, m.levels));
    b.flush(cmd);
    m.tile_pipeline.dispatch(cmd, m.tile_bindings(), m.tile_push, m.tile_groups_x * 256, m.tile_groups_y);
  }
  if (profiler) profiler->mark(cmd, "hi-z");
}

namespace detail {

HiZStream hiz_resolve_stream(HiZStream requested, VkPhysicalDeviceType type, uint32_t shared_bytes, uint32_t levels,
                             const std::string& device_name) {
  const bool fits = shared_bytes >= kHiZSharedBytes;
  HiZStream s = requested;
  if (s == HiZStream::device) {
    s = type != VK_PHYSICAL_DEVICE_TYPE_CPU && fits ? HiZStream::blocks : HiZStream::texels;
  }
  if (!fits && (s == HiZStream::blocks || levels > hiz_stream_levels(s))) {
    throw Error(ErrorCode::no_device,
                concat("HiZPyramid: ", levels, " levels need ", kHiZSharedBytes,
                       " bytes of compute shared memory; device '", device_name, "' has ", shared_bytes,
                       " (maxComputeSharedMemorySize). A pyramid of at most 2 levels (HiZConfig::max_cell_px "
                       "<= 4) needs none"));
  }
  return s;
}

void HiZAccess::select_stream(HiZPyramid& hiz, HiZStream stream) { hiz.impl_->select(stream); }
HiZStream HiZAccess::stream(const HiZPyramid& hiz) { return hiz.impl_->stream; }

}  // namespace detail

}  // namespace glint
