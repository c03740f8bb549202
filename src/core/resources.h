// Images and buffers that glint owns (pyramid levels, staging), with their memory. Move-only.
#pragma once

#include <glint/glint.h>

#include <cstddef>
#include <vector>

namespace glint::detail {

/// A 2D image with its memory and a view of all its mips; `state` tracks its last use for
/// barriers. With levels > 1 (a mip chain, e.g. the Hi-Z pyramid or the flare atlas) it also has one
/// view per level, for kernels that write one level each.
class OwnedImage {
 public:
  OwnedImage() = default;
  /// With layers > 1 an array image: `state` shows layer 0 through a 2D view; layer_view(l) shows
  /// layer l (tests of caller array images).
  OwnedImage(const Context& context, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage, uint32_t levels = 1,
             uint32_t layers = 1);
  OwnedImage(OwnedImage&& other) noexcept { *this = std::move(other); }
  OwnedImage& operator=(OwnedImage&& other) noexcept;
  OwnedImage(const OwnedImage&) = delete;
  OwnedImage& operator=(const OwnedImage&) = delete;
  ~OwnedImage() { reset(); }

  void reset();
  explicit operator bool() const { return state.image != VK_NULL_HANDLE; }
  uint32_t levels() const { return levels_; }
  /// A view of mip `k` alone (levels > 1), or the view of the whole image (levels == 1).
  VkImageView level_view(uint32_t k) const { return level_views_.empty() ? state.view : level_views_.at(k); }
  uint32_t layers() const { return layers_; }
  /// A 2D view of layer `l` (all mips).
  VkImageView layer_view(uint32_t l) const { return l == 0 ? state.view : layer_views_.at(l - 1); }
  /// The image as effects see it; the state fields are shared with this object by reference.
  Image& image() { return state; }
  const Image& image() const { return state; }

  Image state;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  uint32_t levels_ = 0;
  uint32_t layers_ = 0;
  std::vector<VkImageView> level_views_;
  std::vector<VkImageView> layer_views_;  // layers 1, 2, ...
};

/// A buffer with its memory, optionally host-visible and mapped.
class OwnedBuffer {
 public:
  OwnedBuffer() = default;
  OwnedBuffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible);
  OwnedBuffer(OwnedBuffer&& other) noexcept { *this = std::move(other); }
  OwnedBuffer& operator=(OwnedBuffer&& other) noexcept;
  OwnedBuffer(const OwnedBuffer&) = delete;
  OwnedBuffer& operator=(const OwnedBuffer&) = delete;
  ~OwnedBuffer() { reset(); }

  void reset();
  VkBuffer buffer() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }
  /// Makes host writes visible to the device / device writes visible to the host (non-coherent
  /// memory); no-op on coherent memory.
  void flush() const;
  void invalidate() const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  bool coherent_ = true;
};

/// Bytes per texel of the formats glint handles.
uint32_t texel_bytes(VkFormat format);

/// Whether `format` is RGBA16F or RGBA32F: the formats of glint's own intermediate images (and of
/// the flare gather's target, which it reads and writes). Caller images of bloom and blur take
/// more (core/formats.h).
inline bool is_float_rgba(VkFormat format) {
  return format == VK_FORMAT_R16G16B16A16_SFLOAT || format == VK_FORMAT_R32G32B32A32_SFLOAT;
}

/// The kernel-variant suffix of an intermediate storage format ("rgba32f" or "rgba16f";
/// each effect.cmake compiles its image-writing kernels once per storage format). Caller
/// outputs pick theirs with check_color_write() (core/formats.h).
inline const char* format_variant(VkFormat format) {
  return format == VK_FORMAT_R32G32B32A32_SFLOAT ? "rgba32f" : "rgba16f";
}

/// A clamp-to-edge sampler with `filter` for minification and magnification, `mipmap` between
/// levels and levels 0 to `max_lod`. Samplers are immutable: one per context and settings is made
/// on first use and shared by every effect; the context destroys it.
VkSampler clamp_sampler(const Context& context, VkFilter filter, VkSamplerMipmapMode mipmap, float max_lod);

}  // namespace glint::detail
