// Internal switches of the object cull for benchmarks and tests (not installed).
#pragma once

#include <glint/object_cull.h>

#include <cstdint>

namespace glint::detail {

/// The test kernels an ObjectCuller can run (object_cull_select_kernel()).
enum class ObjectCullKernel : uint32_t {
  /// object_cull.comp; its subgroup variants (per-group counts reduced over each subgroup) where
  /// the device's subgroups support arithmetic in compute, else the shared-atomic ones. The default.
  current,
  /// object_cull.comp counting with shared atomics alone (what devices without subgroup arithmetic
  /// run), in every mode: the tests reach it on any device.
  shared_atomics,
  /// object_cull_v1.comp (the same test before the cost work of docs/OCCLUSION.md "Cost") for the
  /// single-phase record(); phase 1 and 2 run `current`. glint_bench times it against `current`.
  previous,
  /// `current`, with the subgroup tile scan forced onto the serial path it takes where a subgroup's
  /// invocations are not consecutive (object_cull_scan.comp): the tests reach that path on any
  /// device with the subgroup variants (elsewhere this is `current`).
  serial_scan,
  /// `current`, with the subgroup tile scan as a device may run it that launches subgroup 0 with
  /// inactive invocations (its odd ones sit out the scan of the subgroups' totals) and whose
  /// subgroups of odd index hold invocations out of order (object_cull_scan.comp): the tests reach
  /// that case on any device with the subgroup variants and subgroups of 2 or more invocations
  /// (elsewhere this is `current`).
  partial_scan,
};

/// Selects the kernel `culler` records from now on. Call it while no recorded cull of `culler` is
/// pending: it may replace the tile-scan pipeline a pending command buffer uses.
void object_cull_select_kernel(ObjectCuller& culler, ObjectCullKernel kernel);
/// Whether `culler` runs the subgroup variants in ObjectCullKernel::current (the device supports them).
bool object_cull_has_subgroup_variant(const ObjectCuller& culler);

}  // namespace glint::detail
