#include "core/barriers.h"

#include <atomic>

#include "core/formats.h"

namespace glint::detail {

void Barriers::use(Image& image, VkImageLayout layout, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
                   uint32_t level_count) {
  const bool was_write = (image.access & kWriteAccess) != 0;
  const bool is_write = (access & kWriteAccess) != 0;
  if (!was_write && !is_write && image.layout == layout && image.layout != VK_IMAGE_LAYOUT_UNDEFINED) {
    // Read after read. A stage that the earlier barrier did not cover still needs the last write
    // made visible to it: chain an execution dependency from the earlier readers (whose barrier
    // made the write available) to the new stage.
    if ((stage & ~image.stage) != 0) queue_read_chain(image.stage, stage, access, &image, nullptr);
    image.stage |= stage;
    image.access |= access;
    return;
  }
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = image.stage;
  b.srcAccessMask = image.access & kWriteAccess;  // only writes need to be made available
  b.dstStageMask = stage;
  b.dstAccessMask = access;
  b.oldLayout = image.layout;
  b.newLayout = layout;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image.image;
  b.subresourceRange = {image_aspects(image.format), 0, level_count, image.base_array_layer, 1};
  // The same layer of an image twice in one batch (in-place use) merges into one barrier; two
  // layers of one image are two subresources with barriers of their own.
  for (auto& p : pending_) {
    if (p.image == image.image && p.subresourceRange.baseArrayLayer == image.base_array_layer) {
      p.dstStageMask |= stage;
      p.dstAccessMask |= access;
      p.newLayout = layout;
      image.layout = layout;
      image.stage = p.dstStageMask;
      image.access = p.dstAccessMask;
      return;
    }
  }
  pending_.push_back(b);
  image.layout = layout;
  image.stage = stage;
  image.access = access;
}

void Barriers::use(Buffer& buffer, VkPipelineStageFlags2 stage, VkAccessFlags2 access) {
  const bool was_write = (buffer.access & kWriteAccess) != 0;
  const bool is_write = (access & kWriteAccess) != 0;
  if (!was_write && !is_write) {  // read after read (see the image case)
    if ((stage & ~buffer.stage) != 0) queue_read_chain(buffer.stage, stage, access, nullptr, &buffer);
    buffer.stage |= stage;
    buffer.access |= access;
    return;
  }
  VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
  b.srcStageMask = buffer.stage;
  b.srcAccessMask = buffer.access & kWriteAccess;
  b.dstStageMask = stage;
  b.dstAccessMask = access;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.buffer = buffer.buffer;
  b.offset = buffer.offset;
  b.size = buffer.size;
  pending_buffers_.push_back(b);
  buffer.stage = stage;
  buffer.access = access;
}

void Barriers::queue_read_chain(VkPipelineStageFlags2 readers, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
                                const Image* image, const Buffer* buffer) {
  if (readers == VK_PIPELINE_STAGE_2_NONE) return;  // never written or read in this command buffer's view
  if (image) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = readers;
    b.dstStageMask = stage;
    b.dstAccessMask = access;
    b.oldLayout = image->layout;
    b.newLayout = image->layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image->image;
    b.subresourceRange = {image_aspects(image->format), 0, VK_REMAINING_MIP_LEVELS, image->base_array_layer, 1};
    pending_.push_back(b);
  } else {
    VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    b.srcStageMask = readers;
    b.dstStageMask = stage;
    b.dstAccessMask = access;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buffer->buffer;
    b.offset = buffer->offset;
    b.size = buffer->size;
    pending_buffers_.push_back(b);
  }
}

namespace {
std::atomic<uint64_t> g_recorded_commands{0};
}

uint64_t recorded_commands() { return g_recorded_commands.load(); }
void count_recorded_command() { g_recorded_commands.fetch_add(1, std::memory_order_relaxed); }

void record_zero_fill(VkCommandBuffer cmd, Barriers& b, Buffer& buffer, VkDeviceSize bytes) {
  b.use(buffer, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);  // a fill is "transfer"
  b.flush(cmd);
  vkCmdFillBuffer(cmd, buffer.buffer, buffer.offset, bytes, 0);
  count_recorded_command();
}

void Barriers::flush(VkCommandBuffer cmd) {
  if (pending_.empty() && pending_buffers_.empty()) return;
  count_recorded_command();
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = static_cast<uint32_t>(pending_.size());
  dep.pImageMemoryBarriers = pending_.data();
  dep.bufferMemoryBarrierCount = static_cast<uint32_t>(pending_buffers_.size());
  dep.pBufferMemoryBarriers = pending_buffers_.data();
  vkCmdPipelineBarrier2(cmd, &dep);
  pending_.clear();
  pending_buffers_.clear();
}

}  // namespace glint::detail
