// Object occlusion cull: camera validation and reduction to the push-constant form, and the three
// dispatches of a cull (docs/OCCLUSION.md, "Object culling").
#include <glint/object_cull.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>
#include <vector>

#include "core/barriers.h"
#include "core/check.h"
#include "core/compaction.h"
#include "core/context_state.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "visibility/object_cull_internal.h"
#include "visibility/shaders/object_cull_params.h"
#include "visibility/visibility_util.h"

namespace glint {

using detail::concat;

static_assert(sizeof(GlintCullObject) == 32);
static_assert(offsetof(GlintCullObject, box_max) == 16);
static_assert(offsetof(GlintCullObject, kind) == 28);
static_assert(sizeof(GlintObjectCullPush) == 128);
static_assert(offsetof(GlintObjectCullPush, plane_len) == 112);
static_assert(offsetof(GlintObjectCullPush, proj_x) == 48);
static_assert(offsetof(GlintObjectCullPush, width) == 84);
static_assert(offsetof(GlintObjectCullPush, groups_x) == 104);
static_assert(sizeof(GlintObjectCompactPush) == sizeof(GlintCompactPush));
static_assert(offsetof(GlintObjectCompactPush, tile_groups) == offsetof(GlintCompactPush, tile_groups));
static_assert(offsetof(GlintObjectCompactPush, groups_x) == offsetof(GlintCompactPush, groups_x));
static_assert(offsetof(GlintObjectCompactPush, payload_words) == offsetof(GlintCompactPush, step));
static_assert(sizeof(GlintObjectCullIndirect) == 16);
static_assert(sizeof(GlintObjectCullStats) == 32);
static_assert(GLINT_OBJECT_GROUP == 64, "object_cull.comp keeps a workgroup's mask in two 32-bit words");

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kSampled = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
constexpr VkAccessFlags2 kRead = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
constexpr VkAccessFlags2 kWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr uint32_t kGroup = GLINT_OBJECT_GROUP;
constexpr uint32_t kMaxObjects = 1u << 28;

using detail::check_buffer;
using visibility_detail::check_uint;
using visibility_detail::view_of;

// Rounds a positive double up to a float.
float round_up(double v) {
  float f = static_cast<float>(v);
  if (double(f) < v) f = std::nextafter(f, FLT_MAX);
  return f;
}

// The camera part of the push constants. Matrices are column-major: entry (row r, column c) at
// c * 4 + r. Throws Error naming the entry that breaks the accepted form.
void camera_push(const ObjectCullFrame& frame, bool reversed_z, GlintObjectCullPush& push) {
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(frame.view[i]))
      throw Error(ErrorCode::invalid_argument,
                  concat("ObjectCullFrame::view[", i, "] = ", frame.view[i], " is not finite"));
    if (!std::isfinite(frame.proj[i]))
      throw Error(ErrorCode::invalid_argument,
                  concat("ObjectCullFrame::proj[", i, "] = ", frame.proj[i], " is not finite"));
  }
  const float* v = frame.view;
  const int affine[4] = {3, 7, 11, 15};
  for (int k = 0; k < 4; ++k) {
    const float want = k == 3 ? 1.0f : 0.0f;
    if (v[affine[k]] != want) {
      throw Error(ErrorCode::invalid_argument,
                  concat("ObjectCullFrame::view[", affine[k], "] = ", v[affine[k]], " must be ", want,
                         ": the view matrix must be affine (row 3 = 0 0 0 1)"));
    }
  }
  const float* p = frame.proj;
  for (int i : {1, 2, 3, 4, 6, 7, 12, 13, 15}) {
    if (p[i] != 0.0f) {
      throw Error(ErrorCode::invalid_argument,
                  concat("ObjectCullFrame::proj[", i, "] = ", p[i],
                         " must be 0: a Vulkan perspective projection has only P00, P11, P02, P12, P22, P23, P32"));
    }
  }
  if (p[11] != 1.0f && p[11] != -1.0f) {
    throw Error(ErrorCode::invalid_argument,
                concat("ObjectCullFrame::proj[11] = ", p[11], " (P32) must be -1 or 1 (w = -z_view or z_view)"));
  }
  if (p[0] == 0.0f || p[5] == 0.0f) {
    throw Error(ErrorCode::invalid_argument,
                concat("ObjectCullFrame::proj[", p[0] == 0.0f ? 0 : 5, "] = 0: P00 and P11 must be non-zero"));
  }
  const double s = p[11];
  for (int c = 0; c < 4; ++c) {
    push.view_x[c] = v[c * 4 + 0];
    push.view_y[c] = v[c * 4 + 1];
    push.view_w[c] = static_cast<float>(s * v[c * 4 + 2]);  // exact: s = +-1
  }
  push.proj_x = p[0];
  push.proj_ox = static_cast<float>(double(p[8]) * s);
  push.proj_y = p[5];
  push.proj_oy = static_cast<float>(double(p[9]) * s);
  // The side planes' normal lengths |(s, 1 + o)| and |(-s, 1 - o)| per axis, exact in double then
  // rounded up: never below the fp32 values the test used to compute.
  const double ax[2][2] = {{push.proj_x, push.proj_ox}, {push.proj_y, push.proj_oy}};
  for (int k = 0; k < 2; ++k) {
    const double sk = ax[k][0], ok = ax[k][1];
    push.plane_len[2 * k] = round_up(std::sqrt(sk * sk + (1.0 + ok) * (1.0 + ok)));
    push.plane_len[2 * k + 1] = round_up(std::sqrt(sk * sk + (1.0 - ok) * (1.0 - ok)));
  }
  const double a = double(p[10]) * s, b = p[14];
  push.depth_a = static_cast<float>(a);
  push.depth_b = p[14];
  // depth = a + b / w: the near plane is where depth is 0 (standard) or 1 (reversed), the far
  // plane where it is 1 (standard) or 0 (reversed); no positive solution: infinitely far.
  if (reversed_z ? !(b > 0) : !(b < 0)) {
    throw Error(ErrorCode::invalid_argument,
                concat("ObjectCullFrame::proj[14] = ", b, " (P23) must be ", reversed_z ? "> 0" : "< 0", " for ",
                       reversed_z ? "reversed" : "standard", " Z (ObjectCullConfig::reversed_z)"));
  }
  const double near_w = reversed_z ? b / (1.0 - a) : -b / a;
  const double far_w = reversed_z ? -b / a : b / (1.0 - a);
  if (!(near_w > 0) || !std::isfinite(near_w) || !(float(near_w) > 0.0f)) {
    throw Error(ErrorCode::invalid_argument, concat("ObjectCullFrame::proj: the near plane is at w = ", near_w,
                                                    "; it must lie in front of the camera (w > 0)"));
  }
  const bool far_finite = far_w > 0 && std::isfinite(far_w) && far_w < double(FLT_MAX);
  if (far_finite && !(far_w > near_w)) {
    throw Error(ErrorCode::invalid_argument, concat("ObjectCullFrame::proj: the far plane (w = ", far_w,
                                                    ") is not beyond the near plane (w = ", near_w, ")"));
  }
  push.near_w = static_cast<float>(near_w);
  push.far_w = far_finite ? static_cast<float>(far_w) : FLT_MAX;
  // A view-space radius bound: an affine view maps a ball of radius r into a ball of radius
  // r * sigma_max of its 3x3 part V. sigma_max^2 = lambda_max(V^T V) is at most the largest row sum
  // of |V^T V| (Gershgorin), which is exact for rotations and uniform scales, and at most the
  // squared Frobenius norm; the smaller bound is used, rounded up.
  double frob = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) frob += double(v[c * 4 + r]) * v[c * 4 + r];
  double g = 0;
  for (int i = 0; i < 3; ++i) {
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k) d += double(v[i * 4 + k]) * v[j * 4 + k];
      row += std::abs(d);
    }
    g = std::max(g, row);
  }
  const double spectral_bound = std::min(std::sqrt(frob), std::sqrt(g));
  push.radius_scale = round_up(spectral_bound * (1.0 + 1e-12));
}

}  // namespace

void ObjectCullConfig::validate() const {
  check_uint("ObjectCullConfig::max_objects", max_objects, 1, kMaxObjects);
  check_uint("ObjectCullConfig::capacity", capacity, 1, kMaxObjects);
  check_uint("ObjectCullConfig::payload_words", payload_words, 0, 64);
  check_uint("ObjectCullConfig::objects_per_group", objects_per_group, 1, 1024);
}

struct ObjectCuller::Impl {
  const Context* context = nullptr;
  ObjectCullConfig config;
  uint64_t max_range = 1u << 27;  // the device's maxStorageBufferRange
  uint32_t max_groups_x = 65535;  // the device's maxComputeWorkGroupCount[0]
  // The test kernel of each mode: cull (single phase and phase 2) and phase1, the subgroup variants
  // where the device supports them; cull_atomic / phase1_atomic count with shared atomics alone.
  detail::ComputePipeline cull, phase1, cull_atomic, phase1_atomic;
  // The previous single-phase test kernel (object_cull_v1.comp), made on first use by
  // detail::object_cull_select_kernel (benchmarks time it against `cull`).
  detail::ComputePipeline cull_v1;
  bool subgroup = false;
  // Invocations per workgroup of object_cull.comp: 128 (two groups of 64 objects, sorted by kind
  // for the test), which Vulkan guarantees; 256 on CPU devices. On the H100 128 beat 256 (1 M
  // objects 41.6 against 44.0 us, 10 M 295.8 against 317.4 us: more workgroups fit its registers)
  // and 64 (46 us on the mixed scene; docs/OCCLUSION.md, "Cost"). The previous kernel keeps one
  // group per workgroup.
  uint32_t test_threads = kGroup;
  detail::ObjectCullKernel kernel = detail::ObjectCullKernel::current;
  // The ordered compaction of the emitted objects (core/compaction.h): its group buffer holds the
  // test's masks and packed counts; object_cull_scan.comp scans each tile (`scan`: its subgroup
  // variant where the device supports it; `scan_hook`: the variant a test kernel selected by
  // detail::object_cull_select_kernel runs with, when it is not `scan`), object_cull_scatter.comp
  // writes the payloads, the arguments and the statistics.
  detail::Compaction compact;
  detail::ComputePipeline scan, scan_hook;
  detail::OwnedBuffer dummy;
  Buffer dummy_state;
  // Each tile's counts of the four states (object_cull_scan.comp writes them every cull, the
  // scatter's workgroup 0 sums them): nothing is carried from one cull to the next.
  detail::OwnedBuffer tile_counts;
  Buffer tile_counts_state;

  void check_common(const char* where, const ObjectCullFrame& frame, ObjectCullBuffers& in, ObjectCullOutputs& out,
                    GlintObjectCullPush& push) const {
    check_uint(concat(where, ": ObjectCullFrame::count").c_str(), frame.count, 0, config.max_objects);
    camera_push(frame, config.reversed_z, push);
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    const VkDeviceSize n = std::max<VkDeviceSize>(1, frame.count);
    check_buffer(where, "objects", in.objects, n * sizeof(GlintCullObject), st);
    if (config.payload_words > 0) check_buffer(where, "payloads", in.payloads, n * config.payload_words * 4, st);
    check_buffer(where, "visibility", in.visibility, n * 4, st);
    check_buffer(where, "list", out.list, VkDeviceSize(config.capacity) * std::max(1u, config.payload_words) * 4, st);
    check_buffer(where, "indirect", out.indirect, sizeof(GlintObjectCullIndirect),
                 st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    check_buffer(where, "stats", out.stats, sizeof(GlintObjectCullStats), st);
    // Storage descriptors bind each buffer's whole range, which the device limits.
    const std::pair<const char*, const Buffer*> bound[] = {{"objects", &in.objects},       {"payloads", &in.payloads},
                                                           {"visibility", &in.visibility}, {"list", &out.list},
                                                           {"indirect", &out.indirect},    {"stats", &out.stats}};
    for (const auto& [role, b] : bound) {
      if (b == &in.payloads && config.payload_words == 0) continue;
      if (b->size > max_range) {
        throw Error(ErrorCode::invalid_argument, concat(where, ": ", role, " buffer size = ", b->size,
                                                        " bytes is above the device's maxStorageBufferRange = ",
                                                        max_range, "; pass a smaller range"));
      }
    }
  }

  void check_images(const char* where, HiZPyramid& hiz, Image& depth) const {
    const HiZConfig& hc = hiz.config();
    if (hc.reversed_z != config.reversed_z) {
      throw Error(ErrorCode::invalid_argument,
                  concat(where, ": HiZConfig::reversed_z = ", hc.reversed_z,
                         " differs from ObjectCullConfig::reversed_z = ", config.reversed_z));
    }
    if (!depth.image || !depth.view)
      throw Error(ErrorCode::invalid_argument, concat(where, ": depth image or view is null"));
    if (depth.format != hc.format || depth.extent.width != hc.extent.width || depth.extent.height != hc.extent.height) {
      throw Error(ErrorCode::invalid_argument,
                  concat(where, ": depth (", detail::format_name(depth.format), " ", depth.extent.width, "x",
                         depth.extent.height, ") does not match the Hi-Z pyramid (", detail::format_name(hc.format),
                         " ", hc.extent.width, "x", hc.extent.height, ")"));
    }
    if (!(depth.usage & VK_IMAGE_USAGE_SAMPLED_BIT))
      throw Error(ErrorCode::missing_usage, concat(where, ": depth image lacks VK_IMAGE_USAGE_SAMPLED_BIT usage"));
  }

  // A tile-scan pipeline (object_cull_scan.comp variant `kernel_id`): group buffer and tile counts,
  // one workgroup of compact.tile_groups() invocations per tile.
  detail::ComputePipeline make_scan(const char* kernel_id) const {
    detail::PipelineDesc d;
    d.kernel_id = kernel_id;
    d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    d.push_constant_bytes = sizeof(GlintObjectCompactPush);
    d.workgroup = {compact.tile_groups(), 1};
    return detail::ComputePipeline(*context, d);
  }

  void run(VkCommandBuffer cmd, HiZPyramid* hiz, Image* depth, uint32_t mode, GlintObjectCullPush push, uint32_t count,
           ObjectCullBuffers& in, ObjectCullOutputs& out, Profiler* profiler);
};

ObjectCuller::ObjectCuller(const Context& context, const ObjectCullConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  Impl& m = *impl_;
  m.context = &context;
  m.config = config;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context.physical_device(), &props);
  m.max_range = props.limits.maxStorageBufferRange;
  // The objects, payload and list buffers are each one storage descriptor (limits come from the
  // device): their largest sizes must fit maxStorageBufferRange (2^27 bytes guaranteed, 4 M objects).
  const uint64_t object_bytes = uint64_t(config.max_objects) * sizeof(GlintCullObject);
  const uint64_t payload_bytes = uint64_t(config.max_objects) * config.payload_words * 4;
  const uint64_t list_bytes = uint64_t(config.capacity) * std::max(1u, config.payload_words) * 4;
  if (object_bytes > m.max_range || payload_bytes > m.max_range) {
    throw Error(ErrorCode::unsupported_size,
                concat("ObjectCullConfig::max_objects = ", config.max_objects, " needs ",
                       std::max(object_bytes, payload_bytes), "-byte object/payload buffers; the device's ",
                       "maxStorageBufferRange = ", m.max_range, " allows at most ",
                       m.max_range / std::max<uint64_t>(sizeof(GlintCullObject), uint64_t(config.payload_words) * 4),
                       " objects"));
  }
  if (list_bytes > m.max_range) {
    throw Error(ErrorCode::unsupported_size,
                concat("ObjectCullConfig::capacity = ", config.capacity, " x max(1, payload_words) x 4 = ", list_bytes,
                       " bytes exceeds the device's maxStorageBufferRange = ", m.max_range));
  }
  const uint64_t groups = (uint64_t(config.max_objects) + kGroup - 1) / kGroup;
  m.max_groups_x = props.limits.maxComputeWorkGroupCount[0];
  if ((groups + m.max_groups_x - 1) / m.max_groups_x > props.limits.maxComputeWorkGroupCount[1]) {
    throw Error(ErrorCode::invalid_argument,
                concat("ObjectCullConfig::max_objects = ", config.max_objects,
                       " needs more workgroups than the device's maxComputeWorkGroupCount allows"));
  }
  // 128 invocations (every Vulkan device allows them); 256 on CPU devices (lavapipe), where larger
  // workgroups measured faster (1 M objects: about 10 % on 2 cores) and no register file limits them.
  m.test_threads =
      context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU &&
              std::min(props.limits.maxComputeWorkGroupInvocations, props.limits.maxComputeWorkGroupSize[0]) >= 256
          ? 256
          : 128;
  const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
  const auto B = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  detail::PipelineDesc d;
  // The subgroup variants reduce the per-group counts with subgroupOr / subgroupAdd / subgroupElect
  // (Vulkan 1.1 guarantees only the basic operations in compute; arithmetic is checked).
  VkPhysicalDeviceSubgroupProperties sub{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &sub;
  vkGetPhysicalDeviceProperties2(context.physical_device(), &props2);
  const VkSubgroupFeatureFlags need =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
  m.subgroup = (sub.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 && (sub.supportedOperations & need) == need;
  d.kernel_id = m.subgroup ? "object_cull_main_subgroup" : "object_cull_main";
  d.bindings = {S, S, B, B, B};
  d.push_constant_bytes = sizeof(GlintObjectCullPush);
  d.workgroup = {m.test_threads, 1};
  m.cull = detail::ComputePipeline(context, d);
  d.kernel_id = m.subgroup ? "object_cull_phase1_subgroup" : "object_cull_phase1";
  d.bindings = {B, B, B};
  m.phase1 = detail::ComputePipeline(context, d);
  detail::Compaction::Desc cd;
  cd.max_items = config.max_objects;
  cd.scatter_kernel = "object_cull_scatter_main";  // reads payloads and tile counts; writes the
  cd.scatter_inputs = 2;                           // list, the arguments and the statistics
  cd.scatter_outputs = 3;
  m.compact = detail::Compaction(context, cd);  // no top-level scan: this records its tile scan
  m.scan = m.make_scan(m.subgroup ? "object_cull_scan_main_subgroup" : "object_cull_scan_main");
  const uint64_t tiles = (groups + m.compact.tile_groups() - 1) / m.compact.tile_groups();
  m.tile_counts =
      detail::OwnedBuffer(context, std::max<uint64_t>(1, tiles) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  m.tile_counts_state = view_of(m.tile_counts, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  m.dummy = detail::OwnedBuffer(context, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  m.dummy_state = view_of(m.dummy, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

ObjectCuller::ObjectCuller(ObjectCuller&&) noexcept = default;
ObjectCuller& ObjectCuller::operator=(ObjectCuller&&) noexcept = default;
ObjectCuller::~ObjectCuller() = default;

const ObjectCullConfig& ObjectCuller::config() const { return impl_->config; }

uint64_t ObjectCuller::min_bytes_moved(uint32_t count, uint32_t written) const {
  const uint64_t groups = (uint64_t(count) + kGroup - 1) / kGroup;
  const uint64_t words = std::max(1u, impl_->config.payload_words);
  // Objects read, states written (4 + 4 bytes each); the group words written by the test, read
  // and written by the tile scan, read by the scatter; payloads read and written.
  return uint64_t(count) * (sizeof(GlintCullObject) + 8) + groups * 16 * 3 + uint64_t(written) * words * 4 * 2;
}

void ObjectCuller::Impl::run(VkCommandBuffer cmd, HiZPyramid* hiz, Image* depth, uint32_t mode,
                             GlintObjectCullPush push, uint32_t count, ObjectCullBuffers& in, ObjectCullOutputs& out,
                             Profiler* profiler) {
  Buffer& payloads = config.payload_words > 0 ? in.payloads : dummy_state;
  Buffer& groups_state = compact.groups();
  const bool images = mode != GLINT_OBJECT_MODE_PHASE1;
  using detail::ObjectCullKernel;
  const bool atomic = kernel == ObjectCullKernel::shared_atomics;
  const bool v1 = kernel == ObjectCullKernel::previous && mode == GLINT_OBJECT_MODE_SINGLE;
  // The test's descriptors: depth and Hi-Z (not in phase 1), objects, visibility, group records.
  detail::Bindings test;
  if (images) {
    test.push_back({depth->view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    test.push_back({hiz->image().view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  }
  test.push_back(in.objects);
  test.push_back(in.visibility);
  test.push_back(groups_state);

  detail::Barriers b;
  // The test's workgroups (test_threads objects each; the previous kernel's one group each) as a 2D
  // grid of at most maxComputeWorkGroupCount[0] per row.
  const uint32_t threads = v1 ? kGroup : test_threads;
  const uint32_t workgroups = std::max(1u, (count + threads - 1) / threads);
  const uint32_t gx = std::min(workgroups, max_groups_x), gy = (workgroups + gx - 1) / gx;
  // 1. Test: masks, counts, states.
  if (images) {
    b.use(*depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled);
    b.use(hiz->image(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kSampled, std::max(1u, hiz->levels()));
  }
  b.use(in.objects, kCompute, kRead);
  b.use(in.visibility, kCompute, images ? (kRead | kWrite) : kRead);
  b.use(groups_state, kCompute, kRead | kWrite);
  b.flush(cmd);
  if (count > 0) {
    push.count = count;
    push.flags = mode | (config.reversed_z ? GLINT_OBJECT_REVERSED_Z : 0u);
    push.groups_x = gx;
    push.tile_groups = compact.tile_groups();
    if (images) {
      push.width = static_cast<int32_t>(hiz->config().extent.width);
      push.height = static_cast<int32_t>(hiz->config().extent.height);
      push.levels = hiz->levels();
    }
    const detail::ComputePipeline& test_pipeline = !images  ? (atomic ? phase1_atomic : phase1)
                                                   : v1     ? cull_v1
                                                   : atomic ? cull_atomic
                                                            : cull;
    test_pipeline.dispatch(cmd, test, push, gx * threads, gy);
  }
  if (profiler) profiler->mark(cmd, "object cull");
  GlintObjectCompactPush op{};
  op.count = count;
  op.capacity = config.capacity;
  op.payload_words = config.payload_words;
  op.objects_per_group = config.objects_per_group;
  GlintCompactPush cp;
  static_assert(sizeof(cp) == sizeof(op));
  std::memcpy(&cp, &op, sizeof(cp));
  // 2. Scan: each tile's slots, total and counts (one workgroup per tile).
  const uint32_t tile_groups = compact.tile_groups();
  const uint32_t tiles = ((count + kGroup - 1) / kGroup + tile_groups - 1) / tile_groups;
  if (tiles > 0) {
    b.use(groups_state, kCompute, kRead | kWrite);
    b.use(tile_counts_state, kCompute, kWrite);
    b.flush(cmd);
    op.tile_groups = tile_groups;
    (scan_hook ? scan_hook : scan).dispatch(cmd, {groups_state, tile_counts_state}, op, tiles * tile_groups, 1);
  }
  if (profiler) profiler->mark(cmd, "object cull scan");
  // 3. Scatter: payloads in object order (each workgroup adds the earlier tiles' totals); the
  //    arguments and statistics.
  compact.record_scatter(cmd, b, cp, {&payloads, &tile_counts_state}, {&out.list, &out.indirect, &out.stats});
  if (profiler) profiler->mark(cmd, "object cull scatter");
}

void ObjectCuller::record(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, const ObjectCullFrame& frame,
                          ObjectCullBuffers& buffers, ObjectCullOutputs& outputs, Profiler* profiler) {
  Impl& m = *impl_;
  GlintObjectCullPush push{};
  m.check_common("ObjectCuller::record", frame, buffers, outputs, push);
  m.check_images("ObjectCuller::record", hiz, depth);
  m.run(cmd, &hiz, &depth, GLINT_OBJECT_MODE_SINGLE, push, frame.count, buffers, outputs, profiler);
}

void ObjectCuller::record_phase1(VkCommandBuffer cmd, const ObjectCullFrame& frame, ObjectCullBuffers& buffers,
                                 ObjectCullOutputs& outputs, Profiler* profiler) {
  Impl& m = *impl_;
  GlintObjectCullPush push{};
  m.check_common("ObjectCuller::record_phase1", frame, buffers, outputs, push);
  m.run(cmd, nullptr, nullptr, GLINT_OBJECT_MODE_PHASE1, push, frame.count, buffers, outputs, profiler);
}

void ObjectCuller::record_phase2(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, const ObjectCullFrame& frame,
                                 ObjectCullBuffers& buffers, ObjectCullOutputs& outputs, Profiler* profiler) {
  Impl& m = *impl_;
  GlintObjectCullPush push{};
  m.check_common("ObjectCuller::record_phase2", frame, buffers, outputs, push);
  m.check_images("ObjectCuller::record_phase2", hiz, depth);
  m.run(cmd, &hiz, &depth, GLINT_OBJECT_MODE_PHASE2, push, frame.count, buffers, outputs, profiler);
}

void ObjectCuller::record_clear_history(VkCommandBuffer cmd, Buffer& visibility, uint32_t count) {
  const char* where = "ObjectCuller::record_clear_history";
  check_uint(concat(where, ": count").c_str(), count, 0, impl_->config.max_objects);
  check_buffer(where, "visibility", visibility, std::max<VkDeviceSize>(4, VkDeviceSize(count) * 4),
               VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  if (count == 0) return;
  detail::Barriers b;
  detail::record_zero_fill(cmd, b, visibility, VkDeviceSize(count) * 4);
}

namespace detail {

struct ObjectCullerAccess {
  static ObjectCuller::Impl& impl(ObjectCuller& c) { return *c.impl_; }
  static const ObjectCuller::Impl& impl(const ObjectCuller& c) { return *c.impl_; }
};

void object_cull_select_kernel(ObjectCuller& culler, ObjectCullKernel kernel) {
  ObjectCuller::Impl& m = ObjectCullerAccess::impl(culler);
  const auto S = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
  const auto B = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  PipelineDesc d;
  d.push_constant_bytes = sizeof(GlintObjectCullPush);
  d.workgroup = {kGroup, 1};
  if (kernel == ObjectCullKernel::previous && !m.cull_v1) {
    d.kernel_id = "object_cull_v1_main";
    d.bindings = {S, S, B, B, B};
    m.cull_v1 = ComputePipeline(*m.context, d);
  }
  d.workgroup = {m.test_threads, 1};
  if (kernel == ObjectCullKernel::shared_atomics && !m.cull_atomic) {
    d.kernel_id = "object_cull_main";
    d.bindings = {S, S, B, B, B};
    m.cull_atomic = ComputePipeline(*m.context, d);
    d.kernel_id = "object_cull_phase1";
    d.bindings = {B, B, B};
    m.phase1_atomic = ComputePipeline(*m.context, d);
  }
  // The tile scan the selection runs with: the shared-memory one with the shared-atomic kernels,
  // the subgroup one forced onto its serial or partial-subgroup path for those hooks (where the
  // device has the subgroup variants), else `scan`.
  const char* hook = kernel == ObjectCullKernel::shared_atomics               ? "object_cull_scan_main"
                     : kernel == ObjectCullKernel::serial_scan && m.subgroup  ? "object_cull_scan_main_serial"
                     : kernel == ObjectCullKernel::partial_scan && m.subgroup ? "object_cull_scan_main_partial"
                                                                              : nullptr;
  m.scan_hook = hook ? m.make_scan(hook) : ComputePipeline{};
  m.kernel = kernel;
}

bool object_cull_has_subgroup_variant(const ObjectCuller& culler) { return ObjectCullerAccess::impl(culler).subgroup; }

}  // namespace detail
}  // namespace glint
