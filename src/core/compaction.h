// The ordered compaction shared by the object cull and the light cull (src/core/shaders/compact.glsl,
// docs/OCCLUSION.md "The shared compaction core"): the user's test kernel sets one bit per emitted item in
// its 64-item group's mask of the group buffer this owns; record_scan() runs the two-level scan
// (compact_scan_tiles.comp, then the user's top-level scan, which writes the user's indirect
// arguments and statistics and resets the header's counters); record_scatter() runs the user's
// scatter, which puts every emitted item's record into its slot in item order, clamped to the
// capacity. A user with no top-level scan kernel (the object cull) records its own tile scan.
#pragma once

#include <glint/glint.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <string>

#include "core/barriers.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "core/shaders/compact_params.h"

namespace glint::detail {

class Compaction {
 public:
  struct Desc {
    uint32_t max_items = 1;  //!< items of the largest run (a group buffer of ceil(max_items / 64) groups)
    /// The user's top-level scan (compact_top_scan of compact.glsl, then its outputs): binding 0
    /// the group buffer, then `scan_outputs` storage buffers it writes. Empty: no scan pipeline is
    /// made (the user dispatches its own tile scan, one workgroup of tile_groups() invocations per
    /// tile, and its scatter adds the totals of the tiles before each item's tile itself).
    std::string scan_kernel;
    uint32_t scan_outputs = 2;
    /// The scatter: one workgroup of 64 invocations per `scatter_groups` consecutive groups (a 2D
    /// grid, groups_x per row; at least one workgroup, also for no items); binding 0 the group
    /// buffer, then `scatter_inputs` storage buffers it reads and `scatter_outputs` it writes.
    std::string scatter_kernel;
    uint32_t scatter_inputs = 1;
    uint32_t scatter_outputs = 1;
    uint32_t scatter_groups = GLINT_COMPACT_SCATTER_GROUPS;
  };

  Compaction() = default;
  Compaction(const Context& context, const Desc& desc);

  /// The group buffer (header counters, then one uvec4 per group): the user's test kernel writes
  /// each group's mask (x, y) and adds to the counters.
  Buffer& groups() { return groups_state_; }
  /// Groups per tile of the scan (the scan workgroup's size, from the device).
  uint32_t tile_groups() const { return scan_threads_; }

  /// Zeroes the header's counters the first time (the top-level scan resets them after every run).
  void record_clear_once(VkCommandBuffer cmd, Barriers& b);
  /// The two-level scan of `push.count` items; `outputs` are the top-level scan's buffers (read and
  /// written). Fills push.tile_groups.
  void record_scan(VkCommandBuffer cmd, Barriers& b, GlintCompactPush push, std::initializer_list<Buffer*> outputs);
  /// The scatter of `push.count` items: `inputs` read, `outputs` written. Fills push.tile_groups and
  /// push.groups_x.
  void record_scatter(VkCommandBuffer cmd, Barriers& b, GlintCompactPush push, std::initializer_list<Buffer*> inputs,
                      std::initializer_list<Buffer*> outputs);

 private:
  static constexpr size_t kMaxBuffers = 6;  // user buffers of one kernel (after the group buffer)
  uint32_t max_groups_x_ = 65535;
  uint32_t scan_threads_ = 1;
  uint32_t scatter_groups_ = 1;
  ComputePipeline scan_tiles_, scan_, scatter_;
  OwnedBuffer groups_;
  Buffer groups_state_;
  bool counters_cleared_ = false;
};

}  // namespace glint::detail
