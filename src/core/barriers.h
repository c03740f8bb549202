// The one place that writes barriers. Each image carries its last use (glint::Image's layout,
// stage, access); use() queues the transition to the next use and flush() records them together.
#pragma once

#include <glint/glint.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glint::detail {

/// A vector whose first N elements live inside the object, so that a frame's barriers (a handful
/// per flush) never touch the heap; past N it moves everything to a std::vector.
template <typename T, size_t N>
class InlineVector {
 public:
  void push_back(const T& v) {
    if (heap_.empty() && size_ < N) {
      inline_[size_++] = v;
      return;
    }
    if (heap_.empty()) heap_.assign(inline_, inline_ + size_);
    heap_.push_back(v);
    ++size_;
  }
  T* data() { return heap_.empty() ? inline_ : heap_.data(); }
  T* begin() { return data(); }
  T* end() { return data() + size_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  void clear() {
    size_ = 0;
    heap_.clear();
  }

 private:
  T inline_[N];
  size_t size_ = 0;
  std::vector<T> heap_;
};

class Barriers {
 public:
  /// Declares that `image` is next used with (layout, stage, access). Read-after-read in the same
  /// layout needs no barrier and only widens the tracked use; anything else queues one.
  /// `level_count` mip levels from level 0 are covered (glint-owned mip chains such as the Hi-Z
  /// pyramid; caller images are views of level 0), in the one layer Image::base_array_layer. The
  /// aspect follows the format (core/formats.h, image_aspects(): depth and stencil for a combined
  /// depth/stencil format, depth for a depth format, colour otherwise).
  void use(Image& image, VkImageLayout layout, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
           uint32_t level_count = 1);
  /// The same for a buffer range (no layouts).
  void use(Buffer& buffer, VkPipelineStageFlags2 stage, VkAccessFlags2 access);
  /// Records every queued barrier in one vkCmdPipelineBarrier2 (nothing if none are queued).
  void flush(VkCommandBuffer cmd);

 private:
  void queue_read_chain(VkPipelineStageFlags2 readers, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
                        const Image* image, const Buffer* buffer);
  InlineVector<VkImageMemoryBarrier2, 16> pending_;
  InlineVector<VkBufferMemoryBarrier2, 16> pending_buffers_;
};

/// Commands glint has recorded into any command buffer since the process started. Every vkCmd* call
/// of the library goes through Barriers::flush, ComputePipeline::dispatch (one per dispatch) or
/// Profiler::reset/mark, and each counts here; transfer.cpp (tools only) does not. Tests use it to
/// prove that a record() that throws recorded nothing.
uint64_t recorded_commands();
void count_recorded_command();

/// Records zeros over `bytes` bytes of `buffer` from its offset (VK_WHOLE_SIZE: to the end of the
/// VkBuffer) with vkCmdFillBuffer, after the barrier from its last use (its state fields, flushed
/// through `b`), and counts the command. The kernels' counters that reset themselves after each use
/// are cleared so once per object (`if (!cleared) { record_zero_fill(...); cleared = true; }`): the
/// command buffer that holds the first fill must be submitted.
void record_zero_fill(VkCommandBuffer cmd, Barriers& b, Buffer& buffer, VkDeviceSize bytes = VK_WHOLE_SIZE);

inline constexpr VkAccessFlags2 kWriteAccess = VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                                               VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                                               VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                                               VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;

}  // namespace glint::detail
