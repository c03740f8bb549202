// Light culler: tests each light against the Hi-Z pyramid and compacts the visible ones into the
// flare draw's instances (docs/OCCLUSION.md).
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
#include "visibility/light_cull_internal.h"
#include "visibility/shaders/light_cull_params.h"  // push constants and buffer layouts shared with the kernels
#include "visibility/visibility_util.h"

namespace glint {

using detail::check_range;
using detail::concat;
using namespace visibility_detail;

// The GLSL push-constant blocks must match byte for byte (CONTRIBUTING.md, "Shared structs").
static_assert(sizeof(GlintCullPush) == 112);
static_assert(offsetof(GlintCullPush, width) == 64);
static_assert(offsetof(GlintCullPush, flags) == 88);
static_assert(offsetof(GlintCullPush, depth_bias) == 96);
static_assert(sizeof(GlintCullCompactPush) == sizeof(GlintCompactPush));
static_assert(offsetof(GlintCullCompactPush, tile_groups) == offsetof(GlintCompactPush, tile_groups));
static_assert(offsetof(GlintCullCompactPush, groups_x) == offsetof(GlintCompactPush, groups_x));
static_assert(offsetof(GlintCullCompactPush, vertex_count) == offsetof(GlintCompactPush, step));
static_assert(sizeof(LightCullFrame::view_proj) == sizeof(GlintCullPush::view_proj));

namespace {

constexpr uint32_t kCullGroup = GLINT_CULL_GROUP;  // lights per workgroup: one 64-bit visibility mask
static_assert(kCullGroup == 64, "light_cull.comp keeps a workgroup's visibility in two 32-bit words");
// light_cull.comp and light_cull_scatter.comp read lights and write instances as three 16-byte words:
// (position, intensity), (colour, size_px), (element, enabled, reserved x2) and (centre, size_px,
// fraction), (colour, intensity), (light_index, element, ndc_depth, reserved). Every member's offset
// (flare_types.h asserts the sizes and some offsets; these are the ones the words rely on).
static_assert(offsetof(GlintFlareLight, position_x) == 0 && offsetof(GlintFlareLight, position_y) == 4 &&
              offsetof(GlintFlareLight, position_z) == 8 && offsetof(GlintFlareLight, intensity) == 12 &&
              offsetof(GlintFlareLight, color_r) == 16 && offsetof(GlintFlareLight, color_g) == 20 &&
              offsetof(GlintFlareLight, color_b) == 24 && offsetof(GlintFlareLight, size_px) == 28 &&
              offsetof(GlintFlareLight, element) == 32 && offsetof(GlintFlareLight, enabled) == 36 &&
              offsetof(GlintFlareLight, reserved0) == 40 && offsetof(GlintFlareLight, reserved1) == 44);
static_assert(offsetof(GlintFlareInstance, center_x_px) == 0 && offsetof(GlintFlareInstance, center_y_px) == 4 &&
              offsetof(GlintFlareInstance, size_px) == 8 && offsetof(GlintFlareInstance, visible_fraction) == 12 &&
              offsetof(GlintFlareInstance, color_r) == 16 && offsetof(GlintFlareInstance, color_g) == 20 &&
              offsetof(GlintFlareInstance, color_b) == 24 && offsetof(GlintFlareInstance, intensity) == 28 &&
              offsetof(GlintFlareInstance, light_index) == 32 && offsetof(GlintFlareInstance, element) == 36 &&
              offsetof(GlintFlareInstance, ndc_depth) == 40 && offsetof(GlintFlareInstance, reserved) == 44);
constexpr uint32_t kMaxGroupsX = 65535;  // guaranteed maxComputeWorkGroupCount[0]
// Samples (lights x N^2) up to which the one-workgroup cull runs: on an NVIDIA H200 it won at
// 1024 lights with N = 4 (22.9 against 28.4 us; 15.0 against 25.8 at 64 lights) and lost at
// 1000 lights with N = 8 and 16 (65.7 against 61.9 us, 231.7 against 185.9), where one
// multiprocessor's fetch rate holds it; fewer samples only shorten its work.
constexpr uint32_t kOneGroupSamples = 16384;

// The depth-image cull's pipeline in workgroups of `size` invocations (kShareSamples = 0: its last
// workgroup culls one light per invocation).
detail::PipelineDesc from_depth_desc(uint32_t size) {
  const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
  const auto B = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  detail::PipelineDesc d;
  d.kernel_id = "light_cull_from_depth";
  d.bindings = {S, S, B, B, B, B, B, B, B};
  d.push_constant_bytes = sizeof(GlintCullPush);
  d.workgroup = {size, 1};
  d.specialization = {0};
  return d;
}
// The depth-image cull's workgroup: on an NVIDIA H200 the 10-light flare frame took 27.1 us with
// 256 invocations against 30.1 with 1024 (docs/OCCLUSION.md, "Few lights from the depth image").
constexpr uint32_t kDepthGroup = 256;
// The deepest pyramid whose windows the depth-image cull reads instead (LightCuller::needs_pyramid):
// the flare pass's for lights of up to 128 px at N = 4, where it was measured.
constexpr uint32_t kDepthMaxLevels = 5;
// Samples (lights x N^2) the depth-image cull holds words for: a workgroup each, within the
// guaranteed maxComputeWorkGroupCount[0]. The device's choice stays under kOneGroupSamples.
constexpr uint32_t kDepthSamples = 65535;

}  // namespace

void LightCullConfig::validate() const {
  check_uint("LightCullConfig::capacity", capacity, 1, 16777216);
  check_uint("LightCullConfig::grid", grid, 1, 16);
  check_range("LightCullConfig::margin_ndc", margin_ndc, 1.0, 8.0);
  check_range("LightCullConfig::depth_bias", depth_bias, 0.0, 0.1);
  check_uint("LightCullConfig::max_lights", max_lights, 1, uint64_t(kMaxGroupsX) * kCullGroup);
  const auto q = static_cast<uint32_t>(pattern);
  if (q > 1) {
    throw Error(ErrorCode::invalid_argument, concat("LightCullConfig::pattern = ", q,
                                                    " is not an OcclusionPattern: accepted multi_jittered, regular"));
  }
}

struct LightCuller::Impl {
  const Context* context = nullptr;
  LightCullConfig config;
  uint32_t max_groups_x = kMaxGroupsX;
  uint32_t max_groups_y = kMaxGroupsX;
  // The dispatches of a cull (docs/OCCLUSION.md): cull + grid test, then the ordered compaction
  // (core/compaction.h): its two-level scan, finished by light_cull_scan.comp (indirect arguments,
  // statistics), and light_cull_scatter.comp (instances in light order).
  detail::ComputePipeline cull;
  detail::Compaction compact;
  // The whole cull in one workgroup of one_group_size invocations (light_cull.comp built with
  // GLINT_CULL_ONE_GROUP), which the count chooses up to one_group_lights lights
  // (detail::LightCullPath).
  detail::ComputePipeline one_group;
  // The same kernel with one invocation per light (specialization constant kShareSamples = 0), for
  // more than half as many lights as invocations (where each light would get one) and on CPU devices.
  detail::ComputePipeline one_group_per_light;
  // light_cull.comp built with GLINT_CULL_FROM_DEPTH too: a workgroup of depth_group_size per sample
  // reads its window from the depth image, the last to finish runs the one-workgroup cull
  // (needs_pyramid() == false). Its words (one per sample) and its count of finished workgroups,
  // which the kernel resets after each cull (cleared once, by the first record() that uses it).
  detail::ComputePipeline from_depth;
  uint32_t depth_group_size = 64;  // its workgroup (kDepthGroup or less; detail::LightCullAccess may change it)
  detail::OwnedBuffer sample_words;
  Buffer sample_words_state;
  detail::OwnedBuffer finished;
  Buffer finished_state;
  bool finished_cleared = false;
  uint32_t depth_samples = 0;  // words in sample_words
  uint32_t one_group_size = 64;
  uint32_t one_group_lights = 64;
  // Whether up to half as many lights as invocations share their samples (GPUs). CPU devices run a
  // workgroup's invocations one after another, so sharing only adds its barrier and atomics there
  // (lavapipe, 10 lights: 79 us per light, 119 us shared).
  bool share_samples = true;
  detail::LightCullPath path = detail::LightCullPath::device;
  // One vec4 record per light.
  detail::OwnedBuffer records;
  Buffer records_state;
  detail::OwnedBuffer dummy_results;  // bound when the caller wants no per-light results
  Buffer dummy_state;
};

LightCuller::LightCuller(const Context& context, const LightCullConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  Impl& m = *impl_;
  m.context = &context;
  m.config = config;
  // The group limit and the scan's workgroup size from the device (CONTRIBUTING.md, "Device limits").
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context.physical_device(), &props);
  m.max_groups_x = props.limits.maxComputeWorkGroupCount[0];
  m.max_groups_y = props.limits.maxComputeWorkGroupCount[1];
  const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
  const auto B = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  detail::PipelineDesc d;
  d.kernel_id = "light_cull_main";
  d.bindings = {S, S, B, B, B, B};
  d.push_constant_bytes = sizeof(GlintCullPush);
  d.workgroup = {kCullGroup, 1};
  m.cull = detail::ComputePipeline(context, d);
  // One workgroup of up to 1024 invocations (32 mask words in light_cull.comp); 64 on CPU devices,
  // where a larger workgroup runs on one core while the four-dispatch path spreads its workgroups.
  m.one_group_size =
      context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU
          ? kCullGroup
          : std::min({1024u, props.limits.maxComputeWorkGroupInvocations, props.limits.maxComputeWorkGroupSize[0]});
  // Up to kOneGroupSamples samples (lights x N^2): one multiprocessor then tests the lights faster
  // than the four dispatches launch and drain (docs/OCCLUSION.md, "One workgroup for few lights").
  m.one_group_lights = std::min(m.one_group_size, std::max(1u, kOneGroupSamples / (config.grid * config.grid)));
  m.share_samples = context.info().type != VK_PHYSICAL_DEVICE_TYPE_CPU;
  d.kernel_id = "light_cull_one_group";
  d.bindings = {S, S, B, B, B, B, B};
  d.workgroup = {m.one_group_size, 1};
  d.specialization = {1};
  m.one_group = detail::ComputePipeline(context, d);
  d.specialization = {0};
  m.one_group_per_light = detail::ComputePipeline(context, d);
  m.depth_group_size = std::min(kDepthGroup, m.one_group_size);
  m.from_depth = detail::ComputePipeline(context, from_depth_desc(m.depth_group_size));
  d.specialization = {};
  m.depth_samples =
      uint32_t(std::min<uint64_t>(uint64_t(config.max_lights) * config.grid * config.grid, kDepthSamples));
  m.sample_words =
      detail::OwnedBuffer(context, VkDeviceSize(m.depth_samples) * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  m.sample_words_state = view_of(m.sample_words, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const VkBufferUsageFlags counter_usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  m.finished = detail::OwnedBuffer(context, 16, counter_usage, false);
  m.finished_state = view_of(m.finished, counter_usage);
  detail::Compaction::Desc cd;
  cd.max_items = config.max_lights;
  cd.scan_kernel = "light_cull_scan_main";  // writes the indirect arguments and statistics
  cd.scan_outputs = 2;
  cd.scatter_kernel = "light_cull_scatter_main";  // reads lights and records; writes instances and results
  cd.scatter_groups = 1;                          // one workgroup per 64-light group
  cd.scatter_inputs = 2;
  cd.scatter_outputs = 2;
  m.compact = detail::Compaction(context, cd);
  m.records =
      detail::OwnedBuffer(context, VkDeviceSize(config.max_lights) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  m.records_state = view_of(m.records, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  m.dummy_results =
      detail::OwnedBuffer(context, sizeof(GlintFlareLightResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  m.dummy_state = view_of(m.dummy_results, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

LightCuller::LightCuller(LightCuller&&) noexcept = default;
LightCuller& LightCuller::operator=(LightCuller&&) noexcept = default;
LightCuller::~LightCuller() = default;

const LightCullConfig& LightCuller::config() const { return impl_->config; }

uint32_t LightCuller::max_groups_per_instance() const {
  const Impl& m = *impl_;
  // capacity x groups workgroups as rows of max_groups_x: at most max_groups_y rows, and the
  // scan's groups + max_groups_x - 1 must not wrap in 32 bits.
  const uint64_t total = std::min<uint64_t>(uint64_t(m.max_groups_x) * m.max_groups_y, (1ull << 32) - m.max_groups_x);
  return uint32_t(std::min<uint64_t>(65535, total / std::max(1u, m.config.capacity)));
}

uint32_t LightCuller::one_group_lights() const { return impl_->one_group_lights; }

bool LightCuller::needs_pyramid(const HiZPyramid& hiz, uint32_t count) const {
  const Impl& m = *impl_;
  if (m.path == detail::LightCullPath::depth) return false;
  if (m.path != detail::LightCullPath::device || count > m.one_group_lights) return true;
  // A pyramid of at most kDepthMaxLevels levels, so that a sample's window is a few thousand pixels
  // (at most 2x2 texels of 32x32 pixels inside the light, 3x3 on its border; a light larger than the
  // pyramid's cap up to GLINT_CULL_MAX_WINDOW_TEXELS texels): one round of fetches for a workgroup
  // of 256, where a deep pyramid's windows would have a few workgroups read most of the image.
  // Then the windows' pixels, estimated as 2x2 texels of level `levels` per sample (4^(levels + 1)),
  // against twice the pixels the pyramid's build reads: on an NVIDIA H200 at 1920x1080 with 5
  // levels the depth image won the flare frame at 10, 31 and 64 lights (27.1 / 59.5 / 74.1 us
  // against 33.4 / 64.7 / 78.5; the rule takes up to 63). No light: nothing to read.
  const uint32_t levels = hiz.levels();
  if (levels > kDepthMaxLevels) return true;
  const uint64_t n2 = uint64_t(m.config.grid) * m.config.grid;
  const uint64_t window = uint64_t(1) << (2 * (levels + 1));
  const VkExtent2D e = hiz.config().extent;
  return uint64_t(count) * n2 * window > 2 * uint64_t(e.width) * e.height;
}

void LightCuller::record(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, Buffer& lights, uint32_t count,
                         const LightCullFrame& frame, LightCullOutputs& out, Profiler* profiler) {
  detail::check_command_buffer("LightCuller::record", cmd);
  Impl& m = *impl_;
  const char* where = "LightCuller::record";
  const HiZConfig& hc = hiz.config();
  // Everything is checked before anything is recorded.
  check_uint("LightCuller::record: count", count, 0, m.config.max_lights);
  check_uint("LightCullFrame::vertex_count", frame.vertex_count, 0, 1 << 20);
  if (frame.groups_per_instance > max_groups_per_instance()) {
    throw Error(ErrorCode::invalid_argument,
                concat("LightCullFrame::groups_per_instance = ", frame.groups_per_instance,
                       " is out of range for LightCullConfig::capacity = ", m.config.capacity,
                       " on this device: accepted 0 to ", max_groups_per_instance(),
                       " (capacity x groups must fit maxComputeWorkGroupCount[0] x [1] = ", m.max_groups_x, " x ",
                       m.max_groups_y, ")"));
  }
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(frame.view_proj[i])) {
      throw Error(ErrorCode::invalid_argument,
                  concat("LightCullFrame::view_proj[", i, "] = ", frame.view_proj[i], " is not finite"));
    }
  }
  if (!depth.image || !depth.view)
    throw Error(ErrorCode::invalid_argument, concat(where, ": depth image or view is null"));
  detail::check_layers(depth, where, "depth");
  if (depth.format != hc.format || depth.extent.width != hc.extent.width || depth.extent.height != hc.extent.height) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": depth (", detail::format_name(depth.format), " ", depth.extent.width, "x",
                       depth.extent.height, ") does not match the Hi-Z pyramid (", detail::format_name(hc.format), " ",
                       hc.extent.width, "x", hc.extent.height, ")"));
  }
  if (!(depth.usage & VK_IMAGE_USAGE_SAMPLED_BIT)) {
    throw Error(ErrorCode::missing_usage, concat(where, ": depth image lacks VK_IMAGE_USAGE_SAMPLED_BIT usage"));
  }
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  detail::check_buffer(where, "lights", lights, VkDeviceSize(count) * sizeof(GlintFlareLight), storage);
  detail::check_buffer(where, "instances", out.instances, VkDeviceSize(m.config.capacity) * sizeof(GlintFlareInstance),
                       storage);
  detail::check_buffer(where, "indirect", out.indirect, sizeof(GlintFlareIndirect),
                       storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  detail::check_buffer(where, "stats", out.stats, sizeof(GlintFlareStats), storage);
  const bool want_results = out.results.buffer != VK_NULL_HANDLE;
  if (want_results) {
    detail::check_buffer(where, "results", out.results, VkDeviceSize(count) * sizeof(GlintFlareLightResult), storage);
  }
  Buffer& results = want_results ? out.results : m.dummy_state;

  const uint32_t flags = want_results ? GLINT_CULL_WRITE_RESULTS : 0u;
  GlintCullPush push{};
  std::copy(frame.view_proj, frame.view_proj + 16, push.view_proj);
  push.width = static_cast<int32_t>(hc.extent.width);
  push.height = static_cast<int32_t>(hc.extent.height);
  push.count = count;
  push.grid = m.config.grid;
  push.levels = hiz.levels();
  push.flags = (hc.reversed_z ? GLINT_CULL_REVERSED_Z : 0u) | flags |
               (m.config.pattern == OcclusionPattern::regular ? GLINT_CULL_REGULAR_GRID : 0u);
  push.margin_ndc = m.config.margin_ndc;
  push.depth_bias = m.config.depth_bias;
  const bool from_depth = !needs_pyramid(hiz, count);
  const uint64_t depth_groups = std::max<uint64_t>(1, uint64_t(count) * m.config.grid * m.config.grid);
  if (from_depth && depth_groups > m.depth_samples) {  // only where the path is forced (tests)
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": count = ", count, " is out of range for the depth-image cull: accepted 0 to ",
                       m.depth_samples / (m.config.grid * m.config.grid), " (", m.depth_samples,
                       " samples of N^2 = ", m.config.grid * m.config.grid, ")"));
  }
  detail::Barriers b;
  const bool one_group = m.path == detail::LightCullPath::one_group ||
                         m.path == detail::LightCullPath::one_group_shared_samples ||
                         ((m.path == detail::LightCullPath::device || m.path == detail::LightCullPath::pyramid) &&
                          count <= m.one_group_lights);
  // Every path's first dispatch reads the depth, the pyramid (the depth-image path binds the depth
  // in its place) and the lights (bindings 0 to 2).
  b.use(depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled);
  if (!from_depth) {
    b.use(hiz.image(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled, std::max(1u, hiz.levels()));
  }
  b.use(lights, kCompute, kStorageRead);
  const detail::Binding depth_binding{depth.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const detail::Bindings inputs{
      depth_binding,
      from_depth ? depth_binding : detail::Binding{hiz.image().view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, lights};
  if (from_depth || one_group) {
    // One dispatch writes the slots, instances, results, arguments and statistics: one workgroup,
    // or from the depth image a workgroup per sample, the last of which culls.
    if (from_depth && !m.finished_cleared) {  // once per object: the kernel resets the count after each cull
      detail::record_zero_fill(cmd, b, m.finished_state);
      m.finished_cleared = true;
    }
    b.use(out.instances, kCompute, kStorageWrite);
    b.use(results, kCompute, kStorageWrite);
    b.use(out.indirect, kCompute, kStorageWrite);
    b.use(out.stats, kCompute, kStorageWrite);
    if (from_depth) {
      b.use(m.sample_words_state, kCompute, kStorageRead | kStorageWrite);
      b.use(m.finished_state, kCompute, kStorageRead | kStorageWrite);
    }
    b.flush(cmd);
    push.capacity = m.config.capacity;
    push.vertex_count = frame.vertex_count;
    push.groups_per_instance = frame.groups_per_instance;
    push.max_group_count_x = m.max_groups_x;
    detail::Bindings set = inputs;
    for (const Buffer* o : {&out.instances, &results, &out.indirect, &out.stats}) set.push_back(*o);
    if (from_depth) {
      set.push_back(m.sample_words_state);
      set.push_back(m.finished_state);
      m.from_depth.dispatch(cmd, set, push, uint32_t(depth_groups) * m.depth_group_size, 1);
    } else {
      // At most half as many lights as invocations: on GPUs the lights share their samples over the
      // workgroup (at least two invocations each).
      const bool share = (m.share_samples || m.path == detail::LightCullPath::one_group_shared_samples) &&
                         m.one_group_size / std::max(count, 1u) >= 2;
      (share ? m.one_group : m.one_group_per_light).dispatch(cmd, set, push, m.one_group_size, 1);
    }
    if (profiler) profiler->mark(cmd, "light cull");
    return;
  }
  Buffer& groups_state = m.compact.groups();
  m.compact.record_clear_once(cmd, b);  // the scan kernel resets the counters every frame
  // 1. Cull + grid test: visibility masks and records, the other lights' results, the counters.
  b.use(m.records_state, kCompute, kStorageWrite);
  b.use(results, kCompute, kStorageWrite);
  b.use(groups_state, kCompute, kStorageRead | kStorageWrite);
  b.use(out.instances, kCompute, kStorageWrite);  // written by the scatter; here after the last frame's reads
  b.flush(cmd);
  if (count > 0) {
    detail::Bindings set = inputs;
    for (const Buffer* o : {&m.records_state, &results, &groups_state}) set.push_back(*o);
    m.cull.dispatch(cmd, set, push, count, 1);
  }
  if (profiler) profiler->mark(cmd, "light cull");
  // 2. Scan: the masks (and the counters' atomics) are complete; first slots, arguments, stats.
  GlintCullCompactPush lp{};
  lp.count = count;
  lp.capacity = m.config.capacity;
  lp.vertex_count = frame.vertex_count;
  lp.groups_per_instance = frame.groups_per_instance;
  lp.flags = flags;
  lp.max_group_count_x = m.max_groups_x;
  GlintCompactPush cp;
  static_assert(sizeof(cp) == sizeof(lp));
  std::memcpy(&cp, &lp, sizeof(cp));
  m.compact.record_scan(cmd, b, cp, {&out.indirect, &out.stats});
  if (profiler) profiler->mark(cmd, "cull scan");
  // 3. Scatter: instances in light order, the visible lights' results.
  m.compact.record_scatter(cmd, b, cp, {&lights, &m.records_state}, {&out.instances, &results});
  if (profiler) profiler->mark(cmd, "cull scatter");
}

namespace detail {

void LightCullAccess::select_path(LightCuller& culler, LightCullPath path) { culler.impl_->path = path; }

void LightCullAccess::set_depth_workgroup(LightCuller& culler, uint32_t size) {
  LightCuller::Impl& m = *culler.impl_;
  if (size < 32 || size > m.one_group_size || size % 32 != 0) {
    throw Error(ErrorCode::invalid_argument,
                concat("LightCullAccess::set_depth_workgroup: size = ", size,
                       " is out of range: accepted multiples of 32 from 32 to ", m.one_group_size));
  }
  if (size == m.depth_group_size) return;
  m.from_depth = detail::ComputePipeline(*m.context, from_depth_desc(size));
  m.depth_group_size = size;
}

}  // namespace detail

}  // namespace glint
