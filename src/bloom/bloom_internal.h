// Bloom's dispatch structure, switchable for benchmarks and tests (not installed, not public API):
// docs/BLOOM.md "Dispatches" says what each switch fuses and what each costs. The default is one
// dispatch per level (both off): on the NVIDIA H100 each fusion measured slower (docs/BLOOM.md).
#pragma once

#include <glint/bloom.h>

#include "core/pipeline.h"

namespace glint::detail {

struct BloomPath {
  /// The levels that fit one workgroup's shared memory run in one dispatch (bloom_tail.comp):
  /// their downsamples, blurs and upsamples back to the level above them.
  bool fuse_small_levels = false;
  /// The composite evaluates A(0) = level 0 + Up(A(1)) itself (bloom_composite_up.comp) instead of
  /// an upsample dispatch writing A(0) over level 0.
  bool fuse_last_up = false;
  /// Where an image is exactly twice the level it upsamples on both axes and the filter is
  /// separable (cod13, gauss9), the composite (bloom_composite_2x.comp) and the upsample steps
  /// (bloom_up_2x.comp) run one invocation per 2x2 block instead of the tiled kernels.
  bool composite_2x = true;
  bool up_2x = true;
  /// Whether those 2:1 kernels store their blocks' outputs in copy order through shared memory
  /// (src/bloom/shaders/bloom_up_2x.glsl, COPY_ORDER): as the device type decides (GPUs yes, CPU
  /// devices no), or forced either way (tests reach both forms on any device).
  enum class CopyOrder { device, on, off };
  CopyOrder copy_order_2x = CopyOrder::device;
  /// Workgroup shapes per kind of kernel: the downsamples (bloom_down, level0_height's steps
  /// included), the upsamples (bloom_up, bloom_up_2x) and the composite (bloom_composite,
  /// bloom_composite_2x; not bloom_composite_up, the fused path's). {0, 0}: the bloom's own shape,
  /// which the bright-pass kernels, the gauss9 blur and the small-levels dispatch always take.
  /// BloomAccess::set_path() refuses a shape the device cannot run (its invocations or the
  /// kernels' shared memory).
  Workgroup2D down_workgroup{0, 0};
  Workgroup2D up_workgroup{0, 0};
  Workgroup2D composite_workgroup{0, 0};
};

struct BloomAccess {
  /// Replaces the path; makes the pipelines it needs (here, not in record()).
  static void set_path(Bloom& bloom, const BloomPath& path);
  static BloomPath path(const Bloom& bloom);
  /// The level T that the small-levels dispatch reads and accumulates into at the current size,
  /// or -1 when it does not run (switched off, one level, or the levels below every T do not fit).
  static int small_levels_top(const Bloom& bloom);
};

}  // namespace glint::detail
