// Internal switch of the compute flare draw's path for benchmarks and tests (not installed).
#pragma once

#include <glint/flare.h>

#include <cstdint>

namespace glint::detail {

/// The dispatches LensFlare::record_compute() makes (docs/FLARE.md, "Compute (record_compute)").
enum class FlareGatherPath : uint32_t {
  /// As the instances buffer's size decides: `one_dispatch` up to
  /// LensFlare::one_dispatch_instances() instances, else `pre_pass`. The default.
  device,
  /// flare_gather_args.comp, flare_sprites.comp, flare_gather.comp: the launch arguments, every
  /// sprite evaluated once, then the gather reading them.
  pre_pass,
  /// flare_gather.comp with kFused: the gather evaluates the sprites itself, one per invocation,
  /// in batches of (workgroup size / 9) instances. Any count, on any device whose gather workgroup
  /// holds at least 9 invocations (else the pre-pass).
  one_dispatch,
};

struct LensFlareAccess {
  /// Selects the path `flare` records from now on.
  static void select_gather(LensFlare& flare, FlareGatherPath path);
};

}  // namespace glint::detail
