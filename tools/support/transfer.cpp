#include "support/transfer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/barriers.h"
#include "core/check.h"
#include "core/formats.h"
#include "core/half.h"
#include "core/packed_float.h"

namespace glint::detail {

namespace {

void check_same_size(const Image& image, const CpuImage& pixels) {
  if (image.extent.width != pixels.width || image.extent.height != pixels.height) {
    throw Error(ErrorCode::invalid_argument, concat("upload: pixels are ", pixels.width, "x", pixels.height,
                                                    ", image is ", image.extent.width, "x", image.extent.height));
  }
}

// Mip 0 of the image's layer; the depth aspect alone of a depth/stencil format (a copy names one).
VkBufferImageCopy whole(const Image& image) {
  VkBufferImageCopy region{};
  const VkImageAspectFlags aspect = image_aspects(image.format) & ~VkImageAspectFlags(VK_IMAGE_ASPECT_STENCIL_BIT);
  region.imageSubresource = {aspect, 0, image.base_array_layer, 1};
  region.imageExtent = {image.extent.width, image.extent.height, 1};
  return region;
}

// The colour formats upload() and download() convert: RGBA float to the format's texels.
bool is_transfer_color(VkFormat f) {
  return f == VK_FORMAT_R16G16B16A16_SFLOAT || f == VK_FORMAT_R32G32B32A32_SFLOAT ||
         f == VK_FORMAT_B10G11R11_UFLOAT_PACK32 || f == VK_FORMAT_R16G16B16_SFLOAT || f == VK_FORMAT_R32G32B32_SFLOAT;
}
constexpr const char* kTransferColor = "RGBA16F, RGBA32F, B10G11R11_UFLOAT, RGB16F or RGB32F";

void encode(VkFormat f, const float* rgba, size_t texels, void* dst) {
  for (size_t i = 0; i < texels; ++i) {
    const float* t = rgba + 4 * i;
    switch (f) {
      case VK_FORMAT_R16G16B16A16_SFLOAT:
        for (int c = 0; c < 4; ++c) static_cast<uint16_t*>(dst)[4 * i + c] = float_to_half(t[c]);
        break;
      case VK_FORMAT_R16G16B16_SFLOAT:
        for (int c = 0; c < 3; ++c) static_cast<uint16_t*>(dst)[3 * i + c] = float_to_half(t[c]);
        break;
      case VK_FORMAT_R32G32B32A32_SFLOAT:
        std::memcpy(static_cast<float*>(dst) + 4 * i, t, 16);
        break;
      case VK_FORMAT_R32G32B32_SFLOAT:
        std::memcpy(static_cast<float*>(dst) + 3 * i, t, 12);
        break;
      default:  // B10G11R11_UFLOAT_PACK32
        static_cast<uint32_t*>(dst)[i] = pack_b10g11r11(t[0], t[1], t[2]);
        break;
    }
  }
}

void decode(VkFormat f, const void* src, size_t texels, float* rgba) {
  for (size_t i = 0; i < texels; ++i) {
    float* t = rgba + 4 * i;
    t[3] = 1.0f;  // formats without alpha read as alpha 1 (Vulkan, "Conversion to RGBA")
    switch (f) {
      case VK_FORMAT_R16G16B16A16_SFLOAT:
        for (int c = 0; c < 4; ++c) t[c] = half_to_float(static_cast<const uint16_t*>(src)[4 * i + c]);
        break;
      case VK_FORMAT_R16G16B16_SFLOAT:
        for (int c = 0; c < 3; ++c) t[c] = half_to_float(static_cast<const uint16_t*>(src)[3 * i + c]);
        break;
      case VK_FORMAT_R32G32B32A32_SFLOAT:
        std::memcpy(t, static_cast<const float*>(src) + 4 * i, 16);
        break;
      case VK_FORMAT_R32G32B32_SFLOAT:
        std::memcpy(t, static_cast<const float*>(src) + 3 * i, 12);
        break;
      default:  // B10G11R11_UFLOAT_PACK32
        unpack_b10g11r11(static_cast<const uint32_t*>(src)[i], t);
        break;
    }
  }
}

}  // namespace

OwnedBuffer make_upload_staging(const Context& context, const Image& image, const CpuImage& pixels) {
  check_same_size(image, pixels);
  const size_t texels = size_t(pixels.width) * pixels.height;
  if (!is_transfer_color(image.format)) {
    throw Error(ErrorCode::unsupported_format,
                concat("upload: ", format_name(image.format), " is not ", kTransferColor));
  }
  OwnedBuffer staging(context, texels * texel_bytes(image.format), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  encode(image.format, pixels.rgba.data(), texels, staging.mapped());
  staging.flush();
  return staging;
}

OwnedBuffer make_upload_staging_r32(const Context& context, const Image& image, const std::vector<float>& values) {
  if (!is_depth_format(image.format) && image.format != VK_FORMAT_R32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("upload_r32: ", format_name(image.format), " is not a depth format or R32_SFLOAT"));
  }
  const size_t texels = size_t(image.extent.width) * image.extent.height;
  if (values.size() != texels) {
    throw Error(ErrorCode::invalid_argument, concat("upload_r32: ", values.size(), " values for ", texels, " texels"));
  }
  // The depth aspect's buffer layout (Vulkan, "Depth/Stencil Formats" in copies): D16 as uint16,
  // X8_D24 and D24S8 as the low 24 bits of a uint32, D32 and D32S8 as float. UNORM depth holds
  // round(d * (2^bits - 1)) (Vulkan, "Conversion from Floating-Point to Normalized Fixed-Point").
  const bool d16 = image.format == VK_FORMAT_D16_UNORM;
  const bool d24 = image.format == VK_FORMAT_X8_D24_UNORM_PACK32 || image.format == VK_FORMAT_D24_UNORM_S8_UINT;
  OwnedBuffer staging(context, texels * (d16 ? 2 : 4), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  for (size_t i = 0; i < texels; ++i) {
    const double d = std::clamp(double(values[i]), 0.0, 1.0);
    if (d16) {
      static_cast<uint16_t*>(staging.mapped())[i] = static_cast<uint16_t>(std::nearbyint(d * 65535.0));
    } else if (d24) {
      static_cast<uint32_t*>(staging.mapped())[i] = static_cast<uint32_t>(std::nearbyint(d * 16777215.0));
    } else {
      static_cast<float*>(staging.mapped())[i] = values[i];
    }
  }
  staging.flush();
  return staging;
}

void record_upload(VkCommandBuffer cmd, const OwnedBuffer& staging, Image& image) {
  Barriers b;
  b.use(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  b.flush(cmd);
  VkBufferImageCopy region = whole(image);
  vkCmdCopyBufferToImage(cmd, staging.buffer(), image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}

OwnedBuffer make_readback_staging(const Context& context, const Image& image) {
  const size_t texels = size_t(image.extent.width) * image.extent.height;
  return OwnedBuffer(context, texels * texel_bytes(image.format), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
}

void record_host_read_barrier(VkCommandBuffer cmd) {
  VkMemoryBarrier2 host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
  host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &host;
  vkCmdPipelineBarrier2(cmd, &dep);
}

void record_readback(VkCommandBuffer cmd, Image& image, const OwnedBuffer& staging) {
  Barriers b;
  b.use(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  b.flush(cmd);
  VkBufferImageCopy region = whole(image);
  vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer(), 1, &region);
  record_host_read_barrier(cmd);
}

CpuImage read_staged(const OwnedBuffer& staging, const Image& image) {
  staging.invalidate();
  const size_t texels = size_t(image.extent.width) * image.extent.height;
  CpuImage out(image.extent.width, image.extent.height);
  if (!is_transfer_color(image.format)) {
    throw Error(ErrorCode::unsupported_format,
                concat("download: ", format_name(image.format), " is not ", kTransferColor));
  }
  decode(image.format, staging.mapped(), texels, out.rgba.data());
  return out;
}

void upload(const Context& context, Image& image, const CpuImage& pixels) {
  const OwnedBuffer staging = make_upload_staging(context, image, pixels);
  context.run_once([&](VkCommandBuffer cmd) { record_upload(cmd, staging, image); });
}

CpuImage download(const Context& context, Image& image) {
  if (!is_transfer_color(image.format)) {
    throw Error(ErrorCode::unsupported_format,
                concat("download: ", format_name(image.format), " is not ", kTransferColor));
  }
  const OwnedBuffer staging = make_readback_staging(context, image);
  context.run_once([&](VkCommandBuffer cmd) { record_readback(cmd, image, staging); });
  return read_staged(staging, image);
}

void upload_r32(const Context& context, Image& image, const std::vector<float>& values) {
  const OwnedBuffer staging = make_upload_staging_r32(context, image, values);
  context.run_once([&](VkCommandBuffer cmd) { record_upload(cmd, staging, image); });
}

std::vector<float> download_r32(const Context& context, Image& image, uint32_t level, VkExtent2D extent,
                                uint32_t level_count) {
  const size_t texels = size_t(extent.width) * extent.height;
  OwnedBuffer staging(context, texels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  context.run_once([&](VkCommandBuffer cmd) {
    Barriers b;
    b.use(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
          level_count);
    b.flush(cmd);
    VkBufferImageCopy region = whole(image);
    region.imageSubresource.mipLevel = level;
    region.imageExtent = {extent.width, extent.height, 1};
    vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer(), 1, &region);
    record_host_read_barrier(cmd);
  });
  staging.invalidate();
  std::vector<float> out(texels);
  std::memcpy(out.data(), staging.mapped(), texels * 4);
  return out;
}

void record_fill(VkCommandBuffer cmd, Image& image, float value) {
  Barriers b;
  b.use(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  b.flush(cmd);
  VkClearColorValue color{};
  for (float& c : color.float32) c = value;
  VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, image.base_array_layer, 1};
  vkCmdClearColorImage(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &range);
}

void fill(const Context& context, Image& image, float value) {
  context.run_once([&](VkCommandBuffer cmd) { record_fill(cmd, image, value); });
}

}  // namespace glint::detail
