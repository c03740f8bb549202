// Internal switch of the Hi-Z build for benchmarks and tests (not installed).
#pragma once

#include <glint/occlusion.h>

#include <cstdint>

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

struct HiZAccess {
  /// Selects the stream pass `hiz` records from now on (making its pipelines here). Call it while
  /// no recorded build of `hiz` is pending.
  static void select_stream(HiZPyramid& hiz, HiZStream stream);
  /// The stream pass `hiz` records: `blocks` or `texels`, never `device`.
  static HiZStream stream(const HiZPyramid& hiz);
};

}  // namespace glint::detail
