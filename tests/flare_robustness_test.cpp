// Robustness of the lens flares and their visibility stage, beyond what
// occlusion_test.cpp and flare_e2e_test.cpp already cover (zero lights, lights behind the camera,
// the image of lights at w = 0, overflow counts):
// - determinism: the Hi-Z pyramid, everything LightCuller writes (instances, indirect arguments,
//   statistics, per-light results) and the images of LensFlarePass (raster and compute) are the
//   same bits over five runs of a scene of hundreds of overlapping lights, and the instances are
//   the visible lights in increasing light index (the atomic compaction this replaced failed that);
// - edge cases in a table, each against the float64 references (occlusion_reference.h for the
//   cull, flare_reference.h for the image): lights on the near and far planes, at clip w = 0 and at
//   tiny w, far outside the screen, thousands on one pixel, more visible than the instance buffer
//   holds, and NaN / Inf in every float field (culled as disabled, docs/OCCLUSION.md);
// - the Hi-Z pyramid and the whole pass at 1x1, 1xN, Nx1, 4097x3 and the device's largest side as
//   a thin image;
// - the LOD kernel's finiteness test on the GPU: Inf derivatives must give level 0 (a test folded
//   by a compiler that assumes finite floats would give the top level).
// Validation with synchronization validation is on for every test (support/gpu_test.h).
#include <glint/flare_pass.h>
#include <glint/gpu/flare_types.h>
#include <glint/lod.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/barriers.h"
#include "core/half.h"
#include "reference/flare_reference.h"
#include "reference/occlusion_reference.h"
#include "support/flare_check.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {
namespace {

class FlareRobustnessTest : public GpuTest {};

constexpr int kRuns = 5;
constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkImageUsageFlags kColorUsage = detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
constexpr std::array<float, 16> kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

template <typename T>
std::vector<T> as(const std::vector<uint8_t>& bytes, size_t n) {
  std::vector<T> out(n);
  if (n) std::memcpy(out.data(), bytes.data(), n * sizeof(T));
  return out;
}

bool finite_instance(const GlintFlareInstance& g) {
  for (float v : {g.center_x_px, g.center_y_px, g.size_px, g.visible_fraction, g.color_r, g.color_g, g.color_b,
                  g.intensity, g.ndc_depth}) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// ---- Scenes ----------------------------------------------------------------------------------------

// Hundreds of overlapping lights over a depth buffer of boxes, with the identity as view_proj (the
// light's position is its NDC): random positions (some off screen, some behind boxes, partly
// occluded ones on box edges), colours, intensities, sizes and elements; every 23rd disabled.
// Intensities keep the fp16 sums of the flares far from overflow.
struct Scene {
  reference::DepthImage depth;
  std::vector<GlintFlareLight> lights;
};

Scene overlapping_scene(uint32_t w, uint32_t h, uint32_t n, uint32_t stream, float max_size_px) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Scene s;
  s.depth = {w, h, std::vector<float>(size_t(w) * h, 1.0f)};
  for (int b = 0; b < 10; ++b) {
    const auto x0 = uint32_t(unit(rng) * w), y0 = uint32_t(unit(rng) * h);
    const auto bw = uint32_t((0.05f + 0.25f * unit(rng)) * w), bh = uint32_t((0.05f + 0.25f * unit(rng)) * h);
    const float z = 0.2f + 0.6f * unit(rng);
    for (uint32_t y = y0; y < std::min(h, y0 + bh); ++y)
      for (uint32_t x = x0; x < std::min(w, x0 + bw); ++x) s.depth.depth[size_t(y) * w + x] = z;
  }
  for (uint32_t i = 0; i < n; ++i) {
    GlintFlareLight l{};
    l.position_x = -1.1f + 2.2f * unit(rng);
    l.position_y = -1.1f + 2.2f * unit(rng);
    l.position_z = 0.02f + 0.96f * unit(rng);
    l.intensity = 0.05f + 0.45f * unit(rng);
    l.color_r = 0.05f + 0.95f * unit(rng);
    l.color_g = 0.05f + 0.95f * unit(rng);
    l.color_b = 0.05f + 0.95f * unit(rng);
    l.size_px = 3.0f + (max_size_px - 3.0f) * unit(rng);
    l.element = rng() % GLINT_FLARE_ELEMENT_COUNT;
    l.enabled = i % 23 == 7 ? 0u : 1u;
    s.lights.push_back(l);
  }
  return s;
}

// ---- LightCuller runs ------------------------------------------------------------------------------

// Everything one cull wrote, as bytes (for bit comparisons) and typed.
struct CullOutput {
  std::vector<uint8_t> instance_bytes;  // the first instance_count slots
  std::vector<uint8_t> indirect_bytes, stats_bytes, result_bytes;
  std::vector<GlintFlareInstance> instances;
  GlintFlareIndirect indirect{};
  GlintFlareStats stats{};
  std::vector<GlintFlareLightResult> results;

  void decode(uint32_t n) {
    std::memcpy(&indirect, indirect_bytes.data(), sizeof(indirect));
    std::memcpy(&stats, stats_bytes.data(), sizeof(stats));
    results = as<GlintFlareLightResult>(result_bytes, n);
    instances = as<GlintFlareInstance>(instance_bytes, instance_bytes.size() / sizeof(GlintFlareInstance));
  }
};

// The instances are exactly the visible lights (per-light result VISIBLE) in increasing light index,
// every overflowed light comes after every drawn one, and every instance field is finite.
void expect_light_order(const CullOutput& o, const std::string& what) {
  std::vector<uint32_t> drawn, overflowed;
  for (uint32_t i = 0; i < o.results.size(); ++i) {
    if (o.results[i].culled == GLINT_FLARE_VISIBLE) drawn.push_back(i);
    if (o.results[i].culled == GLINT_FLARE_OVERFLOW) overflowed.push_back(i);
  }
  ASSERT_EQ(o.instances.size(), drawn.size()) << what;
  size_t out_of_order = 0;
  for (size_t k = 1; k < o.instances.size(); ++k) {
    if (!(o.instances[k - 1].light_index < o.instances[k].light_index) && out_of_order++ < 3) {
      ADD_FAILURE() << what << ": instance " << k << " names light " << o.instances[k].light_index << " after light "
                    << o.instances[k - 1].light_index << ": not in light order";
    }
  }
  EXPECT_EQ(out_of_order, 0u) << what << ": instances out of light order";
  size_t mismatched = 0;
  for (size_t k = 0; k < drawn.size(); ++k) mismatched += o.instances[k].light_index != drawn[k];
  EXPECT_EQ(mismatched, 0u) << what << ": instances are not the drawn lights in light order";
  if (!drawn.empty() && !overflowed.empty()) {
    EXPECT_LT(drawn.back(), overflowed.front()) << what << ": a later light took a slot an earlier one lost";
  }
  for (const auto& g : o.instances) EXPECT_TRUE(finite_instance(g)) << what << ": light " << g.light_index;
  EXPECT_EQ(o.stats.overflow, overflowed.size()) << what;
  EXPECT_EQ(o.indirect.instance_count, drawn.size()) << what;
}

// A Hi-Z pyramid and a culler over one depth image and light list, run as separate submissions
// into poisoned host-visible outputs.
struct CullRig {
  detail::OwnedImage depth;
  HiZPyramid hiz;
  LightCuller culler;
  HostBuffer lights, instances, indirect, stats, results;
  uint32_t count;
  LightCullFrame frame;

  CullRig(const Scene& s, const LightCullConfig& config, const std::array<float, 16>& view_proj)
      : depth(make_depth(s.depth, VK_FORMAT_D32_SFLOAT)),
        hiz(context(), HiZConfig{{s.depth.width, s.depth.height}}),
        culler(context(), config),
        lights(s.lights.size() * sizeof(GlintFlareLight)),
        instances(VkDeviceSize(config.capacity) * sizeof(GlintFlareInstance)),
        indirect(sizeof(GlintFlareIndirect)),
        stats(sizeof(GlintFlareStats)),
        results(s.lights.size() * sizeof(GlintFlareLightResult)),
        count(static_cast<uint32_t>(s.lights.size())) {
    if (count) std::memcpy(lights.owned.mapped(), s.lights.data(), count * sizeof(GlintFlareLight));
    lights.owned.flush();
    std::copy(view_proj.begin(), view_proj.end(), frame.view_proj);
    frame.vertex_count = LensFlare::vertices_per_instance();
    frame.groups_per_instance = 1;
  }

  CullOutput run() {
    for (HostBuffer* b : {&instances, &indirect, &stats, &results}) b->poison();
    LightCullOutputs out{instances.view, indirect.view, stats.view, results.view};
    context().run_once([&](VkCommandBuffer cmd) {
      hiz.record(cmd, depth.state);
      culler.record(cmd, hiz, depth.state, lights.view, count, frame, out);
      detail::Barriers b;
      for (Buffer* v : {&out.instances, &out.indirect, &out.stats, &out.results})
        b.use(*v, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
      b.flush(cmd);
    });
    instances.view = out.instances;
    indirect.view = out.indirect;
    stats.view = out.stats;
    results.view = out.results;
    CullOutput o;
    o.indirect_bytes = indirect.bytes(sizeof(GlintFlareIndirect));
    o.stats_bytes = stats.bytes(sizeof(GlintFlareStats));
    o.result_bytes = results.bytes(size_t(count) * sizeof(GlintFlareLightResult));
    GlintFlareIndirect args;
    std::memcpy(&args, o.indirect_bytes.data(), sizeof(args));
    const uint32_t written = std::min(args.instance_count, culler.config().capacity);
    o.instance_bytes = instances.bytes(size_t(written) * sizeof(GlintFlareInstance));
    o.decode(count);
    return o;
  }
};

// ---- LensFlarePass runs ----------------------------------------------------------------------------

struct PassRun {
  CpuImage image;
  GlintFlareStats stats{};
  GlintFlareIndirect indirect{};
  std::vector<GlintFlareInstance> instances;  // the first instance_count slots
  std::vector<GlintFlareLightResult> results;
};

// Uploads the background, the depth and the lights once, then records `runs` frames of
// pass.record(), each in its own submission that first restores the background, and reads
// everything back after each.
std::vector<PassRun> run_pass(LensFlarePass& pass, const CpuImage& background, const reference::DepthImage& depth,
                              const std::vector<GlintFlareLight>& lights, const std::array<float, 16>& view_proj,
                              const FlareConfig& look, int runs) {
  const Context& ctx = context();
  const auto n = static_cast<uint32_t>(lights.size());
  const VkExtent2D extent{background.width, background.height};
  detail::OwnedImage color(ctx, extent, kF16, kColorUsage);
  detail::OwnedImage depth_image = make_depth(depth, VK_FORMAT_D32_SFLOAT);
  HostBuffer light_buffer(VkDeviceSize(n) * sizeof(GlintFlareLight));
  if (n) std::memcpy(light_buffer.owned.mapped(), lights.data(), size_t(n) * sizeof(GlintFlareLight));
  light_buffer.owned.flush();
  const auto color_up = detail::make_upload_staging(ctx, color.image(), background);
  const auto color_down = detail::make_readback_staging(ctx, color.image());
  const VkDeviceSize instance_bytes = VkDeviceSize(pass.config().cull.capacity) * sizeof(GlintFlareInstance);
  const VkDeviceSize result_bytes = VkDeviceSize(n) * sizeof(GlintFlareLightResult);
  detail::OwnedBuffer down(ctx, 64 + instance_bytes + result_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  std::vector<PassRun> out;
  for (int r = 0; r < runs; ++r) {
    ctx.run_once([&](VkCommandBuffer cmd) {
      detail::record_upload(cmd, color_up, color.image());
      pass.record(cmd, color.image(), depth_image.image(), light_buffer.view, n, view_proj.data(), look);
      detail::record_readback(cmd, color.image(), color_down);
      detail::Barriers b;
      for (Buffer* v : {&pass.stats(), &pass.indirect(), &pass.instances(), &pass.results()})
        b.use(*v, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
      b.flush(cmd);
      const VkBufferCopy sc{0, 0, 32}, ic{0, 32, 32}, nc{0, 64, instance_bytes},
          rc{0, 64 + instance_bytes, result_bytes};
      vkCmdCopyBuffer(cmd, pass.stats().buffer, down.buffer(), 1, &sc);
      vkCmdCopyBuffer(cmd, pass.indirect().buffer, down.buffer(), 1, &ic);
      vkCmdCopyBuffer(cmd, pass.instances().buffer, down.buffer(), 1, &nc);
      if (n) vkCmdCopyBuffer(cmd, pass.results().buffer, down.buffer(), 1, &rc);
      detail::record_host_read_barrier(cmd);
    });
    PassRun run;
    run.image = detail::read_staged(color_down, color.image());
    down.invalidate();
    const auto* bytes = static_cast<const uint8_t*>(down.mapped());
    std::memcpy(&run.stats, bytes, 32);
    std::memcpy(&run.indirect, bytes + 32, 32);
    const uint32_t written = std::min(run.indirect.instance_count, pass.config().cull.capacity);
    run.instances.resize(written);
    if (written) std::memcpy(run.instances.data(), bytes + 64, written * sizeof(GlintFlareInstance));
    run.results.resize(n);
    if (n) std::memcpy(run.results.data(), bytes + 64 + instance_bytes, result_bytes);
    out.push_back(std::move(run));
  }
  return out;
}

FlarePassConfig pass_config(VkExtent2D extent, FlareDrawPath path, uint32_t capacity, uint32_t max_lights) {
  FlarePassConfig pc;
  pc.extent = extent;
  pc.cull.capacity = capacity;
  pc.cull.max_lights = std::max(max_lights, 1u);
  pc.draw = path;
  pc.per_light_results = true;
  return pc;
}

const char* path_name(FlareDrawPath p) { return p == FlareDrawPath::raster ? "raster" : "compute"; }

// ---- Determinism -----------------------------------------------------------------------------------

// The pyramid is a max / min reduction, so it is deterministic by construction; checked anyway, at a
// one-pass and a two-pass size.
TEST_F(FlareRobustnessTest, HiZPyramidIsBitIdenticalAcrossRuns) {
  for (VkExtent2D e : {VkExtent2D{1000, 600}, VkExtent2D{4500, 5}}) {
    const Scene s = overlapping_scene(e.width, e.height, 0, 3, 8.0f);
    reference::DepthImage d = s.depth;
    std::mt19937 rng(4);
    for (float& v : d.depth) v *= 0.5f + 0.5f * std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
    auto img = make_depth(d, VK_FORMAT_D32_SFLOAT);
    HiZPyramid hiz(context(), HiZConfig{e});
    std::vector<std::vector<float>> first;
    for (int r = 0; r < kRuns; ++r) {
      context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, img.state); });
      for (uint32_t k = 1; k <= hiz.levels(); ++k) {
        const VkExtent2D le{std::max(1u, e.width >> k), std::max(1u, e.height >> k)};
        auto level = detail::download_r32(context(), hiz.image(), k - 1, le, hiz.levels());
        if (r == 0) {
          first.push_back(std::move(level));
        } else {
          EXPECT_EQ(std::memcmp(level.data(), first[k - 1].data(), level.size() * 4), 0)
              << e.width << "x" << e.height << " run " << r << " level " << k;
        }
      }
    }
  }
}

// Instances, indirect arguments, statistics and per-light results: the same bits on every run, and
// the instances in light order, with and without overflow (the instances kept are then the visible
// lights with the smallest indices). 20000 lights = 313 cull workgroups, which the atomic compaction
// put in a different order from run to run on lavapipe.
TEST_F(FlareRobustnessTest, CullerOutputIsBitIdenticalAcrossRunsAndInLightOrder) {
  const Scene s = overlapping_scene(320, 200, 20000, 7, 48.0f);
  for (uint32_t capacity : {20000u, 3000u}) {
    LightCullConfig config;
    config.capacity = capacity;
    config.max_lights = 20000;
    CullRig rig(s, config, kIdentity);
    const CullOutput first = rig.run();
    const std::string what = "capacity " + std::to_string(capacity);
    ASSERT_GT(first.stats.visible, 5000u) << what << ": too few visible lights for the test to mean anything";
    ASSERT_GT(first.stats.occluded, 200u) << what;
    if (capacity < first.stats.visible) {
      EXPECT_EQ(first.indirect.instance_count, capacity) << what;
    }
    expect_light_order(first, what);
    for (int r = 1; r < kRuns; ++r) {
      const CullOutput again = rig.run();
      const std::string w = what + " run " + std::to_string(r);
      EXPECT_EQ(again.instance_bytes, first.instance_bytes) << w << ": instance buffer differs";
      EXPECT_EQ(again.indirect_bytes, first.indirect_bytes) << w << ": indirect arguments differ";
      EXPECT_EQ(again.stats_bytes, first.stats_bytes) << w << ": statistics differ";
      EXPECT_EQ(again.result_bytes, first.result_bytes) << w << ": per-light results differ";
      expect_light_order(again, w);
    }
  }
}

// The image of LensFlarePass over five runs, both draw paths: hundreds of overlapping visible
// lights, so a different summation order would change fp16 roundings (raster: the blend order is
// the instance order; compute: the per-tile list order). The two paths also cull identically.
TEST_F(FlareRobustnessTest, FlarePassImageIsBitIdenticalAcrossRuns) {
  const VkExtent2D extent{256, 160};
  const Scene s = overlapping_scene(extent.width, extent.height, 500, 11, 24.0f);
  const CpuImage background = random_hdr(extent.width, extent.height, 12);
  const FlareConfig look = FlareConfig::preset(FlarePreset::retro_intense);
  std::vector<GlintFlareInstance> raster_instances;
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    LensFlarePass pass(context(), pass_config(extent, path, 512, 500));
    const auto runs = run_pass(pass, background, s.depth, s.lights, kIdentity, look, kRuns);
    const PassRun& first = runs[0];
    ASSERT_GT(first.stats.visible, 200u) << path_name(path);
    EXPECT_TRUE(all_finite(first.image)) << path_name(path);
    size_t lit = 0;
    const CpuImage stored = as_stored(background, kF16);
    for (size_t i = 0; i < first.image.rgba.size(); ++i) lit += first.image.rgba[i] != stored.rgba[i];
    EXPECT_GT(lit, first.image.rgba.size() / 4) << path_name(path) << ": the flares cover too little";
    for (int r = 1; r < kRuns; ++r) {
      EXPECT_TRUE(bit_equal(runs[r].image, first.image)) << path_name(path) << " run " << r << ": image differs";
      EXPECT_EQ(std::memcmp(&runs[r].stats, &first.stats, sizeof(first.stats)), 0) << path_name(path) << " run " << r;
      ASSERT_EQ(runs[r].instances.size(), first.instances.size());
      EXPECT_EQ(std::memcmp(runs[r].instances.data(), first.instances.data(),
                            first.instances.size() * sizeof(GlintFlareInstance)),
                0)
          << path_name(path) << " run " << r << ": instances differ";
    }
    for (size_t k = 1; k < first.instances.size(); ++k) {
      ASSERT_LT(first.instances[k - 1].light_index, first.instances[k].light_index) << path_name(path);
    }
    if (path == FlareDrawPath::raster) {
      raster_instances = first.instances;
    } else {
      ASSERT_EQ(raster_instances.size(), first.instances.size());
      EXPECT_EQ(std::memcmp(raster_instances.data(), first.instances.data(),
                            first.instances.size() * sizeof(GlintFlareInstance)),
                0)
          << "the raster and compute passes culled differently";
    }
  }
}

// ---- Edge cases ------------------------------------------------------------------------------------

constexpr uint32_t kW = 192, kH = 128;

// The occluder: pixels [40, 100) x [30, 90) at distance 5 over the far plane.
reference::DepthImage edge_depth(const Camera& cam) {
  reference::DepthImage d{kW, kH, std::vector<float>(size_t(kW) * kH, 1.0f)};
  const auto box = float(cam.depth_at(5.0));
  for (uint32_t y = 30; y < 90; ++y)
    for (uint32_t x = 40; x < 100; ++x) d.depth[size_t(y) * kW + x] = box;
  return d;
}

constexpr int kReference = -1;  // expected state: whatever the float64 reference says

struct EdgeCase {
  std::string name;
  std::array<float, 16> view_proj;
  uint32_t capacity;
  std::vector<GlintFlareLight> lights;
  std::vector<int> expected;  // per light: GLINT_FLARE_* or kReference
  void add(const GlintFlareLight& l, int state) {
    lights.push_back(l);
    expected.push_back(state);
  }
};

GlintFlareLight ndc_light(float x, float y, float z, float size_px) {
  GlintFlareLight l{};
  l.position_x = x;
  l.position_y = y;
  l.position_z = z;
  l.color_r = 1.0f;
  l.color_g = 2.0f;
  l.color_b = 0.5f;
  l.intensity = 2.0f;
  l.size_px = size_px;
  l.element = GLINT_FLARE_ELEMENT_STARBURST;
  l.enabled = 1;
  return l;
}

std::vector<EdgeCase> edge_cases(const Camera& cam) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<EdgeCase> cases;
  {
    // The identity projection makes the planes exact: ndc.z = position z.
    EdgeCase c{"near and far planes (exact)", kIdentity, 64, {}, {}};
    c.add(ndc_light(0.5f, 0.5f, 0.0f, 15), GLINT_FLARE_VISIBLE);     // on the near plane
    c.add(ndc_light(-0.5f, 0.6f, -0.0f, 15), GLINT_FLARE_VISIBLE);   // on it, negative zero
    c.add(ndc_light(0.5f, -0.5f, -1e-7f, 15), GLINT_FLARE_FRUSTUM);  // just in front of it
    c.add(ndc_light(0.7f, 0.7f, 1.0f, 15), GLINT_FLARE_VISIBLE);     // on the far plane (depth 1 there)
    c.add(ndc_light(0.7f, -0.7f, std::nextafter(1.0f, 2.0f), 15), GLINT_FLARE_FRUSTUM);  // just beyond
    c.add(ndc_light(-0.3f, -0.1f, 0.995f, 15), GLINT_FLARE_OCCLUDED);                    // behind the box (depth 0.981)
    cases.push_back(c);
  }
  {
    EdgeCase c{"near plane (perspective)", cam.view_proj(), 64, {}, {}};
    c.add(cam.light_at(150.3, 100.3, cam.n, 14), kReference);  // at the near distance: either side
    c.add(cam.light_at(160.3, 30.3, cam.n * 1.0001, 14), kReference);
    c.add(cam.light_at(120.3, 20.3, cam.n * 0.999, 14), GLINT_FLARE_FRUSTUM);
    c.add(cam.light_at(20.3, 110.3, cam.fa * 0.999, 14), kReference);  // just inside the far plane
    c.add(cam.light_at(30.3, 100.3, cam.fa * 1.01, 14), GLINT_FLARE_FRUSTUM);
    cases.push_back(c);
  }
  {
    EdgeCase c{"clip w = 0 and tiny w", cam.view_proj(), 64, {}, {}};
    c.add(ndc_light(0.3f, -0.2f, 0.0f, 15), GLINT_FLARE_FRUSTUM);    // w = 0
    c.add(ndc_light(0.3f, -0.2f, -0.0f, 15), GLINT_FLARE_FRUSTUM);   // w = +0 from -(-0)
    c.add(ndc_light(0.0f, 0.0f, 0.0f, 15), GLINT_FLARE_FRUSTUM);     // the camera itself: clip (0, 0, b, 0)
    c.add(ndc_light(0.0f, 0.0f, -1e-30f, 15), GLINT_FLARE_FRUSTUM);  // w = 1e-30: ndc.z = b / w
    c.add(ndc_light(0.0f, 0.0f, -1e-40f, 15), GLINT_FLARE_FRUSTUM);  // subnormal w (may be flushed)
    c.add(ndc_light(0.0f, 0.0f, 1e-30f, 15), GLINT_FLARE_FRUSTUM);   // w = -1e-30
    c.add(cam.light_at(150.3, 40.3, 20, 15), kReference);            // a normal light among them
    cases.push_back(c);
  }
  {
    EdgeCase c{"far outside the screen", cam.view_proj(), 64, {}, {}};
    c.add(cam.light_at(3.0 * kW, 64, 20, 15), GLINT_FLARE_FRUSTUM);
    c.add(cam.light_at(1e6 * kW, -1e6 * kH, 20, 15), GLINT_FLARE_FRUSTUM);
    c.add(ndc_light(3e38f, 0.0f, -1.0f, 15), GLINT_FLARE_FRUSTUM);           // clip.x overflows fp32
    c.add(ndc_light(1e30f, 0.0f, -1e30f, 15), GLINT_FLARE_FRUSTUM);          // ndc.x = 1.22: beyond the margin
    c.add(ndc_light(5e29f, 0.0f, -1e30f, 15), GLINT_FLARE_FRUSTUM);          // ndc.z just beyond 1
    c.add(cam.light_at(1.075 * kW, 0.65 * kH, 20, 40), kReference);          // ndc.x = 1.15: inside the margin
    c.add(cam.light_at(-0.07 * kW, -0.05 * kH, 20, 40), kReference);         // off the top-left corner
    c.add(cam.light_at(1.125 * kW, 0.5 * kH, 20, 40), GLINT_FLARE_FRUSTUM);  // ndc.x = 1.25
    cases.push_back(c);
  }
  {
    // 3000 lights on one pixel (every 7th behind the box), all of them drawn: fp16 sums of up to
    // 23k sprites at one pixel, kept in range by small intensities.
    EdgeCase c{"thousands of lights on one pixel", cam.view_proj(), 3000, {}, {}};
    for (uint32_t i = 0; i < 3000; ++i) {
      c.add(i % 7 == 0 ? cam.light_at(70.3, 60.3, 20, 12, 0.02f) : cam.light_at(150.3, 40.3, 20, 12, 0.02f),
            kReference);
    }
    cases.push_back(c);
  }
  {
    // 400 lights, most visible, 64 slots: the instances are the 64 visible lights with the smallest
    // indices, and the image is theirs.
    EdgeCase c{"more visible lights than the instance buffer holds", cam.view_proj(), 64, {}, {}};
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (uint32_t i = 0; i < 400; ++i) {
      c.add(cam.light_at(kW * unit(rng), kH * unit(rng), 10 + 30 * unit(rng), float(4 + 20 * unit(rng)), 0.3f),
            kReference);
    }
    cases.push_back(c);
  }
  {
    // NaN (quiet, negative, signalling) and +-Inf in each float field: disabled, never drawn, and
    // the valid lights between them are unaffected.
    EdgeCase c{"non-finite positions, colours, intensities and sizes", cam.view_proj(), 64, {}, {}};
    const GlintFlareLight good = cam.light_at(150.3, 40.3, 20, 15);
    const float neg_nan = std::bit_cast<float>(0xFFC00000u), signalling = std::bit_cast<float>(0x7F800001u);
    const std::vector<std::pair<float GlintFlareLight::*, float>> spoils = {
        {&GlintFlareLight::position_x, nan},  {&GlintFlareLight::position_y, inf},
        {&GlintFlareLight::position_z, -inf}, {&GlintFlareLight::position_x, signalling},
        {&GlintFlareLight::intensity, nan},   {&GlintFlareLight::intensity, inf},
        {&GlintFlareLight::color_r, nan},     {&GlintFlareLight::color_g, inf},
        {&GlintFlareLight::color_b, -inf},    {&GlintFlareLight::color_r, neg_nan},
        {&GlintFlareLight::size_px, nan},     {&GlintFlareLight::size_px, inf},
        {&GlintFlareLight::size_px, -inf}};
    for (size_t i = 0; i < spoils.size(); ++i) {
      if (i % 4 == 0) c.add(cam.light_at(60.3 + 8.0 * i, 100.3, 20, 15), kReference);
      GlintFlareLight bad = good;
      bad.*spoils[i].first = spoils[i].second;
      c.add(bad, GLINT_FLARE_DISABLED);
    }
    cases.push_back(c);
  }
  return cases;
}

// Each case, through LensFlarePass with both draw paths: every light's state and fraction against the
// float64 cull reference (or the state the case names), the statistics, the instances (in light
// order, finite, centres and depths against the reference), and the image: finite, unchanged where
// nothing is drawn, else within docs/FLARE.md's tolerance of the float64 composite of the
// instances the GPU kept.
TEST_F(FlareRobustnessTest, EdgeCaseLightsAreCulledAsDocumentedAndDrawFiniteImages) {
  const Camera cam{kW, kH};
  const reference::DepthImage depth = edge_depth(cam);
  const CpuImage background = as_stored(random_hdr(kW, kH, 31), kF16);
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);
  for (const EdgeCase& c : edge_cases(cam)) {
    const auto n = static_cast<uint32_t>(c.lights.size());
    reference::CullSettings settings;
    std::copy(c.view_proj.begin(), c.view_proj.end(), settings.view_proj);
    for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
      const std::string what = c.name + " (" + path_name(path) + ")";
      LensFlarePass pass(context(), pass_config({kW, kH}, path, c.capacity, n));
      settings.grid = pass.config().cull.grid;
      settings.levels = pass.hiz().levels();
      const auto pyramid = reference::hiz_pyramid(depth, false, settings.levels);
      const PassRun run = run_pass(pass, background, depth, c.lights, c.view_proj, look, 1)[0];

      // Per light against the reference.
      uint32_t counts[5] = {}, failures = 0, ambiguous = 0;
      std::vector<reference::LightVisibility> refs(n);
      for (uint32_t i = 0; i < n; ++i) {
        refs[i] = reference::cull_light(c.lights[i], settings, depth, pyramid);
        const auto& res = run.results[i];
        const uint32_t state = res.culled == GLINT_FLARE_OVERFLOW ? GLINT_FLARE_VISIBLE : res.culled;
        counts[std::min(res.culled, 4u)]++;
        EXPECT_TRUE(std::isfinite(res.visible_fraction)) << what << ": light " << i;
        if (c.expected[i] != kReference) {
          if (res.culled != uint32_t(c.expected[i]) && failures++ < 5)
            ADD_FAILURE() << what << ": light " << i << " is " << res.culled << ", expected " << c.expected[i];
          if (refs[i].culled != uint32_t(c.expected[i]) && !refs[i].ambiguous && failures++ < 5)
            ADD_FAILURE() << what << ": light " << i << ": the reference says " << refs[i].culled;
          if (c.expected[i] != GLINT_FLARE_VISIBLE) {
            EXPECT_EQ(res.visible_fraction, 0.0f) << what << ": " << i;
          }
          continue;
        }
        if (refs[i].ambiguous) {
          ++ambiguous;
          continue;
        }
        if (state != refs[i].culled && failures++ < 5)
          ADD_FAILURE() << what << ": light " << i << " is " << res.culled << ", the reference says " << refs[i].culled;
        const double fraction = res.culled == GLINT_FLARE_VISIBLE ? refs[i].grid_fraction : 0.0;
        if (std::fabs(res.visible_fraction - fraction) > 1e-6 && failures++ < 5)
          ADD_FAILURE() << what << ": light " << i << " fraction " << res.visible_fraction << ", reference "
                        << fraction;
      }
      EXPECT_EQ(failures, 0u) << what;
      EXPECT_LE(ambiguous, n / 20 + 2) << what << ": too many lights within rounding of a boundary";
      EXPECT_EQ(run.stats.total, n) << what;
      EXPECT_EQ(run.stats.visible, counts[GLINT_FLARE_VISIBLE] + counts[GLINT_FLARE_OVERFLOW]) << what;
      EXPECT_EQ(run.stats.frustum_culled, counts[GLINT_FLARE_FRUSTUM]) << what;
      EXPECT_EQ(run.stats.occluded, counts[GLINT_FLARE_OCCLUDED]) << what;
      EXPECT_EQ(run.stats.disabled, counts[GLINT_FLARE_DISABLED]) << what;
      EXPECT_EQ(run.indirect.instance_count, std::min(run.stats.visible, c.capacity)) << what;

      // The instances: in light order, finite, where the reference puts them.
      CullOutput o;
      o.instances = run.instances;
      o.results = run.results;
      o.stats = run.stats;
      o.indirect = run.indirect;
      expect_light_order(o, what);
      for (const auto& g : run.instances) {
        const auto& r = refs[g.light_index];
        const GlintFlareLight& l = c.lights[g.light_index];
        if (r.ambiguous) continue;
        EXPECT_NEAR(g.center_x_px, r.center_x, 1e-4 * (1.0 + std::fabs(r.center_x))) << what << ": " << g.light_index;
        EXPECT_NEAR(g.center_y_px, r.center_y, 1e-4 * (1.0 + std::fabs(r.center_y))) << what << ": " << g.light_index;
        EXPECT_NEAR(g.ndc_depth, r.ndc_z, 1e-5) << what << ": " << g.light_index;
        EXPECT_TRUE(g.size_px == l.size_px && g.intensity == l.intensity && g.color_r == l.color_r &&
                    g.color_g == l.color_g && g.color_b == l.color_b && g.element == l.element && g.reserved == 0)
            << what << ": instance of light " << g.light_index << " does not carry the light's fields";
      }

      // The image.
      EXPECT_TRUE(all_finite(run.image)) << what;
      double worst = 0.0;
      if (run.instances.empty()) {
        EXPECT_TRUE(bit_equal(run.image, background)) << what << ": nothing visible, yet the image changed";
      } else {
        const auto ref = reference::flare_composite(background, run.instances, uint32_t(run.instances.size()), look,
                                                    read_flare_atlas(pass.flare()), flare_sampler_precision());
        const FlareDeviation d = compare_flare(run.image, ref, kF16);
        EXPECT_EQ(d.outside, 0u) << what << ": worst ratio " << d.worst_ratio << ", first " << d.first;
        worst = d.worst_ratio;
      }
      std::printf(
          "%-62s %4u lights: visible %4u (drawn %4u), occluded %4u, frustum %2u, disabled %2u, ambiguous %u;"
          " image/reference worst ratio %.3f\n",
          what.c_str(), n, run.stats.visible, run.indirect.instance_count, run.stats.occluded, run.stats.frustum_culled,
          run.stats.disabled, ambiguous, worst);
    }
  }
}

// ---- Flare sizes -----------------------------------------------------------------------------------

// The whole pass (Hi-Z, cull, draw) at 1x1, 1xN, Nx1, 4097x3 and the device's largest side as a
// thin image, both draw paths: lights at ndc positions across the image (identity view-projection,
// nothing occluded, one off screen), the image finite and within docs/FLARE.md's tolerance of the
// float64 composite of what was drawn.
TEST_F(FlareRobustnessTest, FlarePassHandlesDegenerateAndThinSizes) {
  const uint32_t max_side = std::min(16384u, context().info().max_image_dimension_2d);
  const VkExtent2D sizes[] = {{1, 1}, {1, 61}, {61, 1}, {4097, 3}, {max_side, 2}, {2, max_side}};
  std::array<float, 16> identity{};
  identity[0] = identity[5] = identity[10] = identity[15] = 1.0f;
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);
  const std::vector<GlintFlareLight> lights = {ndc_light(0.0f, 0.0f, 0.5f, 6.0f), ndc_light(-0.9f, 0.7f, 0.5f, 3.0f),
                                               ndc_light(0.95f, -0.95f, 0.5f, 12.0f),
                                               ndc_light(3.0f, 0.0f, 0.5f, 4.0f)};  // off screen
  for (VkExtent2D e : sizes) {
    const reference::DepthImage depth{e.width, e.height, std::vector<float>(size_t(e.width) * e.height, 1.0f)};
    const CpuImage background = as_stored(random_hdr(e.width, e.height, e.width + 7 * e.height), kF16);
    for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
      const std::string what = std::to_string(e.width) + "x" + std::to_string(e.height) + " " + path_name(path);
      LensFlarePass pass(context(), pass_config(e, path, 8, uint32_t(lights.size())));
      const PassRun run = run_pass(pass, background, depth, lights, identity, look, 1)[0];
      EXPECT_EQ(run.stats.total, lights.size()) << what;
      EXPECT_EQ(run.stats.frustum_culled, 1u) << what;
      EXPECT_EQ(run.stats.visible, 3u) << what;
      ASSERT_TRUE(all_finite(run.image)) << what;
      const auto ref = reference::flare_composite(background, run.instances, uint32_t(run.instances.size()), look,
                                                  read_flare_atlas(pass.flare()), flare_sampler_precision());
      const FlareDeviation d = compare_flare(run.image, ref, kF16);
      EXPECT_EQ(d.outside, 0u) << what << ": worst ratio " << d.worst_ratio << ", first " << d.first;
      EXPECT_FALSE(bit_equal(run.image, background)) << what << ": the visible lights drew nothing";
    }
  }
}

// ---- Hi-Z sizes ------------------------------------------------------------------------------------

// 1x1 (no level), 1xN and Nx1 (one side stays 1 at every level), 4097x3 (a 64-wide edge tile plus
// one column, odd folds on the short side) and the device's largest side as a 2-pixel-thin image,
// both ways (16384x2 and 2x16384 on lavapipe): bit-identical to the float64 reference,
// D32 / R32 and both Z conventions in turn.
TEST_F(FlareRobustnessTest, HiZMatchesTheReferenceAtDegenerateAndThinSizes) {
  const uint32_t max_side = std::min(16384u, context().info().max_image_dimension_2d);
  const VkExtent2D sizes[] = {{1, 1}, {1, 300}, {300, 1}, {4097, 3}, {max_side, 2}, {2, max_side}};
  uint32_t stream = 41;
  for (const VkExtent2D& e : sizes) {
    const bool reversed = stream % 2 == 1;
    const VkFormat format = stream % 3 == 0 ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_D32_SFLOAT;
    std::mt19937 rng(stream++);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    reference::DepthImage d{e.width, e.height, std::vector<float>(size_t(e.width) * e.height)};
    for (float& v : d.depth) v = unit(rng);
    auto img = make_depth(d, format);
    HiZConfig config;
    config.extent = e;
    config.format = format;
    config.reversed_z = reversed;
    HiZPyramid hiz(context(), config);
    const auto expected_levels = static_cast<uint32_t>(std::floor(std::log2(double(std::max(e.width, e.height)))));
    ASSERT_EQ(hiz.levels(), expected_levels);
    context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, img.state); });
    const auto ref = reference::hiz_pyramid(d, reversed, hiz.levels());
    const std::string what = std::to_string(e.width) + "x" + std::to_string(e.height);
    for (uint32_t k = 1; k <= hiz.levels(); ++k) {
      const VkExtent2D le{std::max(1u, e.width >> k), std::max(1u, e.height >> k)};
      const auto level = detail::download_r32(context(), hiz.image(), k - 1, le, hiz.levels());
      ASSERT_EQ(level.size(), ref[k - 1].depth.size()) << what;
      EXPECT_EQ(std::memcmp(level.data(), ref[k - 1].depth.data(), level.size() * 4), 0)
          << what << ": level " << k << " differs from the reference";
      for (float v : level) ASSERT_TRUE(std::isfinite(v)) << what << ": level " << k;
    }
    if (hiz.levels() == 0) {  // 1x1: the depth image is the whole pyramid and is left readable
      EXPECT_EQ(img.state.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    }
  }
}

// ---- LOD finiteness on the GPU ---------------------------------------------------------------------

// glint_lod_finite (include/glint/gpu/lod_impl.h) reads the exponent bits. Written as
// x == x && x - x == 0, a compiler that assumes finite floats folds it to true, and an infinite
// derivative then reaches the top level instead of the documented fallback, level 0.
TEST_F(FlareRobustnessTest, LodNonFiniteQueriesFallBackToLevelZeroOnTheGpu) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  LodQuery base;
  base.dudx = base.dvdy = 1.0f / 8.0f;  // 32 texels per pixel on a 256-texel tile: level 5
  base.tex_w = base.tex_h = 256.0f;
  base.off_x = base.off_y = 512.0f;
  std::vector<LodQuery> queries = {base};
  for (float bad : {inf, -inf, nan}) {
    for (float LodQuery::*field :
         {&LodQuery::dudx, &LodQuery::dvdx, &LodQuery::dudy, &LodQuery::dvdy, &LodQuery::tex_w, &LodQuery::off_y}) {
      LodQuery q = base;
      q.*field = bad;
      queries.push_back(q);
    }
  }
  const auto n = static_cast<uint32_t>(queries.size());
  HostBuffer qbuf(n * sizeof(LodQuery)), lbuf(n * sizeof(float));
  std::memcpy(qbuf.owned.mapped(), queries.data(), n * sizeof(LodQuery));
  qbuf.owned.flush();
  LodBatch batch(context());
  for (bool aniso : {false, true}) {
    LodAtlasConfig atlas;
    atlas.anisotropic = aniso;
    lbuf.poison();
    context().run_once([&](VkCommandBuffer cmd) {
      batch.record(cmd, qbuf.view, lbuf.view, n, atlas);
      detail::Barriers b;
      b.use(lbuf.view, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
      b.flush(cmd);
    });
    const auto levels = as<float>(lbuf.bytes(n * sizeof(float)), n);
    EXPECT_NEAR(levels[0], 5.0f, 1e-4f) << "the valid query";
    for (uint32_t i = 1; i < n; ++i) {
      EXPECT_EQ(levels[i], 0.0f) << "query " << i << (aniso ? " (anisotropic)" : "") << ": a non-finite field";
      EXPECT_EQ(lod_level(queries[i], atlas), 0.0f) << "query " << i << " on the host";
    }
  }
}

}  // namespace
}  // namespace glint::test
