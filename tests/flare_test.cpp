// Lens flares, drawing half, on the GPU (lavapipe in CI) against the float64 reference
// (tools/reference/flare_reference.h), and the two paths against each other. The instance and
// indirect buffers are filled from the CPU through a copy, standing in for the visibility stage,
// so the barriers from a writer to DRAW_INDIRECT / INDIRECT_COMMAND_READ are exercised. Validation
// with synchronization validation is on for every test (support/gpu_test.h).
#include <glint/flare.h>
#include <glint/flare_pass.h>
#include <glint/gpu/flare_types.h>
#include <glint/gpu/lod.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "core/barriers.h"
#include "core/half.h"
#include "core/pipeline.h"
#include "flare/flare_internal.h"
#include "flare/shaders/flare_params.h"
#include "reference/flare_reference.h"
#include "reference/lod_reference.h"
#include "support/flare_check.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkImageUsageFlags kUsage = detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
constexpr uint32_t kW = 160, kH = 96;
// A float stored to fp16 may be rounded to nearest or toward zero (Vulkan spec, "Floating-Point
// Format Conversions"; lavapipe truncates): less than one ulp, 2^-10 of the value. fp32: 2^-23.
const double kHalfStore = std::ldexp(1.0, -10);
const double kFloatStore = std::ldexp(1.0, -23);

enum class Path { raster, compute };
const char* path_name(Path p) { return p == Path::raster ? "raster" : "compute"; }

class FlareTest : public GpuTest {};

// The instance and indirect buffers as the visibility stage leaves them: device-local, written by
// a transfer (here) or a compute shader (the cull), with STORAGE and INDIRECT usage.
struct FlareInputs {
  detail::OwnedBuffer instances, indirect, staging;
  Buffer instances_view, indirect_view;
  std::vector<GlintFlareInstance> data;
  GlintFlareIndirect args{};

  FlareInputs(const std::vector<GlintFlareInstance>& list, uint32_t instance_count, uint32_t groups_per_instance,
              size_t capacity = 0)
      : data(list) {
    capacity = std::max({capacity, list.size(), size_t(1)});
    const VkBufferUsageFlags usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    instances = detail::OwnedBuffer(context(), capacity * sizeof(GlintFlareInstance), usage, false);
    indirect = detail::OwnedBuffer(context(), sizeof(GlintFlareIndirect), usage, false);
    staging = detail::OwnedBuffer(context(), instances.size() + sizeof(GlintFlareIndirect),
                                  VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    args.vertex_count = LensFlare::vertices_per_instance();
    args.instance_count = instance_count;
    args.group_count_x = instance_count * groups_per_instance;
    args.group_count_y = 1;
    args.group_count_z = 1;
    auto* bytes = static_cast<uint8_t*>(staging.mapped());
    std::memset(bytes, 0, staging.size());
    if (!list.empty()) std::memcpy(bytes, list.data(), list.size() * sizeof(GlintFlareInstance));
    std::memcpy(bytes + instances.size(), &args, sizeof(args));
    staging.flush();
    instances_view = {instances.buffer(), 0, instances.size(), usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
    indirect_view = {indirect.buffer(), 0, indirect.size(), usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  }

  // Records the copies (the stand-in for the cull) and says so in the buffers' state.
  void record_upload(VkCommandBuffer cmd) {
    detail::Barriers b;
    b.use(instances_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.use(indirect_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    VkBufferCopy a{0, 0, instances.size()};
    vkCmdCopyBuffer(cmd, staging.buffer(), instances.buffer(), 1, &a);
    VkBufferCopy b2{instances.size(), 0, sizeof(GlintFlareIndirect)};
    vkCmdCopyBuffer(cmd, staging.buffer(), indirect.buffer(), 1, &b2);
  }
};

detail::OwnedImage make_color(const CpuImage& pixels, VkFormat format) {
  detail::OwnedImage img(context(), {pixels.width, pixels.height}, format, kUsage);
  detail::upload(context(), img.state, pixels);
  return img;
}

void record(LensFlare& flare, Path path, VkCommandBuffer cmd, Image& color, FlareInputs& in,
            const FlareConfig& config) {
  if (path == Path::raster) {
    flare.record_raster(cmd, color, in.instances_view, in.indirect_view, config);
  } else {
    flare.record_compute(cmd, color, in.instances_view, in.indirect_view, config);
  }
}

// Uploads `background`, draws the flares of `in` with `path`, reads the image back.
CpuImage draw(LensFlare& flare, Path path, const CpuImage& background, VkFormat format, FlareInputs& in,
              const FlareConfig& config) {
  auto color = make_color(background, format);
  context().run_once([&](VkCommandBuffer cmd) {
    in.record_upload(cmd);
    record(flare, path, cmd, color.state, in, config);
  });
  return detail::download(context(), color.state);
}

// Random lights over the image and around it: inside, on the edges, partly and fully off screen,
// sizes 3 to 60 px (tiny ones exercise the coarse atlas levels), HDR colours, fractions, elements.
std::vector<GlintFlareInstance> random_instances(uint32_t n, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<GlintFlareInstance> out(n);
  for (uint32_t i = 0; i < n; ++i) {
    GlintFlareInstance& g = out[i];
    g.center_x_px = -0.2f * kW + 1.4f * kW * unit(rng);
    g.center_y_px = -0.2f * kH + 1.4f * kH * unit(rng);
    if (i % 5 == 1) g.center_x_px = std::round(g.center_x_px);  // on pixel edges
    if (i % 5 == 2) g.center_y_px = 0.0f;
    g.size_px = 3.0f + 57.0f * unit(rng) * unit(rng);
    g.visible_fraction = 0.05f + 0.95f * unit(rng);
    g.color_r = 0.2f + 4.0f * unit(rng);
    g.color_g = 0.2f + 4.0f * unit(rng);
    g.color_b = 0.2f + 4.0f * unit(rng);
    g.intensity = 0.5f + 3.0f * unit(rng);
    g.light_index = i;
    g.element = i % (GLINT_FLARE_ELEMENT_COUNT + 1);  // the last value is out of range: glow
    g.ndc_depth = unit(rng);
  }
  return out;
}

// 500 small lights (2 to 14 px): every light's ghost at t = 1 lands on the image centre, so
// hundreds of sprites pile on its tiles.
std::vector<GlintFlareInstance> piled_lights(uint32_t stream) {
  auto lights = random_instances(500, stream);
  for (auto& g : lights) g.size_px = 2.0f + 0.2f * g.size_px;
  return lights;
}

// ---- Config ---------------------------------------------------------------------------------------

TEST_F(FlareTest, PresetsHaveTheSeedsValues) {
  const FlareConfig subtle = FlareConfig::preset(FlarePreset::retro_subtle);
  const FlareConfig intense = FlareConfig::preset(FlarePreset::retro_intense);
  const FlareConfig cinematic = FlareConfig::preset(FlarePreset::cinematic);
  const FlareConfig disabled = FlareConfig::preset(FlarePreset::disabled);
  EXPECT_FLOAT_EQ(subtle.anamorphic_ratio, 1.8f);
  EXPECT_FLOAT_EQ(subtle.intensity, 0.6f);
  EXPECT_FLOAT_EQ(intense.anamorphic_ratio, 2.5f);
  EXPECT_FLOAT_EQ(intense.intensity, 1.2f);
  EXPECT_FLOAT_EQ(cinematic.anamorphic_ratio, 2.0f);
  EXPECT_FLOAT_EQ(cinematic.intensity, 0.8f);
  EXPECT_TRUE(subtle.enabled && intense.enabled && cinematic.enabled);
  EXPECT_FALSE(disabled.enabled);
  EXPECT_FLOAT_EQ(disabled.intensity, 0.0f);
  for (const FlareConfig& c : {subtle, intense, cinematic, disabled}) EXPECT_NO_THROW(c.validate());
  const FlareConfig defaults;
  EXPECT_FLOAT_EQ(defaults.anamorphic_ratio, 2.0f);
  const std::array<float, 5> default_ghosts = {0.0f, 0.3f, 0.7f, 1.0f, 1.5f};
  EXPECT_EQ(defaults.ghost_positions, default_ghosts);
  EXPECT_THROW(FlareConfig::preset(static_cast<FlarePreset>(7)), Error);
}

TEST_F(FlareTest, BadConfigThrowsNamingTheFieldAndRecordsNothing) {
  struct Case {
    const char* field;
    void (*spoil)(FlareConfig&);
  };
  const Case cases[] = {
      {"anamorphic_ratio", [](FlareConfig& c) { c.anamorphic_ratio = std::nanf(""); }},
      {"anamorphic_ratio", [](FlareConfig& c) { c.anamorphic_ratio = 3.5f; }},
      {"anamorphic_ratio", [](FlareConfig& c) { c.anamorphic_ratio = 0.9f; }},
      {"intensity", [](FlareConfig& c) { c.intensity = -0.1f; }},
      {"intensity", [](FlareConfig& c) { c.intensity = INFINITY; }},
      {"streak_length", [](FlareConfig& c) { c.streak_length = 0.5f; }},
      {"ghost_weight", [](FlareConfig& c) { c.ghost_weight = std::nanf(""); }},
      {"ghost_positions[3]", [](FlareConfig& c) { c.ghost_positions[3] = 3.5f; }},
      {"tint_color[2]", [](FlareConfig& c) { c.tint_color[2] = 1.5f; }},
  };
  LensFlare flare(context(), kF32, {kW, kH});
  const CpuImage background = random_hdr(kW, kH, 5);
  FlareInputs in(random_instances(6, 1), 6, flare.groups_per_instance());
  for (const Case& k : cases) {
    FlareConfig c;
    k.spoil(c);
    try {
      c.validate();
      ADD_FAILURE() << k.field << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      EXPECT_NE(std::string(e.what()).find(k.field), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("accepted"), std::string::npos) << e.what();
    }
    for (Path path : {Path::raster, Path::compute}) {
      auto color = make_color(background, kF32);
      const Image before = color.state;
      context().run_once(
          [&](VkCommandBuffer cmd) { EXPECT_THROW(record(flare, path, cmd, color.state, in, c), Error) << k.field; });
      EXPECT_EQ(color.state.layout, before.layout) << "state touched by a throwing record";
      const CpuImage out = detail::download(context(), color.state);
      EXPECT_EQ(std::memcmp(out.rgba.data(), background.rgba.data(), out.rgba.size() * 4), 0) << k.field;
    }
  }
}

TEST_F(FlareTest, BadImagesAndBuffersThrowBeforeRecording) {
  EXPECT_THROW(LensFlare(context(), VK_FORMAT_R8G8B8A8_UNORM, {kW, kH}), Error);
  EXPECT_THROW(LensFlare(context(), kF16, {0, kH}), Error);
  LensFlare flare(context(), kF16, {kW, kH});
  detail::OwnedImage color(context(), {kW, kH}, kF16, kUsage);
  FlareInputs in(random_instances(2, 2), 2, flare.groups_per_instance());
  const FlareConfig config;
  auto expect_code = [&](ErrorCode code, const char* words, auto&& spoil, Path path) {
    Image img = color.state;
    Buffer inst = in.instances_view, ind = in.indirect_view;
    spoil(img, inst, ind);
    context().run_once([&](VkCommandBuffer cmd) {
      try {
        if (path == Path::raster) {
          flare.record_raster(cmd, img, inst, ind, config);
        } else {
          flare.record_compute(cmd, img, inst, ind, config);
        }
        ADD_FAILURE() << words << ": no error";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      }
    });
  };
  for (Path path : {Path::raster, Path::compute}) {
    expect_code(
        ErrorCode::unsupported_format, "VK_FORMAT_R32G32B32A32_SFLOAT",
        [](Image& i, Buffer&, Buffer&) { i.format = kF32; }, path);
    expect_code(
        ErrorCode::invalid_argument, "extent", [](Image& i, Buffer&, Buffer&) { i.extent.width = 8; }, path);
    expect_code(
        ErrorCode::invalid_argument, "non-null", [](Image& i, Buffer&, Buffer&) { i.view = VK_NULL_HANDLE; }, path);
    expect_code(
        ErrorCode::missing_usage, "INDIRECT_BUFFER",
        [](Image&, Buffer&, Buffer& b) { b.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT; }, path);
    expect_code(
        ErrorCode::missing_usage, "STORAGE_BUFFER",
        [](Image&, Buffer& b, Buffer&) { b.usage = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT; }, path);
    expect_code(
        ErrorCode::invalid_argument, "multiple of 4", [](Image&, Buffer&, Buffer& b) { b.offset = 2; }, path);
    expect_code(
        ErrorCode::invalid_argument, "32", [](Image&, Buffer&, Buffer& b) { b.size = 16; }, path);
    expect_code(
        ErrorCode::invalid_argument, "instances buffer is null",
        [](Image&, Buffer& b, Buffer&) { b.buffer = VK_NULL_HANDLE; }, path);
  }
  expect_code(
      ErrorCode::missing_usage, "COLOR_ATTACHMENT",
      [](Image& i, Buffer&, Buffer&) { i.usage = detail::kToolImageUsage; }, Path::raster);
  expect_code(
      ErrorCode::missing_usage, "STORAGE_BIT",
      [](Image& i, Buffer&, Buffer&) { i.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT; }, Path::compute);
}

// ---- Atlas ----------------------------------------------------------------------------------------

TEST_F(FlareTest, AtlasMatchesTheFloat64ReferenceAtEveryLevel) {
  LensFlare flare(context(), kF16, {kW, kH});
  ASSERT_TRUE(flare.atlas().generated);
  const reference::FlareAtlas gpu = read_flare_atlas(flare);
  const reference::FlareAtlas ref = reference::flare_atlas();
  ASSERT_EQ(gpu.size(), size_t(GLINT_FLARE_ATLAS_LEVELS));
  const double u = kHalfStore;
  const double fp16_min_normal = std::ldexp(1.0, -14);  // a device may flush fp16 subnormals
  for (size_t k = 0; k < gpu.size(); ++k) {
    ASSERT_EQ(gpu[k].width, ref[k].width);
    // Level k from the GPU's own level k - 1: one fp32 evaluation (level 0: exp and sqrt within a
    // few ulp, about 1e-5 relative at the largest arguments) and one fp16 store (kHalfStore).
    const reference::FlareAtlasLevel step = k == 0 ? ref[0] : reference::flare_atlas_reduce(gpu[k - 1]);
    double worst_step = 0, worst_chain = 0;
    for (size_t i = 0; i < gpu[k].rgba.size(); ++i) {
      const double g = gpu[k].rgba[i];
      ASSERT_TRUE(std::isfinite(g));
      const double e_step = std::fabs(g - step.rgba[i]) / ((u + 2e-5) * std::fabs(step.rgba[i]) + fp16_min_normal);
      // Against the all-float64 chain: one rounding per level on the way down.
      const double e_chain =
          std::fabs(g - ref[k].rgba[i]) / ((k + 1) * (u + 2e-5) * std::fabs(ref[k].rgba[i]) + fp16_min_normal);
      worst_step = std::max(worst_step, e_step);
      worst_chain = std::max(worst_chain, e_chain);
    }
    EXPECT_LE(worst_step, 1.0) << "level " << k << " vs its reduction of the GPU's level above";
    EXPECT_LE(worst_chain, 1.0) << "level " << k << " vs the float64 chain";
  }
}

TEST_F(FlareTest, AtlasTilesArePaddedAndNoLevelMixesTwoTiles) {
  LensFlare flare(context(), kF16, {kW, kH});
  const reference::FlareAtlas gpu = read_flare_atlas(flare);
  for (size_t k = 0; k < gpu.size(); ++k) {
    const uint32_t s = 1u << k;
    std::vector<int> owner(size_t(gpu[k].width) * gpu[k].height, -1);
    for (uint32_t e = 0; e < GLINT_FLARE_ELEMENT_COUNT; ++e) {
      const auto t = reference::flare_tile(e);
      ASSERT_EQ(t[0] % s + t[1] % s + t[2] % s + t[3] % s, 0u) << "tile " << e << " not aligned at level " << k;
      double peak = 0;
      for (uint32_t y = t[1] / s; y < (t[1] + t[3]) / s; ++y) {
        for (uint32_t x = t[0] / s; x < (t[0] + t[2]) / s; ++x) {
          owner[size_t(y) * gpu[k].width + x] = int(e);
          peak = std::max(peak, gpu[k].at(x, y)[3]);
        }
      }
      EXPECT_GT(peak, 0.05) << "tile " << e << " is empty at level " << k;
      // The padding ring: every texel within padding / 2^k of the tile is exactly zero.
      const uint32_t p = GLINT_FLARE_ATLAS_PADDING / s;
      for (uint32_t y = t[1] / s - p; y < (t[1] + t[3]) / s + p; ++y) {
        for (uint32_t x = t[0] / s - p; x < (t[0] + t[2]) / s + p; ++x) {
          if (owner[size_t(y) * gpu[k].width + x] == int(e)) continue;
          for (int c = 0; c < 4; ++c)
            ASSERT_EQ(gpu[k].at(x, y)[c], 0.0) << "padding texel (" << x << ", " << y << ") level " << k;
        }
      }
    }
    for (uint32_t y = 0; y < gpu[k].height; ++y) {  // nothing outside the tiles at all
      for (uint32_t x = 0; x < gpu[k].width; ++x) {
        if (owner[size_t(y) * gpu[k].width + x] >= 0) continue;
        for (int c = 0; c < 4; ++c) ASSERT_EQ(gpu[k].at(x, y)[c], 0.0) << "(" << x << ", " << y << ") level " << k;
      }
    }
  }
}

// The atlas-aware LOD picks levels that keep every bilinear footprint inside its tile's padding:
// the level count is the padding cap + 1, and for sprites from 0.25 px to 4000 px the level is
// never above the cap, so a tap at the tile's border reaches at most 1.5 * 2^L < padding texels.
TEST_F(FlareTest, ChosenLevelsKeepFootprintsInsideThePadding) {
  GlintLodQuery q{};
  q.tex_w = q.tex_h = 64.0f;
  const GlintLodAtlas a = reference::flare_lod_atlas();
  const double cap = reference::lod_padding_cap(q, a);
  EXPECT_EQ(cap + 1, double(GLINT_FLARE_ATLAS_LEVELS));
  FlareConfig config;
  double highest = 0;
  for (double size = 0.25; size < 4000; size *= 1.07) {
    GlintFlareInstance inst{};
    inst.center_x_px = 50;
    inst.center_y_px = 40;
    inst.size_px = float(size);
    inst.visible_fraction = inst.intensity = inst.color_r = inst.color_g = inst.color_b = 1;
    for (uint32_t slot = 0; slot < GLINT_FLARE_SPRITES; ++slot) {
      const auto s = reference::flare_sprite(inst, slot, config, kW, kH);
      ASSERT_LE(s.lod, cap);
      EXPECT_LT(1.5 * std::ldexp(1.0, int(std::ceil(s.lod))), double(GLINT_FLARE_ATLAS_PADDING));
      highest = std::max(highest, s.lod);
    }
  }
  EXPECT_EQ(highest, cap);  // tiny sprites do reach the cap: the test is not vacuous
}

// Poisoning: an adopted context records the generation in the first frame; every texel of every
// level, cleared to NaN before, must come out finite and equal to the standalone atlas.
TEST_F(FlareTest, AdoptedContextGeneratesTheAtlasInTheFirstRecordOverPoison) {
  Context engine =
      Context::adopt(with_glint_extensions({context().instance(), VK_API_VERSION_1_3, context().physical_device(),
                                            context().device(), context().queue_family_index()}));
  LensFlare flare(engine, kF32, {kW, kH});
  EXPECT_FALSE(flare.atlas().generated);
  const FlareAtlasInfo a = flare.atlas();
  context().run_once([&](VkCommandBuffer cmd) {
    Image img{
        a.image,         a.view, a.format, {a.width, a.height}, 0, VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_NONE,
        VK_ACCESS_2_NONE};
    detail::Barriers b;
    b.use(img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
          a.levels);
    b.flush(cmd);
    VkClearColorValue nan{};
    nan.float32[0] = nan.float32[1] = nan.float32[2] = nan.float32[3] = std::nanf("");
    VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, a.levels, 0, 1};
    vkCmdClearColorImage(cmd, a.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &nan, 1, &all);
  });
  // A second submission, after the first has completed (run_once waits for its fence): the
  // LensFlare's first barrier starts from UNDEFINED, which may discard the NaNs but need not; any
  // texel the generation did not write would stay NaN on lavapipe.
  context().run_once([&](VkCommandBuffer cmd) { flare.record_setup(cmd); });
  EXPECT_TRUE(flare.atlas().generated);
  LensFlare standalone(context(), kF32, {kW, kH});
  const reference::FlareAtlas got = read_flare_atlas(flare), want = read_flare_atlas(standalone);
  for (size_t k = 0; k < got.size(); ++k) {
    for (size_t i = 0; i < got[k].rgba.size(); ++i) {
      ASSERT_TRUE(std::isfinite(got[k].rgba[i])) << "level " << k << " texel " << i / 4 << " never written";
      ASSERT_EQ(got[k].rgba[i], want[k].rgba[i]) << "level " << k;
    }
  }
  // The engine enabled no dynamicRendering (its feature chain says so): the raster path refuses.
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.synchronization2 = VK_TRUE;
  f13.maintenance4 = VK_TRUE;
  AdoptInfo info{context().instance(),           VK_API_VERSION_1_3,
                 context().physical_device(),    context().device(),
                 context().queue_family_index(), &f13};
  Context no_rendering = Context::adopt(with_glint_extensions(info));
  LensFlare compute_only(no_rendering, kF32, {kW, kH});
  detail::OwnedImage color(context(), {kW, kH}, kF32, kUsage);
  FlareInputs in({}, 0, compute_only.groups_per_instance());
  context().run_once([&](VkCommandBuffer cmd) {
    try {
      compute_only.record_raster(cmd, color.state, in.instances_view, in.indirect_view, FlareConfig{});
      ADD_FAILURE() << "record_raster without dynamicRendering did not throw";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("dynamicRendering"), std::string::npos) << e.what();
    }
  });
  // LensFlarePass refuses the raster path when it is made, not after recording the Hi-Z and cull.
  FlarePassConfig pc;
  pc.extent = {kW, kH};
  pc.color_format = kF32;
  try {
    LensFlarePass raster(no_rendering, pc);
    ADD_FAILURE() << "LensFlarePass raster without dynamicRendering did not throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("VkPhysicalDeviceVulkan13Features::dynamicRendering"), std::string::npos)
        << e.what();
  }
  pc.draw = FlareDrawPath::compute;
  EXPECT_NO_THROW((LensFlarePass{no_rendering, pc}));
}

// ---- Drawing --------------------------------------------------------------------------------------

class FlareDrawTest : public FlareTest, public ::testing::WithParamInterface<std::tuple<Path, VkFormat>> {};

TEST_P(FlareDrawTest, MatchesTheReferenceOnRandomLights) {
  const auto [path, format] = GetParam();
  LensFlare flare(context(), format, {kW, kH});
  const reference::FlareAtlas atlas = read_flare_atlas(flare);
  const CpuImage background = as_stored(random_hdr(kW, kH, 11), format);
  const auto lights = random_instances(24, 7);
  FlareInputs in(lights, uint32_t(lights.size()), flare.groups_per_instance());
  FlareConfig config = FlareConfig::preset(FlarePreset::retro_intense);
  config.halo_weight = 0.8f;  // every element clearly visible
  const CpuImage gpu = draw(flare, path, background, format, in, config);
  ASSERT_TRUE(all_finite(gpu));
  const auto ref =
      reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas, flare_sampler_precision());
  // The flares really add light here (the comparison is not of the background with itself).
  double added = 0;
  for (size_t i = 0; i < ref.rgba.size(); ++i) added += ref.rgba[i] - background.rgba[i];
  EXPECT_GT(added, 100.0);
  const FlareDeviation d = compare_flare(gpu, ref, format);
  EXPECT_EQ(d.outside, 0u) << path_name(path) << ": " << d.first;
  // The tolerance can fail: sampling one level too coarse (the atlas shifted by a level) must fall
  // outside it at many pixels.
  reference::FlareAtlas coarser(atlas.begin() + 1, atlas.end());
  coarser.push_back(coarser.back());
  const auto wrong = reference::flare_composite(background, lights, uint32_t(lights.size()), config, coarser,
                                                flare_sampler_precision());
  const FlareDeviation off_by_a_level = compare_flare(gpu, wrong, format);
  EXPECT_GT(off_by_a_level.outside, 100u) << "a one-level error stays within the tolerance";
  std::printf("flare %s %s vs float64: worst |error| / tolerance %.3f (one level off: %.1f, %zu channels outside)\n",
              path_name(path), format == kF16 ? "rgba16f" : "rgba32f", d.worst_ratio, off_by_a_level.worst_ratio,
              off_by_a_level.outside);
}

INSTANTIATE_TEST_SUITE_P(Paths, FlareDrawTest,
                         ::testing::Combine(::testing::Values(Path::raster, Path::compute),
                                            ::testing::Values(kF16, kF32)),
                         [](const auto& info) {
                           return std::string(path_name(std::get<0>(info.param))) +
                                  (std::get<1>(info.param) == kF16 ? "_rgba16f" : "_rgba32f");
                         });

// Raster and compute evaluate the same function at the same pixel centres with the same sampler
// and explicit level; they differ in how the sum is rounded: the raster path rounds to the target
// after every blend, the splat sums in fp32 and rounds once. Tolerance: (2n + 1) * u * |value| with
// n the number of sprites on the pixel (as in compare_flare()), plus the reference's coverage bound
// at pixels whose centre lies within 2e-3 px of a sprite edge, where the vertex and compute stages'
// fp32 may disagree.
TEST_F(FlareTest, RasterAndComputeGiveTheSameImageWithinTolerance) {
  for (VkFormat format : {kF16, kF32}) {
    LensFlare flare(context(), format, {kW, kH});
    const reference::FlareAtlas atlas = read_flare_atlas(flare);
    const CpuImage background = as_stored(random_hdr(kW, kH, 21), format);
    const auto lights = random_instances(40, 9);
    FlareInputs in(lights, uint32_t(lights.size()), flare.groups_per_instance());
    const FlareConfig config;
    const CpuImage raster = draw(flare, Path::raster, background, format, in, config);
    const CpuImage compute = draw(flare, Path::compute, background, format, in, config);
    const auto ref = reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas,
                                                flare_sampler_precision());
    const double u = format == kF16 ? kHalfStore : kFloatStore;
    size_t outside = 0, differ = 0;
    double worst = 0;
    for (uint32_t y = 0; y < kH; ++y) {
      for (uint32_t x = 0; x < kW; ++x) {
        const size_t p = size_t(y) * kW + x;
        for (int c = 0; c < 4; ++c) {
          const double r = raster.at(x, y)[c], k = compute.at(x, y)[c];
          // Coverage bound only where an edge is ambiguous: the reference adds the full contribution
          // there, and sampling differences are zero (same sampler, same inputs) elsewhere.
          const double coverage =
              ref.bound[p * 4 + c] > 1e-3 * std::fabs(ref.rgba[p * 4 + c]) ? ref.bound[p * 4 + c] : 0.0;
          const double tol = (2 * ref.count[p] + 1) * u * std::max(std::fabs(r), std::fabs(k)) + coverage + 1e-7;
          differ += r != k;
          if (!(std::fabs(r - k) <= tol)) ++outside;
          worst = std::max(worst, std::fabs(r - k) / tol);
        }
      }
    }
    EXPECT_EQ(outside, 0u) << (format == kF16 ? "rgba16f" : "rgba32f");
    std::printf("flare raster vs compute %s: %zu of %u channels differ, worst |diff| / tolerance %.3f\n",
                format == kF16 ? "rgba16f" : "rgba32f", differ, kW * kH * 4, worst);
  }
}

// The compute gather bins instances in batches of one per invocation and builds the listed sprites
// in chunks of one per invocation (flare_gather.comp): 300 lights give several batches, and the
// tiles near the centre, where every light's t = 1 ghost lands, list more sprites than a chunk
// holds. The indirect arguments sit at an offset that is not a multiple of the storage-buffer
// alignment, so the count is read through the rounded-down binding.
TEST_F(FlareTest, ComputeGathersManyLightsInBatchesAndChunks) {
  LensFlare flare(context(), kF32, {kW, kH});
  const reference::FlareAtlas atlas = read_flare_atlas(flare);
  const CpuImage background = random_hdr(kW, kH, 61);
  auto lights = random_instances(300, 23);
  for (auto& g : lights) g.size_px = 2.0f + 0.2f * g.size_px;  // small, so the image stays readable
  FlareInputs in(lights, uint32_t(lights.size()), flare.groups_per_instance());
  // Move the arguments 20 bytes into the buffer (a multiple of 4, not of any storage alignment).
  detail::OwnedBuffer shifted(context(), 64, in.indirect_view.usage, false);
  Buffer shifted_view{shifted.buffer(),           20,
                      sizeof(GlintFlareIndirect), in.indirect_view.usage,
                      VK_PIPELINE_STAGE_2_NONE,   VK_ACCESS_2_NONE};
  const FlareConfig config;
  auto color = make_color(background, kF32);
  context().run_once([&](VkCommandBuffer cmd) {
    in.record_upload(cmd);
    detail::Barriers b;
    b.use(shifted_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    VkBufferCopy c{in.instances.size(), 20, sizeof(GlintFlareIndirect)};  // the staged arguments
    vkCmdCopyBuffer(cmd, in.staging.buffer(), shifted.buffer(), 1, &c);
    flare.record_compute(cmd, color.state, in.instances_view, shifted_view, config);
  });
  const CpuImage gpu = detail::download(context(), color.state);
  const auto ref =
      reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas, flare_sampler_precision());
  uint32_t most = 0;
  for (uint32_t n : ref.count) most = std::max(most, n);
  EXPECT_GT(most, 64u) << "no pixel is covered by more sprites than a chunk of the gather holds";
  const FlareDeviation d = compare_flare(gpu, ref, kF32);
  EXPECT_EQ(d.outside, 0u) << d.first;
  std::printf("flare compute, 300 lights: %u sprites on the busiest pixel, worst |error| / tolerance %.3f\n", most,
              d.worst_ratio);
}

// Up to one_dispatch_instances() instances (the gather's workgroup / 9 on GPUs, none on CPU
// devices), record_compute() draws in one dispatch whose invocations evaluate the sprites themselves
// (flare_gather.comp, kFused); above it, the launch arguments, the sprite pre-pass and the gather.
// Both list a tile's sprites in (instance, slot) order and sum them in that order, so they give the
// same bits: 1 instance, 28 (one batch of the GPUs' 32x8 workgroup, four of lavapipe's 8x8) and 300
// (several batches, and chunks), both formats, the path forced. The instances buffer's size picks
// the path: the commands record_compute() makes (barriers and dispatches,
// detail::recorded_commands()) are the one-dispatch path's up to the limit and the pre-pass's above.
TEST_F(FlareTest, OneDispatchDrawGivesTheBitsOfThePrePass) {
  for (VkFormat format : {kF16, kF32}) {
    const std::string fmt = format == kF16 ? "rgba16f" : "rgba32f";
    LensFlare flare(context(), format, {kW, kH});
    // A split tile groups its sums by slice (CrowdedTilesSplitIntoSlicesMatchTheReference): the
    // bits compared here are those of the unsplit gather.
    detail::LensFlareAccess::set_split(flare, false);
    const reference::FlareAtlas atlas = read_flare_atlas(flare);
    const uint32_t most = flare.one_dispatch_instances();
    // The one-dispatch limit is one batch of its gather's workgroup (GLINT_FLARE_ONE_DISPATCH_GROUP_X/Y
    // on GPUs with 256 invocations and 32-wide subgroups), none on CPU devices.
    const DeviceInfo& info = context().info();
    const detail::FlareGatherTile one_tile = detail::LensFlareAccess::gather_tile(flare, true, 1);
    if (info.type != VK_PHYSICAL_DEVICE_TYPE_CPU && info.max_workgroup_invocations >= 256 && info.subgroup_size >= 32) {
      EXPECT_EQ(one_tile.width, GLINT_FLARE_ONE_DISPATCH_GROUP_X) << fmt;
      EXPECT_EQ(one_tile.row_step, GLINT_FLARE_ONE_DISPATCH_GROUP_Y) << fmt;
    }
    const uint32_t expected =
        info.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0 : one_tile.width * one_tile.row_step / GLINT_FLARE_SPRITES;
    EXPECT_EQ(most, expected) << fmt;
    const CpuImage background = as_stored(random_hdr(kW, kH, 81), format);
    auto lights = random_instances(300, 31);
    for (auto& g : lights) g.size_px = 2.0f + 0.3f * g.size_px;  // small, so that 300 stay readable
    const FlareConfig config;
    for (uint32_t n : {1u, 28u, 300u}) {
      const std::vector<GlintFlareInstance> list(lights.begin(), lights.begin() + n);
      FlareInputs in(list, n, flare.groups_per_instance());
      detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::pre_pass);
      const CpuImage a = draw(flare, Path::compute, background, format, in, config);
      detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::one_dispatch);
      const CpuImage b = draw(flare, Path::compute, background, format, in, config);
      const std::string what = fmt + ", " + std::to_string(n) + " instances";
      EXPECT_NE(std::memcmp(a.rgba.data(), background.rgba.data(), a.rgba.size() * 4), 0) << what << ": drew nothing";
      EXPECT_EQ(std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * 4), 0) << what;
      // And against the float64 reference on its own (lavapipe never takes it by itself).
      const auto ref = reference::flare_composite(background, list, n, config, atlas, flare_sampler_precision());
      const FlareDeviation d = compare_flare(b, ref, format);
      EXPECT_EQ(d.outside, 0u) << what << ", one dispatch: " << d.first;
    }
    detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::device);
    // Commands of one record_compute() with a buffer of `capacity` instances, on the same LensFlare
    // (its pipelines and sprite store already made).
    auto commands = [&](detail::FlareGatherPath path, size_t capacity) {
      detail::LensFlareAccess::select_gather(flare, path);
      FlareInputs in(std::vector<GlintFlareInstance>(lights.begin(), lights.begin() + 1), 1,
                     flare.groups_per_instance(), capacity);
      auto color = make_color(background, format);
      uint64_t made = 0;
      context().run_once([&](VkCommandBuffer cmd) {
        in.record_upload(cmd);
        record(flare, Path::compute, cmd, color.state, in, config);  // first use: makes what it needs
        const uint64_t before = detail::recorded_commands();
        record(flare, Path::compute, cmd, color.state, in, config);
        made = detail::recorded_commands() - before;
      });
      detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::device);
      return made;
    };
    const uint64_t one = commands(detail::FlareGatherPath::one_dispatch, most + 1);
    const uint64_t three = commands(detail::FlareGatherPath::pre_pass, std::max(most, 1u));
    EXPECT_LT(one, three) << fmt;
    if (most > 0) {
      EXPECT_EQ(commands(detail::FlareGatherPath::device, most), one) << fmt << ": " << most << " instances";
    }
    EXPECT_EQ(commands(detail::FlareGatherPath::device, most + 1), three) << fmt << ": " << most + 1 << " instances";
  }
}

// The pre-pass gather's tile height (rows per invocation: 2 on GPUs for buffers of fewer than
// GLINT_FLARE_SPLIT_FROM_INSTANCES instances, else 8, as in the one-dispatch gather) and the order its workgroups take
// the tiles in (from the image centre on GPUs, the IDs' order on CPU devices and in the one-dispatch gather) change
// which workgroup shades a pixel and when, not the list it sums nor its order (without the split of crowded tiles,
// which groups a split tile's sums by slice: the next test): 500 small lights, whose ghosts at t = 1 all land on the
// image centre (hundreds of sprites on its pixels, several chunks of the shared list), both formats, give the same bits
// at 1, 2, 4 and 8 rows (an odd count of tiles at 4 rows on lavapipe, 5 columns on GPUs), in both orders, and match the
// float64 reference.
TEST_F(FlareTest, PrePassGatherGivesTheSameBitsAtEveryTileHeight) {
  const DeviceInfo& info = context().info();
  for (VkFormat format : {kF16, kF32}) {
    const std::string fmt = format == kF16 ? "rgba16f" : "rgba32f";
    LensFlare flare(context(), format, {kW, kH});
    const detail::FlareGatherTile pre = detail::LensFlareAccess::gather_tile(flare, false, 500);
    const detail::FlareGatherTile one = detail::LensFlareAccess::gather_tile(flare, true, 500);
    const detail::FlareGatherTile split =
        detail::LensFlareAccess::gather_tile(flare, false, GLINT_FLARE_SPLIT_FROM_INSTANCES);
    const bool cpu = info.type == VK_PHYSICAL_DEVICE_TYPE_CPU;
    EXPECT_EQ(pre.height, (cpu ? GLINT_FLARE_GATHER_ROWS : GLINT_FLARE_GATHER_PRE_PASS_ROWS) * pre.row_step) << fmt;
    EXPECT_EQ(split.height, GLINT_FLARE_GATHER_ROWS * split.row_step) << fmt;
    EXPECT_EQ(split.centre_first, !cpu) << fmt;
    EXPECT_EQ(one.height, GLINT_FLARE_GATHER_ROWS * one.row_step) << fmt;
    EXPECT_EQ(pre.centre_first, info.type != VK_PHYSICAL_DEVICE_TYPE_CPU) << fmt;
    EXPECT_FALSE(one.centre_first) << fmt;
    const reference::FlareAtlas atlas = read_flare_atlas(flare);
    const CpuImage background = as_stored(random_hdr(kW, kH, 83), format);
    const auto lights = piled_lights(37);
    const FlareConfig config;
    FlareInputs in(lights, uint32_t(lights.size()), flare.groups_per_instance());
    detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::pre_pass);
    detail::LensFlareAccess::set_split(flare, false);
    std::vector<CpuImage> images;
    for (bool centre_first : {false, true}) {
      for (uint32_t r : {1u, 2u, 4u, 8u}) {
        detail::LensFlareAccess::set_pre_pass_tiles(flare, r, centre_first);
        images.push_back(draw(flare, Path::compute, background, format, in, config));
        EXPECT_EQ(std::memcmp(images.back().rgba.data(), images.front().rgba.data(), images.front().rgba.size() * 4), 0)
            << fmt << ", " << r << " rows" << (centre_first ? ", centre first" : "") << " against 1 row";
      }
    }
    // Other workgroup shapes (the benchmarks compare them per device): other tiles, the same sums.
    for (detail::Workgroup2D g : {detail::Workgroup2D{16, 8}, detail::Workgroup2D{8, 16}, detail::Workgroup2D{64, 4},
                                  detail::Workgroup2D{4, 4}}) {
      detail::LensFlareAccess::set_gather_workgroup(flare, g.x, g.y);
      EXPECT_EQ(detail::LensFlareAccess::gather_tile(flare, false, 500).width, g.x) << fmt;
      const CpuImage image = draw(flare, Path::compute, background, format, in, config);
      EXPECT_EQ(std::memcmp(image.rgba.data(), images.front().rgba.data(), images.front().rgba.size() * 4), 0)
          << fmt << ", workgroup " << g.x << "x" << g.y << " against the device's";
    }
    // The one-dispatch gather (forced: the piled lights make several batches) in other shapes and rows.
    detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::one_dispatch);
    for (auto [g, rows] : {std::pair{detail::Workgroup2D{16, 16}, 8u}, std::pair{detail::Workgroup2D{32, 8}, 2u},
                           std::pair{detail::Workgroup2D{8, 32}, 4u}}) {
      detail::LensFlareAccess::set_gather_workgroup(flare, g.x, g.y, true, rows);
      const detail::FlareGatherTile tile = detail::LensFlareAccess::gather_tile(flare, true, 37);
      EXPECT_EQ(tile.width, g.x) << fmt;
      EXPECT_EQ(tile.height, g.y * rows) << fmt;
      const CpuImage image = draw(flare, Path::compute, background, format, in, config);
      EXPECT_EQ(std::memcmp(image.rgba.data(), images.front().rgba.data(), images.front().rgba.size() * 4), 0)
          << fmt << ", one dispatch in " << g.x << "x" << g.y << ", " << rows << " rows, against the pre-pass";
    }
    detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::pre_pass);
    EXPECT_NE(std::memcmp(images[0].rgba.data(), background.rgba.data(), background.rgba.size() * 4), 0)
        << fmt << ": drew nothing";
    const auto ref = reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas,
                                                flare_sampler_precision());
    const FlareDeviation d = compare_flare(images[1], ref, format);
    EXPECT_EQ(d.outside, 0u) << fmt << ": " << d.first;
    EXPECT_THROW(detail::LensFlareAccess::set_pre_pass_tiles(flare, 0, false), Error);
    EXPECT_THROW(detail::LensFlareAccess::set_pre_pass_tiles(flare, GLINT_FLARE_GATHER_ROWS + 1, true), Error);
    EXPECT_THROW(detail::LensFlareAccess::set_gather_workgroup(flare, 2, 4), Error);
    EXPECT_THROW(detail::LensFlareAccess::set_gather_workgroup(flare, 32, 16), Error);
    EXPECT_THROW(detail::LensFlareAccess::set_gather_workgroup(flare, 16, 16, true, GLINT_FLARE_GATHER_ROWS + 1),
                 Error);
    EXPECT_THROW(detail::LensFlareAccess::set_gather_workgroup(flare, 32, 8, false, 2), Error);
  }
}

// The words of a device buffer (the split plan), read back after the commands before.
std::vector<uint32_t> read_words(Buffer buffer) {
  detail::OwnedBuffer staging(context(), buffer.size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  context().run_once([&](VkCommandBuffer cmd) {
    detail::Barriers b;
    b.use(buffer, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    VkBufferCopy c{buffer.offset, 0, buffer.size};
    vkCmdCopyBuffer(cmd, buffer.buffer, staging.buffer(), 1, &c);
  });
  staging.invalidate();
  std::vector<uint32_t> words(buffer.size / 4);
  std::memcpy(words.data(), staging.mapped(), words.size() * 4);
  return words;
}

// Crowded tiles split into slices (flare_params.h, "Crowded tiles"), on every device: 500 small
// lights whose ghosts at t = 1 pile on the image centre, both formats, with thresholds that split
// the tiles counting at least 200 sprites into up to 8 slices. The plan read back splits some
// tiles and uses at most GLINT_FLARE_SPLIT_SLOTS slots; the image matches the float64 reference
// (and, in rgba32f, differs from the unsplit gather's: the split gather ran); a second frame plans
// the same and gives the same bits (the plan zeroes the counts, and the finished-slice words,
// which read every slice of a split tile finished once).
// With a tile's every sprite a slice (up to 31), the frame would need more slots than there are:
// the tiles keep a fraction of their slices, within the slots, and the image still matches.
TEST_F(FlareTest, CrowdedTilesSplitIntoSlicesMatchTheReference) {
  for (VkFormat format : {kF16, kF32}) {
    const std::string fmt = format == kF16 ? "rgba16f" : "rgba32f";
    LensFlare flare(context(), format, {kW, kH});
    const reference::FlareAtlas atlas = read_flare_atlas(flare);
    const CpuImage background = as_stored(random_hdr(kW, kH, 87), format);
    const auto lights = piled_lights(41);
    const FlareConfig config;
    FlareInputs in(lights, uint32_t(lights.size()), flare.groups_per_instance());
    detail::LensFlareAccess::select_gather(flare, detail::FlareGatherPath::pre_pass);
    detail::LensFlareAccess::set_split(flare, false);
    const CpuImage unsplit = draw(flare, Path::compute, background, format, in, config);

    detail::LensFlareAccess::set_split(flare, true, 200, 16, 8);
    const detail::FlareGatherTile tile = detail::LensFlareAccess::gather_tile(flare, false, lights.size());
    const size_t tiles = size_t((kW + tile.width - 1) / tile.width) * ((kH + tile.height - 1) / tile.height);
    const size_t used_word = 3 * tiles + GLINT_FLARE_SPLIT_SLOTS;
    const CpuImage a = draw(flare, Path::compute, background, format, in, config);
    const std::vector<uint32_t> first = read_words(detail::LensFlareAccess::split_words(flare));
    const CpuImage b = draw(flare, Path::compute, background, format, in, config);
    const std::vector<uint32_t> second = read_words(detail::LensFlareAccess::split_words(flare));
    ASSERT_EQ(first.size(), used_word + 1) << fmt;
    size_t split_tiles = 0, slots = 0;
    for (size_t i = 0; i < tiles; ++i) {
      const uint32_t slices = first[tiles + i] & 31u;
      EXPECT_GE(slices, 1u) << fmt << ", tile " << i;
      EXPECT_LE(slices, 8u) << fmt << ", tile " << i;
      if (slices > 1) {
        ++split_tiles, slots += slices;
        // The tile's slots name it and its slices in order.
        const uint32_t slot0 = first[tiles + i] >> 5u;
        for (uint32_t k = 0; k < slices && slot0 + k < GLINT_FLARE_SPLIT_SLOTS; ++k)
          EXPECT_EQ(first[3 * tiles + slot0 + k], (uint32_t(i) << 5u) | k) << fmt << ", tile " << i << " slot " << k;
      }
      EXPECT_EQ(first[i], 0u) << fmt << ": the count of tile " << i << " was not zeroed";
      // Every slice of a split tile finished once (the next frame's plan zeroes the count).
      EXPECT_EQ(first[2 * tiles + i], slices > 1 ? slices : 0u) << fmt << ": the finished slices of tile " << i;
    }
    EXPECT_GT(split_tiles, 0u) << fmt << ": no tile was split";
    EXPECT_EQ(first[used_word], slots) << fmt;
    EXPECT_LE(slots, GLINT_FLARE_SPLIT_SLOTS) << fmt;
    EXPECT_EQ(first, second) << fmt << ": the second frame planned otherwise";
    EXPECT_EQ(std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * 4), 0) << fmt << ": frames differ";
    const auto ref = reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas,
                                                flare_sampler_precision());
    const FlareDeviation d = compare_flare(a, ref, format);
    EXPECT_EQ(d.outside, 0u) << fmt << ", " << split_tiles << " tiles split: " << d.first;
    // The split gather ran: its sums are grouped by slice (thousands of fp32 values differ; in
    // rgba16f the rounding to half hides nearly all).
    if (format == kF32) {
      EXPECT_NE(std::memcmp(a.rgba.data(), unsplit.rgba.data(), a.rgba.size() * 4), 0);
    }

    // Every sprite a slice, up to 31 a tile: more slots than there are on this image's tiles
    // (every tile grid of it has at least 9 tiles of 31 sprites or more: 279 slots), so every tile
    // keeps 1 / scale of its slices, scale >= 2 (at most 15 slices), and the slots stay within the
    // cap; the image still matches and repeats.
    detail::LensFlareAccess::set_split(flare, true, 1, 1, 31);
    const CpuImage c = draw(flare, Path::compute, background, format, in, config);
    const std::vector<uint32_t> over = read_words(detail::LensFlareAccess::split_words(flare));
    const CpuImage c2 = draw(flare, Path::compute, background, format, in, config);
    size_t over_tiles = 0, over_slots = 0;
    for (size_t i = 0; i < tiles; ++i) {
      const uint32_t slices = over[tiles + i] & 31u;
      EXPECT_LE(slices, 15u) << fmt << ", tile " << i << ": the slices were not scaled down";
      if (slices > 1) ++over_tiles, over_slots += slices;
    }
    EXPECT_GT(over_tiles, 0u) << fmt;
    EXPECT_EQ(over[used_word], over_slots) << fmt;
    EXPECT_LE(over_slots, GLINT_FLARE_SPLIT_SLOTS) << fmt;
    const FlareDeviation dc = compare_flare(c, ref, format);
    EXPECT_EQ(dc.outside, 0u) << fmt << ", slices scaled: " << dc.first;
    EXPECT_EQ(std::memcmp(c.rgba.data(), c2.rgba.data(), c.rgba.size() * 4), 0) << fmt << ": frames differ";
    EXPECT_THROW(detail::LensFlareAccess::set_split(flare, true, 1, 0, 8), Error);
    EXPECT_THROW(detail::LensFlareAccess::set_split(flare, true, 1, 1, 32), Error);

    // The split gather in another workgroup (the benchmarks compare shapes): the counted tiles, the
    // plan and the slots follow the gather's tiles.
    detail::LensFlareAccess::set_split(flare, true, 200, 16, 8);
    detail::LensFlareAccess::set_gather_workgroup(flare, 16, 16);
    const detail::FlareGatherTile t16 = detail::LensFlareAccess::gather_tile(flare, false, lights.size());
    EXPECT_EQ(t16.width, 16u) << fmt;
    const size_t tiles16 = size_t((kW + t16.width - 1) / t16.width) * ((kH + t16.height - 1) / t16.height);
    const CpuImage s16 = draw(flare, Path::compute, background, format, in, config);
    const std::vector<uint32_t> w16 = read_words(detail::LensFlareAccess::split_words(flare));
    ASSERT_EQ(w16.size(), 3 * tiles16 + GLINT_FLARE_SPLIT_SLOTS + 1) << fmt;
    size_t split16 = 0;
    for (size_t i = 0; i < tiles16; ++i) split16 += (w16[tiles16 + i] & 31u) > 1 ? 1 : 0;
    EXPECT_GT(split16, 0u) << fmt << ": no 16x" << t16.height << " tile was split";
    const FlareDeviation d16 = compare_flare(s16, ref, format);
    EXPECT_EQ(d16.outside, 0u) << fmt << ", 16x16 workgroups, " << split16 << " tiles split: " << d16.first;
  }
}

// Draws `stored` + 6 instances with the sprite store holding `stored` (the device's limit, or a
// smaller cap set through LensFlareAccess::set_max_stored_instances): the first 6 and last 6 are
// lights, the rest zeros (size 0, nothing drawn), so the last 6 are evaluated by the gather
// itself. Checks the image against the float64 reference, at another tile height, and split.
void check_beyond_store(LensFlare& flare, uint64_t stored, const reference::FlareAtlas& atlas) {
  const uint64_t n = stored + 6;
  const CpuImage background = random_hdr(kW, kH, 71);
  const auto lights = random_instances(12, 29);
  std::vector<GlintFlareInstance> list(n);  // zeros: size 0, nothing drawn
  for (uint32_t k = 0; k < 6; ++k) {
    list[k] = lights[k];              // sprites from the store
    list[n - 6 + k] = lights[6 + k];  // sprites evaluated by the gather
  }
  FlareInputs big(list, uint32_t(n), flare.groups_per_instance());
  FlareInputs small(lights, uint32_t(lights.size()), flare.groups_per_instance());
  const FlareConfig config;
  const auto ref_small =
      reference::flare_composite(background, lights, uint32_t(lights.size()), config, atlas, flare_sampler_precision());
  const auto ref_big =
      reference::flare_composite(background, list, uint32_t(n), config, atlas, flare_sampler_precision());
  const auto ref_front = reference::flare_composite(background, lights, 6, config, atlas, flare_sampler_precision());
  const std::string what = std::to_string(stored) + " stored";
  const CpuImage a = draw(flare, Path::compute, background, kF32, small, config);
  const CpuImage b = draw(flare, Path::compute, background, kF32, big, config);
  const CpuImage c = draw(flare, Path::compute, background, kF32, small, config);
  EXPECT_EQ(compare_flare(a, ref_small, kF32).outside, 0u) << what;
  const FlareDeviation d = compare_flare(b, ref_big, kF32);
  EXPECT_EQ(d.outside, 0u) << what << ": " << d.first;
  EXPECT_GT(compare_flare(b, ref_front, kF32).outside, 100u) << what << ": the lights beyond the store were not drawn";
  EXPECT_EQ(detail::LensFlareAccess::sprite_store_capacity(flare), stored) << what << ": the store holds more";
  EXPECT_EQ(compare_flare(c, ref_small, kF32).outside, 0u) << what;
  // The gather beyond the store at another tile height (made again when the rows change): the
  // same bits. 4 rows where the device takes 8 (CPU devices: half as many tiles again to bin the
  // 441 k instances in, where 2 rows would triple them), else 8.
  const detail::FlareGatherTile tile = detail::LensFlareAccess::gather_tile(flare, false, n);
  const uint32_t other = tile.height / tile.row_step == GLINT_FLARE_GATHER_ROWS ? 4u : GLINT_FLARE_GATHER_ROWS;
  detail::LensFlareAccess::set_pre_pass_tiles(flare, other, true);
  const CpuImage e = draw(flare, Path::compute, background, kF32, big, config);
  EXPECT_EQ(std::memcmp(e.rgba.data(), b.rgba.data(), b.rgba.size() * 4), 0) << what << ", " << other << " rows";
  // And with the tiles that the lights light split into slices (the split gather beyond the store).
  detail::LensFlareAccess::set_split(flare, true, 1, 4, 8);
  const CpuImage g = draw(flare, Path::compute, background, kF32, big, config);
  const detail::FlareGatherTile split_tile = detail::LensFlareAccess::gather_tile(flare, false, n);
  const size_t tiles =
      size_t((kW + split_tile.width - 1) / split_tile.width) * ((kH + split_tile.height - 1) / split_tile.height);
  EXPECT_GT(read_words(detail::LensFlareAccess::split_words(flare))[3 * tiles + GLINT_FLARE_SPLIT_SLOTS], 0u)
      << what << ": no tile was split";
  const FlareDeviation dg = compare_flare(g, ref_big, kF32);
  EXPECT_EQ(dg.outside, 0u) << what << ", split: " << dg.first;
  std::printf("flare compute, %llu instances (%llu stored): worst |error| / tolerance %.3f\n",
              static_cast<unsigned long long>(n), static_cast<unsigned long long>(stored), d.worst_ratio);
}

// The sprite pre-pass stores 304 bytes per instance in one storage-buffer descriptor, fewer
// instances than the 48-byte instances buffer may hold (maxStorageBufferRange / 304 against / 48):
// the gather evaluates the sprites of the instances beyond the store itself. Lights at both ends of
// such a buffer (the rest draw nothing), between draws from a small buffer with the same LensFlare
// (its first store is kept for it, a second, larger one made): every draw matches the reference.
// At the device's own limit where those instances fit in 64 MiB (lavapipe's 2^27-byte ranges), and
// on every device with the store capped at 64 instances.
TEST_F(FlareTest, ComputeDrawsInstancesBeyondItsSpriteStore) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  const uint64_t stored = props.limits.maxStorageBufferRange / (GLINT_FLARE_BLOCK_VEC4S * 16);
  {
    LensFlare flare(context(), kF32, {kW, kH});
    if ((stored + 6) * sizeof(GlintFlareInstance) <= (uint64_t(64) << 20) &&
        stored + 6 <= flare.max_compute_instances()) {
      check_beyond_store(flare, stored, read_flare_atlas(flare));
    } else {
      std::printf(
          "maxStorageBufferRange %u: the device's own sprite store is not reached (its instances need more "
          "than 64 MiB); the capped store is\n",
          props.limits.maxStorageBufferRange);
    }
  }
  LensFlare flare(context(), kF32, {kW, kH});
  detail::LensFlareAccess::set_max_stored_instances(flare, 64);
  check_beyond_store(flare, 64, read_flare_atlas(flare));
  EXPECT_THROW(detail::LensFlareAccess::set_max_stored_instances(flare, 0), Error);
}

TEST_F(FlareTest, ZeroInstancesAndDisabledLeaveTheImageBitIdentical) {
  for (VkFormat format : {kF16, kF32}) {
    LensFlare flare(context(), format, {kW, kH});
    const CpuImage background = as_stored(random_hdr(kW, kH, 31), format);
    const auto lights = random_instances(8, 3);
    FlareInputs none(lights, 0, flare.groups_per_instance());  // the cull found nothing visible
    FlareInputs some(lights, 8, flare.groups_per_instance());
    for (Path path : {Path::raster, Path::compute}) {
      const CpuImage a = draw(flare, path, background, format, none, FlareConfig{});
      EXPECT_EQ(std::memcmp(a.rgba.data(), background.rgba.data(), a.rgba.size() * 4), 0)
          << path_name(path) << " 0 instances";
      const CpuImage b = draw(flare, path, background, format, some, FlareConfig::preset(FlarePreset::disabled));
      EXPECT_EQ(std::memcmp(b.rgba.data(), background.rgba.data(), b.rgba.size() * 4), 0)
          << path_name(path) << " disabled";
      const CpuImage c = draw(flare, path, background, format, some, FlareConfig{});
      EXPECT_NE(std::memcmp(c.rgba.data(), background.rgba.data(), c.rgba.size() * 4), 0)
          << path_name(path) << " drew nothing";
      // Alpha is never written.
      for (size_t i = 3; i < c.rgba.size(); i += 4) ASSERT_EQ(c.rgba[i], background.rgba[i]) << path_name(path);
    }
  }
}

TEST_F(FlareTest, InstancesBeyondTheIndirectCountAreIgnored) {
  LensFlare flare(context(), kF32, {kW, kH});
  const reference::FlareAtlas atlas = read_flare_atlas(flare);
  const CpuImage background = random_hdr(kW, kH, 41);
  const auto lights = random_instances(10, 13);
  FlareInputs three(lights, 3, flare.groups_per_instance());
  const FlareConfig config;
  const auto ref3 = reference::flare_composite(background, lights, 3, config, atlas, flare_sampler_precision());
  const auto ref10 = reference::flare_composite(background, lights, 10, config, atlas, flare_sampler_precision());
  for (Path path : {Path::raster, Path::compute}) {
    const CpuImage gpu = draw(flare, path, background, kF32, three, config);
    EXPECT_EQ(compare_flare(gpu, ref3, kF32).outside, 0u) << path_name(path) << " differs from the first 3 lights";
    EXPECT_GT(compare_flare(gpu, ref10, kF32).outside, 100u) << path_name(path) << ": the other 7 would have shown";
  }
}

// Added light (image minus background) on a black background, one light in the middle.
std::vector<double> added_light(LensFlare& flare, Path path, GlintFlareInstance light, const FlareConfig& config) {
  FlareInputs in({light}, 1, flare.groups_per_instance());
  const CpuImage black(kW, kH, 0.0f);
  const CpuImage out = draw(flare, path, black, kF32, in, config);
  std::vector<double> added(size_t(kW) * kH);
  for (size_t p = 0; p < added.size(); ++p) added[p] = out.rgba[p * 4] + out.rgba[p * 4 + 1] + out.rgba[p * 4 + 2];
  return added;
}

GlintFlareInstance centre_light(float size) {
  GlintFlareInstance g{};
  g.center_x_px = kW / 2.0f + 0.3f;
  g.center_y_px = kH / 2.0f - 0.2f;
  g.size_px = size;
  g.visible_fraction = 0.8f;
  g.color_r = 2.0f;
  g.color_g = 1.5f;
  g.color_b = 1.0f;
  g.intensity = 3.0f;
  g.element = GLINT_FLARE_ELEMENT_GLOW;
  return g;
}

TEST_F(FlareTest, BrightnessIsLinearInVisibleFractionAndIntensity) {
  LensFlare flare(context(), kF32, {kW, kH});
  for (Path path : {Path::raster, Path::compute}) {
    const GlintFlareInstance base = centre_light(20.0f);
    const auto a = added_light(flare, path, base, FlareConfig{});
    GlintFlareInstance half_fraction = base;
    half_fraction.visible_fraction *= 0.5f;
    GlintFlareInstance double_intensity = base;
    double_intensity.intensity *= 2.0f;
    FlareConfig dim;
    dim.intensity = 0.25f;
    const auto b = added_light(flare, path, half_fraction, FlareConfig{});
    const auto c = added_light(flare, path, double_intensity, FlareConfig{});
    const auto d = added_light(flare, path, base, dim);
    double total = 0;
    for (size_t p = 0; p < a.size(); ++p) {
      total += a[p];
      // Scaling by a power of two is exact in fp32 up to the sum's rounding (a few ulp).
      ASSERT_NEAR(b[p], 0.5 * a[p], 1e-6 * a[p] + 1e-12) << path_name(path) << " pixel " << p;
      ASSERT_NEAR(c[p], 2.0 * a[p], 1e-6 * a[p] + 1e-12) << path_name(path) << " pixel " << p;
      ASSERT_NEAR(d[p], 0.25 * a[p], 1e-6 * a[p] + 1e-12) << path_name(path) << " pixel " << p;
    }
    EXPECT_GT(total, 10.0) << path_name(path);
  }
}

// Second moments of the added light about the light: the anamorphic ratio stretches x only.
TEST_F(FlareTest, AnamorphicRatioStretchesHorizontally) {
  LensFlare flare(context(), kF32, {kW, kH});
  FlareConfig only_main;
  only_main.streak_weight = only_main.halo_weight = only_main.starburst_weight = only_main.ghost_weight = 0.0f;
  const GlintFlareInstance light = centre_light(24.0f);
  for (Path path : {Path::raster, Path::compute}) {
    auto moments = [&](float ratio) {
      FlareConfig c = only_main;
      c.anamorphic_ratio = ratio;
      const auto added = added_light(flare, path, light, c);
      double e = 0, xx = 0, yy = 0;
      for (uint32_t y = 0; y < kH; ++y) {
        for (uint32_t x = 0; x < kW; ++x) {
          const double a = added[size_t(y) * kW + x];
          e += a;
          xx += a * (x + 0.5 - light.center_x_px) * (x + 0.5 - light.center_x_px);
          yy += a * (y + 0.5 - light.center_y_px) * (y + 0.5 - light.center_y_px);
        }
      }
      return std::array<double, 3>{e, xx / e, yy / e};
    };
    const auto one = moments(1.0f), three = moments(3.0f);
    EXPECT_NEAR(three[1] / one[1], 9.0, 0.3) << path_name(path) << ": x spread scales with the ratio squared";
    EXPECT_NEAR(three[2] / one[2], 1.0, 0.03) << path_name(path) << ": y spread unchanged";
    EXPECT_NEAR(three[0] / one[0], 3.0, 0.1) << path_name(path) << ": area (energy) scales with the ratio";
  }
}

TEST_F(FlareTest, RecordingAgainCreatesNoVulkanObject) {
  LensFlare flare(context(), kF16, {kW, kH});
  const auto lights = random_instances(5, 17);
  FlareInputs in(lights, 5, flare.groups_per_instance());
  auto color = make_color(random_hdr(kW, kH, 3), kF16);
  auto frame = [&] {
    context().run_once([&](VkCommandBuffer cmd) {
      in.record_upload(cmd);
      flare.record_raster(cmd, color.state, in.instances_view, in.indirect_view, FlareConfig{});
      flare.record_compute(cmd, color.state, in.instances_view, in.indirect_view, FlareConfig{});
    });
  };
  frame();
  const uint64_t before = context().objects_created();
  frame();
  frame();
  EXPECT_EQ(context().objects_created(), before);
}

TEST_F(FlareTest, NonFiniteOrEmptyInstancesDrawNothing) {
  LensFlare flare(context(), kF32, {kW, kH});
  std::vector<GlintFlareInstance> bad(5, centre_light(20.0f));
  bad[0].center_x_px = std::nanf("");
  bad[1].size_px = 0.0f;
  bad[2].visible_fraction = 0.0f;
  bad[3].intensity = INFINITY;
  bad[4].color_g = std::nanf("");
  const CpuImage background = random_hdr(kW, kH, 51);
  FlareInputs in(bad, 5, flare.groups_per_instance());
  for (Path path : {Path::raster, Path::compute}) {
    const CpuImage out = draw(flare, path, background, kF32, in, FlareConfig{});
    EXPECT_EQ(std::memcmp(out.rgba.data(), background.rgba.data(), out.rgba.size() * 4), 0) << path_name(path);
  }
}

}  // namespace
}  // namespace glint::test
