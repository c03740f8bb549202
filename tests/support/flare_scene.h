// Pieces the occlusion and flare tests share: a poisoned host-visible buffer, a depth image made
// from a float64-reference depth map, and the perspective camera the end-to-end and robustness
// scenes use.
#pragma once

#include <glint/glint.h>
#include <glint/gpu/flare_types.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/resources.h"
#include "reference/occlusion_reference.h"

namespace glint::test {

inline constexpr VkBufferUsageFlags kFlareBufferUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
    VK_BUFFER_USAGE_TRANSFER_DST_BIT;

/// A host-visible buffer (at least 4 bytes) with kFlareBufferUsage; poison() fills it with 0xFF
/// bytes (NaN as float, ~0u as uint), so data a run did not write shows. Made poisoned.
struct HostBuffer {
  detail::OwnedBuffer owned;
  Buffer view;
  explicit HostBuffer(VkDeviceSize bytes);
  void poison();
  /// The first n bytes, after invalidating the mapping.
  std::vector<uint8_t> bytes(size_t n) const;
  template <typename T>
  const T* as() const {
    owned.invalidate();
    return static_cast<const T*>(owned.mapped());
  }
};

/// A sampled depth image (D32_SFLOAT or R32_SFLOAT) holding `d`.
detail::OwnedImage make_depth(const reference::DepthImage& d, VkFormat format);

/// The depth a UNORM depth format holds and reads back, in place: round(d * (2^bits - 1)) /
/// (2^bits - 1) (Vulkan, "Fixed-Point Data Conversions"), computed in float64 and rounded once to
/// float. Float depth formats keep the values as they are. Returns the UNORM bits (0: float).
int quantize_for_format(reference::DepthImage& depth, VkFormat format);

/// A perspective camera at the origin looking down -z onto a width x height image (Vulkan depth
/// [0, 1], standard Z, ndc.y = -1 on the first row, 1 radian vertical field of view, near 0.1,
/// far 100), as an engine would hand it over.
struct Camera {
  uint32_t width, height;
  double f = 1.0 / std::tan(0.5);
  double n = 0.1, fa = 100.0;
  double aspect() const { return double(width) / height; }
  double a() const { return fa / (n - fa); }
  double b() const { return n * fa / (n - fa); }
  std::array<float, 16> view_proj() const;
  double depth_at(double distance) const { return (a() * -distance + b()) / distance; }
  /// A glow light (colour 2, 1.5, 1) at the world position seen at pixel (px, py), `distance` in
  /// front of the camera.
  GlintFlareLight light_at(double px, double py, double distance, float size_px, float intensity = 3.0f) const;
};

}  // namespace glint::test
