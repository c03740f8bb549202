#include "core/resources.h"

#include <algorithm>
#include <mutex>
#include <utility>

#include "core/check.h"
#include "core/context_state.h"
#include "core/formats.h"

namespace glint::detail {

VkSampler clamp_sampler(const Context& context, VkFilter filter, VkSamplerMipmapMode mipmap, float max_lod) {
  auto& s = context.state();
  std::lock_guard<std::mutex> lock(s.sampler_mutex);
  VkSampler& sampler = s.samplers[{int(filter), int(mipmap), max_lod}];
  if (!sampler) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = filter;
    si.mipmapMode = mipmap;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.minLod = 0.0f;
    si.maxLod = max_lod;
    vk_check(vkCreateSampler(s.device, &si, nullptr, &sampler), "vkCreateSampler");
    s.count_object();
  }
  return sampler;
}

uint32_t texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    case VK_FORMAT_R8G8B8A8_UNORM:
      return 4;
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_R32_UINT:
      return 4;
    case VK_FORMAT_R16_SFLOAT:
    case VK_FORMAT_D16_UNORM:
      return 2;
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
    case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
      return 4;
    case VK_FORMAT_R16G16B16_SFLOAT:
      return 6;
    case VK_FORMAT_R32G32B32_SFLOAT:
      return 12;
    default:
      throw Error(ErrorCode::unsupported_format, concat("texel size of ", format_name(format), " is unknown"));
  }
}

namespace {

// An image larger than VkImageFormatProperties::maxResourceSize may not be created (Vulkan,
// "vkGetPhysicalDeviceImageFormatProperties": at least 2^31 bytes; lavapipe's is 2^32 - 1, so a
// 16384x16384 RGBA32F image is over it): refused with Error(unsupported_size) before vkCreateImage.
// The bytes are the texels of every layer and level (each level a quarter of the one above), a
// lower bound on what the driver needs. Formats whose texel size is not known here, and format
// and usage pairs the query does not support, are left to vkCreateImage.
void check_resource_size(const ContextState& s, const VkImageCreateInfo& info) {
  VkImageFormatProperties props{};
  if (vkGetPhysicalDeviceImageFormatProperties(s.physical_device, info.format, info.imageType, info.tiling, info.usage,
                                               info.flags, &props) != VK_SUCCESS) {
    return;
  }
  uint64_t texel = 0;
  try {
    texel = texel_bytes(info.format);
  } catch (const Error&) {
    return;
  }
  uint64_t bytes = 0;
  uint64_t w = info.extent.width, h = info.extent.height;
  for (uint32_t l = 0; l < info.mipLevels; ++l) {
    bytes += w * h * texel * info.arrayLayers;
    w = std::max<uint64_t>(1, w / 2);
    h = std::max<uint64_t>(1, h / 2);
  }
  if (bytes > props.maxResourceSize) {
    throw Error(ErrorCode::unsupported_size,
                concat("a ", info.extent.width, "x", info.extent.height, " ", format_name(info.format), " image needs ",
                       bytes, " bytes; the device's largest image of this format and usage (maxResourceSize) is ",
                       props.maxResourceSize, " bytes: make it smaller"));
  }
}

}  // namespace

OwnedImage::OwnedImage(const Context& context, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                       uint32_t levels, uint32_t layers) {
  device_ = context.device();
  auto& s = context.state();
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {extent.width, extent.height, 1};
  info.mipLevels = levels;
  info.arrayLayers = layers;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check_resource_size(s, info);
  vk_check(vkCreateImage(device_, &info, nullptr, &state.image), "vkCreateImage");
  s.count_object();
  state.format = format;
  state.extent = extent;
  state.usage = usage;
  levels_ = levels;
  layers_ = layers;
  try {
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, state.image, &req);
    memory_ = s.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                         concat("a ", extent.width, "x", extent.height, " ", format_name(format), " image"));
    vk_check(vkBindImageMemory(device_, state.image, memory_, 0), "vkBindImageMemory");
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = state.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    // Views of a depth/stencil image show the depth aspect alone (a sampled view has one aspect).
    const VkImageAspectFlags aspect = image_aspects(format) & ~VkImageAspectFlags(VK_IMAGE_ASPECT_STENCIL_BIT);
    view.subresourceRange = {aspect, 0, levels, 0, 1};
    vk_check(vkCreateImageView(device_, &view, nullptr, &state.view), "vkCreateImageView");
    s.count_object();
    for (uint32_t l = 1; l < layers; ++l) {
      view.subresourceRange = {aspect, 0, levels, l, 1};
      VkImageView v = VK_NULL_HANDLE;
      vk_check(vkCreateImageView(device_, &view, nullptr, &v), "vkCreateImageView (layer)");
      s.count_object();
      layer_views_.push_back(v);
    }
    view.subresourceRange = {aspect, 0, levels, 0, 1};
    for (uint32_t k = 0; levels > 1 && k < levels; ++k) {
      view.subresourceRange = {aspect, k, 1, 0, 1};
      VkImageView v = VK_NULL_HANDLE;
      vk_check(vkCreateImageView(device_, &view, nullptr, &v), "vkCreateImageView (level)");
      s.count_object();
      level_views_.push_back(v);
    }
  } catch (...) {
    reset();
    throw;
  }
}

OwnedImage& OwnedImage::operator=(OwnedImage&& other) noexcept {
  if (this != &other) {
    reset();
    device_ = std::exchange(other.device_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    state = std::exchange(other.state, Image{});
    levels_ = std::exchange(other.levels_, 0);
    layers_ = std::exchange(other.layers_, 0);
    level_views_ = std::exchange(other.level_views_, {});
    layer_views_ = std::exchange(other.layer_views_, {});
  }
  return *this;
}

void OwnedImage::reset() {
  if (device_) {
    for (VkImageView v : level_views_) vkDestroyImageView(device_, v, nullptr);
    for (VkImageView v : layer_views_) vkDestroyImageView(device_, v, nullptr);
    if (state.view) vkDestroyImageView(device_, state.view, nullptr);
    if (state.image) vkDestroyImage(device_, state.image, nullptr);
    if (memory_) vkFreeMemory(device_, memory_, nullptr);
  }
  device_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  state = Image{};
  levels_ = 0;
  layers_ = 0;
  level_views_.clear();
  layer_views_.clear();
}

OwnedBuffer::OwnedBuffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible) {
  device_ = context.device();
  size_ = size;
  auto& s = context.state();
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  vk_check(vkCreateBuffer(device_, &info, nullptr, &buffer_), "vkCreateBuffer");
  s.count_object();
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    VkMemoryPropertyFlags flags =
        host_visible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    uint32_t type = 0;
    memory_ = s.allocate(req, flags, concat("a ", size, "-byte buffer"), &type);
    coherent_ = (s.memory.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    vk_check(vkBindBufferMemory(device_, buffer_, memory_, 0), "vkBindBufferMemory");
    if (host_visible) vk_check(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
  } catch (...) {
    reset();
    throw;
  }
}

OwnedBuffer& OwnedBuffer::operator=(OwnedBuffer&& other) noexcept {
  if (this != &other) {
    reset();
    device_ = std::exchange(other.device_, VK_NULL_HANDLE);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    coherent_ = other.coherent_;
  }
  return *this;
}

void OwnedBuffer::reset() {
  if (device_) {
    if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
    if (memory_) vkFreeMemory(device_, memory_, nullptr);  // unmaps implicitly
  }
  device_ = VK_NULL_HANDLE;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  size_ = 0;
}

void OwnedBuffer::flush() const {
  if (coherent_ || !mapped_) return;
  VkMappedMemoryRange r{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_, 0, VK_WHOLE_SIZE};
  vk_check(vkFlushMappedMemoryRanges(device_, 1, &r), "vkFlushMappedMemoryRanges");
}

void OwnedBuffer::invalidate() const {
  if (coherent_ || !mapped_) return;
  VkMappedMemoryRange r{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_, 0, VK_WHOLE_SIZE};
  vk_check(vkInvalidateMappedMemoryRanges(device_, 1, &r), "vkInvalidateMappedMemoryRanges");
}

}  // namespace glint::detail
