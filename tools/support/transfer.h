// Upload and readback of whole images through staging buffers, for tools and tests only (they
// submit and wait via Context::run_once, so they are never part of an effect's frame path).
#pragma once

#include <glint/glint.h>

#include <vector>

#include "core/cpu_image.h"
#include "core/resources.h"

namespace glint::detail {

/// Usage that test and tool images get: sampled, storage, transfer source and destination.
inline constexpr VkImageUsageFlags kToolImageUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

/// Copies `pixels` (RGBA float, converted to the image's format: RGBA16F, RGBA32F,
/// B10G11R11_UFLOAT (core/packed_float.h), RGB16F or RGB32F) into layer Image::base_array_layer of
/// `image` and leaves it in TRANSFER_DST_OPTIMAL, last written by a transfer. Sizes must match.
void upload(const Context& context, Image& image, const CpuImage& pixels);

/// Reads `image` (that layer) back as RGBA float (from any state; the state is updated). Formats
/// without alpha read as alpha 1.
CpuImage download(const Context& context, Image& image);

/// Copies one float per texel into R32_SFLOAT or the depth aspect of a depth `image` (depth
/// buffers, Hi-Z inputs; UNORM depth gets round(clamp(v, 0, 1) * (2^bits - 1))), leaving it in
/// TRANSFER_DST_OPTIMAL, last written by a transfer.
void upload_r32(const Context& context, Image& image, const std::vector<float>& values);

/// Reads mip `level` (of size `extent`) of an R32_SFLOAT or D32_SFLOAT image back, from any state
/// of its first `level_count` mips (the state is updated and covers them all).
std::vector<float> download_r32(const Context& context, Image& image, uint32_t level, VkExtent2D extent,
                                uint32_t level_count = 1);

// The same, recorded into a caller's command buffer (so that uploads, effects and readbacks share
// one submission): make_*_staging() makes and fills a host-visible buffer, record_upload() /
// record_readback() record the barrier and the copy (readback adds the barrier to host reads),
// read_staged() converts what a completed readback left in its staging buffer.

/// A staging buffer holding `pixels` in `image`'s format (as upload(); sizes must match).
OwnedBuffer make_upload_staging(const Context& context, const Image& image, const CpuImage& pixels);
/// A staging buffer holding one value per texel of `image` (as upload_r32()).
OwnedBuffer make_upload_staging_r32(const Context& context, const Image& image, const std::vector<float>& values);
/// Records the copy of a whole staging buffer into mip 0 of `image` (depth aspect for D32), leaving
/// it in TRANSFER_DST_OPTIMAL, last written by a transfer.
void record_upload(VkCommandBuffer cmd, const OwnedBuffer& staging, Image& image);
/// A host-visible buffer for reading mip 0 of `image` back.
OwnedBuffer make_readback_staging(const Context& context, const Image& image);
/// Records the copy of mip 0 of a colour `image` into `staging` and the barrier to host reads.
void record_readback(VkCommandBuffer cmd, Image& image, const OwnedBuffer& staging);
/// Makes every earlier transfer write visible to host reads after the submission completes
/// (COPY/TRANSFER_WRITE -> HOST/HOST_READ), the barrier every readback ends with.
void record_host_read_barrier(VkCommandBuffer cmd);
/// `image`'s texels (as download()) from a staging buffer a completed readback filled.
CpuImage read_staged(const OwnedBuffer& staging, const Image& image);

/// Fills `image` with `value` in every channel (NaN poisons: an unwritten texel stays NaN).
void fill(const Context& context, Image& image, float value);

/// Records (no submit) a barrier plus clear of `image` to `value`, updating its state.
void record_fill(VkCommandBuffer cmd, Image& image, float value);

}  // namespace glint::detail
