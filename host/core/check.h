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
    throw Error(ErrorCode::invalid_argument,
                concat(name, " = ", value, " is out of range: accepted ", lo, " to ", hi));
  }
}

const char* format_name(VkFormat format);

}  // namespace glint::detail
