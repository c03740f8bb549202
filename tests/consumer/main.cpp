// The consumer check: only the installed public headers and glint::glint. Makes its own 16x16
// RGBA32F images with plain Vulkan (as an engine would), clears the input to 2.0 (above the default
// threshold), runs a default bloom through run_once, reads the output back and checks that every
// texel is finite and brighter than the input. Prints "ok" and exits 0, else prints why and exits 1.
#include <glint/bloom.h>
#include <glint/glint.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace {

constexpr uint32_t kSize = 16;
constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr float kInput = 2.0f;

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: " + std::to_string(result));
}

uint32_t memory_type(VkPhysicalDevice physical, uint32_t allowed, VkMemoryPropertyFlags wanted) {
  VkPhysicalDeviceMemoryProperties props;
  vkGetPhysicalDeviceMemoryProperties(physical, &props);
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((allowed & (1u << i)) && (props.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  }
  throw std::runtime_error("no suitable memory type");
}

// A 16x16 image with its memory and view, described as a glint::Image in UNDEFINED layout.
struct TestImage {
  VkDevice device = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  glint::Image image;

  TestImage(const glint::Context& ctx, VkImageUsageFlags usage) : device(ctx.device()) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = kFormat;
    info.extent = {kSize, kSize, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check(vkCreateImage(device, &info, nullptr, &image.image), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, image.image, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memory_type(ctx.physical_device(), req.memoryTypeBits, 0);
    check(vkAllocateMemory(device, &alloc, nullptr, &memory), "vkAllocateMemory");
    check(vkBindImageMemory(device, image.image, memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = kFormat;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    check(vkCreateImageView(device, &view, nullptr, &image.view), "vkCreateImageView");
    image.format = kFormat;
    image.extent = {kSize, kSize};
    image.usage = usage;
  }
  TestImage(const TestImage&) = delete;
  TestImage& operator=(const TestImage&) = delete;
  ~TestImage() {
    vkDestroyImageView(device, image.view, nullptr);
    vkDestroyImage(device, image.image, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
};

struct ReadbackBuffer {
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  static constexpr VkDeviceSize kBytes = VkDeviceSize(kSize) * kSize * 4 * sizeof(float);

  explicit ReadbackBuffer(const glint::Context& ctx) : device(ctx.device()) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = kBytes;
    info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    check(vkCreateBuffer(device, &info, nullptr, &buffer), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memory_type(ctx.physical_device(), req.memoryTypeBits,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check(vkAllocateMemory(device, &alloc, nullptr, &memory), "vkAllocateMemory");
    check(vkBindBufferMemory(device, buffer, memory, 0), "vkBindBufferMemory");
  }
  ReadbackBuffer(const ReadbackBuffer&) = delete;
  ReadbackBuffer& operator=(const ReadbackBuffer&) = delete;
  ~ReadbackBuffer() {
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
};

void image_barrier(VkCommandBuffer cmd, glint::Image& img, VkImageLayout layout, VkPipelineStageFlags2 stage,
                   VkAccessFlags2 access) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = img.stage;
  b.srcAccessMask = img.access;
  b.dstStageMask = stage;
  b.dstAccessMask = access;
  b.oldLayout = img.layout;
  b.newLayout = layout;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img.image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &dep);
  img.layout = layout;
  img.stage = stage;
  img.access = access;
}

int run() {
  const glint::Context ctx = glint::Context::create();
  std::printf("glint %d.%d.%d on %s\n", glint::kVersionMajor, glint::kVersionMinor, glint::kVersionPatch,
              ctx.info().name.c_str());
  TestImage input(ctx, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  TestImage output(ctx, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  ReadbackBuffer readback(ctx);
  glint::Bloom bloom(ctx);

  ctx.run_once([&](VkCommandBuffer cmd) {
    image_barrier(cmd, input.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_TRANSFER_WRITE_BIT);
    const VkClearColorValue colour{{kInput, kInput, kInput, 1.0f}};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, input.image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &colour, 1, &range);

    bloom.record(cmd, input.image, output.image);  // reads input.image's state, writes output's

    image_barrier(cmd, output.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                  VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {kSize, kSize, 1};
    vkCmdCopyImageToBuffer(cmd, output.image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &copy);
    VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &to_host;
    vkCmdPipelineBarrier2(cmd, &dep);
  });

  void* mapped = nullptr;
  check(vkMapMemory(ctx.device(), readback.memory, 0, ReadbackBuffer::kBytes, 0, &mapped), "vkMapMemory");
  const float* px = static_cast<const float*>(mapped);
  int bad = 0;
  for (uint32_t i = 0; i < kSize * kSize; ++i) {
    for (int c = 0; c < 3; ++c) {
      const float v = px[i * 4 + c];
      if (!std::isfinite(v) || !(v > kInput)) ++bad;
    }
  }
  const float centre = px[((kSize / 2) * kSize + kSize / 2) * 4];
  vkUnmapMemory(ctx.device(), readback.memory);

  std::printf("bloom: %u level(s); centre red %.4f (input %.1f)\n", bloom.levels(), double(centre), double(kInput));
  if (bad) {
    std::printf("FAIL: %d channel(s) not finite or not above the input\n", bad);
    return 1;
  }
  if (ctx.validation_messages() != 0) {
    std::printf("FAIL: %u validation message(s)\n", ctx.validation_messages());
    return 1;
  }
  std::printf("ok\n");
  return 0;
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::printf("FAIL: %s\n", e.what());
    return 1;
  }
}
