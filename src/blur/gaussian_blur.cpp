// GaussianBlur (docs/BLUR.md): the plan the planner chooses per size (separable lines, fused
// levels, pyramid or dual), turned into steps (blur_steps.h) that record() walks.
#include <glint/blur.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <map>
#include <string>
#include <utility>

#include "blur/blur_plan.h"
#include "blur/blur_steps.h"
#include "blur/shaders/blur_params.h"
#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/formats.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "core/size_cache.h"

namespace glint {

using namespace blur_steps;
using detail::check_range;
using detail::concat;

static_assert(sizeof(BlurPush) == 124, "BlurPush layout changed: update src/blur/shaders/blur_params.h users");
static_assert(offsetof(BlurPush, max_value) == 16);
static_assert(offsetof(BlurPush, tap_count) == 28);
static_assert(offsetof(BlurPush, weights) == 32);
static_assert(offsetof(BlurPush, src_origin_x) == 96);
static_assert(offsetof(BlurPush, ratio_y) == 116);
static_assert(offsetof(BlurPush, band_rows) == 120);
static_assert(static_cast<uint32_t>(BlurMethod::separable) - 1 == static_cast<uint32_t>(blur_plan::Method::separable));
static_assert(static_cast<uint32_t>(BlurMethod::pyramid) == static_cast<uint32_t>(blur_plan::Method::pyramid));
static_assert(static_cast<uint32_t>(BlurMethod::dual) == static_cast<uint32_t>(blur_plan::Method::dual));

const char* blur_method_name(BlurMethod method) {
  switch (method) {
    case BlurMethod::automatic:
      return "auto";
    case BlurMethod::separable:
      return "separable";
    case BlurMethod::pyramid:
      return "pyramid";
    case BlurMethod::dual:
      return "dual";
  }
  return "unknown";
}

const char* to_string(BlurMethod method) { return blur_method_name(method); }
void GaussianBlurConfig::validate() const {
  check_range("GaussianBlurConfig::sigma_px", sigma_px, 0.5, 64.0);
  check_range("GaussianBlurConfig::max_relative_error", max_relative_error, 1e-4, 1.0);
  detail::check_enum("GaussianBlurConfig::method", method, 4, "BlurMethod", "automatic, separable, pyramid, dual");
  detail::check_enum("GaussianBlurConfig::precision", precision, 2, "Precision", "fp16, fp32");
  const double costs[4] = {cost_model.us_per_dispatch, cost_model.us_per_byte, cost_model.us_per_shared_tap,
                           cost_model.us_per_fetch_tap};
  const char* cost_names[4] = {"us_per_dispatch", "us_per_byte", "us_per_shared_tap", "us_per_fetch_tap"};
  int zeros = 0;
  for (int i = 0; i < 4; ++i) {
    if (!(costs[i] >= 0.0) || !std::isfinite(costs[i])) {
      throw Error(ErrorCode::invalid_argument, concat("GaussianBlurConfig::cost_model.", cost_names[i], " = ", costs[i],
                                                      " is out of range: accepted finite and >= 0"));
    }
    zeros += costs[i] == 0.0;
  }
  if (zeros != 0 && zeros != 4) {
    throw Error(ErrorCode::invalid_argument,
                concat("GaussianBlurConfig::cost_model has ", zeros,
                       " zero fields: accepted all zero (measure on the device) or all > 0"));
  }
  if (linear_sampling && method != BlurMethod::separable) {
    throw Error(
        ErrorCode::invalid_argument,
        concat("GaussianBlurConfig::linear_sampling = true needs method separable, not ", blur_method_name(method)));
  }
}

namespace {

constexpr uint32_t kLineSegment = 256;  // blur_line.comp: outputs per workgroup along the line
using blur_plan::kFusedMaxRadius;       // one constant for the planner and the driver

// blur_plan::Storage's unit of a store into `format`: one ulp of its mantissa, relative.
double store_unit(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32_SFLOAT:
      return blur_plan::store_unit(23);
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
      return blur_plan::store_unit(5);  // 6 bits (R, G), 5 (B)
    case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
      return blur_plan::store_unit(8);  // relative to the largest channel
    default:
      return blur_plan::store_unit(10);  // fp16
  }
}

// A padded chain's first step (docs/BLUR.md "Borders"): it reads the caller's input, `input`
// texels, as the virtual padded level 0 whose texel u is the input's clamp(u - pad). The step's
// ratio stays that of the virtual sizes.
void read_padded_input(Step& s, VkExtent2D input, const blur_plan::Padding& pad) {
  s.push.src_width = static_cast<int32_t>(input.width);
  s.push.src_height = static_cast<int32_t>(input.height);
  s.push.src_origin_x = static_cast<int32_t>(pad.pad_x);
  s.push.src_origin_y = static_cast<int32_t>(pad.pad_y);
}

// A padded chain's last step: it writes only the input's extent of the virtual padded output,
// texel xy of the caller's output being the virtual texel xy + pad.
void write_padded_output(Step& s, VkExtent2D output, const blur_plan::Padding& pad) {
  if (s.rows == 0) {
    throw Error(ErrorCode::invalid_argument,
                concat("write_padded_output: step '", s.label, "' has no rows per invocation to size its dispatch"));
  }
  s.push.dst_width = static_cast<int32_t>(output.width);
  s.push.dst_height = static_cast<int32_t>(output.height);
  s.push.dst_origin_x = static_cast<int32_t>(pad.pad_x);
  s.push.dst_origin_y = static_cast<int32_t>(pad.pad_y);
  s.invocations_x = output.width;
  s.invocations_y = (output.height + s.rows - 1) / s.rows;
}

}  // namespace

struct GaussianBlur::Impl {
  const Context* context = nullptr;
  GaussianBlurConfig config;
  PipelineMap pipelines;
  // The plan and program of one (input size, output format, config generation): steps writing the
  // output are specialized for its format. Kept until no submitted work can use it
  // (core/size_cache.h).
  struct Size {
    StepProgram prog;
    VkExtent2D extent{0, 0};
    VkFormat output_format = VK_FORMAT_UNDEFINED;
    BlurChoice choice;
    std::vector<std::pair<VkExtent2D, VkFormat>> intermediates;  // for min_bytes_moved
  };
  detail::SizeCache<Size> cache;
  Size* cur = nullptr;      // the size of the last prepare() or record()
  uint32_t generation = 0;  // bumped by set_config() and detail::BlurAccess::select_separable()
  SeparableKernel separable_kernel = SeparableKernel::device;

  VkFormat level_format() const { return precision_format(config.precision); }

  Size& size_for(VkExtent2D size, VkFormat out_format, const char* who) {
    cur = &cache.get({size, out_format, generation}, cur, who, [&] { return make(size, out_format); });
    return *cur;
  }

  // The rounding of every store on the path (docs/BLUR.md "Error model"): intermediates at the
  // configured precision, the output in its own format.
  blur_plan::Storage storage(VkFormat out_format) const {
    blur_plan::Storage st;
    st.level_unit = store_unit(level_format());
    st.output_unit = store_unit(out_format);
    st.level_half = level_format() == VK_FORMAT_R16G16B16A16_SFLOAT;
    st.output_half = out_format == VK_FORMAT_R16G16B16A16_SFLOAT;
    st.sub_texel_bits = context->info().sub_texel_precision_bits;
    return st;
  }

  // The cost model automatic ranks plans by: the config's, else the device's (docs/BLUR.md "Cost
  // model").
  blur_plan::CostModel cost_model() const {
    BlurCostModel c = config.cost_model;
    if (c.us_per_dispatch == 0.0) c = context->is_adopted() ? BlurCostModel{} : measure_blur_cost_model(*context);
    blur_plan::CostModel m;
    if (c.us_per_dispatch == 0.0) return m;  // adopted, nothing passed in: the built-in constants
    m.us_per_dispatch = c.us_per_dispatch;
    m.us_per_byte = c.us_per_byte;
    m.us_per_shared_tap = c.us_per_shared_tap;
    m.us_per_fetch_tap = c.us_per_fetch_tap;
    return m;
  }

  blur_plan::Plan plan(VkExtent2D size, VkFormat out_format, BlurChoice& choice) const {
    const double bound = config.max_relative_error;
    const blur_plan::Storage st = storage(out_format);
    blur_plan::Plan p;
    switch (config.method) {
      case BlurMethod::automatic:
        p = blur_plan::plan_auto(config.sigma_px, size.width, size.height, bound, st, cost_model());
        break;
      case BlurMethod::separable:
        p = blur_plan::plan_method(
            config.linear_sampling ? blur_plan::Method::separable_linear : blur_plan::Method::separable,
            config.sigma_px, size.width, size.height, bound, st);
        break;
      case BlurMethod::pyramid:
        p = blur_plan::plan_method(blur_plan::Method::pyramid, config.sigma_px, size.width, size.height, bound, st);
        break;
      case BlurMethod::dual:
        p = blur_plan::plan_method(blur_plan::Method::dual, config.sigma_px, size.width, size.height, bound, st);
        break;
    }
    choice = BlurChoice{};
    choice.linear_sampling = p.method == blur_plan::Method::separable_linear;
    choice.method = (p.method == blur_plan::Method::separable || choice.linear_sampling) ? BlurMethod::separable
                    : p.method == blur_plan::Method::pyramid                             ? BlurMethod::pyramid
                                                                                         : BlurMethod::dual;
    choice.radius = p.radius;
    choice.levels = p.levels;
    choice.level_sigma = p.level_sigma;
    choice.dual_offset = p.dual_offset;
    choice.effective_sigma_px = p.effective_sigma_px;
    choice.expected_relative_error = p.expected_relative_l2;
    choice.estimated_us = p.cost;
    return p;
  }

  std::unique_ptr<Size> make(VkExtent2D size, VkFormat out_format) {
    auto made = std::make_unique<Size>();
    StepProgram& prog = made->prog;
    prog.context = context;
    prog.pipelines = &pipelines;
    made->extent = size;
    made->output_format = out_format;
    const blur_plan::Plan plan_made = plan(size, out_format, made->choice);
    const blur_plan::Padding& pad = plan_made.padding;
    const VkExtent2D padded{pad.padded_width, pad.padded_height};  // the virtual level 0
    BlurChoice& choice = made->choice;
    std::vector<std::pair<VkExtent2D, VkFormat>>& intermediates = made->intermediates;
    const DeviceInfo& info = context->info();
    const VkFormat lf = level_format();
    const float max_value = max_value_for(lf, out_format);
    const uint32_t sanitize = GLINT_BLUR_FLAG_SANITIZE;
    auto add = [&](VkExtent2D e) {
      intermediates.emplace_back(e, lf);
      return prog.add_image(e, lf);
    };
    if (choice.method == BlurMethod::separable && choice.linear_sampling) {
      // Paired taps (docs/BLUR.md): (0, w0), then (offset, weight) per pair, per side.
      const std::vector<double> w = blur_plan::gaussian_half_taps(config.sigma_px, blur_plan::kGaussTruncation);
      std::vector<float> taps = {0.0f, static_cast<float>(w[0])};
      for (size_t t = 1; t < w.size(); t += 2) {
        const double w1 = w[t], w2 = t + 1 < w.size() ? w[t + 1] : 0.0;
        taps.push_back(static_cast<float>((t * w1 + (t + 1) * w2) / (w1 + w2)));
        taps.push_back(static_cast<float>(w1 + w2));
      }
      prog.sampler = detail::clamp_sampler(*prog.context, VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST, 0.0f);
      const detail::OwnedBuffer* buf = prog.add_taps(taps);
      const int scratch = add(size);
      for (int pass = 0; pass < 2; ++pass) {
        Step s = simple_step(prog, "blur_linear", pass == 0 ? kInput : scratch, pass == 0 ? scratch : kOutput, size,
                             size, pass == 0 ? lf : out_format, pass == 0 ? 0u : GLINT_BLUR_FLAG_VERTICAL, max_value,
                             pass == 0 ? "gauss linear horizontal" : "gauss linear vertical",
                             {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
                              VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
        s.sampler = true;
        s.taps = buf;
        s.push.tap_count = static_cast<uint32_t>(taps.size() / 2 - 1);
        prog.steps.push_back(std::move(s));
      }
      // The sampler cannot sanitize: NaN or Inf in the input reach the output
      // (GaussianBlurConfig::linear_sampling, docs/BLUR.md "Notation").
    } else if (choice.method == BlurMethod::separable && choice.radius <= kFusedMaxRadius) {
      prog.steps.push_back(fused_step(prog, info, kInput, kOutput, size, size, out_format, config.sigma_px,
                                      blur_plan::kGaussTruncation, sanitize, max_value, "gauss separable (fused)",
                                      false, separable_kernel));
    } else if (choice.method == BlurMethod::separable) {
      const std::vector<double> w = blur_plan::gaussian_half_taps(config.sigma_px, blur_plan::kGaussTruncation);
      const detail::OwnedBuffer* buf = prog.add_taps(std::vector<float>(w.begin(), w.end()));
      const uint32_t radius = static_cast<uint32_t>(w.size()) - 1;
      const int scratch = add(size);
      for (int pass = 0; pass < 2; ++pass) {
        const VkFormat f = pass == 0 ? lf : out_format;
        Step s;
        s.pipeline = &prog.pipeline(
            "blur_line", f, {kLineSegment, 1}, {radius},
            {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
        s.src = pass == 0 ? kInput : scratch;
        s.dst = pass == 0 ? scratch : kOutput;
        s.push = make_push(size, size, pass == 0 ? sanitize : GLINT_BLUR_FLAG_VERTICAL, max_value);
        s.push.tap_count = radius;
        s.taps = buf;
        s.invocations_x = pass == 0 ? size.width : size.height;  // along the line
        s.invocations_y = pass == 0 ? size.height : size.width;  // one workgroup row per line
        s.label = pass == 0 ? "gauss line horizontal" : "gauss line vertical";
        prog.steps.push_back(std::move(s));
      }
    } else if (choice.method == BlurMethod::pyramid) {
      // The chain runs on the padded extent (docs/BLUR.md "Borders"): exact halves down to level k.
      VkExtent2D prev = padded;
      int src = kInput;
      for (uint32_t j = 1; j <= choice.levels; ++j) {
        const VkExtent2D e = half_extent(prev);
        const int dst = add(e);
        const uint32_t flags = src == kInput ? sanitize : 0u;
        // Every level is D alone (blur_steps::down_step); the last one is then blurred at its own
        // size. Storing it first beat the fused blur that downsampled its source in its load (16
        // fetches a loaded texel) at every level count on the H100 (docs/BLUR.md).
        Step s = down_step(prog, info, src, dst, prev, e, lf, flags, max_value,
                           concat("gauss pyramid level ", j, " (down)"), separable_kernel);
        if (src == kInput) read_padded_input(s, size, pad);
        prog.steps.push_back(std::move(s));
        src = dst;
        prev = e;
      }
      const int blurred = add(prev);
      prog.steps.push_back(fused_step(
          prog, info, src, blurred, prev, prev, lf, choice.level_sigma, blur_plan::kGaussTruncation, 0u, max_value,
          concat("gauss pyramid level ", choice.levels, " (blur)"), plan_made.fp32_shared, separable_kernel));
      src = blurred;
      Step up = upsample_step(prog, info, src, kOutput, prev, padded, out_format, max_value, "gauss pyramid upsample",
                              separable_kernel);
      write_padded_output(up, size, pad);
      prog.steps.push_back(std::move(up));
    } else {  // dual, on the padded extent as the pyramid
      std::vector<VkExtent2D> sizes = {padded};
      std::vector<int> ids = {kInput};
      for (uint32_t j = 1; j <= choice.levels; ++j) {
        const VkExtent2D e = half_extent(sizes.back());
        const int dst = add(e);
        Step s = simple_step(prog, "blur_dual_down", ids.back(), dst, sizes.back(), e, lf,
                             ids.back() == kInput ? sanitize : 0u, max_value, concat("gauss dual down ", j));
        s.push.offset = static_cast<float>(choice.dual_offset);
        if (ids.back() == kInput) read_padded_input(s, size, pad);
        prog.steps.push_back(std::move(s));
        sizes.push_back(e);
        ids.push_back(dst);
      }
      // Up: level j is rewritten from level j+1 (its downsampled content is no longer needed).
      for (uint32_t j = choice.levels; j-- > 0;) {
        const bool last = j == 0;
        Step s = simple_step(prog, "blur_dual_up", ids[j + 1], last ? kOutput : ids[j], sizes[j + 1], sizes[j],
                             last ? out_format : lf, 0u, max_value, concat("gauss dual up ", j));
        s.push.offset = static_cast<float>(choice.dual_offset);
        if (last) write_padded_output(s, size, pad);
        prog.steps.push_back(std::move(s));
      }
    }
    choice.dispatches = static_cast<uint32_t>(prog.steps.size());
    return made;
  }
};

GaussianBlur::GaussianBlur(const Context& context, const GaussianBlurConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  impl_->config = config;
  impl_->context = &context;
  impl_->cache.bind(context);
}
GaussianBlur::GaussianBlur(GaussianBlur&&) noexcept = default;
GaussianBlur& GaussianBlur::operator=(GaussianBlur&&) noexcept = default;
GaussianBlur::~GaussianBlur() = default;

void GaussianBlur::set_config(const GaussianBlurConfig& config) {
  config.validate();
  impl_->config = config;
  // Programs of the old config stay cached, never found again, until no submitted work uses them.
  ++impl_->generation;
  if (impl_->cur) impl_->size_for(impl_->cur->extent, impl_->cur->output_format, "GaussianBlur::set_config");
}
const GaussianBlurConfig& GaussianBlur::config() const { return impl_->config; }

void GaussianBlur::prepare(VkExtent2D extent) {
  detail::check_extent(*impl_->context, extent, "GaussianBlur::prepare");
  const VkFormat out = impl_->cur ? impl_->cur->output_format : VK_FORMAT_R16G16B16A16_SFLOAT;
  impl_->size_for(extent, out, "GaussianBlur::prepare");
}

void GaussianBlur::prepare(VkExtent2D extent, VkFormat output_format) {
  detail::check_extent(*impl_->context, extent, "GaussianBlur::prepare");
  detail::check_color_write(*impl_->context, output_format, "GaussianBlur::prepare", "output");
  impl_->size_for(extent, output_format, "GaussianBlur::prepare");
}

void GaussianBlur::record(VkCommandBuffer cmd, Image& input, Image& output, Profiler* profiler) {
  detail::check_command_buffer("GaussianBlur::record", cmd);
  detail::check_image_layout("GaussianBlur::record", "input", input);
  detail::check_image_layout("GaussianBlur::record", "output", output);
  const Context& ctx = *impl_->context;
  check_image(ctx, input, "GaussianBlur::record", "input", VK_IMAGE_USAGE_SAMPLED_BIT, "VK_IMAGE_USAGE_SAMPLED_BIT");
  check_image(ctx, output, "GaussianBlur::record", "output", VK_IMAGE_USAGE_STORAGE_BIT, "VK_IMAGE_USAGE_STORAGE_BIT");
  if (input.image == output.image && input.base_array_layer == output.base_array_layer) {
    throw Error(ErrorCode::invalid_argument,
                concat("GaussianBlur::record: input and output are layer ", input.base_array_layer,
                       " of the same image; they must be different images or layers"));
  }
  if (input.extent.width != output.extent.width || input.extent.height != output.extent.height) {
    throw Error(ErrorCode::invalid_argument,
                concat("GaussianBlur::record: output extent ", output.extent.width, "x", output.extent.height,
                       " differs from input extent ", input.extent.width, "x", input.extent.height));
  }
  Impl::Size& size = impl_->size_for(input.extent, output.format, "GaussianBlur::record");
  // The paired-tap method reads the input through a bilinear sampler (docs/BLUR.md).
  if (size.choice.linear_sampling) detail::check_color_read(ctx, input.format, "GaussianBlur::record", "input", true);
  impl_->cache.recorded(&size, cmd);
  size.prog.record(cmd, input, &output, profiler);
}

void detail::BlurAccess::select_separable(GaussianBlur& blur, blur_steps::SeparableKernel kernel) {
  GaussianBlur::Impl& impl = *blur.impl_;
  impl.separable_kernel = kernel;
  ++impl.generation;  // as set_config(): the current size plans again
  if (impl.cur) impl.size_for(impl.cur->extent, impl.cur->output_format, "BlurAccess::select_separable");
}

uint32_t detail::BlurAccess::streamed(const GaussianBlur& blur) {
  return blur.impl_->cur ? blur.impl_->cur->prog.streamed_steps() : 0;
}

uint32_t detail::BlurAccess::gpu_ordered(const GaussianBlur& blur) {
  return blur.impl_->cur ? blur.impl_->cur->prog.gpu_order_steps() : 0;
}

void GaussianBlur::release_unused() { impl_->cache.release_unused(impl_->cur); }
uint32_t GaussianBlur::cached_sizes() const { return impl_->cache.size(); }

const BlurChoice& GaussianBlur::choice() const {
  static const BlurChoice none{};
  return impl_->cur ? impl_->cur->choice : none;
}

uint64_t GaussianBlur::min_bytes_moved(VkFormat input_format, VkFormat output_format) const {
  if (!impl_->cur) return 0;
  const Impl::Size& size = *impl_->cur;
  const uint64_t texels = uint64_t(size.extent.width) * size.extent.height;
  uint64_t total = texels * (detail::texel_bytes(input_format) + detail::texel_bytes(output_format));
  for (const auto& [e, f] : size.intermediates) total += 2 * uint64_t(e.width) * e.height * detail::texel_bytes(f);
  return total;
}

}  // namespace glint