#include "core/formats.h"

#include <cfloat>

#include "core/check.h"
#include "core/context_state.h"

namespace glint::detail {

FormatFeatureTable fill_format_features(VkPhysicalDevice physical_device) {
  FormatFeatureTable table{};
  for (size_t i = 0; i < kCheckedFormats.size(); ++i) {
    // VkFormatProperties3 (Vulkan 1.3) reports the 64-bit flags, among them
    // STORAGE_WRITE_WITHOUT_FORMAT, which the 32-bit VkFormatProperties cannot.
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 p2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(physical_device, kCheckedFormats[i], &p2);
    table[i] = p3.optimalTilingFeatures;
  }
  return table;
}

VkFormatFeatureFlags2 format_features(const Context& context, VkFormat format) {
  for (size_t i = 0; i < kCheckedFormats.size(); ++i) {
    if (kCheckedFormats[i] == format) return context.state().format_features[i];
  }
  throw Error(ErrorCode::unsupported_format,
              concat("format ", format_name(format), " is none of those glint checks for a device: ",
                     float_color_formats(), ", a depth format of HiZConfig::format or VK_FORMAT_R32_SFLOAT"));
}

bool is_float_color(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R16G16B16_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R32G32B32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
    case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
      return true;
    default:
      return false;
  }
}

const char* float_color_formats() {
  return "VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_B10G11R11_UFLOAT_PACK32, "
         "VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT or VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, as the "
         "device supports them";
}

const char* qualified_variant(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return "rgba16f";
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return "rgba32f";
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
      return "r11f_g11f_b10f";
    default:
      return nullptr;
  }
}

void check_color_read(const Context& context, VkFormat format, const char* where, const char* role, bool linear) {
  if (!is_float_color(format)) {
    throw Error(ErrorCode::unsupported_format,
                concat(where, ": ", role, " format is ", format_name(format), "; accepted ", float_color_formats()));
  }
  const VkFormatFeatureFlags2 f = format_features(context, format);
  if (!(f & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) {
    throw Error(ErrorCode::unsupported_format,
                concat(where, ": ", role, " format is ", format_name(format), ", which device '", context.info().name,
                       "' cannot sample (no VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT with optimal tiling)"));
  }
  if (linear && !(f & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
    throw Error(ErrorCode::unsupported_format,
                concat(where, ": ", role, " format is ", format_name(format), ", which device '", context.info().name,
                       "' cannot filter linearly (no VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_FILTER_LINEAR_BIT), as this "
                       "blur method reads it"));
  }
}

const char* check_color_write(const Context& context, VkFormat format, const char* where, const char* role) {
  if (!is_float_color(format)) {
    throw Error(ErrorCode::unsupported_format,
                concat(where, ": ", role, " format is ", format_name(format), "; accepted ", float_color_formats()));
  }
  const VkFormatFeatureFlags2 f = format_features(context, format);
  const char* qualified = qualified_variant(format);
  if (qualified && (f & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT)) return qualified;
  // Without a matching qualifier the kernel declares the image with format Unknown; Vulkan 1.3
  // allows writing it where the view's format has STORAGE_WRITE_WITHOUT_FORMAT.
  if ((f & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT) && (f & VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT)) {
    return "noformat";
  }
  throw Error(
      ErrorCode::unsupported_format,
      concat(where, ": ", role, " format is ", format_name(format), ", which device '", context.info().name,
             "' cannot write as a storage image (",
             (f & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT) ? "no VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT"
                                                         : "no VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT",
             " with optimal tiling)"));
}

float format_max(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32G32B32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return FLT_MAX;
    case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
      return 65024.0f;  // the 11-bit channels' largest finite value; blue (10-bit) converts values above
                        // its 64512 to 64512 (Vulkan, "Unsigned 10-Bit Floating-Point Numbers")
    case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
      return 65408.0f;  // (2^9 - 1) / 2^9 * 2^(31 - 15) (Vulkan, "Shared Exponent")
    default:
      return 65504.0f;
  }
}

bool is_depth_format(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
      return true;
    default:
      return false;
  }
}

bool has_stencil(VkFormat format) {
  return format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT ||
         format == VK_FORMAT_D16_UNORM_S8_UINT || format == VK_FORMAT_S8_UINT;
}

VkImageAspectFlags image_aspects(VkFormat format) {
  if (format == VK_FORMAT_S8_UINT) return VK_IMAGE_ASPECT_STENCIL_BIT;
  if (is_depth_format(format) || format == VK_FORMAT_D16_UNORM_S8_UINT) {
    return has_stencil(format) ? VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT)
                               : VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT);
  }
  return VK_IMAGE_ASPECT_COLOR_BIT;
}

void check_layers(const Image& image, const char* where, const char* role) {
  if (image.layer_count != 1) {
    throw Error(ErrorCode::invalid_argument,
                concat(where, ": ", role, " Image::layer_count = ", image.layer_count,
                       " is not accepted: 1 (pass a 2D view of one layer, its index in Image::base_array_layer)"));
  }
}

}  // namespace glint::detail
