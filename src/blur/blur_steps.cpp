// The blur step machinery (blur_steps.h): tile shapes, caller-image checks, step programs and the
// steps both drivers plan.
#include "blur/blur_steps.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/formats.h"

namespace glint::blur_steps {

using blur_plan::kFusedMaxRadius;  // one constant for the planner and the driver
using detail::concat;

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kSampled = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
constexpr VkAccessFlags2 kStorageWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

// Shared memory of src/blur/shaders/blur_level.comp: the loaded tile + apron and the horizontal pass's
// rows, 16 bytes a texel (8 packed as fp16).
uint32_t fused_shared_bytes(FusedShape s, uint32_t radius, bool half_shared) {
  const uint32_t w = s.workgroup.x, h = s.workgroup.y * s.rows;
  const auto padded = [](uint32_t n) { return n + (17 - n % 16) % 16; };  // LOAD_S, ROW_S
  return (half_shared ? 8 : 16) * (padded(w + 2 * radius) * (h + 2 * radius) + padded(w) * (h + 2 * radius));
}

// Shared memory of src/blur/shaders/blur_stream.comp: a step's source rows (two values a texel for
// the 2:1 mean, mode 1: HALVES) and the ring of STEP + 2 RADIUS filtered rows, each row skewed by
// one element every 2^SKEW (16 elements of 8 bytes in fp16, 8 of 16 in fp32), plus the unused
// arrays' one element each (two fp32 elements of 16 bytes with fp16 copies, two packed ones of 8
// with fp32 copies).
uint32_t stream_shared_bytes(detail::Workgroup2D wg, uint32_t radius, bool half_shared, bool split_mean) {
  const uint32_t strip = 4 * wg.x, step = wg.y, skew = half_shared ? 4 : 3;
  const uint32_t load_w = (strip + 2 * radius) * (split_mean ? 2 : 1);
  const uint32_t load_s = load_w + ((load_w - 1) >> skew), row_s = strip + ((strip - 1) >> skew);
  return (half_shared ? 8 : 16) * (load_s * step + row_s * (step + 2 * radius)) + (half_shared ? 32 : 16);
}

// The first shape of `gpu` (of `cpu` on CPU devices) whose invocations and shared memory
// (`shared_bytes(shape)`) fit the device (CONTRIBUTING.md, "Device limits"): larger tiles first.
// Throws Error(no_device) naming `what` and the smallest shape's need when none fits.
template <typename Bytes>
FusedShape first_fitting(const DeviceInfo& info, std::initializer_list<FusedShape> gpu,
                         std::initializer_list<FusedShape> cpu, Bytes shared_bytes, const std::string& what) {
  const std::initializer_list<FusedShape>& list = info.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? cpu : gpu;
  for (const FusedShape& s : list) {
    if (s.workgroup.x * s.workgroup.y <= info.max_workgroup_invocations &&
        shared_bytes(s) <= info.max_shared_memory_bytes) {
      return s;
    }
  }
  throw Error(ErrorCode::no_device,
              concat(what, " needs ", shared_bytes(*(list.end() - 1)), " bytes of shared memory; device '", info.name,
                     "' has ", info.max_shared_memory_bytes));
}

}  // namespace

VkFormat precision_format(Precision p) {
  return p == Precision::fp32 ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
}

FusedShape fused_shape(const DeviceInfo& info, uint32_t radius, bool half_shared) {
  // CPU widths are multiples of 4 (RUN).
  return first_fitting(
      info, {{{32, 8}, 4}, {{32, 8}, 2}, {{32, 8}, 1}, {{16, 8}, 2}, {{16, 8}, 1}, {{8, 8}, 1}},
      {{{16, 8}, 1}, {{8, 8}, 1}}, [&](FusedShape s) { return fused_shared_bytes(s, radius, half_shared); },
      concat("blur radius ", radius));
}

bool stream_shape(const DeviceInfo& info, uint32_t radius, bool half_shared, bool split_mean,
                  detail::Workgroup2D& workgroup) {
  // Strips of 64 columns walked 8 rows a step (128 invocations), then shorter and narrower ones for
  // large radii in fp32. Of the shapes measured on the H100 this one was the fastest (docs/BLUR.md
  // "Streamed separable").
  for (detail::Workgroup2D wg : {detail::Workgroup2D{16, 8}, {16, 4}, {8, 4}}) {
    if (wg.x * wg.y <= info.max_workgroup_invocations &&
        stream_shared_bytes(wg, radius, half_shared, split_mean) <= info.max_shared_memory_bytes) {
      workgroup = wg;
      return true;
    }
  }
  return false;
}

bool stream_fills_device(const DeviceInfo& info, VkExtent2D size, uint32_t strip_width) {
  if (info.type == VK_PHYSICAL_DEVICE_TYPE_CPU) return true;
  const uint64_t strips = (uint64_t(size.width) + strip_width - 1) / strip_width;
  const uint32_t band = stream_band_rows(size.width, size.height, strip_width);
  return strips * ((size.height + band - 1) / band) >= kStreamMinGroups;
}

uint32_t stream_band_rows(uint32_t width, uint32_t height, uint32_t strip_width) {
  const uint64_t strips = (uint64_t(width) + strip_width - 1) / strip_width;
  const uint64_t bands = std::max<uint64_t>(1, (kStreamGroups + strips - 1) / strips);
  const uint64_t rows = (height + bands - 1) / bands;
  return static_cast<uint32_t>(std::min<uint64_t>(height, std::max<uint64_t>(rows, kStreamMinBand)));
}

float max_value_for(VkFormat a, VkFormat b) {
  return std::min({detail::format_max(a), detail::format_max(b), 1.0e37f});
}

std::string store_variant(VkFormat format) {
  const char* q = detail::qualified_variant(format);
  return q ? q : "noformat";
}

void check_image(const Context& context, const Image& img, const char* where, const char* role, VkImageUsageFlags need,
                 const char* need_name) {
  if (!img.image || !img.view)
    throw Error(ErrorCode::invalid_argument, concat(where, ": ", role, " image and view must be non-null"));
  detail::check_layers(img, where, role);
  if (need & VK_IMAGE_USAGE_STORAGE_BIT) {
    detail::check_color_write(context, img.format, where, role);
  } else {
    detail::check_color_read(context, img.format, where, role);
  }
  detail::check_extent(context, img.extent, where, role);
  if ((img.usage & need) != need)
    throw Error(ErrorCode::missing_usage, concat(where, ": ", role, " image lacks ", need_name, " usage"));
}

const detail::ComputePipeline& StepProgram::pipeline(const std::string& kernel, VkFormat dst_format,
                                                     detail::Workgroup2D wg, std::vector<uint32_t> spec,
                                                     std::vector<VkDescriptorType> bindings) {
  std::string key = concat(kernel, "_", store_variant(dst_format), "/", wg.x, "x", wg.y);
  for (uint32_t v : spec) key += concat("/", v);
  auto it = pipelines->find(key);
  if (it != pipelines->end()) return it->second;
  detail::PipelineDesc d;
  d.kernel_id = concat(kernel, "_", store_variant(dst_format));
  d.bindings = std::move(bindings);
  d.push_constant_bytes = sizeof(BlurPush);
  d.workgroup = wg;
  d.specialization = std::move(spec);
  return pipelines->emplace(key, detail::ComputePipeline(*context, d)).first->second;
}

bool down_shuffles_supported(const Context& context) {
  const detail::ContextState& s = context.state();  // read once by fill_info()
  if (s.min_subgroup_size < 2 || s.max_subgroup_size > 64) return false;
  // Broadcast is in the ballot set (the Vulkan spec, VkSubgroupFeatureFlagBits).
  const VkSubgroupFeatureFlags need =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
  return (s.compute_subgroup_operations & need) == need;
}

uint32_t StepProgram::gpu_order_steps() const {
  return static_cast<uint32_t>(std::count_if(steps.begin(), steps.end(), [](const Step& s) { return s.gpu_order; }));
}

bool gpu_order(const DeviceInfo& info, SeparableKernel kernel) {
  return kernel == SeparableKernel::gpu_order ||
         (kernel == SeparableKernel::device && detail::copy_order_by_default(info));
}

uint32_t StepProgram::streamed_steps() const {
  return static_cast<uint32_t>(std::count_if(steps.begin(), steps.end(), [](const Step& s) { return s.streamed; }));
}

int StepProgram::add_image(VkExtent2D e, VkFormat f) {
  images.emplace_back(*context, e, f,
                      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  return static_cast<int>(images.size()) - 1;
}

const detail::OwnedBuffer* StepProgram::add_taps(const std::vector<float>& values) {
  tap_buffers.emplace_back(*context, values.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  std::memcpy(tap_buffers.back().mapped(), values.data(), values.size() * sizeof(float));
  tap_buffers.back().flush();
  return &tap_buffers.back();
}

detail::Bindings StepProgram::bindings_of(const Step& s, const Image& src, const Image& dst) const {
  detail::Bindings b{{src.view, s.src == kInput ? kReadOnly : kGeneral, s.sampler ? sampler : VK_NULL_HANDLE},
                     {dst.view, kGeneral}};
  if (s.taps) {
    Buffer taps;
    taps.buffer = s.taps->buffer();
    taps.size = s.taps->size();
    b.push_back(taps);
  }
  return b;
}

void StepProgram::record(VkCommandBuffer cmd, Image& input, Image* output, Profiler* profiler) {
  detail::Barriers b;
  for (size_t i = 0; i < steps.size(); ++i) {
    const Step& s = steps[i];
    Image& src = s.src == kInput ? input : images[s.src].state;
    Image& dst = s.dst == kOutput ? *output : images[s.dst].state;
    b.use(src, s.src == kInput ? kReadOnly : kGeneral, kCompute, kSampled);
    b.use(dst, kGeneral, kCompute, kStorageWrite);
    b.flush(cmd);
    s.pipeline->dispatch(cmd, bindings_of(s, src, dst), s.push, s.invocations_x, s.invocations_y);
    if (profiler) profiler->mark(cmd, s.label);
  }
}

BlurPush make_push(VkExtent2D src, VkExtent2D dst, uint32_t flags, float max_value) {
  BlurPush p{};
  p.src_width = static_cast<int32_t>(src.width);
  p.src_height = static_cast<int32_t>(src.height);
  p.dst_width = static_cast<int32_t>(dst.width);
  p.dst_height = static_cast<int32_t>(dst.height);
  p.max_value = max_value;
  p.flags = flags;
  p.offset = 1.0f;
  p.ratio_x = static_cast<float>(src.width) / static_cast<float>(dst.width);
  p.ratio_y = static_cast<float>(src.height) / static_cast<float>(dst.height);
  return p;
}

VkExtent2D half_extent(VkExtent2D e) { return {blur_plan::half_size(e.width), blur_plan::half_size(e.height)}; }

namespace {

// A step of `pipeline` from `src` (src_size texels) to `dst` (dst_size): its push constants, and
// one invocation per destination column and `rows` destination rows. `band_rows` > 0 marks a
// streamed kernel's step, whose workgroups walk bands of that many rows (BlurPush::band_rows).
Step make_step(const detail::ComputePipeline& pipeline, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
               uint32_t flags, float max_value, uint32_t rows, std::string label, uint32_t band_rows = 0) {
  Step s;
  s.pipeline = &pipeline;
  s.src = src;
  s.dst = dst;
  s.push = make_push(src_size, dst_size, flags, max_value);
  s.push.band_rows = static_cast<int32_t>(band_rows);
  s.streamed = band_rows > 0;
  s.rows = rows;
  s.invocations_x = dst_size.width;
  s.invocations_y = (dst_size.height + rows - 1) / rows;
  s.label = std::move(label);
  return s;
}

}  // namespace

// A fused level-blur step B(src -> dst, sigma) (docs/BLUR.md); sigma 0 is the area downsample alone.
Step fused_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
                VkFormat dst_format, double sigma, double truncation, uint32_t flags, float max_value,
                std::string label, bool fp32_shared, SeparableKernel kernel) {
  const std::vector<double> w = blur_plan::gaussian_half_taps(sigma, truncation);
  const uint32_t radius = static_cast<uint32_t>(w.size()) - 1;
  if (radius > kFusedMaxRadius)
    throw Error(ErrorCode::invalid_argument, concat("blur sigma ", sigma, " needs radius ", radius,
                                                    "; the fused kernel takes at most ", kFusedMaxRadius));
  // Where the result is stored as fp16, the shared copies may be too (half the shared traffic),
  // unless the plan's error bound needs them in fp32 (blur_plan::Plan::fp32_shared).
  const bool half_shared = dst_format == VK_FORMAT_R16G16B16A16_SFLOAT && !fp32_shared;
  const FusedShape shape = fused_shape(info, radius, half_shared);
  // The source read, fixed per pipeline so each variant compiles only its own path.
  const bool same = src_size.width == dst_size.width && src_size.height == dst_size.height;
  const bool exact_half = src_size.width == 2 * dst_size.width && src_size.height == 2 * dst_size.height;
  const uint32_t mode = same ? 0u : exact_half ? 1u : 2u;
  // The 2:1 mean loaded as two column means in copy order (blur_stream.comp, SPLIT_MEAN) where the
  // loads are ordered for GPUs (SeparableKernel): on lavapipe it made the 3-level BlurPyramid about
  // a third slower (docs/BLUR.md, "Streamed separable"). The one step in flight below was measured
  // with the four fetches, on the H100.
  const bool split_mean = mode == 1 && gpu_order(info, kernel);
  detail::Workgroup2D stream;
  if (mode <= 1 && kernel != SeparableKernel::tiles && stream_shape(info, radius, half_shared, split_mean, stream) &&
      (kernel == SeparableKernel::stream || kernel == SeparableKernel::gpu_order ||
       stream_fills_device(info, dst_size, 4 * stream.x))) {
    // Two steps' rows in flight for a same-size read; one for the 2:1 mean, whose four fetches a
    // texel fill the registers (H100, 3-level BlurPyramid at 3840x2160: 94.0 us with one, 96.8 with
    // two, 124.7 with the tiles).
    const uint32_t ahead = mode == 0 ? 2u : 1u;
    const detail::ComputePipeline& pipeline = prog.pipeline(
        "blur_stream", dst_format, stream, {radius, half_shared ? 1u : 0u, mode, ahead, split_mean ? 1u : 0u},
        {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
    const uint32_t band = stream_band_rows(dst_size.width, dst_size.height, 4 * stream.x);
    Step s = make_step(pipeline, src, dst, src_size, dst_size, flags, max_value, 1, std::move(label), band);
    for (uint32_t t = 0; t <= radius; ++t) s.push.weights[t] = static_cast<float>(w[t]);
    s.gpu_order = split_mean;
    s.invocations_x = (dst_size.width + 3) / 4;                        // RUN columns per invocation
    s.invocations_y = (dst_size.height + band - 1) / band * stream.y;  // a workgroup row of stream.y a band
    s.rows = 0;  // its invocation rows are the steps of a walk, not output rows (Step::rows)
    return s;
  }
  // Prefetching the load step (shaders/blur_level.comp, PREFETCH) pays on GPUs only.
  const uint32_t prefetch = info.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0u : 1u;
  const detail::ComputePipeline& pipeline = prog.pipeline(
      "blur_level", dst_format, shape.workgroup, {shape.rows, radius, mode, half_shared ? 1u : 0u, prefetch},
      {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
  Step s = make_step(pipeline, src, dst, src_size, dst_size, flags, max_value, shape.rows, std::move(label));
  for (uint32_t t = 0; t <= radius; ++t) s.push.weights[t] = static_cast<float>(w[t]);
  return s;
}

namespace {

// A step of a tiled kernel that takes only the source and destination (and the rows constant).
Step tiled_step(StepProgram& prog, const char* kernel, FusedShape shape, int src, int dst, VkExtent2D src_size,
                VkExtent2D dst_size, VkFormat dst_format, uint32_t flags, float max_value, std::string label) {
  // Constant 3: prefetch the load step on GPUs only (as fused_step's).
  const uint32_t prefetch = prog.context->info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0u : 1u;
  const detail::ComputePipeline& pipeline =
      prog.pipeline(kernel, dst_format, shape.workgroup, {shape.rows, prefetch},
                    {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
  return make_step(pipeline, src, dst, src_size, dst_size, flags, max_value, shape.rows, std::move(label));
}

}  // namespace

Step upsample_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size,
                   VkExtent2D dst_size, VkFormat dst_format, float max_value, std::string label,
                   SeparableKernel kernel) {
  // The tiled kernel needs a magnification of 2 or more: its shared footprint holds a tile's
  // source texels. The streamed one is right at any (it advances its level rows in a loop), and at
  // 2 or more they move by at most one for each of an invocation's rows, 2 output rows apart.
  if (2 * src_size.width > dst_size.width || 2 * src_size.height > dst_size.height) {
    throw Error(ErrorCode::invalid_argument, concat("upsample_step: ", src_size.width, "x", src_size.height, " -> ",
                                                    dst_size.width, "x", dst_size.height, " magnifies less than 2x"));
  }
  if (kernel != SeparableKernel::tiles) {
    // The kUpWorkgroup.y invocations of a column share a band of kUpBandRows rows, each taking every
    // kUpWorkgroup.y-th row; no shared memory, so it fits every device. 16x2 and bands of 64 rows
    // were the fastest of the shapes measured on the H100 (docs/BLUR.md "pyramid").
    static_assert(kUpBandRows % kUpWorkgroup.y == 0, "the band's rows divide among the workgroup's rows");
    const detail::ComputePipeline& pipeline =
        prog.pipeline("blur_upsample_stream", dst_format, kUpWorkgroup, {},
                      {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
    return make_step(pipeline, src, dst, src_size, dst_size, 0u, max_value, kUpBandRows / kUpWorkgroup.y,
                     std::move(label), kUpBandRows);
  }
  // Output tiles of 64x16 on GPUs (wide rows: coalesced writes, a footprint of 36x12 level
  // texels); CPU devices (lavapipe) get 16x8, as their other 2D kernels. Shared memory: the
  // footprint (TW / 2 + 4) x (TH / 2 + 4) and the horizontal pass (TH / 2 + 4) x TW, 16 bytes each.
  const FusedShape shape = first_fitting(
      info, {{{64, 4}, 4}, {{32, 4}, 2}, {{16, 8}, 1}, {{8, 8}, 1}}, {{{16, 8}, 1}, {{8, 8}, 1}},
      [](FusedShape s) {
        const uint32_t tw = s.workgroup.x, th = s.workgroup.y * s.rows;
        return 16 * (th / 2 + 4) * (tw / 2 + 4 + tw);
      },
      "the blur upsample");
  return tiled_step(prog, "blur_upsample", shape, src, dst, src_size, dst_size, dst_format, 0u, max_value,
                    std::move(label));
}

Step down_step(StepProgram& prog, const DeviceInfo& info, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
               VkFormat dst_format, uint32_t flags, float max_value, std::string label, SeparableKernel kernel) {
  if (src_size.width != 2 * dst_size.width || src_size.height != 2 * dst_size.height) {
    throw Error(ErrorCode::invalid_argument, concat("down_step: ", src_size.width, "x", src_size.height, " -> ",
                                                    dst_size.width, "x", dst_size.height, " is not an exact 2:1 step"));
  }
  if (kernel != SeparableKernel::tiles) {
    // 64 columns by one band of rows a workgroup; no shared memory, so it fits every device.
    const bool shuffled = gpu_order(info, kernel) && down_shuffles_supported(*prog.context);
    const detail::ComputePipeline& pipeline =
        prog.pipeline(shuffled ? "blur_down_stream_shuffle" : "blur_down_stream", dst_format, {64, 1}, {},
                      {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
    const uint32_t band = shuffled ? kDownShuffleBandRows : kDownBandRows;
    Step step = make_step(pipeline, src, dst, src_size, dst_size, flags, max_value, band, std::move(label), band);
    step.gpu_order = shuffled;
    return step;
  }
  // Output tiles of 32x8 on GPUs (a source block of 66x18), 16x8 on CPU devices. Shared memory:
  // the block (2 TW + 2) x (2 TH + 2) and its rows summed along x, (2 TH + 2) x TW, 16 bytes each.
  const FusedShape shape = first_fitting(
      info, {{{32, 8}, 1}, {{16, 8}, 1}, {{8, 8}, 1}}, {{{16, 8}, 1}, {{8, 8}, 1}},
      [](FusedShape s) {
        const uint32_t tw = s.workgroup.x, th = s.workgroup.y * s.rows;
        return 16 * (2 * th + 2) * (3 * tw + 2);
      },
      "the blur downsample");
  return tiled_step(prog, "blur_down", shape, src, dst, src_size, dst_size, dst_format, flags, max_value,
                    std::move(label));
}

Step simple_step(StepProgram& prog, const char* kernel, int src, int dst, VkExtent2D src_size, VkExtent2D dst_size,
                 VkFormat dst_format, uint32_t flags, float max_value, std::string label,
                 std::vector<VkDescriptorType> bindings) {
  const detail::ComputePipeline& pipeline =
      prog.pipeline(kernel, dst_format, detail::choose_workgroup_2d(*prog.context), {}, std::move(bindings));
  return make_step(pipeline, src, dst, src_size, dst_size, flags, max_value, 1, std::move(label));
}

}  // namespace glint::blur_steps
