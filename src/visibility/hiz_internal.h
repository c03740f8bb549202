// Internal switch of the Hi-Z build for benchmarks and tests (not installed).
#pragma once

#include <glint/occlusion.h>

#include <cstdint>
#include <string>

#include "visibility/shaders/light_cull_params.h"

namespace glint::detail {

/// The stream pass an HiZPyramid runs (docs/OCCLUSION.md, "Hi-Z pyramid").
enum class HiZStream : uint32_t {
  /// As the device type decides: `blocks` on GPUs, `texels` on CPU devices. The default.
  device,
  /// hiz_stream.comp: levels 1 to 6 by 64x64 blocks of the depth image, through shared memory;
  /// the tile pass starts at level 6.
  blocks,
  /// hiz_stream_texels.comp: levels 1 and 2, one invocation per level-2 texel, no shared memory or
  /// barrier; the tile pass starts at level 2.
  texels,
};

/// Levels the stream pass `s` (`blocks` or `texels`) writes from the depth image; the tile pass
/// starts at that level.
constexpr uint32_t hiz_stream_levels(HiZStream s) { return s == HiZStream::blocks ? GLINT_HIZ_STREAM_LEVELS : 2u; }

/// Compute shared memory the Hi-Z kernels declare, in bytes: the ping-pong tiles of hiz_fold.glsl
/// (64x64 and 32x32 floats), which the block stream pass and the tile pass use, and the tile pass's
/// last-workgroup flag. The texel stream pass declares none.
constexpr uint32_t kHiZSharedBytes = (64 * 64 + 32 * 32) * 4 + 4;

/// The stream pass a pyramid of `levels` levels runs on a device of type `type` with
/// `shared_bytes` of compute shared memory (maxComputeSharedMemorySize), asked for `requested`:
/// `device` resolves to `blocks` on GPUs and `texels` on CPU devices, and to `texels` where the
/// blocks do not fit. Throws Error(no_device), naming the device and both sizes, where the passes
/// it needs do not fit: `blocks` asked for by name, or the tile pass (a pyramid of more levels
/// than the stream pass writes). Vulkan guarantees 16 KiB; lavapipe and desktop GPUs have 32 KiB
/// or more.
HiZStream hiz_resolve_stream(HiZStream requested, VkPhysicalDeviceType type, uint32_t shared_bytes, uint32_t levels,
                             const std::string& device_name);

struct HiZAccess {
  /// Selects the stream pass `hiz` records from now on (making its pipelines here). Call it while
  /// no recorded build of `hiz` is pending.
  static void select_stream(HiZPyramid& hiz, HiZStream stream);
  /// The stream pass `hiz` records: `blocks` or `texels`, never `device`.
  static HiZStream stream(const HiZPyramid& hiz);
};

}  // namespace glint::detail
