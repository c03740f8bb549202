// Helpers shared by the Hi-Z pyramid (hiz_pyramid.cpp) and the light culler (light_culler.cpp).
// Internal.
#pragma once

#include <glint/glint.h>

#include <cstdint>

#include "core/check.h"
#include "core/resources.h"

namespace glint::visibility_detail {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kSampled = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
constexpr VkAccessFlags2 kStorageRead = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
constexpr VkAccessFlags2 kStorageWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

// A glint-made buffer described as a glint::Buffer with its last use.
inline Buffer view_of(const detail::OwnedBuffer& b, VkBufferUsageFlags usage) {
  Buffer v;
  v.buffer = b.buffer();
  v.size = b.size();
  v.usage = usage;
  return v;
}

// Integer range check whose message prints the values exactly (check_range formats doubles).
inline void check_uint(const char* name, uint64_t value, uint64_t lo, uint64_t hi) {
  if (value < lo || value > hi) {
    throw Error(ErrorCode::invalid_argument,
                detail::concat(name, " = ", value, " is out of range: accepted ", lo, " to ", hi));
  }
}

}  // namespace glint::visibility_detail
