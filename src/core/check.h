// The one error mechanism: every failure becomes glint::Error with a message that names the
// parameter, the value and the accepted range.
#pragma once

#include <glint/glint.h>

#include <cmath>
#include <sstream>
#include <string>

namespace glint::detail {

const char* vk_result_name(VkResult result);

/// Throws Error(vulkan_failure) naming the call when result is an error code.
inline void vk_check(VkResult result, const char* call) {
  if (result < 0) {
    throw Error(ErrorCode::vulkan_failure, std::string(call) + " failed: " + vk_result_name(result));
  }
}

template <typename... Parts>
std::string concat(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return out.str();
}

/// Throws Error(invalid_argument) unless lo <= value <= hi (NaN fails).
inline void check_range(const char* name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    throw Error(ErrorCode::invalid_argument, concat(name, " = ", value, " is out of range: accepted ", lo, " to ", hi));
  }
}

/// Throws Error(invalid_argument) "NAME = V is not a TYPE: accepted ACCEPTED" unless the enum value
/// `value` is below `count` (a config's enum field, cast from any integer by the caller).
template <typename E>
void check_enum(const char* name, E value, uint32_t count, const char* type, const char* accepted) {
  const auto v = static_cast<uint32_t>(value);
  if (v >= count) {
    throw Error(ErrorCode::invalid_argument, concat(name, " = ", v, " is not a ", type, ": accepted ", accepted));
  }
}

/// "VK_FORMAT_B10G11R11_UFLOAT_PACK32", ...: every VkFormat by its enumerant name (a value unknown to
/// the headers as "VkFormat <number>"), so that every refusal names the format it refused.
std::string format_name(VkFormat format);

/// The checks every effect makes on a caller's buffer before recording, in one place so that
/// effects (and composites such as LensFlarePass) declare what they need instead of repeating
/// the tests. `where` names the call ("LightCuller::record"), `role` the argument ("instances").
/// Throws Error for a null buffer, a size of 0 or VK_WHOLE_SIZE (glint cannot query a VkBuffer's
/// size, so the caller states it), fewer than `need` bytes, a missing usage flag, or an offset
/// that is not a multiple of `offset_alignment`.
void check_buffer(const char* where, const char* role, const Buffer& b, VkDeviceSize need, VkBufferUsageFlags usage,
                  VkDeviceSize offset_alignment = 4);

/// Throws Error(unsupported_size) "<where>: <role> extent WxH is out of range: accepted 1 to N on
/// each side" (role may be empty) unless `e` fits the device's maxImageDimension2D. The message is
/// built only when it is thrown.
void check_extent(const Context& context, VkExtent2D e, const char* where, const char* role = "");

/// Throws Error(invalid_argument) for a null command buffer.
void check_command_buffer(const char* where, VkCommandBuffer cmd);

/// Throws Error(invalid_argument) if `image.layout` is not a VkImageLayout an image can be in
/// (a value outside the enumeration, or PREINITIALIZED for an image glint would read).
void check_image_layout(const char* where, const char* role, const Image& image);

}  // namespace glint::detail
