// Lens-flare driver, the shared half: the configuration, the element atlas, the argument checks
// and construction (which makes the raster pipeline, flare_raster.cpp, and the compute pipelines,
// flare_compute.cpp). docs/FLARE.md explains the choices.
#include "flare/flare_impl.h"

namespace glint {

using namespace flare_detail;
using detail::check_range;
using detail::concat;

static_assert(sizeof(GlintFlareGatherArgsPush) == 20);
static_assert(sizeof(GlintFlareSplitPush) == 32);
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
  p.tile_w = 0;  // record_compute sets its path's tile (0 would draw nothing)
  p.tile_h = 0;
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
  detail::check_extent(context, extent, "LensFlare");
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
  // The gathers' workgroups, as measured (docs/FLARE.md, "Speed"): on GPUs 32x8 for the pre-pass
  // gathers (on the H100 it beat 16x8 when both gathered 8 rows, 16x8's tiles binning every
  // instance twice as often; on the H200 16x8, 16x16, 64x4 and 8x16 were slower with and without
  // the split) and GLINT_FLARE_ONE_DISPATCH_GROUP_X/Y (the same) for the one-dispatch gather; the device's 2D
  // choice (8x8, or ContextOptions::workgroup_2d) on CPU devices.
  static_assert(GLINT_FLARE_ONE_DISPATCH_GROUP_X * GLINT_FLARE_ONE_DISPATCH_GROUP_Y >= GLINT_FLARE_SPRITES &&
                GLINT_FLARE_ONE_DISPATCH_GROUP_X * GLINT_FLARE_ONE_DISPATCH_GROUP_Y <= GLINT_FLARE_GATHER_MAX_THREADS);
  const bool cpu = context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const bool gpu_shapes = !cpu && context.info().max_workgroup_invocations >= 256 && context.info().subgroup_size >= 32;
  detail::Workgroup2D group = detail::choose_workgroup_2d(context), one_group = group;
  if (gpu_shapes) group = {32, 8}, one_group = {GLINT_FLARE_ONE_DISPATCH_GROUP_X, GLINT_FLARE_ONE_DISPATCH_GROUP_Y};
  if (group.x * group.y > GLINT_FLARE_GATHER_MAX_THREADS) group = one_group = {16, 16};
  // The tiles of each gather (flare_params.h): on GPUs the pre-pass gather starts from the image
  // centre, where every light's ghost at t = 1 piles up, in tiles 4 times shorter, or, for
  // instances buffers of GLINT_FLARE_SPLIT_FROM_INSTANCES and more, in full tiles with the crowded
  // ones split; the one-dispatch gather and CPU devices take full tiles in the workgroup IDs' order
  // and split none, which was faster there.
  m.tiles_one_dispatch = m.gather_tiles(GLINT_FLARE_GATHER_ROWS, false, one_group);
  m.tiles_pre_pass = m.gather_tiles(cpu ? GLINT_FLARE_GATHER_ROWS : GLINT_FLARE_GATHER_PRE_PASS_ROWS, !cpu, group);
  m.tiles_split = m.gather_tiles(GLINT_FLARE_GATHER_ROWS, !cpu, group);
  m.one_dispatch_limit = cpu ? 0 : m.one_dispatch_batch();
  m.split_from = cpu ? UINT32_MAX : GLINT_FLARE_SPLIT_FROM_INSTANCES;
  m.split_params = {0, 0, 0, 0, GLINT_FLARE_SPLIT_MIN_SPRITES, GLINT_FLARE_SPLIT_SPRITES, GLINT_FLARE_SPLIT_MAX_SLICES,
                    0};
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
uint32_t LensFlare::one_dispatch_instances() const { return impl_->one_dispatch_limit; }
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
}  // namespace glint
