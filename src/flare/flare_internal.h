// Internal switch of the compute flare draw's path for benchmarks and tests (not installed).
#pragma once

#include <glint/flare.h>

#include <cstdint>

#include "flare/shaders/flare_params.h"

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

/// One tile of a gather: `width` x `height` pixels; invocation (x, y) shades rows y, y + row_step,
/// ... of column x (row_step is the workgroup height, height / row_step the rows per invocation).
struct FlareGatherTile {
  uint32_t width = 0, height = 0, row_step = 0;
  bool centre_first = false;  // the workgroups take the tiles from the image centre outwards
};

struct LensFlareAccess {
  /// Selects the path `flare` records from now on.
  static void select_gather(LensFlare& flare, FlareGatherPath path);
  /// The tile of the one-dispatch gather, or of the pre-pass gather for an instances buffer of
  /// `instances` instances (workgroup x by workgroup y * rows; full tiles with the split of crowded
  /// tiles from GLINT_FLARE_SPLIT_FROM_INSTANCES on GPUs).
  static FlareGatherTile gather_tile(const LensFlare& flare, bool one_dispatch, uint64_t instances);
  /// Makes the pre-pass gathers, with and without the split (and those beyond the sprite store),
  /// shade `rows` pixels per invocation from now on, 1 to GLINT_FLARE_GATHER_ROWS, their
  /// workgroups taking the tiles from the image centre outwards or in their IDs' order (tests:
  /// every tile height and order gives the same bits). Remakes pipelines and buffers: call it only
  /// while no command buffer recorded with `flare` is pending.
  static void set_pre_pass_tiles(LensFlare& flare, uint32_t rows, bool centre_first);
  /// Makes every pre-pass draw split crowded tiles, or none (by default GPUs split them for
  /// instances buffers of GLINT_FLARE_SPLIT_FROM_INSTANCES and more, CPU devices never); a tile
  /// counting at least `min_sprites` sprites gets min(count / sprites_per_slice, max_slices)
  /// slices (flare_params.h, "Crowded tiles"; tests split many tiles with small values).
  /// max_slices is 1 to 31. May remake pipelines and buffers, as set_pre_pass_tiles().
  static void set_split(LensFlare& flare, bool on, uint32_t min_sprites = GLINT_FLARE_SPLIT_MIN_SPRITES,
                        uint32_t sprites_per_slice = GLINT_FLARE_SPLIT_SPRITES,
                        uint32_t max_slices = GLINT_FLARE_SPLIT_MAX_SLICES);
  /// Makes the pre-pass gathers (with and without the split), or with `one_dispatch` the
  /// one-dispatch gather, run in workgroups of x by y (tiles x wide) from now on, each invocation
  /// shading as many rows as before, or (one-dispatch gather) `rows` if not 0: the benchmarks
  /// compare shapes per device. The one-dispatch limit follows its workgroup's size (GPUs). x * y
  /// is GLINT_FLARE_SPRITES (one instance's sprites) to GLINT_FLARE_GATHER_MAX_THREADS; rows is 0
  /// (unchanged), or 1 to GLINT_FLARE_GATHER_ROWS for the one-dispatch gather. Remakes pipelines
  /// and buffers, as set_pre_pass_tiles().
  static void set_gather_workgroup(LensFlare& flare, uint32_t x, uint32_t y, bool one_dispatch = false,
                                   uint32_t rows = 0);
  /// Caps the instances whose sprites the pre-pass stores at `instances` (at least 1; at most what
  /// one descriptor holds, LensFlare's own limit), dropping the stores made so far: the gather
  /// evaluates the sprites of every instance beyond, as it does beyond maxStorageBufferRange, so
  /// tests reach that path on every device. Call it only while no command buffer recorded with
  /// `flare` is pending.
  static void set_max_stored_instances(LensFlare& flare, uint32_t instances);
  /// Instances whose sprites the last pre-pass draw stored at most (its store's capacity; 0 before
  /// any).
  static uint32_t sprite_store_capacity(const LensFlare& flare);
  /// Whether record_compute() splits crowded tiles in a pre-pass draw from an instances buffer of
  /// `instances` instances.
  static bool splits(const LensFlare& flare, uint64_t instances);
  /// The split words (layout in flare_params.h, for the tiles gather_tile() gives for a split
  /// draw) as the last split pre-pass draw left them (tests read the plan back).
  static Buffer split_words(const LensFlare& flare);
};

}  // namespace glint::detail
