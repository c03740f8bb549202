// Lens flares end to end through the public API (LensFlarePass: Hi-Z -> cull -> draw in
// one command buffer) on a scene with a known occluder: lights behind it add nothing, visible ones
// add light at their position, the statistics and per-light results match a CPU classification,
// the raster and compute paths agree within docs/FLARE.md's tolerance, lights behind the camera,
// at w = 0 and far off screen add nothing, thousands of lights on one pixel overflow the capacity
// safely, and zero lights leave the image bit for bit. Validation with synchronization validation
// is on for every test (support/gpu_test.h).
#include <glint/flare_pass.h>
#include <glint/gpu/flare_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/barriers.h"
#include "core/half.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"
#include "visibility/light_cull_internal.h"

namespace glint::test {
namespace {

constexpr uint32_t kW = 192, kH = 128;
constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkImageUsageFlags kColorUsage = detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
constexpr VkBufferUsageFlags kLightUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

class FlareEndToEndTest : public GpuTest {};

// The occluder: pixels [40, 100) x [30, 90) at distance 5 over the far plane.
std::vector<float> scene_depth(const Camera& cam) {
  std::vector<float> d(size_t(kW) * kH, 1.0f);
  const auto box = float(cam.depth_at(5.0));
  for (uint32_t y = 30; y < 90; ++y)
    for (uint32_t x = 40; x < 100; ++x) d[size_t(y) * kW + x] = box;
  return d;
}

// Named lights of the scene with the class the CPU expects for each.
struct SceneLight {
  const char* name;
  GlintFlareLight light;
  uint32_t expected;  // GLINT_FLARE_*
};

std::vector<SceneLight> scene_lights(const Camera& cam) {
  std::vector<SceneLight> s;
  s.push_back({"behind the box", cam.light_at(70, 60, 20, 16), GLINT_FLARE_OCCLUDED});
  s.push_back({"in the open", cam.light_at(150, 40, 20, 16), GLINT_FLARE_VISIBLE});
  s.push_back({"before the box", cam.light_at(60, 50, 3, 16), GLINT_FLARE_VISIBLE});
  GlintFlareLight behind = cam.light_at(96, 64, 10, 16);
  behind.position_z = 5.0f;  // behind the camera: w = -5
  s.push_back({"behind the camera", behind, GLINT_FLARE_FRUSTUM});
  GlintFlareLight w0 = behind;
  w0.position_x = 0.3f;
  w0.position_y = -0.2f;
  w0.position_z = 0.0f;  // w = 0 exactly
  s.push_back({"at w = 0", w0, GLINT_FLARE_FRUSTUM});
  s.push_back({"far off screen", cam.light_at(3.0 * kW, 64, 20, 16), GLINT_FLARE_FRUSTUM});
  GlintFlareLight off = cam.light_at(150, 100, 20, 16);
  off.enabled = 0;
  s.push_back({"disabled", off, GLINT_FLARE_DISABLED});
  return s;
}

struct FrameResult {
  CpuImage image;
  GlintFlareStats stats{};
  GlintFlareIndirect indirect{};
  std::vector<GlintFlareLightResult> results;
};

// Uploads `background`, the depth and the lights, records pass.record() once (or `frames` times)
// and reads everything back, in one command buffer.
FrameResult run_frame(LensFlarePass& pass, const CpuImage& background, const std::vector<float>& depth,
                      const std::vector<GlintFlareLight>& lights, const std::array<float, 16>& view_proj,
                      const FlareConfig& look, int frames = 1) {
  const Context& ctx = context();
  const auto n = static_cast<uint32_t>(lights.size());
  const VkExtent2D extent{background.width, background.height};
  detail::OwnedImage color(ctx, extent, kF16, kColorUsage);
  detail::OwnedImage depth_image(ctx, extent, VK_FORMAT_D32_SFLOAT,
                                 VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  const VkDeviceSize light_bytes = std::max<VkDeviceSize>(VkDeviceSize(n) * sizeof(GlintFlareLight), 16);
  detail::OwnedBuffer light_buffer(ctx, light_bytes, kLightUsage, false);
  Buffer light_view{light_buffer.buffer(), 0, light_bytes, kLightUsage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  detail::OwnedBuffer light_up(ctx, light_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  if (n) std::memcpy(light_up.mapped(), lights.data(), size_t(n) * sizeof(GlintFlareLight));
  light_up.flush();
  const auto color_up = detail::make_upload_staging(ctx, color.image(), background);
  const auto depth_up = detail::make_upload_staging_r32(ctx, depth_image.image(), depth);
  const auto color_down = detail::make_readback_staging(ctx, color.image());
  const VkDeviceSize results_bytes = VkDeviceSize(n) * sizeof(GlintFlareLightResult);
  detail::OwnedBuffer down(ctx, 64 + results_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  const bool with_results = pass.config().per_light_results;
  ctx.run_once([&](VkCommandBuffer cmd) {
    detail::record_upload(cmd, color_up, color.image());
    detail::record_upload(cmd, depth_up, depth_image.image());
    detail::Barriers b;
    b.use(light_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    const VkBufferCopy lc{0, 0, light_bytes};
    vkCmdCopyBuffer(cmd, light_up.buffer(), light_buffer.buffer(), 1, &lc);
    for (int f = 0; f < frames; ++f) {
      pass.record(cmd, color.image(), depth_image.image(), light_view, n, view_proj.data(), look);
    }
    detail::record_readback(cmd, color.image(), color_down);
    b.use(pass.stats(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.use(pass.indirect(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    if (with_results) b.use(pass.results(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    const VkBufferCopy sc{0, 0, 32}, ic{0, 32, 32}, rc{0, 64, results_bytes};
    vkCmdCopyBuffer(cmd, pass.stats().buffer, down.buffer(), 1, &sc);
    vkCmdCopyBuffer(cmd, pass.indirect().buffer, down.buffer(), 1, &ic);
    if (with_results && n) vkCmdCopyBuffer(cmd, pass.results().buffer, down.buffer(), 1, &rc);
    Buffer d{down.buffer(), 0, down.size(), 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(d, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  FrameResult r;
  r.image = detail::read_staged(color_down, color.image());
  down.invalidate();
  const auto* bytes = static_cast<const char*>(down.mapped());
  std::memcpy(&r.stats, bytes, 32);
  std::memcpy(&r.indirect, bytes + 32, 32);
  if (with_results) {
    r.results.resize(n);
    if (n) std::memcpy(r.results.data(), bytes + 64, results_bytes);
  }
  return r;
}

FlarePassConfig pass_config(FlareDrawPath path, uint32_t capacity = 64, uint32_t max_lights = 64) {
  FlarePassConfig pc;
  pc.extent = {kW, kH};
  pc.cull.capacity = capacity;
  pc.cull.max_lights = max_lights;
  pc.draw = path;
  pc.per_light_results = true;
  return pc;
}

std::vector<GlintFlareLight> only(const std::vector<SceneLight>& s, std::initializer_list<uint32_t> classes) {
  std::vector<GlintFlareLight> out;
  for (const auto& l : s) {
    if (std::find(classes.begin(), classes.end(), l.expected) != classes.end()) out.push_back(l.light);
  }
  return out;
}

// Sum of RGB over the (2r+1)^2 pixels around (cx, cy).
double energy(const CpuImage& img, int cx, int cy, int r) {
  double sum = 0;
  for (int y = std::max(0, cy - r); y <= std::min(int(img.height) - 1, cy + r); ++y)
    for (int x = std::max(0, cx - r); x <= std::min(int(img.width) - 1, cx + r); ++x)
      for (int c = 0; c < 3; ++c) sum += img.at(uint32_t(x), uint32_t(y))[c];
  return sum;
}

TEST_F(FlareEndToEndTest, StatisticsAndResultsMatchTheCpuClassification) {
  const Camera cam{kW, kH};
  const auto lights = scene_lights(cam);
  std::vector<GlintFlareLight> list;
  for (const auto& l : lights) list.push_back(l.light);
  const CpuImage background = random_hdr(kW, kH, 5);
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    LensFlarePass pass(context(), pass_config(path));
    const FrameResult r = run_frame(pass, background, scene_depth(cam), list, cam.view_proj(),
                                    FlareConfig::preset(FlarePreset::cinematic));
    uint32_t counts[5] = {};
    for (size_t i = 0; i < lights.size(); ++i) {
      counts[lights[i].expected]++;
      EXPECT_EQ(r.results[i].culled, lights[i].expected) << lights[i].name;
      if (lights[i].expected == GLINT_FLARE_VISIBLE) {
        EXPECT_EQ(r.results[i].visible_fraction, 1.0f) << lights[i].name << ": far from any edge";
      } else {
        EXPECT_EQ(r.results[i].visible_fraction, 0.0f) << lights[i].name;
      }
    }
    EXPECT_EQ(r.stats.total, lights.size());
    EXPECT_EQ(r.stats.visible, counts[GLINT_FLARE_VISIBLE]);
    EXPECT_EQ(r.stats.occluded, counts[GLINT_FLARE_OCCLUDED]);
    EXPECT_EQ(r.stats.frustum_culled, counts[GLINT_FLARE_FRUSTUM]);
    EXPECT_EQ(r.stats.disabled, counts[GLINT_FLARE_DISABLED]);
    EXPECT_EQ(r.stats.overflow, 0u);
    EXPECT_EQ(r.indirect.instance_count, counts[GLINT_FLARE_VISIBLE]);
    EXPECT_EQ(r.indirect.vertex_count, LensFlare::vertices_per_instance());
    EXPECT_EQ(r.indirect.group_count_x, counts[GLINT_FLARE_VISIBLE] * pass.flare().groups_per_instance());
    EXPECT_TRUE(all_finite(r.image));
  }
}

// Culled and occluded lights add nothing at all: a frame of only those leaves the image bit for
// bit, and the whole scene gives the image of its visible lights alone (both paths).
TEST_F(FlareEndToEndTest, CulledAndOccludedLightsAddNothingAndVisibleOnesAddLight) {
  const Camera cam{kW, kH};
  const auto lights = scene_lights(cam);
  const auto depth = scene_depth(cam);
  const CpuImage background = random_hdr(kW, kH, 6);
  const FlareConfig look = FlareConfig::preset(FlarePreset::retro_intense);
  std::vector<GlintFlareLight> all;
  for (const auto& l : lights) all.push_back(l.light);
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    LensFlarePass pass(context(), pass_config(path));
    const auto hidden = only(lights, {GLINT_FLARE_OCCLUDED, GLINT_FLARE_FRUSTUM, GLINT_FLARE_DISABLED});
    ASSERT_EQ(hidden.size(), 5u);
    const FrameResult none = run_frame(pass, background, depth, hidden, cam.view_proj(), look);
    EXPECT_EQ(none.stats.visible, 0u);
    const CpuImage stored = as_stored(background, kF16);
    EXPECT_TRUE(bit_equal(none.image, stored)) << "a culled or occluded light changed the image";

    const FrameResult full = run_frame(pass, background, depth, all, cam.view_proj(), look);
    const FrameResult visible =
        run_frame(pass, background, depth, only(lights, {GLINT_FLARE_VISIBLE}), cam.view_proj(), look);
    // Same two instances in the same (light) order either way: the same bits.
    EXPECT_TRUE(bit_equal(full.image, visible.image)) << "the whole scene differs from its visible lights alone";

    // Visible lights add light at their position; the occluded one's position only gets what the
    // visible lights' sprites (ghosts, streaks) put there, which the visible-only frame has too.
    EXPECT_GT(energy(full.image, 150, 40, 2), energy(stored, 150, 40, 2) + 10.0);
    EXPECT_GT(energy(full.image, 60, 50, 2), energy(stored, 60, 50, 2) + 10.0);
    EXPECT_TRUE(all_finite(full.image));
  }
}

// docs/FLARE.md: |raster - compute| <= (2n + 1) u max(|raster|, |compute|) + C per channel, n the
// sprites covering the pixel (at most 9 per drawn light here), C the tiny coverage-ambiguous term.
TEST_F(FlareEndToEndTest, RasterAndComputeAgreeWithinTheDocumentedTolerance) {
  const Camera cam{kW, kH};
  const auto lights = scene_lights(cam);
  std::vector<GlintFlareLight> list;
  for (const auto& l : lights) list.push_back(l.light);
  // More visible lights, partly occluded ones on the box's edges, various sizes and elements.
  for (int i = 0; i < 12; ++i) {
    GlintFlareLight l = cam.light_at(10 + 15.3 * i, 8 + 9.1 * i, 10 + i, 6.0f + 3.0f * i);
    l.element = uint32_t(i) % GLINT_FLARE_ELEMENT_COUNT;
    list.push_back(l);
  }
  list.push_back(cam.light_at(40, 60, 20, 24));  // straddles the box's left edge
  list.push_back(cam.light_at(70, 90, 20, 24));  // straddles its bottom edge
  const CpuImage background = random_hdr(kW, kH, 7);
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);
  LensFlarePass raster(context(), pass_config(FlareDrawPath::raster));
  LensFlarePass compute(context(), pass_config(FlareDrawPath::compute));
  const FrameResult r = run_frame(raster, background, scene_depth(cam), list, cam.view_proj(), look);
  const FrameResult c = run_frame(compute, background, scene_depth(cam), list, cam.view_proj(), look);
  ASSERT_EQ(r.stats.visible, c.stats.visible);
  ASSERT_GT(r.stats.visible, 10u);
  uint32_t partial = 0;
  for (size_t i = 0; i < list.size(); ++i) {
    EXPECT_EQ(r.results[i].culled, c.results[i].culled) << "light " << i;
    EXPECT_EQ(r.results[i].visible_fraction, c.results[i].visible_fraction) << "light " << i;
    partial += r.results[i].visible_fraction > 0.0f && r.results[i].visible_fraction < 1.0f;
  }
  EXPECT_GE(partial, 1u) << "no partly occluded light: the edge lights did not straddle the box";
  const double u = std::ldexp(1.0, -10);
  const double n = 9.0 * r.stats.visible;
  double worst = 0;
  size_t outside = 0, changed = 0;
  const CpuImage& bg = background;
  for (size_t i = 0; i < r.image.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const double a = r.image.rgba[i], b = c.image.rgba[i];
    const double tol = (2 * n + 1) * u * std::max(std::fabs(a), std::fabs(b)) + 1e-4;
    worst = std::max(worst, std::fabs(a - b) / tol);
    outside += !(std::fabs(a - b) <= tol);
    changed += std::fabs(a - detail::round_to_half(bg.rgba[i])) > 1e-3;
  }
  EXPECT_EQ(outside, 0u) << "worst ratio " << worst;
  EXPECT_GT(changed, 1000u) << "the flares changed too few pixels for the comparison to mean anything";
  EXPECT_TRUE(all_finite(r.image));
  EXPECT_TRUE(all_finite(c.image));
}

// Few lights and a pyramid capped by max_size_px: the pass leaves the Hi-Z out and the cull reads
// the depth image (LightCuller::needs_pyramid), and the frame is the one the pyramid gives, bit for
// bit: image, statistics, arguments and per-light results, both draw paths, two frames on one
// command buffer. Lights in the open, behind an occluder, straddling its edges, off screen and
// behind the camera, at 1024x768 (cells of up to 8 px: level 3; the 12 lights' windows hold at
// most 12 x 16 x 4^4 = 49152 of the image's 786432 pixels).
TEST_F(FlareEndToEndTest, FewLightsReadTheDepthImageAndDrawTheFrameThePyramidGives) {
  const uint32_t w = 1024, h = 768;
  const Camera cam{w, h};
  std::vector<float> depth(size_t(w) * h, 1.0f);
  const auto box = float(cam.depth_at(5.0));
  for (uint32_t y = 300; y < 500; ++y)
    for (uint32_t x = 200; x < 600; ++x) depth[size_t(y) * w + x] = box;
  std::vector<GlintFlareLight> list;
  list.push_back(cam.light_at(400, 400, 20, 32));      // behind the box
  list.push_back(cam.light_at(800, 200, 20, 32));      // in the open
  list.push_back(cam.light_at(200, 400, 20, 31));      // straddles the box's left edge
  list.push_back(cam.light_at(500, 500.5, 20, 17));    // straddles its bottom edge
  list.push_back(cam.light_at(300, 350, 3, 24));       // before the box
  list.push_back(cam.light_at(3.0 * w, 100, 20, 16));  // far off screen
  list.push_back(cam.light_at(1023.5, 0.5, 20, 32));   // on the corner
  for (int i = 0; i < 5; ++i) list.push_back(cam.light_at(150 + 170.3 * i, 280 + 41.7 * i, 10 + i, 5.0f + 6.0f * i));
  const CpuImage background = random_hdr(w, h, 11);
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);
  for (FlareDrawPath path : {FlareDrawPath::compute, FlareDrawPath::raster}) {
    FlarePassConfig pc = pass_config(path);
    pc.extent = {w, h};
    pc.max_size_px = 32.0f;  // cells of 8 px at N = 4: 3 levels
    LensFlarePass direct(context(), pc);
    LensFlarePass pyramid(context(), pc);
    detail::LightCullAccess::select_path(pyramid.culler(), detail::LightCullPath::pyramid);
    ASSERT_EQ(direct.hiz().levels(), 3u);
    ASSERT_FALSE(direct.culler().needs_pyramid(direct.hiz(), uint32_t(list.size())));
    ASSERT_TRUE(pyramid.culler().needs_pyramid(pyramid.hiz(), uint32_t(list.size())));
    const FrameResult a = run_frame(direct, background, depth, list, cam.view_proj(), look, 2);
    const FrameResult b = run_frame(pyramid, background, depth, list, cam.view_proj(), look, 2);
    const char* what = path == FlareDrawPath::compute ? "compute" : "raster";
    // The pass built no pyramid (its image never left UNDEFINED); the other did.
    EXPECT_EQ(direct.hiz().image().layout, VK_IMAGE_LAYOUT_UNDEFINED) << what;
    EXPECT_NE(pyramid.hiz().image().layout, VK_IMAGE_LAYOUT_UNDEFINED) << what;
    EXPECT_EQ(std::memcmp(&a.stats, &b.stats, sizeof a.stats), 0) << what;
    EXPECT_EQ(std::memcmp(&a.indirect, &b.indirect, sizeof a.indirect), 0) << what;
    ASSERT_EQ(a.results.size(), list.size());
    EXPECT_EQ(std::memcmp(a.results.data(), b.results.data(), list.size() * sizeof a.results[0]), 0) << what;
    EXPECT_TRUE(bit_equal(a.image, b.image)) << what;
    EXPECT_EQ(a.stats.frustum_culled, 1u) << what;
    EXPECT_GE(a.stats.occluded, 1u) << what;
    uint32_t partial = 0;
    for (const auto& r : a.results) partial += r.visible_fraction > 0.0f && r.visible_fraction < 1.0f;
    EXPECT_GE(partial, 2u) << what << ": the edge lights did not straddle the box";
  }
}

// Thousands of lights on one pixel, more visible than the capacity: the instance count is clamped
// to the capacity, the rest is counted as overflow (and reported per light), the image is finite.
TEST_F(FlareEndToEndTest, ThousandsOfLightsOnOnePixelOverflowSafely) {
  const Camera cam{kW, kH};
  const uint32_t count = 3000, capacity = 700;
  std::vector<GlintFlareLight> list(count, cam.light_at(150.5, 40.5, 20, 12));
  for (uint32_t i = 0; i < count; i += 7) list[i] = cam.light_at(70, 60, 20, 12);  // occluded
  uint32_t occluded = 0;
  for (uint32_t i = 0; i < count; i += 7) ++occluded;
  const CpuImage background = random_hdr(kW, kH, 8);
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    LensFlarePass pass(context(), pass_config(path, capacity, count));
    const FrameResult r = run_frame(pass, background, scene_depth(cam), list, cam.view_proj(),
                                    FlareConfig::preset(FlarePreset::retro_subtle));
    EXPECT_EQ(r.stats.total, count);
    EXPECT_EQ(r.stats.occluded, occluded);
    EXPECT_EQ(r.stats.visible, count - occluded);
    EXPECT_EQ(r.stats.overflow, count - occluded - capacity);
    EXPECT_EQ(r.indirect.instance_count, capacity);
    EXPECT_EQ(r.indirect.group_count_x, capacity * pass.flare().groups_per_instance());
    uint32_t drawn = 0, overflowed = 0;
    for (const auto& res : r.results) {
      drawn += res.culled == GLINT_FLARE_VISIBLE;
      overflowed += res.culled == GLINT_FLARE_OVERFLOW;
    }
    EXPECT_EQ(drawn, capacity);
    EXPECT_EQ(overflowed, count - occluded - capacity);
    EXPECT_TRUE(all_finite(r.image));
    EXPECT_GT(energy(r.image, 150, 40, 1), energy(background, 150, 40, 1) + 100.0);
  }
}

// Zero lights: the image is unchanged bit for bit; recording the frame again creates nothing.
TEST_F(FlareEndToEndTest, ZeroLightsLeaveTheImageBitForBitAndFramesCreateNothing) {
  const Camera cam{kW, kH};
  const CpuImage background = random_hdr(kW, kH, 9);
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    LensFlarePass pass(context(), pass_config(path));
    const FrameResult first = run_frame(pass, background, scene_depth(cam), {}, cam.view_proj(),
                                        FlareConfig::preset(FlarePreset::cinematic), 2);
    EXPECT_EQ(first.stats.total, 0u);
    EXPECT_EQ(first.indirect.instance_count, 0u);
    const CpuImage stored = as_stored(background, kF16);
    EXPECT_TRUE(bit_equal(first.image, stored));
    // Same resources twice: the second record() of a known (lights, image) set creates nothing.
    detail::OwnedImage color(context(), {kW, kH}, kF16, kColorUsage);
    detail::OwnedImage depth(context(), {kW, kH}, VK_FORMAT_D32_SFLOAT,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    detail::upload(context(), color.image(), background);
    detail::upload_r32(context(), depth.image(), scene_depth(cam));
    detail::OwnedBuffer lights(context(), 16 * sizeof(GlintFlareLight), kLightUsage, false);
    Buffer lv{lights.buffer(), 0, lights.size(), kLightUsage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
    context().run_once([&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, lights.buffer(), 0, VK_WHOLE_SIZE, 0); });
    lv.stage = VK_PIPELINE_STAGE_2_CLEAR_BIT;
    lv.access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    const auto vp = cam.view_proj();
    const FlareConfig look;
    context().run_once(
        [&](VkCommandBuffer cmd) { pass.record(cmd, color.image(), depth.image(), lv, 16, vp.data(), look); });
    const uint64_t before = context().objects_created();
    context().run_once(
        [&](VkCommandBuffer cmd) { pass.record(cmd, color.image(), depth.image(), lv, 16, vp.data(), look); });
    EXPECT_EQ(context().objects_created(), before);
  }
}

TEST_F(FlareEndToEndTest, BadArgumentsThrowBeforeRecording) {
  // The compute path holds at most maxStorageBufferRange / 48 instances (LensFlare::
  // max_compute_instances()); the config accepts up to 2^24. The device decides which case applies:
  // lavapipe's 128 MiB range holds fewer than 2^24, the H100's 4 GiB more.
  FlarePassConfig pc = pass_config(FlareDrawPath::compute);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  const uint64_t limit = props.limits.maxStorageBufferRange / sizeof(GlintFlareInstance);
  constexpr uint32_t kMaxCapacity = 16777216;
  if (limit < kMaxCapacity) {
    pc.cull.capacity = uint32_t(limit) + 1;
    try {
      LensFlarePass too_many(context(), pc);
      ADD_FAILURE() << "capacity " << pc.cull.capacity << " above the device's " << limit << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(std::to_string(limit)), std::string::npos) << e.what();
    }
    pc.clamp_capacity = true;
    LensFlarePass clamped(context(), pc);
    EXPECT_EQ(clamped.config().cull.capacity, clamped.flare().max_compute_instances());
    EXPECT_EQ(uint64_t(clamped.config().cull.capacity), limit);
  } else {
    pc.cull.capacity = kMaxCapacity;  // within the device's range: accepted as is, clamped or not
    for (bool clamp : {false, true}) {
      pc.clamp_capacity = clamp;
      LensFlarePass pass(context(), pc);
      EXPECT_EQ(pass.config().cull.capacity, kMaxCapacity);
    }
  }
  FlarePassConfig bad = pass_config(FlareDrawPath::raster);
  bad.max_size_px = -1.0f;
  EXPECT_THROW(bad.validate(), Error);
  bad = pass_config(FlareDrawPath::raster);
  bad.extent = {0, 4};
  EXPECT_THROW(bad.validate(), Error);
  bad = pass_config(FlareDrawPath::raster);
  bad.depth_format = VK_FORMAT_R16G16B16A16_SFLOAT;
  EXPECT_THROW(bad.validate(), Error);

  LensFlarePass pass(context(), pass_config(FlareDrawPath::raster, 8, 8));
  detail::OwnedImage color(context(), {kW, kH}, kF16, kColorUsage);
  detail::OwnedImage wrong(context(), {kW, kH - 1}, kF16, kColorUsage);
  detail::OwnedImage depth(context(), {kW, kH}, VK_FORMAT_D32_SFLOAT,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  detail::OwnedBuffer lights(context(), 8 * sizeof(GlintFlareLight), kLightUsage, false);
  Buffer lv{lights.buffer(), 0, lights.size(), kLightUsage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  const Camera cam{kW, kH};
  auto vp = cam.view_proj();
  const FlareConfig look;
  context().run_once([&](VkCommandBuffer cmd) {
    EXPECT_THROW(pass.record(cmd, wrong.image(), depth.image(), lv, 8, vp.data(), look), Error);
    EXPECT_THROW(pass.record(cmd, color.image(), depth.image(), lv, 9, vp.data(), look), Error);  // > max_lights
    Buffer small = lv;
    small.size = 2 * sizeof(GlintFlareLight);
    EXPECT_THROW(pass.record(cmd, color.image(), depth.image(), small, 3, vp.data(), look), Error);
    auto nan = vp;
    nan[5] = std::nanf("");
    EXPECT_THROW(pass.record(cmd, color.image(), depth.image(), lv, 8, nan.data(), look), Error);
    FlareConfig bad_look;
    bad_look.anamorphic_ratio = 7.0f;
    EXPECT_THROW(pass.record(cmd, color.image(), depth.image(), lv, 8, vp.data(), bad_look), Error);
    EXPECT_THROW(pass.record(cmd, color.image(), color.image(), lv, 8, vp.data(), look), Error);  // not depth
  });
  // Nothing was recorded: the images were never touched.
  EXPECT_EQ(color.image().layout, VK_IMAGE_LAYOUT_UNDEFINED);
  EXPECT_EQ(depth.image().layout, VK_IMAGE_LAYOUT_UNDEFINED);
}

}  // namespace
}  // namespace glint::test
