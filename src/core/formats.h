// Which caller image formats an effect reads and writes, decided from the device's format
// features (vkGetPhysicalDeviceFormatProperties2 with VkFormatProperties3, optimal tiling), and
// the aspect masks and layers of caller images. Every refusal names the format and the missing
// feature.
#pragma once

#include <glint/glint.h>

#include <array>
#include <string>

namespace glint::detail {

/// Every format an effect accepts for a caller image: the float colour formats below
/// (is_float_color(); LensFlare's RGBA ones among them) and the formats HiZConfig::format accepts
/// (is_depth_format() and R32_SFLOAT). Their features are read from the device once, when the
/// context is made (fill_format_features()), so that record() only looks them up.
inline constexpr std::array<VkFormat, 12> kCheckedFormats = {
    VK_FORMAT_R16G16B16_SFLOAT,    VK_FORMAT_R16G16B16A16_SFLOAT,     VK_FORMAT_R32G32B32_SFLOAT,
    VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_B10G11R11_UFLOAT_PACK32, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32,
    VK_FORMAT_D16_UNORM,           VK_FORMAT_X8_D24_UNORM_PACK32,     VK_FORMAT_D24_UNORM_S8_UINT,
    VK_FORMAT_D32_SFLOAT,          VK_FORMAT_D32_SFLOAT_S8_UINT,      VK_FORMAT_R32_SFLOAT,
};

/// optimalTilingFeatures of each of kCheckedFormats, in its order.
using FormatFeatureTable = std::array<VkFormatFeatureFlags2, kCheckedFormats.size()>;

/// Queries the optimal-tiling features of every format of kCheckedFormats on `physical_device`
/// (vkGetPhysicalDeviceFormatProperties2 with VkFormatProperties3). Called once per context, at
/// Context::create or Context::adopt.
FormatFeatureTable fill_format_features(VkPhysicalDevice physical_device);

/// optimalTilingFeatures of `format` on the context's device, from the table the context filled
/// when it was made: no Vulkan call, no lock, no allocation (the table never changes afterwards, so
/// any thread may read it). Throws Error(unsupported_format) for a format outside kCheckedFormats,
/// which callers refuse by name before asking.
VkFormatFeatureFlags2 format_features(const Context& context, VkFormat format);

/// The HDR colour formats image effects take: float formats with at least red, green and blue
/// (R16G16B16[A16]_SFLOAT, R32G32B32[A32]_SFLOAT, B10G11R11_UFLOAT_PACK32, E5B9G9R9_UFLOAT_PACK32).
/// Whether the device can read or write one is a separate question (check_color_read/_write).
bool is_float_color(VkFormat format);

/// "VK_FORMAT_R16G16B16A16_SFLOAT, ... or VK_FORMAT_E5B9G9R9_UFLOAT_PACK32": the list above, for
/// messages.
const char* float_color_formats();

/// The kernel variant whose GLSL image format qualifier matches `format` ("rgba16f", "rgba32f",
/// "r11f_g11f_b10f"; each effect.cmake compiles its image-writing kernels once per variant),
/// or null when glint compiles no qualifier for it (written through the "noformat" variant).
const char* qualified_variant(VkFormat format);

/// Throws Error(unsupported_format) "<where>: <role> format is F; ..." unless `format` is a float
/// colour format the device can sample (SAMPLED_IMAGE, and SAMPLED_IMAGE_FILTER_LINEAR when
/// `linear` is set: the kernel reads it through a bilinear sampler).
void check_color_read(const Context& context, VkFormat format, const char* where, const char* role,
                      bool linear = false);

/// The variant of the image-writing kernels that stores `format`: its qualifier's variant when the
/// format has STORAGE_IMAGE, else "noformat" when it has STORAGE_WRITE_WITHOUT_FORMAT (the
/// per-format form of shaderStorageImageWriteWithoutFormat in Vulkan 1.3). Throws
/// Error(unsupported_format) naming the format and what it lacks otherwise.
const char* check_color_write(const Context& context, VkFormat format, const char* where, const char* role);

/// The largest finite value a texel of `format` holds (65504 for 16-bit floats, 65024 for
/// B10G11R11, 65408 for E5B9G9R9, FLT_MAX for 32-bit floats): what effects clamp outputs to.
float format_max(VkFormat format);

/// The depth formats Hi-Z reads: D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT,
/// D32_SFLOAT_S8_UINT (each through a depth-aspect view).
bool is_depth_format(VkFormat format);
bool has_stencil(VkFormat format);

/// The aspect mask of barriers and copies of a whole image of `format`: depth and stencil for a
/// combined format (the Vulkan spec requires both in a layout transition unless
/// separateDepthStencilLayouts is enabled, which glint does not assume), depth for a depth-only
/// format, colour otherwise.
VkImageAspectFlags image_aspects(VkFormat format);

/// Throws Error(invalid_argument) "<where>: <role> Image::layer_count = N ..." unless the image
/// names one layer (layer_count 1); effects read and write 2D views of one layer.
void check_layers(const Image& image, const char* where, const char* role);

}  // namespace glint::detail
