#include "core/transfer.h"

#include <cstring>

#include "core/barriers.h"
#include "core/check.h"
#include "core/half.h"

namespace glint::detail {

namespace {

void check_same_size(const Image& image, const CpuImage& pixels) {
  if (image.extent.width != pixels.width || image.extent.height != pixels.height) {
    throw Error(ErrorCode::invalid_argument, concat("upload: pixels are ", pixels.width, "x", pixels.height,
                                                    ", image is ", image.extent.width, "x", image.extent.height));
  }
}

VkBufferImageCopy whole(const Image& image) {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {image.extent.width, image.extent.height, 1};
  return region;
}

}  // namespace

OwnedBuffer make_upload_staging(const Context& context, const Image& image, const CpuImage& pixels) {
  check_same_size(image, pixels);
  const size_t texels = size_t(pixels.width) * pixels.height;
  if (image.format != VK_FORMAT_R16G16B16A16_SFLOAT && image.format != VK_FORMAT_R32G32B32A32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("upload: ", format_name(image.format), " is not RGBA16F or RGBA32F"));
  }
  OwnedBuffer staging(context, texels * texel_bytes(image.format), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  if (image.format == VK_FORMAT_R16G16B16A16_SFLOAT) {
    auto* dst = static_cast<uint16_t*>(staging.mapped());
    for (size_t i = 0; i < texels * 4; ++i) dst[i] = float_to_half(pixels.rgba[i]);
  } else {
    std::memcpy(staging.mapped(), pixels.rgba.data(), texels * 16);
  }
  staging.flush();
  return staging;
}

OwnedBuffer make_upload_staging_r32(const Context& context, const Image& image, const std::vector<float>& values) {
  if (image.format != VK_FORMAT_D32_SFLOAT && image.format != VK_FORMAT_R32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("upload_r32: ", format_name(image.format), " is not D32_SFLOAT or R32_SFLOAT"));
  }
  const size_t texels = size_t(image.extent.width) * image.extent.height;
  if (values.size() != texels) {
    throw Error(ErrorCode::invalid_argument, concat("upload_r32: ", values.size(), " values for ", texels, " texels"));
  }
  OwnedBuffer staging(context, texels * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  std::memcpy(staging.mapped(), values.data(), texels * 4);
  staging.flush();
  return staging;
}

void record_upload(VkCommandBuffer cmd, const OwnedBuffer& staging, Image& image) {
  Barriers b;
  b.use(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  b.flush(cmd);
  VkBufferImageCopy region = whole(image);
  if (image.format == VK_FORMAT_D32_SFLOAT) region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
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
  if (image.format == VK_FORMAT_R16G16B16A16_SFLOAT) {
    const auto* src = static_cast<const uint16_t*>(staging.mapped());
    for (size_t i = 0; i < texels * 4; ++i) out.rgba[i] = half_to_float(src[i]);
  } else if (image.format == VK_FORMAT_R32G32B32A32_SFLOAT) {
    std::memcpy(out.rgba.data(), staging.mapped(), texels * 16);
  } else {
    throw Error(ErrorCode::unsupported_format,
                concat("download: ", format_name(image.format), " is not RGBA16F or RGBA32F"));
  }
  return out;
}

void upload(const Context& context, Image& image, const CpuImage& pixels) {
  const OwnedBuffer staging = make_upload_staging(context, image, pixels);
  context.run_once([&](VkCommandBuffer cmd) { record_upload(cmd, staging, image); });
}

CpuImage download(const Context& context, Image& image) {
  if (image.format != VK_FORMAT_R16G16B16A16_SFLOAT && image.format != VK_FORMAT_R32G32B32A32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("download: ", format_name(image.format), " is not RGBA16F or RGBA32F"));
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
    VkBufferImageCopy region{};
    const bool depth = image.format == VK_FORMAT_D32_SFLOAT;
    region.imageSubresource = {
        static_cast<VkImageAspectFlags>(depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), level, 0, 1};
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
  VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &range);
}

void fill(const Context& context, Image& image, float value) {
  context.run_once([&](VkCommandBuffer cmd) { record_fill(cmd, image, value); });
}

}  // namespace glint::detail
