// BlurPyramid (docs/BLUR.md): three cumulative Gaussian levels, each a fused blur-and-downsample
// step of the level before (blur_steps.h).
#include <utility>

#include "blur/blur_steps.h"
#include "core/check.h"
#include "core/formats.h"
#include "core/size_cache.h"

namespace glint {

using namespace blur_steps;
using detail::check_range;
using detail::concat;

void BlurPyramidConfig::validate() const {
  const char* names[3] = {"BlurPyramidConfig::sigma_texels[0]", "BlurPyramidConfig::sigma_texels[1]",
                          "BlurPyramidConfig::sigma_texels[2]"};
  for (int k = 0; k < 3; ++k) check_range(names[k], sigma_texels[k], 0.3, 4.0);
  detail::check_enum("BlurPyramidConfig::precision", precision, 2, "Precision", "fp16, fp32");
}

struct BlurPyramid::Impl {
  const Context* context = nullptr;
  BlurPyramidConfig config;
  PipelineMap pipelines;
  // The program of one input size (and config generation), kept per size until no submitted work
  // can use it (core/size_cache.h).
  struct Size {
    StepProgram prog;
    VkExtent2D extent{0, 0};
    std::array<VkExtent2D, 3> sizes{};
  };
  detail::SizeCache<Size> cache;
  Size* cur = nullptr;      // the size of the last prepare() or record()
  uint32_t generation = 0;  // bumped by set_config() and detail::BlurAccess::select_separable()
  SeparableKernel separable_kernel = SeparableKernel::device;

  VkFormat level_format() const { return precision_format(config.precision); }

  Size& size_for(VkExtent2D size, const char* who) {
    cur = &cache.get({size, VK_FORMAT_UNDEFINED, generation}, cur, who, [&] { return make(size); });
    return *cur;
  }

  std::unique_ptr<Size> make(VkExtent2D size) {
    auto made = std::make_unique<Size>();
    StepProgram& prog = made->prog;
    std::array<VkExtent2D, 3>& sizes = made->sizes;
    prog.context = context;
    prog.pipelines = &pipelines;
    made->extent = size;
    const DeviceInfo& info = context->info();
    VkExtent2D prev = size;
    for (int k = 0; k < 3; ++k) {
      sizes[k] = half_extent(prev);
      prog.add_image(sizes[k], level_format());
      prev = sizes[k];
    }
    // The input clamp uses the level format: the levels are the only images written.
    const float max_value = max_value_for(level_format(), level_format());
    prev = size;
    for (int k = 0; k < 3; ++k) {
      prog.steps.push_back(fused_step(prog, info, k == 0 ? kInput : k - 1, k, prev, sizes[k], level_format(),
                                      config.sigma_texels[k], blur_plan::kPyramidTruncation,
                                      k == 0 ? GLINT_BLUR_FLAG_SANITIZE : 0u, max_value,
                                      concat("blur pyramid level ", k + 1), false, separable_kernel));
      prev = sizes[k];
    }
    return made;
  }
};

BlurPyramid::BlurPyramid(const Context& context, const BlurPyramidConfig& config) : impl_(std::make_unique<Impl>()) {
  config.validate();
  impl_->config = config;
  impl_->context = &context;
  impl_->cache.bind(context);
  // Fail now, not at the first record, if the largest radius cannot fit the device.
  for (float s : config.sigma_texels) {
    fused_shape(context.info(),
                static_cast<uint32_t>(blur_plan::gaussian_half_taps(s, blur_plan::kPyramidTruncation).size() - 1));
  }
}
BlurPyramid::BlurPyramid(BlurPyramid&&) noexcept = default;
BlurPyramid& BlurPyramid::operator=(BlurPyramid&&) noexcept = default;
BlurPyramid::~BlurPyramid() = default;

void detail::BlurAccess::select_separable(BlurPyramid& pyramid, blur_steps::SeparableKernel kernel) {
  BlurPyramid::Impl& impl = *pyramid.impl_;
  impl.separable_kernel = kernel;
  ++impl.generation;  // as set_config(): the current size plans again
  if (impl.cur) impl.size_for(impl.cur->extent, "BlurAccess::select_separable");
}

uint32_t detail::BlurAccess::streamed(const BlurPyramid& pyramid) {
  return pyramid.impl_->cur ? pyramid.impl_->cur->prog.streamed_steps() : 0;
}

uint32_t detail::BlurAccess::gpu_ordered(const BlurPyramid& pyramid) {
  return pyramid.impl_->cur ? pyramid.impl_->cur->prog.gpu_order_steps() : 0;
}

void BlurPyramid::set_config(const BlurPyramidConfig& config) {
  config.validate();
  impl_->config = config;
  // Programs of the old config stay cached, never found again, until no submitted work uses them.
  ++impl_->generation;
  if (impl_->cur) impl_->size_for(impl_->cur->extent, "BlurPyramid::set_config");
}
const BlurPyramidConfig& BlurPyramid::config() const { return impl_->config; }

void BlurPyramid::prepare(VkExtent2D input_extent) {
  detail::check_extent(*impl_->context, input_extent, "BlurPyramid::prepare");
  impl_->size_for(input_extent, "BlurPyramid::prepare");
}

void BlurPyramid::record(VkCommandBuffer cmd, Image& input, Profiler* profiler) {
  detail::check_command_buffer("BlurPyramid::record", cmd);
  detail::check_image_layout("BlurPyramid::record", "input", input);
  check_image(*impl_->context, input, "BlurPyramid::record", "input", VK_IMAGE_USAGE_SAMPLED_BIT,
              "VK_IMAGE_USAGE_SAMPLED_BIT");
  Impl::Size& size = impl_->size_for(input.extent, "BlurPyramid::record");
  impl_->cache.recorded(&size, cmd);
  size.prog.record(cmd, input, nullptr, profiler);
}

const Image& BlurPyramid::level(uint32_t k) const {
  if (k < 1 || k > 3)
    throw Error(ErrorCode::invalid_argument,
                concat("BlurPyramid::level: k = ", k, " is out of range: accepted 1 to 3"));
  if (!impl_->cur) throw Error(ErrorCode::invalid_argument, "BlurPyramid::level: call prepare() or record() first");
  return impl_->cur->prog.images[k - 1].state;
}

Image& BlurPyramid::level(uint32_t k) { return const_cast<Image&>(std::as_const(*this).level(k)); }

void BlurPyramid::release_unused() { impl_->cache.release_unused(impl_->cur); }
uint32_t BlurPyramid::cached_sizes() const { return impl_->cache.size(); }

LevelSize BlurPyramid::level_size(uint32_t k) const {
  const Image& l = level(k);
  return {l.extent.width, l.extent.height};
}

EffectiveSigma BlurPyramid::effective_sigma_px(uint32_t k) const {
  level(k);  // validates k and that a size is prepared
  const std::vector<double> s(impl_->config.sigma_texels.begin(), impl_->config.sigma_texels.end());
  return {blur_plan::pyramid_effective_sigma(impl_->cur->extent.width, s)[k - 1],
          blur_plan::pyramid_effective_sigma(impl_->cur->extent.height, s)[k - 1]};
}

uint64_t BlurPyramid::min_bytes_moved(VkFormat input_format) const {
  if (!impl_->cur) return 0;
  const Impl::Size& size = *impl_->cur;
  const uint64_t in_bytes = detail::texel_bytes(input_format);
  const uint64_t level_bytes = detail::texel_bytes(impl_->level_format());
  uint64_t total = uint64_t(size.extent.width) * size.extent.height * in_bytes;
  for (int k = 0; k < 3; ++k) {
    const uint64_t texels = uint64_t(size.sizes[k].width) * size.sizes[k].height;
    total += texels * level_bytes * (k < 2 ? 2 : 1);  // written; read by the next level
  }
  return total;
}

}  // namespace glint
