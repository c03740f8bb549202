// Upload and readback of whole images through staging buffers, for tools and tests only (they
// submit and wait via Context::run_once, so they are never part of an effect's frame path).
#pragma once

#include <glint/glint.h>

#include "core/cpu_image.h"
#include "core/resources.h"

#include <vector>

namespace glint::detail {

/// Usage that test and tool images get: sampled, storage, transfer source and destination.
inline constexpr VkImageUsageFlags kToolImageUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                                    VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

/// Copies `pixels` (RGBA float; converted to half for RGBA16F) into `image` and leaves it in
/// TRANSFER_DST_OPTIMAL, last written by a transfer. Sizes must match.
void upload(const Context& context, Image& image, const CpuImage& pixels);

/// Reads `image` back as RGBA float (from any state; the state is updated).
CpuImage download(const Context& context, Image& image);

/// Copies one float per texel into a D32_SFLOAT or R32_SFLOAT `image` (depth buffers, Hi-Z
/// inputs), leaving it in TRANSFER_DST_OPTIMAL, last written by a transfer.
void upload_r32(const Context& context, Image& image, const std::vector<float>& values);

/// Reads mip `level` (of size `extent`) of an R32_SFLOAT or D32_SFLOAT image back, from any state
/// of its first `level_count` mips (the state is updated and covers them all).
std::vector<float> download_r32(const Context& context, Image& image, uint32_t level, VkExtent2D extent,
                                uint32_t level_count = 1);

/// Fills `image` with `value` in every channel (NaN poisons: an unwritten texel stays NaN).
void fill(const Context& context, Image& image, float value);

/// Records (no submit) a barrier plus clear of `image` to `value`, updating its state.
void record_fill(VkCommandBuffer cmd, Image& image, float value);

}  // namespace glint::detail
