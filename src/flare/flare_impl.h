// LensFlare's state, shared by its three source files: flare.cpp (configuration, atlas, checks
// and construction), flare_raster.cpp (the draw) and flare_compute.cpp (the gather). Internal.
#pragma once

#include <glint/flare.h>
#include <glint/gpu/flare_types.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/kernel_table.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "flare/flare_internal.h"
#include "flare/shaders/flare_params.h"

namespace glint::flare_detail {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags2 kIndirect = VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT;
constexpr VkAccessFlags2 kStorageRW = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

// Bytes of the sprite pre-pass's block per instance (src/flare/shaders/flare_params.h).
constexpr VkDeviceSize kBlockBytes = GLINT_FLARE_BLOCK_VEC4S * 16;

}  // namespace glint::flare_detail

namespace glint {

struct LensFlare::Impl {
  const Context* context = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  uint32_t max_compute_instances = 0;    // instances one storage-buffer descriptor can hold
  uint32_t max_stored_instances = 0;     // instances whose sprite blocks one descriptor can hold
  uint32_t max_groups_x = 65535;         // maxComputeWorkGroupCount[0]
  VkDeviceSize storage_alignment = 256;  // minStorageBufferOffsetAlignment
  // Each gather's tiles: `group` x by group.y * rows pixels (GLINT_FLARE_GATHER_ROWS, except the
  // pre-pass gather's without the split on GPUs: GLINT_FLARE_GATHER_PRE_PASS_ROWS; tests may set
  // others), x by y of them; `group` is the gather's workgroup. centre_first: the workgroups take
  // the tiles from the image centre outwards (specialization constant 5; the pre-pass gathers on
  // GPUs).
  struct GatherTiles {
    uint32_t rows = GLINT_FLARE_GATHER_ROWS, x = 0, y = 0;
    bool centre_first = false;
    detail::Workgroup2D group;
  };
  // tiles_split: the pre-pass gather's when it splits crowded tiles.
  GatherTiles tiles_one_dispatch, tiles_pre_pass, tiles_split;
  // The split of crowded tiles in the pre-pass gather (flare_params.h, "Crowded tiles"): taken for
  // instances buffers of at least split_from instances (GLINT_FLARE_SPLIT_FROM_INSTANCES on GPUs;
  // never on CPU devices: UINT32_MAX). The plan's parameters, the split words (counts, plans,
  // finished slices, slots) for tiles_split, zeroed once at their first use (then the plan zeroes
  // the counts after reading them and the finished slices before the gather), and the slots of
  // partial sums (16 bytes without the split).
  uint32_t split_from = UINT32_MAX;
  bool split() const { return split_from != UINT32_MAX; }
  // Whether a pre-pass draw from an instances buffer of `instances` instances splits crowded tiles.
  bool splits(uint64_t instances) const { return instances >= split_from; }
  GlintFlareSplitPush split_params{};
  detail::OwnedBuffer split_buffer, partials_buffer;
  Buffer split_state, partials_state;
  bool split_cleared = false;
  detail::ComputePipeline split_plan, sprites_count;          // sprites_count: the pre-pass that counts tiles' sprites
  detail::ComputePipeline gather_split, gather_beyond_split;  // kSplit (the second made at its first use)

  // Atlas: one image with every level, a view of all levels (sampling) and one per level (storage).
  detail::OwnedImage atlas_image;      // state tracks all levels together
  VkSampler sampler = VK_NULL_HANDLE;  // owned by the context
  bool atlas_generated = false;
  detail::ComputePipeline atlas_pipeline;

  // Raster path (absent when the device cannot draw into `format` with blending).
  std::string raster_unavailable;                            // empty when the raster path is available
  VkDescriptorSetLayout raster_set_layout = VK_NULL_HANDLE;  // pushed: instances, atlas
  std::vector<VkDescriptorType> raster_types = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER};
  VkPipelineLayout raster_layout = VK_NULL_HANDLE;
  VkPipeline raster_pipeline = VK_NULL_HANDLE;

  // Compute path: the sprite pre-pass and the gather, launched by vkCmdDispatchIndirect with
  // arguments that flare_gather_args.comp writes from the instance count.
  detail::ComputePipeline gather, gather_args, sprites;
  // The gather for instances buffers larger than the sprite store (specialization constant 2 = 1),
  // made at its first use (empty until then).
  detail::ComputePipeline gather_beyond;
  // The one-dispatch gather (specialization constant 3 = 1), made with the others on GPUs, at its
  // first use elsewhere (empty until then).
  detail::ComputePipeline gather_one_dispatch;
  detail::FlareGatherPath gather_path = detail::FlareGatherPath::device;
  detail::OwnedBuffer gather_args_buffer;  // the gather's VkDispatchIndirectCommand, then the pre-pass's
  Buffer gather_args_state;
  // The pre-pass's sprite blocks, one store per size: a larger instances buffer gets a new store,
  // and the smaller ones stay (command buffers recorded with them may still be pending) until the
  // LensFlare goes.
  struct SpriteStore {
    detail::OwnedBuffer buffer;
    Buffer state;
    uint32_t capacity = 0;  // instances
  };
  std::vector<std::unique_ptr<SpriteStore>> sprite_stores;

  ~Impl() {
    if (!device) return;
    if (raster_pipeline) vkDestroyPipeline(device, raster_pipeline, nullptr);
    if (raster_layout) vkDestroyPipelineLayout(device, raster_layout, nullptr);
    if (raster_set_layout) vkDestroyDescriptorSetLayout(device, raster_set_layout, nullptr);
  }

  // The atlas as a combined image sampler binding (every level, trilinear).
  detail::Binding atlas_binding() const {
    return {atlas_image.state.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler};
  }

  void make_atlas();
  void make_raster_pipeline();
  void make_compute_pipelines();
  void make_split_buffers();  // for tiles_split, when split()
  detail::ComputePipeline make_gather(uint32_t beyond_store, uint32_t one_dispatch, bool split = false) const;
  GatherTiles gather_tiles(uint32_t rows, bool centre_first, detail::Workgroup2D group) const;
  // Instances per batch of the one-dispatch gather (one invocation per sprite).
  uint32_t one_dispatch_batch() const {
    return tiles_one_dispatch.group.x * tiles_one_dispatch.group.y / GLINT_FLARE_SPRITES;
  }
  // The most instances for which record_compute() takes the one-dispatch gather by itself: one
  // batch on GPUs; none on CPU devices, which run a tile's invocations one after another, so that
  // every tile evaluating the sprites itself costs more than the two dispatches it saves (lavapipe,
  // 10 lights at 1080p: 164 ms with the pre-pass, 256 ms in one dispatch).
  uint32_t one_dispatch_limit = 0;
  void record_setup(VkCommandBuffer cmd);
  GlintFlarePush push(const FlareConfig& c) const;
  void check_inputs(const char* fn, const Image& color, VkImageUsageFlags usage, const char* usage_name,
                    const Buffer& instances, const Buffer& indirect, const FlareConfig& config) const;
};

}  // namespace glint
