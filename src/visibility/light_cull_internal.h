// Internal switch of the light cull's path for benchmarks and tests (not installed).
#pragma once

#include <glint/occlusion.h>

#include <cstdint>

namespace glint::detail {

/// The dispatches LightCuller::record() makes (docs/OCCLUSION.md, "Cull, occlusion grid test and
/// compaction").
enum class LightCullPath : uint32_t {
  /// As the light count decides: `one_group` up to LightCuller::one_group_lights(), else `groups`.
  /// The default.
  device,
  /// light_cull.comp, compact_scan_tiles.comp, light_cull_scan.comp, light_cull_scatter.comp:
  /// workgroups of 64 lights, then the ordered compaction.
  groups,
  /// light_cull.comp built with GLINT_CULL_ONE_GROUP: one workgroup culls every light, in chunks of
  /// its size, and writes the instances, arguments and statistics itself. Any count, on any device.
  /// Up to half as many lights as invocations share their samples over the workgroup on GPUs, not
  /// on CPU devices (docs/OCCLUSION.md, "One workgroup for few lights").
  one_group,
  /// `one_group` with the samples shared wherever the count allows, on any device (tests run the
  /// shared build on CPU devices so).
  one_group_shared_samples,
  /// light_cull.comp built with GLINT_CULL_ONE_GROUP and GLINT_CULL_FROM_DEPTH: a workgroup per
  /// sample reads its window's pixels from the depth image, the last to finish culls every light
  /// as `one_group` does (one invocation per light). Up to 65535 / N^2 lights (record() refuses more),
  /// on any device; the pyramid is not read.
  depth,
  /// As `device` without `depth`: `one_group` up to one_group_lights(), else `groups` (the choice
  /// before the depth path existed; for comparisons).
  pyramid,
};

struct LightCullAccess {
  /// Selects the path `culler` records from now on.
  static void select_path(LightCuller& culler, LightCullPath path);
  /// The depth-image cull's workgroup (32 to the one-workgroup size, a multiple of 32; the default is
  /// 256 or that size if smaller): each sample's workgroup and the last one, which culls chunks of
  /// that many lights.
  static void set_depth_workgroup(LightCuller& culler, uint32_t size);
};

}  // namespace glint::detail
