// Lens-flare driver, the drawing half: validates, generates the element atlas, owns the
// raster and compute pipelines, and records either path. docs/FLARE.md explains the choices.
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
#include "flare/shaders/flare_params.h"

namespace glint {

using detail::check_range;
using detail::concat;

static_assert(sizeof(GlintFlareGatherArgsPush) == 20);
static_assert(sizeof(GlintFlarePush) == 84,
              "GlintFlarePush layout changed: update src/flare/shaders/flare_params.h users");
static_assert(offsetof(GlintFlarePush, ghost_pos0) == 52);
static_assert(offsetof(GlintFlarePush, tile_w) == 72);
static_assert(offsetof(GlintFlarePush, indirect_word) == 80);
static_assert(sizeof(GlintFlareAtlasPush) == 12);
static_assert(sizeof(GlintFlareInstance) == 48 && sizeof(GlintFlareIndirect) == 32);
static_assert(LensFlare::vertices_per_instance() == GLINT_FLARE_SPRITES * GLINT_FLARE_VERTICES_PER_SPRITE);
// A LightCullFrame left at its defaults feeds the flare draw.
static_assert(LightCullFrame{}.vertex_count == LensFlare::vertices_per_instance());
// Tiles and the atlas must be aligned to the coarsest level so no mip texel straddles two tiles.
static_assert(GLINT_FLARE_ATLAS_WIDTH % (1u << (GLINT_FLARE_ATLAS_LEVELS - 1)) == 0);
static_assert(GLINT_FLARE_ATLAS_HEIGHT % (1u << (GLINT_FLARE_ATLAS_LEVELS - 1)) == 0);
static_assert(GLINT_FLARE_TILE_GHOST_W % (1u << (GLINT_FLARE_ATLAS_LEVELS - 1)) == 0);
static_assert(GLINT_FLARE_ATLAS_PADDING % (1u << (GLINT_FLARE_ATLAS_LEVELS - 1)) == 0);

FlareConfig FlareConfig::preset(FlarePreset preset) {
  FlareConfig c;
  switch (preset) {
    case FlarePreset::retro_subtle:
      c.anamorphic_ratio = 1.8f;
      c.intensity = 0.6f;
      break;
    case FlarePreset::retro_intense:
      c.anamorphic_ratio = 2.5f;
      c.intensity = 1.2f;
      break;
    case FlarePreset::cinematic:
      c.anamorphic_ratio = 2.0f;
      c.intensity = 0.8f;
      break;
    case FlarePreset::disabled:
      c.enabled = false;
      c.anamorphic_ratio = 1.0f;
      c.intensity = 0.0f;
      break;
    default:
      throw Error(ErrorCode::invalid_argument,
                  concat("FlarePreset = ", static_cast<uint32_t>(preset),
                         " is not a preset: accepted retro_subtle, retro_intense, cinematic, disabled"));
  }
  return c;
}

void FlareConfig::validate() const {
  check_range("FlareConfig::anamorphic_ratio", anamorphic_ratio, 1.0, 3.0);
  check_range("FlareConfig::intensity", intensity, 0.0, 2.0);
  check_range("FlareConfig::main_weight", main_weight, 0.0, 10.0);
  check_range("FlareConfig::streak_weight", streak_weight, 0.0, 10.0);
  check_range("FlareConfig::streak_length", streak_length, 1.0, 10.0);
  check_range("FlareConfig::halo_weight", halo_weight, 0.0, 10.0);
  check_range("FlareConfig::starburst_weight", starburst_weight, 0.0, 10.0);
  check_range("FlareConfig::ghost_weight", ghost_weight, 0.0, 10.0);
  // Names on the stack: validate() runs in every record() and allocates nothing.
  char name[48];
  for (size_t i = 0; i < ghost_positions.size(); ++i) {
    std::snprintf(name, sizeof(name), "FlareConfig::ghost_positions[%zu]", i);
    check_range(name, ghost_positions[i], -2.0, 3.0);
  }
  for (size_t i = 0; i < tint_color.size(); ++i) {
    std::snprintf(name, sizeof(name), "FlareConfig::tint_color[%zu]", i);
    check_range(name, tint_color[i], 0.0, 1.0);
  }
}

namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags2 kIndirect = VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT;
constexpr VkAccessFlags2 kStorageRW = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

// Bytes of the sprite pre-pass's block per instance (src/flare/shaders/flare_params.h).
constexpr VkDeviceSize kBlockBytes = GLINT_FLARE_BLOCK_VEC4S * 16;

}  // namespace

struct LensFlare::Impl {
  const Context* context = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  uint32_t max_compute_instances = 0;    // instances one storage-buffer descriptor can hold
  uint32_t max_stored_instances = 0;     // instances whose sprite blocks one descriptor can hold
  uint32_t max_groups_x = 65535;         // maxComputeWorkGroupCount[0]
  VkDeviceSize storage_alignment = 256;  // minStorageBufferOffsetAlignment
  detail::Workgroup2D workgroup;         // the gather's workgroup
  uint32_t tiles_x = 0, tiles_y = 0;     // gather tiles: workgroup x by workgroup y * GATHER_ROWS

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
  // made at its first use.
  detail::ComputePipeline gather_beyond;
  bool gather_beyond_made = false;
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
  detail::ComputePipeline make_gather(uint32_t beyond_store) const;
  void record_setup(VkCommandBuffer cmd);
  GlintFlarePush push(const FlareConfig& c) const;
  void check_inputs(const char* fn, const Image& color, VkImageUsageFlags usage, const char* usage_name,
                    const Buffer& instances, const Buffer& indirect, const FlareConfig& config) const;
};

void LensFlare::Impl::make_atlas() {
  const uint32_t levels = GLINT_FLARE_ATLAS_LEVELS;
  // RGBA16F: HDR tiles scaled by bright lights: 8 bits would band. TRANSFER_SRC and _DST: tests
  // read every level back and poison it before generation.
  atlas_image =
      detail::OwnedImage(*context, {GLINT_FLARE_ATLAS_WIDTH, GLINT_FLARE_ATLAS_HEIGHT}, VK_FORMAT_R16G16B16A16_SFLOAT,
                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                             VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                         levels);
  // Trilinear, clamp to edge (the atlas border is padding), no anisotropy: the level comes from the
  // shader's explicit atlas-aware LOD (textureLod), identical in both paths.
  sampler = detail::clamp_sampler(*context, VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, float(levels - 1));

  detail::PipelineDesc d;
  d.kernel_id = "flare_atlas_main";
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  d.push_constant_bytes = sizeof(GlintFlareAtlasPush);
  d.workgroup = detail::choose_workgroup_2d(*context);
  atlas_pipeline = detail::ComputePipeline(*context, d);
}

void LensFlare::Impl::record_setup(VkCommandBuffer cmd) {
  if (atlas_generated) return;
  const uint32_t levels = GLINT_FLARE_ATLAS_LEVELS;
  detail::Barriers b;
  const VkImageLayout G = VK_IMAGE_LAYOUT_GENERAL;
  for (uint32_t k = 0; k < levels; ++k) {
    b.use(atlas_image.state, G, kCompute, kStorageRW, levels);  // level k - 1 written -> read; level k written
    b.flush(cmd);
    GlintFlareAtlasPush p{k, std::max(1u, atlas_image.state.extent.width >> k),
                          std::max(1u, atlas_image.state.extent.height >> k)};
    // Level k is made from level k - 1 (level 0 from nothing: its source binding is unused).
    atlas_pipeline.dispatch(cmd, {{atlas_image.level_view(k == 0 ? 0 : k - 1), G}, {atlas_image.level_view(k), G}}, p,
                            p.width, p.height);
  }
  b.use(atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
        VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, levels);
  b.flush(cmd);
  atlas_generated = true;
}

void LensFlare::Impl::make_raster_pipeline() {
  if (!context->state().dynamic_rendering) {
    raster_unavailable = "VkPhysicalDeviceVulkan13Features::dynamicRendering is not enabled on the device";
    return;
  }
  if (!context->state().graphics_queue) {
    raster_unavailable = concat("queue family ", context->queue_family_index(), " has no graphics capability");
    return;
  }
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(context->physical_device(), format, &fp);
  if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT)) {
    raster_unavailable = concat("the device cannot blend into ", detail::format_name(format));
    return;
  }
  auto& s = context->state();
  VkDescriptorSetLayoutBinding b[2] = {
      {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
  };
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;  // pushed with each draw
  sl.bindingCount = 2;
  sl.pBindings = b;
  detail::vk_check(vkCreateDescriptorSetLayout(device, &sl, nullptr, &raster_set_layout),
                   "vkCreateDescriptorSetLayout");
  s.count_object();
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(GlintFlarePush)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &raster_set_layout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  detail::vk_check(vkCreatePipelineLayout(device, &pl, nullptr, &raster_layout), "vkCreatePipelineLayout");
  s.count_object();

  VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  const char* ids[2] = {"flare_vert_main", "flare_frag_main"};
  try {
    for (int i = 0; i < 2; ++i) {
      const detail::KernelBinary* bin = detail::find_kernel(ids[i]);
      if (!bin) throw Error(ErrorCode::vulkan_failure, concat("kernel '", ids[i], "' is not embedded in this build"));
      VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      sm.codeSize = bin->size_bytes;
      sm.pCode = bin->code;
      detail::vk_check(vkCreateShaderModule(device, &sm, nullptr, &modules[i]), "vkCreateShaderModule");
    }
    VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                 {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = modules[0];
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = modules[1];
    stages[1].pName = "main";
    VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;  // billboards: both windings
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    // Premultiplied colour, additive: dst.rgb += src.rgb (ONE, ONE). Alpha is not written: flares
    // add light and leave whatever the image keeps in alpha.
    VkPipelineColorBlendAttachmentState blend{};
    blend.blendEnable = VK_TRUE;
    blend.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.colorBlendOp = VK_BLEND_OP_ADD;
    blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.alphaBlendOp = VK_BLEND_OP_ADD;
    blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT;
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = 1;
    cb.pAttachments = &blend;
    VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dyn;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachmentFormats = &format;
    VkGraphicsPipelineCreateInfo gp{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    gp.pNext = &rendering;
    gp.stageCount = 2;
    gp.pStages = stages;
    gp.pVertexInputState = &vertex_input;
    gp.pInputAssemblyState = &assembly;
    gp.pViewportState = &viewport;
    gp.pRasterizationState = &raster;
    gp.pMultisampleState = &ms;
    gp.pColorBlendState = &cb;
    gp.pDynamicState = &dynamic;
    gp.layout = raster_layout;
    detail::vk_check(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &gp, nullptr, &raster_pipeline),
                     "vkCreateGraphicsPipelines (flare)");
    s.count_object();
  } catch (...) {
    for (VkShaderModule m : modules) {
      if (m) vkDestroyShaderModule(device, m, nullptr);
    }
    throw;
  }
  for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
}

detail::ComputePipeline LensFlare::Impl::make_gather(uint32_t beyond_store) const {
  const auto SB = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  detail::PipelineDesc d;
  d.kernel_id = std::string("flare_gather_") + detail::format_variant(format);
  d.bindings = {SB, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, SB, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, SB};
  d.push_constant_bytes = sizeof(GlintFlarePush);
  d.workgroup = workgroup;
  d.specialization = {beyond_store};
  return detail::ComputePipeline(*context, d);
}

void LensFlare::Impl::make_compute_pipelines() {
  const auto SB = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  gather = make_gather(0);
  detail::PipelineDesc sp;
  sp.kernel_id = "flare_sprites_main";
  sp.bindings = {SB, SB, SB};
  sp.push_constant_bytes = sizeof(GlintFlarePush);
  sp.workgroup = {GLINT_FLARE_SPRITES_SLOTS, GLINT_FLARE_SPRITES_INSTANCES};
  sprites = detail::ComputePipeline(*context, sp);
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

GlintFlarePush LensFlare::Impl::push(const FlareConfig& c) const {
  GlintFlarePush p{};
  p.viewport_w = float(extent.width);
  p.viewport_h = float(extent.height);
  p.anamorphic_ratio = c.anamorphic_ratio;
  p.intensity = c.intensity;
  p.weight_main = c.main_weight;
  p.weight_streak = c.streak_weight;
  p.weight_halo = c.halo_weight;
  p.weight_starburst = c.starburst_weight;
  p.weight_ghost = c.ghost_weight;
  p.streak_length = c.streak_length;
  p.tint_r = c.tint ? c.tint_color[0] : 1.0f;
  p.tint_g = c.tint ? c.tint_color[1] : 1.0f;
  p.tint_b = c.tint ? c.tint_color[2] : 1.0f;
  p.ghost_pos0 = c.ghost_positions[0];
  p.ghost_pos1 = c.ghost_positions[1];
  p.ghost_pos2 = c.ghost_positions[2];
  p.ghost_pos3 = c.ghost_positions[3];
  p.ghost_pos4 = c.ghost_positions[4];
  p.tile_w = workgroup.x;
  p.tile_h = workgroup.y * GLINT_FLARE_GATHER_ROWS;
  p.indirect_word = 0;  // set by record_compute
  return p;
}

void LensFlare::Impl::check_inputs(const char* fn, const Image& color, VkImageUsageFlags usage, const char* usage_name,
                                   const Buffer& instances, const Buffer& indirect, const FlareConfig& config) const {
  config.validate();
  if (!color.image || !color.view)
    throw Error(ErrorCode::invalid_argument, concat(fn, ": color image and view must be non-null"));
  if (color.format != format) {
    throw Error(ErrorCode::unsupported_format, concat(fn, ": color format is ", detail::format_name(color.format),
                                                      "; this LensFlare was made for ", detail::format_name(format)));
  }
  if (color.extent.width != extent.width || color.extent.height != extent.height) {
    throw Error(ErrorCode::invalid_argument,
                concat(fn, ": color extent ", color.extent.width, "x", color.extent.height,
                       " differs from the LensFlare's ", extent.width, "x", extent.height));
  }
  if ((color.usage & usage) != usage)
    throw Error(ErrorCode::missing_usage, concat(fn, ": color image lacks ", usage_name, " usage"));
  detail::check_image_layout(fn, "color", color);
  detail::check_buffer(fn, "instances", instances, sizeof(GlintFlareInstance), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  detail::check_buffer(fn, "indirect", indirect, sizeof(GlintFlareIndirect), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
}

LensFlare::LensFlare(const Context& context, VkFormat color_format, VkExtent2D extent)
    : impl_(std::make_unique<Impl>()) {
  if (!detail::is_float_rgba(color_format)) {
    throw Error(ErrorCode::unsupported_format,
                concat("LensFlare: color format is ", detail::format_name(color_format),
                       "; accepted VK_FORMAT_R16G16B16A16_SFLOAT or VK_FORMAT_R32G32B32A32_SFLOAT"));
  }
  const uint32_t max_dim = context.info().max_image_dimension_2d;
  if (extent.width == 0 || extent.height == 0 || extent.width > max_dim || extent.height > max_dim) {
    throw Error(ErrorCode::unsupported_size, concat("LensFlare: extent ", extent.width, "x", extent.height,
                                                    " is out of range: accepted 1 to ", max_dim, " on each side"));
  }
  Impl& m = *impl_;
  m.context = &context;
  m.device = context.device();
  m.format = color_format;
  m.extent = extent;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context.physical_device(), &props);
  m.max_compute_instances = props.limits.maxStorageBufferRange / uint32_t(sizeof(GlintFlareInstance));
  // The sprite blocks take 304 bytes per instance: a device at the minimum range (2^27 bytes) stores
  // 441 k instances' sprites, and the gather evaluates those of any further instance itself.
  m.max_stored_instances = uint32_t(props.limits.maxStorageBufferRange / kBlockBytes);
  m.max_groups_x = props.limits.maxComputeWorkGroupCount[0];
  m.storage_alignment = std::max<VkDeviceSize>(1, props.limits.minStorageBufferOffsetAlignment);
  // The gather's workgroup: 32x8 on GPUs (a 32x64 tile; on the H100 it beat 16x8, whose tiles bin
  // every instance twice as often: docs/FLARE.md), the device's 2D choice (8x8) on CPU devices.
  m.workgroup = detail::choose_workgroup_2d(context);
  if (context.info().type != VK_PHYSICAL_DEVICE_TYPE_CPU && context.info().max_workgroup_invocations >= 256 &&
      context.info().subgroup_size >= 32) {
    m.workgroup = {32, 8};
  }
  if (m.workgroup.x * m.workgroup.y > GLINT_FLARE_GATHER_MAX_THREADS) m.workgroup = {16, 16};
  const uint32_t tile_h = m.workgroup.y * GLINT_FLARE_GATHER_ROWS;
  m.tiles_x = (extent.width + m.workgroup.x - 1) / m.workgroup.x;
  m.tiles_y = (extent.height + tile_h - 1) / tile_h;
  m.make_atlas();
  m.make_raster_pipeline();
  m.make_compute_pipelines();
  if (!context.is_adopted()) context.run_once([&](VkCommandBuffer cmd) { m.record_setup(cmd); });
}

LensFlare::LensFlare(LensFlare&&) noexcept = default;
LensFlare& LensFlare::operator=(LensFlare&&) noexcept = default;
LensFlare::~LensFlare() = default;

uint32_t LensFlare::groups_per_instance() const { return 1; }
uint32_t LensFlare::max_compute_instances() const { return impl_->max_compute_instances; }
void LensFlare::record_setup(VkCommandBuffer cmd) {
  detail::check_command_buffer("LensFlare::record_setup", cmd);
  impl_->record_setup(cmd);
}
VkFormat LensFlare::color_format() const { return impl_->format; }
VkExtent2D LensFlare::extent() const { return impl_->extent; }

FlareAtlasInfo LensFlare::atlas() const {
  FlareAtlasInfo a;
  a.image = impl_->atlas_image.state.image;
  a.view = impl_->atlas_image.state.view;
  a.format = impl_->atlas_image.state.format;
  a.width = impl_->atlas_image.state.extent.width;
  a.height = impl_->atlas_image.state.extent.height;
  a.levels = GLINT_FLARE_ATLAS_LEVELS;
  a.padding_texels = GLINT_FLARE_ATLAS_PADDING;
  a.generated = impl_->atlas_generated;
  return a;
}

void LensFlare::record_raster(VkCommandBuffer cmd, Image& color, Buffer& instances, Buffer& indirect,
                              const FlareConfig& config, Profiler* profiler) {
  detail::check_command_buffer("LensFlare::record_raster", cmd);
  Impl& m = *impl_;
  m.check_inputs("LensFlare::record_raster", color, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                 "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT", instances, indirect, config);
  if (!m.raster_unavailable.empty()) {
    throw Error(
        m.raster_unavailable.find("blend") != std::string::npos ? ErrorCode::unsupported_format : ErrorCode::no_device,
        concat("LensFlare::record_raster: ", m.raster_unavailable, "; use record_compute"));
  }
  if (!config.enabled || config.intensity == 0.0f) return;  // adds nothing: record nothing
  const detail::Bindings bindings{instances, m.atlas_binding()};
  detail::check_bindings(m.raster_types, bindings, "flare raster");  // before anything is recorded
  m.record_setup(cmd);

  detail::Barriers b;
  b.use(instances, VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(indirect, kIndirect, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  b.use(m.atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
        VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, GLINT_FLARE_ATLAS_LEVELS);
  b.use(color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
        VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  b.flush(cmd);

  VkRenderingAttachmentInfo attachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  attachment.imageView = color.view;
  attachment.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, m.extent};
  rendering.layerCount = 1;
  rendering.colorAttachmentCount = 1;
  rendering.pColorAttachments = &attachment;
  vkCmdBeginRendering(cmd, &rendering);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m.raster_pipeline);
  VkViewport viewport{0.0f, 0.0f, float(m.extent.width), float(m.extent.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, m.extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
  detail::push_descriptors(m.context->state().cmd_push_descriptor_set, cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                           m.raster_layout, m.raster_types, bindings, "flare raster");
  const GlintFlarePush p = m.push(config);
  vkCmdPushConstants(cmd, m.raster_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(p), &p);
  vkCmdDrawIndirect(cmd, indirect.buffer, indirect.offset + offsetof(GlintFlareIndirect, vertex_count), 1,
                    sizeof(VkDrawIndirectCommand));
  vkCmdEndRendering(cmd);
  if (profiler) profiler->mark(cmd, "flare raster");
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
  if (beyond && !m.gather_beyond_made) {
    m.gather_beyond = m.make_gather(1);
    m.gather_beyond_made = true;
  }

  GlintFlarePush p = m.push(config);
  p.indirect_word = uint32_t((args_offset - bound_offset) / sizeof(uint32_t));
  GlintFlareGatherArgsPush ap{p.indirect_word, m.tiles_x, m.tiles_y, std::min(capacity, sprite_store.capacity),
                              m.max_groups_x};
  detail::Barriers b;
  // 1. The launch arguments: every tile when any instance is visible, none otherwise; the
  //    pre-pass's groups for the instances.
  b.use(indirect, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(m.gather_args_state, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  m.gather_args.dispatch(cmd, {indirect_words, m.gather_args_state}, ap, 1, 1);
  // 2. The sprite pre-pass: every sprite of every instance, once.
  b.use(m.gather_args_state, kIndirect, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  b.use(instances, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(store, kCompute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  m.sprites.dispatch_indirect(cmd, {instances, indirect_words, store}, p, m.gather_args_buffer.buffer(), 16);
  // 3. The gather, one workgroup per tile.
  b.use(store, kCompute, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(m.atlas_image.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
        GLINT_FLARE_ATLAS_LEVELS);
  b.use(color, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageRW);
  b.flush(cmd);
  (beyond ? m.gather_beyond : m.gather)
      .dispatch_indirect(cmd,
                         {instances, m.atlas_binding(), indirect_words, {color.view, VK_IMAGE_LAYOUT_GENERAL}, store},
                         p, m.gather_args_buffer.buffer(), 0);
  if (profiler) profiler->mark(cmd, "flare gather");
}

}  // namespace glint
