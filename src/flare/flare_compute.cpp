// Lens-flare compute path: the sprite pre-pass and the tiled gather (its arguments written on the
// device from the instance count) and LensFlare::record_compute(). docs/FLARE.md, "Compute (record_compute)".
#include "flare/flare_impl.h"

namespace glint {

using namespace flare_detail;
using detail::concat;

detail::ComputePipeline LensFlare::Impl::make_gather(uint32_t beyond_store, uint32_t one_dispatch, bool split) const {
  const auto SB = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  detail::PipelineDesc d;
  d.kernel_id = std::string("flare_gather_") + detail::format_variant(format);
  d.bindings = {SB, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, SB, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, SB, SB, SB};
  d.push_constant_bytes = sizeof(GlintFlarePush);
  const GatherTiles& tiles = one_dispatch ? tiles_one_dispatch : split ? tiles_split : tiles_pre_pass;
  d.workgroup = tiles.group;
  d.specialization = {beyond_store, one_dispatch, tiles.rows, tiles.centre_first ? 1u : 0u, split ? 1u : 0u};
  return detail::ComputePipeline(*context, d);
}

void LensFlare::Impl::make_split_buffers() {
  // (TRANSFER_SRC: tests read the plan back.)
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const VkDeviceSize words = GLINT_FLARE_SPLIT_WORDS(tiles_split.x * tiles_split.y);
  split_buffer = detail::OwnedBuffer(*context, words * 4, usage, false);
  split_state = Buffer{split_buffer.buffer(), 0, words * 4, usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  split_cleared = false;
  // A slot holds one slice's sums: one vec4 per pixel of a tile.
  const VkDeviceSize partial_bytes = split() ? VkDeviceSize(GLINT_FLARE_SPLIT_SLOTS) * tiles_split.group.x *
                                                   tiles_split.group.y * tiles_split.rows * 16
                                             : 16;
  partials_buffer = detail::OwnedBuffer(*context, partial_bytes, usage, false);
  partials_state =
      Buffer{partials_buffer.buffer(), 0, partial_bytes, usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
}

LensFlare::Impl::GatherTiles LensFlare::Impl::gather_tiles(uint32_t rows, bool centre_first,
                                                           detail::Workgroup2D group) const {
  const uint32_t tile_h = group.y * rows;
  return {rows, (extent.width + group.x - 1) / group.x, (extent.height + tile_h - 1) / tile_h, centre_first, group};
}

void LensFlare::Impl::make_compute_pipelines() {
  const auto SB = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  gather = make_gather(0, 0);
  // The one-dispatch gather, here where the device takes it by itself (so that a first frame does
  // not compile it); on CPU devices only a forced path makes it, at its first use.
  if (one_dispatch_limit > 0) gather_one_dispatch = make_gather(0, 1);
  detail::PipelineDesc sp;
  sp.kernel_id = "flare_sprites_main";
  sp.bindings = {SB, SB, SB, SB};
  sp.push_constant_bytes = sizeof(GlintFlarePush);
  sp.workgroup = {GLINT_FLARE_SPRITES_SLOTS, GLINT_FLARE_SPRITES_INSTANCES};
  sp.specialization = {0u};
  sprites = detail::ComputePipeline(*context, sp);
  if (split()) {  // the split's pipelines (the one beyond the sprite store at its first use)
    sp.specialization = {1u};
    sprites_count = detail::ComputePipeline(*context, sp);
    gather_split = make_gather(0, 0, true);
    detail::PipelineDesc sd;
    sd.kernel_id = "flare_split_plan_main";
    sd.bindings = {SB, SB, SB};
    sd.push_constant_bytes = sizeof(GlintFlareSplitPush);
    sd.workgroup = {GLINT_FLARE_SPLIT_PLAN_THREADS, 1};
    split_plan = detail::ComputePipeline(*context, sd);
  }
  make_split_buffers();
  detail::PipelineDesc a;
  a.kernel_id = "flare_gather_args_main";
  a.bindings = {SB, SB};
  a.push_constant_bytes = sizeof(GlintFlareGatherArgsPush);
  a.workgroup = {1, 1};
  gather_args = detail::ComputePipeline(*context, a);
  // The gather's and the pre-pass's VkDispatchIndirectCommand, written on the GPU each frame.
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  gather_args_buffer = detail::OwnedBuffer(*context, 32, usage, false);
  gather_args_state = Buffer{gather_args_buffer.buffer(), 0, 32, usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
}
void LensFlare::record_compute(VkCommandBuffer cmd, Image& color, Buffer& instances, Buffer& indirect,
                               const FlareConfig& config, Profiler* profiler) {
  detail::check_command_buffer("LensFlare::record_compute", cmd);
  Impl& m = *impl_;
  m.check_inputs("LensFlare::record_compute", color, VK_IMAGE_USAGE_STORAGE_BIT, "VK_IMAGE_USAGE_STORAGE_BIT",
                 instances, indirect, config);
  if (!(indirect.usage & VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)) {
    throw Error(ErrorCode::missing_usage,
                "LensFlare::record_compute: indirect buffer lacks VK_BUFFER_USAGE_STORAGE_BUFFER_BIT usage (the "
                "compute path reads the instance count from it)");
  }
  if (instances.size / sizeof(GlintFlareInstance) > max_compute_instances()) {
    throw Error(
        ErrorCode::invalid_argument,
        concat("LensFlare::record_compute: the instances buffer holds ", instances.size / sizeof(GlintFlareInstance),
               " instances; one storage-buffer descriptor holds at most ", max_compute_instances()));
  }
  if (!config.enabled || config.intensity == 0.0f) return;  // adds nothing: record nothing
  m.record_setup(cmd);

  // The indirect arguments are read as words from a storage-buffer binding whose offset is rounded
  // down to minStorageBufferOffsetAlignment; the push constant says where group_count_x is.
  const VkDeviceSize args_offset = indirect.offset + offsetof(GlintFlareIndirect, instance_count);
  const VkDeviceSize bound_offset = args_offset - args_offset % m.storage_alignment;
  const Buffer indirect_words{indirect.buffer, bound_offset,   args_offset - bound_offset + sizeof(uint32_t),
                              indirect.usage,  indirect.stage, indirect.access};
  GlintFlarePush p = m.push(config);
  p.indirect_word = uint32_t((args_offset - bound_offset) / sizeof(uint32_t));
  detail::Barriers b;
  // (A workgroup of fewer than GLINT_FLARE_SPRITES invocations, which ContextOptions::workgroup_2d
  // can force, holds no instance's sprites: it always takes the pre-pass.)
  const bool one_dispatch =
      m.one_dispatch_batch() > 0 && (m.gather_path == detail::FlareGatherPath::one_dispatch ||
                                     (m.gather_path == detail::FlareGatherPath::device &&
                                      instances.size / sizeof(GlintFlareInstance) <= m.one_dispatch_limit));
  if (one_dispatch) {
    // The gather evaluates the sprites itself: one dispatch of every tile, launched whatever the
    // count (each tile of a frame without instances reads the count and stores nothing). `blocks`
    // (binding 4) is not read; the instances buffer stands in for it.
    if (!m.gather_one_dispatch) m.gather_one_dispatch = m.make_gather(0, 1);
    b.use(indirect, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    b.use(instances, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    b.use(m.atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
          GLINT_FLARE_ATLAS_LEVELS);
    b.use(color, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageRW);
    // Bound for the shader's declarations; this gather splits no tile and does not read them.
    b.use(m.split_state, kCompute, kStorageRW);
    b.use(m.partials_state, kCompute, kStorageRW);
    b.flush(cmd);
    const Impl::GatherTiles& tiles = m.tiles_one_dispatch;
    p.tile_w = tiles.group.x;
    p.tile_h = tiles.group.y * tiles.rows;
    m.gather_one_dispatch.dispatch(cmd,
                                   {instances,
                                    m.atlas_binding(),
                                    indirect_words,
                                    {color.view, VK_IMAGE_LAYOUT_GENERAL},
                                    instances,
                                    m.split_state,
                                    m.partials_state},
                                   p, tiles.x * tiles.group.x, tiles.y * tiles.group.y);
    if (profiler) profiler->mark(cmd, "flare gather");
    return;
  }

  // Instances whose sprites the pre-pass stores (all of them up to max_stored_instances).
  const uint32_t capacity = std::min(uint32_t(instances.size / sizeof(GlintFlareInstance)), m.max_stored_instances);
  if (m.sprite_stores.empty() || m.sprite_stores.back()->capacity < capacity) {
    // A new store for the larger buffer, twice the last one (at most the descriptor's limit), so
    // that buffers growing one by one make few stores.
    uint32_t c = m.sprite_stores.empty() ? 1u : m.sprite_stores.back()->capacity;
    c = std::max(capacity, std::min(2 * c, m.max_stored_instances));
    auto store = std::make_unique<Impl::SpriteStore>();
    const VkDeviceSize bytes = VkDeviceSize(c) * kBlockBytes;
    store->buffer = detail::OwnedBuffer(*m.context, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
    store->state =
        Buffer{store->buffer.buffer(), 0, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_PIPELINE_STAGE_2_NONE,
               VK_ACCESS_2_NONE};
    store->capacity = c;
    m.sprite_stores.push_back(std::move(store));
  }
  Impl::SpriteStore& sprite_store = *m.sprite_stores.back();
  Buffer& store = sprite_store.state;
  // The instances buffer holds more than the store: the gather evaluates the rest itself.
  const bool beyond = instances.size / sizeof(GlintFlareInstance) > sprite_store.capacity;
  // Crowded tiles split (in full tiles) for buffers of split_from instances and more.
  const bool split = m.splits(instances.size / sizeof(GlintFlareInstance));
  const Impl::GatherTiles& tiles = split ? m.tiles_split : m.tiles_pre_pass;
  detail::ComputePipeline& beyond_gather = split ? m.gather_beyond_split : m.gather_beyond;
  if (beyond && !beyond_gather) beyond_gather = m.make_gather(1, 0, split);

  GlintFlareGatherArgsPush ap{p.indirect_word, tiles.x, tiles.y, std::min(capacity, sprite_store.capacity),
                              m.max_groups_x};
  // 1. The launch arguments: every tile when any instance is visible, none otherwise; the
  //    pre-pass's groups for the instances.
  b.use(indirect, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(m.gather_args_state, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  m.gather_args.dispatch(cmd, {indirect_words, m.gather_args_state}, ap, 1, 1);
  if (profiler) profiler->mark(cmd, "flare arguments");
  if (split && !m.split_cleared) {  // once per split buffer: after it, the plan zeroes the words it reads
    detail::record_zero_fill(cmd, b, m.split_state);
    m.split_cleared = true;
  }
  // 2. The sprite pre-pass: every sprite of every instance, once (with the split, each tile's
  //    count of sprites too).
  p.tile_w = tiles.group.x;
  p.tile_h = tiles.group.y * tiles.rows;
  b.use(m.gather_args_state, kIndirect, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  b.use(instances, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(store, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.use(m.split_state, kCompute, kStorageRW);
  b.flush(cmd);
  (split ? m.sprites_count : m.sprites)
      .dispatch_indirect(cmd, {instances, indirect_words, store, m.split_state}, p, m.gather_args_buffer.buffer(), 16);
  if (profiler) profiler->mark(cmd, "flare sprites");
  if (split) {
    // 2b. The split plan: each tile's slices, the slots, and the gather's launch with the slots'
    //     workgroups (rewriting the gather's arguments).
    GlintFlareSplitPush sp = m.split_params;
    sp.indirect_word = p.indirect_word;
    sp.tiles_x = tiles.x;
    sp.tiles_y = tiles.y;
    sp.capacity = ap.capacity;
    b.use(m.split_state, kCompute, kStorageRW);
    b.use(m.gather_args_state, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    b.flush(cmd);
    m.split_plan.dispatch(cmd, {indirect_words, m.split_state, m.gather_args_state}, sp, GLINT_FLARE_SPLIT_PLAN_THREADS,
                          1);
    if (profiler) profiler->mark(cmd, "flare split plan");
  }
  // 3. The gather, one workgroup per tile (and per further slice of a split tile).
  b.use(m.gather_args_state, kIndirect, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  b.use(store, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(m.atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
        GLINT_FLARE_ATLAS_LEVELS);
  b.use(color, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageRW);
  b.use(m.split_state, kCompute, kStorageRW);
  b.use(m.partials_state, kCompute, kStorageRW);
  b.flush(cmd);
  (beyond  ? beyond_gather
   : split ? m.gather_split
           : m.gather)
      .dispatch_indirect(cmd,
                         {instances,
                          m.atlas_binding(),
                          indirect_words,
                          {color.view, VK_IMAGE_LAYOUT_GENERAL},
                          store,
                          m.split_state,
                          m.partials_state},
                         p, m.gather_args_buffer.buffer(), 0);
  if (profiler) profiler->mark(cmd, "flare gather");
}

namespace detail {

void LensFlareAccess::select_gather(LensFlare& flare, FlareGatherPath path) { flare.impl_->gather_path = path; }

FlareGatherTile LensFlareAccess::gather_tile(const LensFlare& flare, bool one_dispatch, uint64_t instances) {
  const LensFlare::Impl& m = *flare.impl_;
  const LensFlare::Impl::GatherTiles& t = one_dispatch          ? m.tiles_one_dispatch
                                          : m.splits(instances) ? m.tiles_split
                                                                : m.tiles_pre_pass;
  return {t.group.x, t.group.y * t.rows, t.group.y, t.centre_first};
}

void LensFlareAccess::set_pre_pass_tiles(LensFlare& flare, uint32_t rows, bool centre_first) {
  if (rows < 1 || rows > GLINT_FLARE_GATHER_ROWS) {
    throw Error(ErrorCode::invalid_argument, concat("LensFlareAccess::set_pre_pass_tiles: rows is ", rows,
                                                    "; accepted 1 to ", GLINT_FLARE_GATHER_ROWS));
  }
  LensFlare::Impl& m = *flare.impl_;
  m.tiles_pre_pass = m.tiles_split = m.gather_tiles(rows, centre_first, m.tiles_pre_pass.group);
  m.gather = m.make_gather(0, 0);
  if (m.split()) m.gather_split = m.make_gather(0, 0, true);
  m.gather_beyond = {};  // both made again at their next use, with these tiles
  m.gather_beyond_split = {};
  m.make_split_buffers();
}

void LensFlareAccess::set_gather_workgroup(LensFlare& flare, uint32_t x, uint32_t y, bool one_dispatch, uint32_t rows) {
  LensFlare::Impl& m = *flare.impl_;
  const uint64_t threads = uint64_t(x) * y;
  if (x < 1 || y < 1 || threads < GLINT_FLARE_SPRITES || threads > GLINT_FLARE_GATHER_MAX_THREADS ||
      threads > m.context->info().max_workgroup_invocations || rows > GLINT_FLARE_GATHER_ROWS ||
      (!one_dispatch && rows != 0)) {
    throw Error(ErrorCode::invalid_argument,
                concat("LensFlareAccess::set_gather_workgroup: ", x, "x", y, " with ", rows,
                       " rows is out of range: accepted ", GLINT_FLARE_SPRITES, " to ",
                       std::min<uint32_t>(GLINT_FLARE_GATHER_MAX_THREADS, m.context->info().max_workgroup_invocations),
                       " invocations and 0 (unchanged) to ", GLINT_FLARE_GATHER_ROWS,
                       " rows (the one-dispatch gather only; 0 for the pre-pass gathers)"));
  }
  LensFlare::Impl::GatherTiles& one = m.tiles_one_dispatch;
  if (one_dispatch) {
    one = m.gather_tiles(rows != 0 ? rows : one.rows, one.centre_first, {x, y});
    if (m.one_dispatch_limit > 0) m.one_dispatch_limit = m.one_dispatch_batch();
  } else {
    m.tiles_pre_pass = m.gather_tiles(m.tiles_pre_pass.rows, m.tiles_pre_pass.centre_first, {x, y});
    m.tiles_split = m.gather_tiles(m.tiles_split.rows, m.tiles_split.centre_first, {x, y});
  }
  m.gather_one_dispatch = {};  // made again by make_compute_pipelines() on GPUs, else at its next use
  m.make_compute_pipelines();
  m.gather_beyond = {};
  m.gather_beyond_split = {};
}

void LensFlareAccess::set_max_stored_instances(LensFlare& flare, uint32_t instances) {
  LensFlare::Impl& m = *flare.impl_;
  if (instances < 1) {
    throw Error(ErrorCode::invalid_argument,
                "LensFlareAccess::set_max_stored_instances: instances is 0; accepted 1 and more");
  }
  m.max_stored_instances = std::min(m.max_stored_instances, instances);
  m.sprite_stores.clear();
}

uint32_t LensFlareAccess::sprite_store_capacity(const LensFlare& flare) {
  const LensFlare::Impl& m = *flare.impl_;
  return m.sprite_stores.empty() ? 0u : m.sprite_stores.back()->capacity;
}

void LensFlareAccess::set_split(LensFlare& flare, bool on, uint32_t min_sprites, uint32_t sprites_per_slice,
                                uint32_t max_slices) {
  if (sprites_per_slice < 1 || max_slices < 1 || max_slices > 31) {
    throw Error(ErrorCode::invalid_argument,
                concat("LensFlareAccess::set_split: sprites_per_slice is ", sprites_per_slice, " and max_slices ",
                       max_slices, "; accepted at least 1, and 1 to 31"));
  }
  LensFlare::Impl& m = *flare.impl_;
  const bool made = m.split();
  m.split_from = on ? 0 : UINT32_MAX;
  m.split_params.min_sprites = min_sprites;
  m.split_params.sprites_per_slice = sprites_per_slice;
  m.split_params.max_slices = max_slices;
  if (on && !made) {  // the split's pipelines and slots (a CPU device)
    m.make_compute_pipelines();
    m.gather_beyond = {};
  }
}

bool LensFlareAccess::splits(const LensFlare& flare, uint64_t instances) { return flare.impl_->splits(instances); }

Buffer LensFlareAccess::split_words(const LensFlare& flare) { return flare.impl_->split_state; }

}  // namespace detail
}  // namespace glint
