// Shared test helpers: one validated Context per test program, random HDR images, comparisons.
#pragma once

#include <glint/glint.h>
#include <gtest/gtest.h>

#include <random>

#include "core/cpu_image.h"
#include "core/resources.h"
#include "support/transfer.h"

namespace glint::test {

/// The test program's Context: lavapipe unless GLINT_DEVICE says otherwise, validation and
/// synchronization validation always on.
const Context& context();

/// Base fixture: fails the test if any validation message appeared during it.
class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;

 private:
  uint32_t messages_before_ = 0;
};

/// Random HDR image: mostly values in [0, 1.5) with a fraction of bright pixels up to `peak`.
CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t stream, float bright_fraction = 0.02f,
                    float peak = 40.0f);

/// An image with its content uploaded, in the given format, with test usage flags.
detail::OwnedImage make_image(const CpuImage& pixels, VkFormat format);
/// An image poisoned with NaN so that an unwritten texel fails any comparison.
detail::OwnedImage make_poisoned(VkExtent2D extent, VkFormat format);

/// True if every channel of every texel is finite (no NaN left from poisoning).
bool all_finite(const CpuImage& image);

/// True if `a` and `b` have the same size and the same bits in every channel.
bool bit_equal(const CpuImage& a, const CpuImage& b);

/// The values the GPU reads from `img` uploaded as `format` (the reference starts from them):
/// RGBA16F rounds each channel to half (core/half.h), B10G11R11 packs and unpacks the colour
/// (core/packed_float.h) and reads alpha as 1, R32G32B32 reads alpha as 1; other formats hold
/// `img` as it is.
CpuImage as_stored(const CpuImage& img, VkFormat format);

/// Records a barrier that makes the device's writes to `b` visible to the host (read it after the
/// submission completes).
void to_host(VkCommandBuffer cmd, Buffer& b);

/// Context::adopt's description of the test program's context (instance, Vulkan 1.3, physical
/// device, device, queue family); no extension list (with_glint_extensions() adds it).
AdoptInfo adopt_info_of_context();

/// The device extensions glint needs (VK_KHR_push_descriptor): tests that create a device for
/// Context::adopt() enable these, as glint's own devices do.
inline const char* const kGlintDeviceExtensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
constexpr uint32_t kGlintDeviceExtensionCount = 1;

/// `info` saying that its device was created with kGlintDeviceExtensions (true of context()'s
/// device and of every device these tests create for adopt()).
inline AdoptInfo with_glint_extensions(AdoptInfo info) {
  info.enabled_extensions = kGlintDeviceExtensions;
  info.enabled_extension_count = kGlintDeviceExtensionCount;
  return info;
}

}  // namespace glint::test
