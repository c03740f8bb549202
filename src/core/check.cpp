#include "core/check.h"

namespace glint::detail {

namespace {

std::string usage_names(VkBufferUsageFlags usage) {
  struct Name {
    VkBufferUsageFlags bit;
    const char* name;
  };
  static constexpr Name kNames[] = {
      {VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "VK_BUFFER_USAGE_TRANSFER_SRC_BIT"},
      {VK_BUFFER_USAGE_TRANSFER_DST_BIT, "VK_BUFFER_USAGE_TRANSFER_DST_BIT"},
      {VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, "VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT"},
      {VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT"},
      {VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, "VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT"},
  };
  std::string out;
  for (const Name& n : kNames) {
    if (usage & n.bit) out += (out.empty() ? "" : " | ") + std::string(n.name);
  }
  return out.empty() ? concat("0x", std::hex, usage) : out;
}

}  // namespace

void check_buffer(const char* where, const char* role, const Buffer& b, VkDeviceSize need, VkBufferUsageFlags usage,
                  VkDeviceSize offset_alignment) {
  if (!b.buffer) throw Error(ErrorCode::invalid_argument, concat(where, ": ", role, " buffer is null"));
  if ((b.usage & usage) != usage) {
    throw Error(ErrorCode::missing_usage, concat(where, ": ", role, " buffer lacks usage ",
                                                 usage_names(usage & ~b.usage), " (needs ", usage_names(usage), ")"));
  }
  if (b.size == VK_WHOLE_SIZE || b.size == 0) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role, " Buffer::size = ", b.size == 0 ? "0" : "VK_WHOLE_SIZE",
                       ": give the bytes from offset that glint may use (at least ", need,
                       "); glint cannot query a VkBuffer's size"));
  }
  if (b.size < need) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role, " buffer holds ", b.size, " bytes: accepted at least ", need));
  }
  if (b.offset % offset_alignment != 0) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role, " buffer offset = ", b.offset, " is not a multiple of ", offset_alignment));
  }
}

void check_extent(const Context& context, VkExtent2D e, const char* where, const char* role) {
  const uint32_t max_dim = context.info().max_image_dimension_2d;
  if (e.width == 0 || e.height == 0 || e.width > max_dim || e.height > max_dim) {
    throw Error(ErrorCode::unsupported_size,
                concat(where, ": ", role, *role ? " " : "", "extent ", e.width, "x", e.height,
                       " is out of range: accepted 1 to ", max_dim, " on each side"));
  }
}

void check_command_buffer(const char* where, VkCommandBuffer cmd) {
  if (cmd == VK_NULL_HANDLE) {
    throw Error(ErrorCode::invalid_argument, concat(where, ": the command buffer is null"));
  }
}

void check_image_layout(const char* where, const char* role, const Image& image) {
  const VkImageLayout l = image.layout;
  const bool known = (l >= VK_IMAGE_LAYOUT_UNDEFINED && l <= VK_IMAGE_LAYOUT_PREINITIALIZED) ||
                     l == VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL ||
                     l == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL ||
                     l == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL || l == VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL ||
                     l == VK_IMAGE_LAYOUT_STENCIL_ATTACHMENT_OPTIMAL ||
                     l == VK_IMAGE_LAYOUT_STENCIL_READ_ONLY_OPTIMAL || l == VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL ||
                     l == VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL || l == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  if (!known) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role, " Image::layout = ", uint32_t(l),
                       " is not a VkImageLayout glint accepts: UNDEFINED, GENERAL, the *_OPTIMAL layouts of Vulkan 1.3 "
                       "or PRESENT_SRC_KHR"));
  }
  if (l == VK_IMAGE_LAYOUT_PREINITIALIZED) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role,
                       " Image::layout = VK_IMAGE_LAYOUT_PREINITIALIZED: glint takes optimal-tiling "
                       "images; transition it first"));
  }
}

}  // namespace glint::detail
