#include "support/flare_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {

HostBuffer::HostBuffer(VkDeviceSize bytes)
    : owned(context(), std::max<VkDeviceSize>(bytes, 4), kFlareBufferUsage, true) {
  view = {owned.buffer(), 0, owned.size(), kFlareBufferUsage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  poison();
}

void HostBuffer::poison() {
  std::memset(owned.mapped(), 0xFF, owned.size());
  owned.flush();
  view.stage = VK_PIPELINE_STAGE_2_HOST_BIT;
  view.access = VK_ACCESS_2_HOST_WRITE_BIT;
}

std::vector<uint8_t> HostBuffer::bytes(size_t n) const {
  owned.invalidate();
  const auto* p = static_cast<const uint8_t*>(owned.mapped());
  return std::vector<uint8_t>(p, p + n);
}

int quantize_for_format(reference::DepthImage& depth, VkFormat format) {
  const int bits = format == VK_FORMAT_D16_UNORM                                                      ? 16
                   : format == VK_FORMAT_X8_D24_UNORM_PACK32 || format == VK_FORMAT_D24_UNORM_S8_UINT ? 24
                                                                                                      : 0;
  if (bits == 0) return 0;
  const double q = std::ldexp(1.0, bits) - 1.0;
  for (float& v : depth.depth) v = static_cast<float>(std::nearbyint(double(v) * q) / q);
  return bits;
}

detail::OwnedImage make_depth(const reference::DepthImage& d, VkFormat format) {
  detail::OwnedImage img(
      context(), {d.width, d.height}, format,
      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  detail::upload_r32(context(), img.state, d.depth);
  return img;
}

std::array<float, 16> Camera::view_proj() const {
  std::array<float, 16> m{};
  m[0] = float(f / aspect());
  m[5] = float(-f);
  m[10] = float(a());
  m[11] = -1.0f;
  m[14] = float(b());
  return m;
}

GlintFlareLight Camera::light_at(double px, double py, double distance, float size_px, float intensity) const {
  const double nx = px / width * 2 - 1, ny = py / height * 2 - 1;
  GlintFlareLight l{};
  l.position_x = float(nx * distance * aspect() / f);
  l.position_y = float(-ny * distance / f);
  l.position_z = float(-distance);
  l.color_r = 2.0f;
  l.color_g = 1.5f;
  l.color_b = 1.0f;
  l.intensity = intensity;
  l.size_px = size_px;
  l.element = GLINT_FLARE_ELEMENT_GLOW;
  l.enabled = 1;
  return l;
}

}  // namespace glint::test
