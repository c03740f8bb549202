#include "support/flare_check.h"

#include <algorithm>
#include <cmath>

#include "core/barriers.h"
#include "core/half.h"
#include "core/resources.h"
#include "support/gpu_test.h"

namespace glint::test {

namespace {
constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
// A float stored to fp16 may be rounded to nearest or toward zero (Vulkan spec, "Floating-Point
// Format Conversions"; lavapipe truncates): less than one ulp, 2^-10 of the value. fp32: 2^-23.
const double kHalfStore = std::ldexp(1.0, -10);
const double kFloatStore = std::ldexp(1.0, -23);
}  // namespace

reference::FlareAtlas read_flare_atlas(const LensFlare& flare) {
  const FlareAtlasInfo a = flare.atlas();
  reference::FlareAtlas out;
  size_t total = 0;
  for (uint32_t k = 0; k < a.levels; ++k) total += size_t(std::max(1u, a.width >> k)) * std::max(1u, a.height >> k) * 8;
  detail::OwnedBuffer staging(context(), total, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  context().run_once([&](VkCommandBuffer cmd) {
    Image img{a.image,
              a.view,
              a.format,
              {a.width, a.height},
              0,
              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
              VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
              VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    detail::Barriers b;
    b.use(img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
          a.levels);
    b.flush(cmd);
    std::vector<VkBufferImageCopy> regions;
    VkDeviceSize offset = 0;
    for (uint32_t k = 0; k < a.levels; ++k) {
      VkBufferImageCopy r{};
      r.bufferOffset = offset;
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, k, 0, 1};
      r.imageExtent = {std::max(1u, a.width >> k), std::max(1u, a.height >> k), 1};
      offset += VkDeviceSize(r.imageExtent.width) * r.imageExtent.height * 8;
      regions.push_back(r);
    }
    vkCmdCopyImageToBuffer(cmd, a.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer(),
                           uint32_t(regions.size()), regions.data());
    // Back to where the LensFlare keeps it; the copy's reads finish first, the host read waits.
    b.use(img, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
          VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, a.levels);
    b.flush(cmd);
    detail::record_host_read_barrier(cmd);
  });
  staging.invalidate();
  const auto* half = static_cast<const uint16_t*>(staging.mapped());
  for (uint32_t k = 0; k < a.levels; ++k) {
    reference::FlareAtlasLevel l{std::max(1u, a.width >> k), std::max(1u, a.height >> k), {}};
    l.rgba.resize(size_t(l.width) * l.height * 4);
    for (double& v : l.rgba) v = detail::half_to_float(*half++);
    out.push_back(std::move(l));
  }
  return out;
}

reference::SamplerPrecision flare_sampler_precision() {
  // The specification's minimums for every conformant device (Vulkan, "Limit Requirements":
  // subTexelPrecisionBits >= 4, mipmapPrecisionBits >= 4), not the device's claim: a sampler is
  // tested against its claims nowhere, and the NVIDIA H100 (claiming 8 and 8) filters the coarse
  // atlas levels up to 3.6 times further from the exact value than 8 sub-texel bits allow, while
  // staying within the guaranteed 4 bits (docs/FLARE.md "Tolerance").
  return {4, 4};
}

FlareDeviation compare_flare(const CpuImage& gpu, const reference::FlareComposite& ref, VkFormat format) {
  const double u = format == kF16 ? kHalfStore : kFloatStore;
  FlareDeviation d;
  for (uint32_t y = 0; y < ref.height; ++y) {
    for (uint32_t x = 0; x < ref.width; ++x) {
      const size_t p = size_t(y) * ref.width + x;
      for (int c = 0; c < 4; ++c) {
        const double r = ref.rgba[p * 4 + c];
        const double tol = ref.bound[p * 4 + c] + (2 * ref.count[p] + 1) * u * std::fabs(r) + 1e-7;
        const double e = std::fabs(double(gpu.at(x, y)[c]) - r);
        if (!(e <= tol)) {
          if (d.outside++ == 0) {
            d.first = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " + std::to_string(c) +
                      ": gpu " + std::to_string(gpu.at(x, y)[c]) + " ref " + std::to_string(r) + " tol " +
                      std::to_string(tol);
          }
        }
        d.worst_ratio = std::max(d.worst_ratio, e / tol);
      }
    }
  }
  return d;
}

}  // namespace glint::test
