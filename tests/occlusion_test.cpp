// Lens-flare visibility on the GPU against the float64 references (tools/reference/
// occlusion_reference.h): the Hi-Z pyramid bit for bit at odd, tiny and very wide sizes, the cull +
// grid test + compaction on random scenes (exact grid result, conservative against brute force,
// error within the bound of docs/OCCLUSION.md), monotone fading, overflow, zero lights, errors.
#include <glint/occlusion.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <set>

#include "core/barriers.h"
#include "core/check.h"
#include "core/formats.h"
#include "reference/occlusion_reference.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"
#include "support/transfer.h"
#include "visibility/hiz_internal.h"
#include "visibility/light_cull_internal.h"
#include "visibility/shaders/light_cull_params.h"

namespace glint::test {
namespace {

class OcclusionTest : public GpuTest {};

reference::DepthImage random_depth(uint32_t w, uint32_t h, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  reference::DepthImage d{w, h, std::vector<float>(size_t(w) * h)};
  for (float& v : d.depth) v = unit(rng);
  return d;
}

// Runs f, which must throw Error with `code` and a message containing `needle`.
template <typename F>
void expect_error(F&& f, ErrorCode code, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error for " << needle;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// Poisons every mip of the pyramid with NaN, so an unwritten texel fails the comparison.
void poison_pyramid(HiZPyramid& hiz) {
  context().run_once([&](VkCommandBuffer cmd) {
    detail::Barriers b;
    b.use(hiz.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
          VK_ACCESS_2_TRANSFER_WRITE_BIT, std::max(1u, hiz.levels()));
    b.flush(cmd);
    VkClearColorValue nan{};
    for (float& c : nan.float32) c = std::nanf("");
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, std::max(1u, hiz.levels()), 0, 1};
    vkCmdClearColorImage(cmd, hiz.image().image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &nan, 1, &range);
  });
}

std::vector<reference::DepthImage> read_pyramid(HiZPyramid& hiz) {
  std::vector<reference::DepthImage> out;
  const VkExtent2D e = hiz.config().extent;
  for (uint32_t k = 1; k <= hiz.levels(); ++k) {
    reference::DepthImage l;
    l.width = std::max(1u, e.width >> k);
    l.height = std::max(1u, e.height >> k);
    l.depth = detail::download_r32(context(), hiz.image(), k - 1, {l.width, l.height}, hiz.levels());
    out.push_back(std::move(l));
  }
  return out;
}

// Bit-exact comparison of every level, plus the conservative property checked directly: every
// texel of level k is at least as far as every source pixel it covers.
void expect_pyramid(const std::vector<reference::DepthImage>& gpu, const reference::DepthImage& depth, bool reversed,
                    const std::string& what) {
  const auto ref = reference::hiz_pyramid(depth, reversed, static_cast<uint32_t>(gpu.size()));
  for (size_t k = 0; k < gpu.size(); ++k) {
    ASSERT_EQ(gpu[k].depth.size(), ref[k].depth.size());
    size_t bad = 0;
    for (size_t i = 0; i < ref[k].depth.size(); ++i) {
      if (std::memcmp(&gpu[k].depth[i], &ref[k].depth[i], 4) != 0 && bad++ < 5) {
        ADD_FAILURE() << what << ": level " << k + 1 << " texel (" << i % ref[k].width << ", " << i / ref[k].width
                      << ") is " << gpu[k].depth[i] << ", reference " << ref[k].depth[i];
      }
    }
    EXPECT_EQ(bad, 0u) << what << ": level " << k + 1;
  }
  // Conservative: walk the source and look each pixel up at every level.
  size_t violations = 0;
  for (uint32_t y = 0; y < depth.height; ++y) {
    for (uint32_t x = 0; x < depth.width; ++x) {
      const float v = depth.at(x, y);
      for (size_t k = 0; k < gpu.size(); ++k) {
        const uint32_t s = static_cast<uint32_t>(k + 1);
        const uint32_t tx = std::min(x >> s, gpu[k].width - 1), ty = std::min(y >> s, gpu[k].height - 1);
        const float t = gpu[k].at(tx, ty);
        if (!(reversed ? t <= v : t >= v)) ++violations;
      }
    }
  }
  EXPECT_EQ(violations, 0u) << what << ": texels nearer than a source pixel they cover";
}

struct HiZCase {
  uint32_t w, h;
};

// Both stream passes (levels 1-6 by blocks, as GPUs run it; levels 1-2 by texels, as CPU devices
// do), each followed by the tile pass from its last level, on any device.
const detail::HiZStream kStreams[] = {detail::HiZStream::blocks, detail::HiZStream::texels};
const char* stream_name(detail::HiZStream s) { return s == detail::HiZStream::blocks ? " blocks" : " texels"; }

TEST_F(OcclusionTest, HiZMatchesReferenceAtAllSizes) {
  // 640x360 and 96x192: one side a multiple of 64, as in 1920x1080, so the block stream pass builds
  // that side's last blocks as interior ones; 96 = 64 + 32 folds (a mask of 31 would miss it).
  // 191x190: a corner block of 127x126 depth texels, 63x63 of level 1 (the most an edge block
  // gathers: all its batches of 4 per invocation).
  const HiZCase cases[] = {{1, 1},     {7, 3},    {3, 7},     {2, 1},      {64, 64},  {65, 63},
                           {127, 129}, {130, 67}, {333, 97},  {640, 360},  {96, 192}, {4097, 2},
                           {2, 600},   {8200, 2}, {3, 16384}, {1030, 771}, {191, 190}};
  uint32_t stream = 1;
  for (const HiZCase& c : cases) {
    for (VkFormat format : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_R32_SFLOAT}) {
      for (bool reversed : {false, true}) {
        if (format == VK_FORMAT_R32_SFLOAT && (c.w * c.h > 20000)) continue;  // big sizes once per format
        auto depth = random_depth(c.w, c.h, stream++);
        // The farthest depth at the last pixel: at odd sizes only the corner's extra read sees it.
        depth.depth.back() = reversed ? 0.0f : 1.0f;
        auto img = make_depth(depth, format);
        HiZConfig config;
        config.extent = {c.w, c.h};
        config.format = format;
        config.reversed_z = reversed;
        HiZPyramid hiz(context(), config);
        ASSERT_EQ(hiz.levels(), static_cast<uint32_t>(std::floor(std::log2(double(std::max(c.w, c.h))))));
        for (detail::HiZStream s : kStreams) {
          detail::HiZAccess::select_stream(hiz, s);
          poison_pyramid(hiz);
          context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, img.state); });
          std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + (reversed ? " reversed" : " standard") +
                             (format == VK_FORMAT_D32_SFLOAT ? " D32" : " R32") + stream_name(s);
          expect_pyramid(read_pyramid(hiz), depth, reversed, what);
        }
      }
    }
  }
}

// The stream pass by device type and shared memory (detail::hiz_resolve_stream): the block kernel
// and the tile pass declare kHiZSharedBytes; a device with less builds with the texel stream pass
// where no tile pass is needed and refuses larger pyramids by name.
TEST_F(OcclusionTest, HiZStreamFitsTheDeviceSharedMemory) {
  using detail::HiZStream;
  const auto gpu = VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, cpu = VK_PHYSICAL_DEVICE_TYPE_CPU;
  const uint32_t need = detail::kHiZSharedBytes;
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::device, gpu, 49152, 11, "g"), HiZStream::blocks);
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::device, gpu, need, 11, "g"), HiZStream::blocks);
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::device, cpu, 32768, 11, "c"), HiZStream::texels);
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::device, gpu, 16384, 2, "g"), HiZStream::texels);
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::texels, gpu, need, 11, "g"), HiZStream::texels);
  EXPECT_EQ(detail::hiz_resolve_stream(HiZStream::blocks, cpu, need, 11, "c"), HiZStream::blocks);
  expect_error([&] { detail::hiz_resolve_stream(HiZStream::device, gpu, need - 1, 11, "small"); }, ErrorCode::no_device,
               "11 levels need 20484 bytes of compute shared memory; device 'small' has 20483");
  expect_error([&] { detail::hiz_resolve_stream(HiZStream::device, gpu, 16384, 3, "small"); }, ErrorCode::no_device,
               "HiZConfig::max_cell_px <= 4");
  expect_error([&] { detail::hiz_resolve_stream(HiZStream::blocks, gpu, 16384, 2, "small"); }, ErrorCode::no_device,
               "device 'small' has 16384");
  // This device builds every pyramid.
  EXPECT_GE(context().info().max_shared_memory_bytes, need);
}

// The counter resets itself: frames with different depth, in separate submissions and twice in
// one command buffer, each give their own exact pyramid. Also the level cap.
TEST_F(OcclusionTest, HiZRepeatsFramesAndCapsLevels) {
  // The stream pass the device type chooses: blocks on GPUs, texels on CPU devices.
  {
    HiZConfig config;
    config.extent = {64, 64};
    const HiZPyramid hiz(context(), config);
    EXPECT_EQ(detail::HiZAccess::stream(hiz), context().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU
                                                  ? detail::HiZStream::texels
                                                  : detail::HiZStream::blocks);
  }
  for (int run = 0; run < 4; ++run) {
    const bool two_pass = run & 1;  // 8300 wide: tiles and the last workgroup's tail after either stream pass
    const detail::HiZStream s = kStreams[run >> 1];
    const uint32_t w = two_pass ? 8300 : 1000, h = two_pass ? 3 : 37;
    HiZConfig config;
    config.extent = {w, h};
    HiZPyramid hiz(context(), config);
    detail::HiZAccess::select_stream(hiz, s);
    for (uint32_t frame = 0; frame < 3; ++frame) {
      const auto a = random_depth(w, h, 100 + frame), b = random_depth(w, h, 200 + frame);
      auto ia = make_depth(a, config.format), ib = make_depth(b, config.format);
      context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, ia.state); });
      expect_pyramid(read_pyramid(hiz), a, false, "frame " + std::to_string(frame) + stream_name(s));
      context().run_once([&](VkCommandBuffer cmd) {
        hiz.record(cmd, ia.state);
        hiz.record(cmd, ib.state);
      });
      expect_pyramid(read_pyramid(hiz), b, false, "second build in one command buffer");
    }
  }
  // Every cap from 1 to 7 levels, on an image with interior and edge blocks in the stream pass
  // (whose unbuilt levels' bindings alias the last built level).
  const auto d = random_depth(300, 200, 9);
  auto img = make_depth(d, VK_FORMAT_D32_SFLOAT);
  for (uint32_t levels = 1; levels <= 7; ++levels) {
    HiZConfig capped;
    capped.extent = {300, 200};
    capped.max_cell_px = (1u << (levels - 1)) + 1;  // ceil(log2) = levels
    HiZPyramid hiz(context(), capped);
    ASSERT_EQ(hiz.levels(), levels);
    for (detail::HiZStream s : kStreams) {
      detail::HiZAccess::select_stream(hiz, s);
      poison_pyramid(hiz);
      context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, img.state); });
      expect_pyramid(read_pyramid(hiz), d, false, "capped at " + std::to_string(levels) + " levels" + stream_name(s));
    }
  }
  // Engine sizes on either side of the block stream pass's split of a remainder into blocks of its
  // own (a remainder r = size % 64 of at least 2^levels): 1920x1080 at 5 levels (r = 56 rows: split;
  // the flare pass's pyramid), 1280x720 at 4 levels (r = 16: split) and 5 (merged), and odd
  // remainders whose blocks fold inside themselves: 333x97 at 3 levels (r = 13 and 33), reversed Z.
  struct Capped {
    uint32_t w, h, levels;
  };
  for (const Capped c : {Capped{1920, 1080, 5}, Capped{1280, 720, 4}, Capped{1280, 720, 5}, Capped{333, 97, 3}}) {
    const auto e = random_depth(c.w, c.h, 11 + c.levels);
    auto depth = make_depth(e, VK_FORMAT_D32_SFLOAT);
    HiZConfig capped;
    capped.extent = {c.w, c.h};
    capped.reversed_z = true;
    capped.max_cell_px = (1u << (c.levels - 1)) + 1;
    HiZPyramid hiz(context(), capped);
    ASSERT_EQ(hiz.levels(), c.levels);
    detail::HiZAccess::select_stream(hiz, detail::HiZStream::blocks);
    poison_pyramid(hiz);
    context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, depth.state); });
    expect_pyramid(read_pyramid(hiz), e, true,
                   std::to_string(c.w) + "x" + std::to_string(c.h) + " capped at " + std::to_string(c.levels));
  }
}

// Everything the cull writes for one frame.
struct CullRun {
  std::vector<GlintFlareLightResult> results;
  std::vector<GlintFlareInstance> instances;  // the written slots (instance_count of them)
  GlintFlareIndirect indirect;
  GlintFlareStats stats;
  bool canary_intact = true;  // bytes past the capacity untouched
};

// A float64 view-projection in float, as a cull frame carries it; passes as `const float*`.
struct FloatViewProj {
  float m[16];
  explicit FloatViewProj(const double (&d)[16]) {
    for (int i = 0; i < 16; ++i) m[i] = static_cast<float>(d[i]);
  }
  operator const float*() const { return m; }
};

// `depth_image`, when given, is the image the cull reads (holding `depth`, of `format`), else one is
// made from `depth`.
CullRun run_cull(const reference::DepthImage& depth, VkFormat format, bool reversed,
                 const std::vector<GlintFlareLight>& lights, const float view_proj[16], const LightCullConfig& config,
                 uint32_t max_cell_px = 0, int frames = 1, uint32_t groups_per_instance = 3,
                 detail::LightCullPath path = detail::LightCullPath::device, uint32_t depth_workgroup = 0,
                 Image* depth_image = nullptr) {
  detail::OwnedImage made;
  if (!depth_image) made = make_depth(depth, format);
  Image& img_state = depth_image ? *depth_image : made.state;
  HiZConfig hc;
  hc.extent = {depth.width, depth.height};
  hc.format = format;
  hc.reversed_z = reversed;
  hc.max_cell_px = max_cell_px;
  HiZPyramid hiz(context(), hc);
  LightCuller culler(context(), config);
  detail::LightCullAccess::select_path(culler, path);
  if (depth_workgroup) detail::LightCullAccess::set_depth_workgroup(culler, depth_workgroup);
  const uint32_t n = static_cast<uint32_t>(lights.size());
  HostBuffer lbuf(n * sizeof(GlintFlareLight));
  if (n) std::memcpy(lbuf.owned.mapped(), lights.data(), n * sizeof(GlintFlareLight));
  lbuf.owned.flush();
  const uint32_t canary_slots = 16;
  HostBuffer inst((config.capacity + canary_slots) * sizeof(GlintFlareInstance));
  HostBuffer indirect(sizeof(GlintFlareIndirect)), stats(sizeof(GlintFlareStats)),
      results(n * sizeof(GlintFlareLightResult));
  LightCullOutputs out{inst.view, indirect.view, stats.view, results.view};
  LightCullFrame frame;
  std::copy(view_proj, view_proj + 16, frame.view_proj);
  frame.vertex_count = 6;
  frame.groups_per_instance = groups_per_instance;
  context().run_once([&](VkCommandBuffer cmd) {
    for (int f = 0; f < frames; ++f) {
      // The depth-image cull reads no pyramid: it is not built for it (so the cull cannot read it).
      if (culler.needs_pyramid(hiz, n)) hiz.record(cmd, img_state);
      culler.record(cmd, hiz, img_state, lbuf.view, n, frame, out);
    }
    to_host(cmd, out.instances);
    to_host(cmd, out.indirect);
    to_host(cmd, out.stats);
    to_host(cmd, out.results);
  });
  CullRun r;
  r.indirect = *indirect.as<GlintFlareIndirect>();
  r.stats = *stats.as<GlintFlareStats>();
  const auto* res = results.as<GlintFlareLightResult>();
  r.results.assign(res, res + n);
  const auto* in = inst.as<GlintFlareInstance>();
  r.instances.assign(in, in + std::min(r.indirect.instance_count, config.capacity));
  const auto* bytes = reinterpret_cast<const uint8_t*>(in + config.capacity);
  for (size_t i = 0; i < canary_slots * sizeof(GlintFlareInstance); ++i)
    r.canary_intact = r.canary_intact && bytes[i] == 0xFF;
  return r;
}

// Two culls of the same lights gave the same bits: indirect arguments, statistics, per-light
// results and the written instances. (memcmp of an empty vector's data(), which may be null, is
// undefined: none are compared.)
void expect_same_bits(const CullRun& a, const CullRun& b, const std::string& what) {
  EXPECT_EQ(std::memcmp(&a.indirect, &b.indirect, sizeof a.indirect), 0) << what;
  EXPECT_EQ(std::memcmp(&a.stats, &b.stats, sizeof a.stats), 0) << what;
  ASSERT_EQ(a.results.size(), b.results.size()) << what;
  if (!a.results.empty()) {
    EXPECT_EQ(std::memcmp(a.results.data(), b.results.data(), a.results.size() * sizeof a.results[0]), 0) << what;
  }
  ASSERT_EQ(a.instances.size(), b.instances.size()) << what;
  if (!a.instances.empty()) {
    EXPECT_EQ(std::memcmp(a.instances.data(), b.instances.data(), a.instances.size() * sizeof a.instances[0]), 0)
        << what;
  }
}

// Compares one GPU run with the references light by light; returns the mean |fraction - brute force|.
double expect_cull_matches(const CullRun& run, const reference::Scene& scene, const LightCullConfig& config,
                           bool reversed, uint32_t levels, const std::string& what) {
  reference::CullSettings s;
  std::copy(scene.view_proj, scene.view_proj + 16, s.view_proj);
  s.grid = config.grid;
  s.margin_ndc = config.margin_ndc;
  s.depth_bias = config.depth_bias;
  s.reversed_z = reversed;
  s.levels = levels;
  s.regular_grid = config.pattern == OcclusionPattern::regular;
  const auto pyramid = reference::hiz_pyramid(scene.depth, reversed, levels);
  uint32_t counts[5] = {};
  uint32_t ambiguous = 0, failures = 0;
  double error_sum = 0.0;
  uint32_t tested = 0;
  std::set<uint32_t> expected_visible;
  const double n2 = double(config.grid) * config.grid;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const auto ref = reference::cull_light(scene.lights[i], s, scene.depth, pyramid);
    const auto& gpu = run.results[i];
    const uint32_t gpu_state = gpu.culled == GLINT_FLARE_OVERFLOW ? GLINT_FLARE_VISIBLE : gpu.culled;
    counts[std::min(gpu_state, 4u)]++;
    if (gpu_state == GLINT_FLARE_VISIBLE) expected_visible.insert(static_cast<uint32_t>(i));
    if (ref.ambiguous) {
      ++ambiguous;
      continue;
    }
    auto fail = [&](const std::string& msg) {
      if (failures++ < 8)
        ADD_FAILURE() << what << ": light " << i << ": " << msg << " (ref state " << ref.culled << " fraction "
                      << ref.grid_fraction << " brute " << ref.brute_force << " level " << ref.level << " centre "
                      << ref.center_x << "," << ref.center_y << " z " << ref.ndc_z << " size "
                      << scene.lights[i].size_px << ")";
    };
    if (gpu_state != ref.culled) fail("GPU state " + std::to_string(gpu.culled));
    const double frac = gpu.culled == GLINT_FLARE_VISIBLE ? ref.grid_fraction : 0.0;
    if (gpu.culled != GLINT_FLARE_OVERFLOW && std::fabs(gpu.visible_fraction - frac) > 1e-6) {
      fail("GPU fraction " + std::to_string(gpu.visible_fraction));
    }
    if (ref.culled == GLINT_FLARE_VISIBLE || ref.culled == GLINT_FLARE_OCCLUDED) {
      // Conservative: any visible pixel under the footprint keeps the light visible; the error is
      // bounded by the mixed samples (docs/OCCLUSION.md). The regular grid (each cell reads the
      // cell itself) also never reports less than the true fraction.
      if (ref.brute_force > 0.0 && gpu_state != GLINT_FLARE_VISIBLE) fail("fully occluded but brute force is > 0");
      if (s.regular_grid && ref.grid_fraction < ref.brute_force - 1e-9) fail("grid fraction below brute force");
      if (std::fabs(ref.grid_fraction - ref.brute_force) > ref.mixed_cells / n2 + 1e-9) fail("error above the bound");
      error_sum += std::fabs(ref.grid_fraction - ref.brute_force);
      ++tested;
    }
  }
  EXPECT_EQ(failures, 0u) << what;
  EXPECT_LE(ambiguous, scene.lights.size() / 20 + 2) << what << ": too many lights within rounding of a boundary";
  // Statistics, indirect arguments and compaction against the CPU count.
  const uint32_t visible = static_cast<uint32_t>(expected_visible.size());
  const uint32_t written = std::min(visible, config.capacity);
  EXPECT_EQ(run.stats.total, scene.lights.size()) << what;
  EXPECT_EQ(run.stats.visible, visible) << what;
  EXPECT_EQ(run.stats.frustum_culled, counts[GLINT_FLARE_FRUSTUM]) << what;
  EXPECT_EQ(run.stats.occluded, counts[GLINT_FLARE_OCCLUDED]) << what;
  EXPECT_EQ(run.stats.disabled, counts[GLINT_FLARE_DISABLED]) << what;
  EXPECT_EQ(run.stats.overflow, visible - written) << what;
  EXPECT_EQ(run.indirect.vertex_count, 6u);
  EXPECT_EQ(run.indirect.instance_count, written);
  EXPECT_EQ(run.indirect.first_vertex, 0u);
  EXPECT_EQ(run.indirect.first_instance, 0u);
  EXPECT_EQ(run.indirect.group_count_x, written * 3);
  EXPECT_EQ(run.indirect.group_count_y, 1u);
  EXPECT_EQ(run.indirect.group_count_z, 1u);
  EXPECT_TRUE(run.canary_intact) << what << ": written past the capacity";
  std::set<uint32_t> seen;
  for (const auto& inst : run.instances) {
    EXPECT_TRUE(seen.insert(inst.light_index).second) << what << ": light " << inst.light_index << " twice";
    if (inst.light_index >= scene.lights.size()) {
      ADD_FAILURE() << what << ": instance names light " << inst.light_index;
      continue;
    }
    const auto& l = scene.lights[inst.light_index];
    const auto& res = run.results[inst.light_index];
    EXPECT_EQ(res.culled, GLINT_FLARE_VISIBLE);
    EXPECT_EQ(inst.visible_fraction, res.visible_fraction);
    EXPECT_EQ(inst.size_px, l.size_px);
    EXPECT_EQ(inst.color_g, l.color_g);
    EXPECT_EQ(inst.intensity, l.intensity);
    EXPECT_EQ(inst.element, l.element);
    EXPECT_EQ(inst.reserved, 0u);
  }
  if (written == visible) {
    EXPECT_EQ(seen, expected_visible) << what << ": compacted set differs from the CPU's";
  } else {
    for (uint32_t i : seen) EXPECT_TRUE(expected_visible.count(i));
    uint32_t overflowed = 0;
    for (const auto& r : run.results) overflowed += r.culled == GLINT_FLARE_OVERFLOW;
    EXPECT_EQ(overflowed, visible - written) << what;
  }
  return tested ? error_sum / tested : 0.0;
}

struct SceneCase {
  uint32_t w, h, lights, grid;
  double max_size;
};

TEST_F(OcclusionTest, CullMatchesReferenceOnRandomScenes) {
  const SceneCase cases[] = {{257, 143, 600, 4, 120}, {257, 143, 300, 1, 120}, {200, 111, 300, 16, 200},
                             {161, 97, 300, 7, 60},   {1, 1, 40, 4, 10},       {7, 3, 80, 4, 12},
                             {4097, 2, 200, 4, 300}};
  uint32_t stream = 11;
  for (const SceneCase& c : cases) {
    for (bool reversed : {false, true}) {
      // The regular pattern once per case (standard Z): it keeps grid >= brute force too.
      for (int variant : reversed ? std::vector<int>{0} : std::vector<int>{0, 2}) {
        const auto scene = reference::random_scene(c.w, c.h, c.lights, stream++, reversed, c.max_size);
        for (detail::LightCullPath path : {detail::LightCullPath::groups, detail::LightCullPath::one_group}) {
          LightCullConfig config;
          config.grid = c.grid;
          config.capacity = c.lights;
          if (variant == 2) config.pattern = OcclusionPattern::regular;
          const FloatViewProj vp(scene.view_proj);
          const VkFormat format = reversed ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_D32_SFLOAT;
          const auto run = run_cull(scene.depth, format, reversed, scene.lights, vp, config, 0, 1, 3, path);
          const uint32_t levels = static_cast<uint32_t>(std::floor(std::log2(double(std::max(c.w, c.h)))));
          const std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + " N=" + std::to_string(c.grid) +
                                   (reversed ? " reversed" : " standard") + (variant == 2 ? " regular" : "") +
                                   (path == detail::LightCullPath::one_group ? ", one workgroup" : ", four dispatches");
          expect_cull_matches(run, scene, config, reversed, levels, what);
          // Enough of every kind in the larger scenes that the checks above mean something.
          if (c.lights >= 300) {
            EXPECT_GT(run.stats.visible, c.lights / 20) << what;
            if (c.grid <= 4) {
              EXPECT_GT(run.stats.occluded, 0u) << what;
            }
            EXPECT_GT(run.stats.frustum_culled, c.lights / 20) << what;
            EXPECT_GT(run.stats.disabled, 0u) << what;
          }
        }
      }
    }
  }
}

// The cull on the other depth formats (depth-aspect views; barriers cover stencil where the format
// has it). UNORM depth is quantized to round(d * (2^bits - 1)) / (2^bits - 1) for the reference,
// as the GPU reads it. A format the device cannot sample is skipped by name (HiZPyramid refuses it).
TEST_F(OcclusionTest, CullReadsEveryDepthFormat) {
  uint32_t stream = 91;
  for (VkFormat format : {VK_FORMAT_D16_UNORM, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D24_UNORM_S8_UINT,
                          VK_FORMAT_D32_SFLOAT_S8_UINT}) {
    if (!(detail::format_features(context(), format) & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) {
      std::printf("skipped %s: device cannot sample it\n", detail::format_name(format).c_str());
      continue;
    }
    auto scene = reference::random_scene(161, 97, 300, stream++, false, 60);
    quantize_for_format(scene.depth, format);
    LightCullConfig config;
    config.capacity = 300;
    const FloatViewProj vp(scene.view_proj);
    const auto run = run_cull(scene.depth, format, false, scene.lights, vp, config);
    expect_cull_matches(run, scene, config, false, 7, "161x97 format " + std::to_string(int(format)));
    EXPECT_GT(run.stats.occluded, 0u);
  }
}

// Lights given in NDC (an identity view-projection) over a D32 depth image with a full pyramid,
// grid N, multi-jittered: the run, compared light by light with the references.
CullRun cull_ndc_lights(const reference::DepthImage& depth, const std::vector<GlintFlareLight>& lights, uint32_t grid,
                        const std::string& what) {
  LightCullConfig config;
  config.grid = grid;
  config.capacity = static_cast<uint32_t>(lights.size());
  const float vp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  CullRun run = run_cull(depth, VK_FORMAT_D32_SFLOAT, false, lights, vp, config);
  reference::Scene scene;
  scene.depth = depth;
  scene.lights = lights;
  std::copy(vp, vp + 16, scene.view_proj);
  const auto levels = static_cast<uint32_t>(std::floor(std::log2(double(std::max(depth.width, depth.height)))));
  expect_cull_matches(run, scene, config, false, levels, what);
  return run;
}

// An occluder over the whole image, nearer than every light, with single far pixels ("holes"):
// a light is seen only through a hole under one of its samples' windows, often at a window's or
// the light's edge. The kernel skips the samples of a light whose windows all lie under coarser
// texels nearer than it (docs/OCCLUSION.md, "whole-light early out"); a hole that window misses
// would turn a visible light into an occluded one here. Both kinds must be common for this test
// to mean something.
TEST_F(OcclusionTest, CullSeesLightsThroughSinglePixelHoles) {
  // Large lights over sparse holes, and lights of a few pixels (cells of up to 2 pixels, read at
  // levels 0 and 1) over dense ones.
  struct HoleCase {
    double max_size;
    uint32_t hole_every;
  };
  uint32_t stream = 301;
  for (const HoleCase c : {HoleCase{70, 409}, HoleCase{6, 23}}) {
    for (bool reversed : {false, true}) {
      for (uint32_t grid : {3u, 4u}) {
        auto scene = reference::random_scene(257, 143, 600, stream++, reversed, c.max_size);
        const float near = reversed ? 1.0f : 0.0f, far = reversed ? 0.0f : 1.0f;
        uint32_t holes = 0;
        for (uint32_t y = 0; y < scene.depth.height; ++y) {
          for (uint32_t x = 0; x < scene.depth.width; ++x) {
            const uint32_t h = (x * 73856093u) ^ (y * 19349663u) ^ (grid * 83492791u);
            const bool hole = h % c.hole_every == 0u;
            scene.depth.depth[size_t(y) * scene.depth.width + x] = hole ? far : near;
            holes += hole;
          }
        }
        ASSERT_GT(holes, 50u);
        LightCullConfig config;
        config.grid = grid;
        config.capacity = 600;
        const FloatViewProj vp(scene.view_proj);
        const VkFormat format = reversed ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_D32_SFLOAT;
        const auto run = run_cull(scene.depth, format, reversed, scene.lights, vp, config);
        const std::string what = "holes max size " + std::to_string(int(c.max_size)) + " N=" + std::to_string(grid) +
                                 (reversed ? " reversed" : " standard");
        expect_cull_matches(run, scene, config, reversed, 8, what);
        EXPECT_GT(run.stats.visible, 40u) << what << ": " << run.stats.occluded << " occluded";
        EXPECT_GT(run.stats.occluded, 40u) << what << ": " << run.stats.visible << " visible";
      }
    }
  }
}

// One light per 64-pixel tile, hidden by an occluder except through one pixel: the first pixel of
// the first texel of its top-left sample's window, or the last pixel of the last texel of its
// bottom-right sample's window (the extremes of the union of its windows; multi-jittered
// footprints reach (N - 1) / N cell past the light's edge there). Every light is then visible
// (the count leaves 2 % for lights whose window ends lie within rounding of a pixel edge). The
// whole-light early out tests that union at a coarser level; a coarse window that missed its
// first or last pixel would hide the light. Sizes of 1 to 8 pixels, read at levels 0 to 2, at
// random sub-pixel positions, so the union's ends fall at every offset within the coarse texels;
// at these sizes the border's reach is within the early out's one-pixel margin, which
// CullSeesLightsThroughSinglePixelHoles covers with lights up to 70 pixels.
TEST_F(OcclusionTest, CullSeesALightThroughOnePixelAtTheEndOfItsWindows) {
  const uint32_t tile = 64, w = 2048, h = 1024;
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> offset(-3.0, 3.0), size_px(1.0, 8.0);
  for (uint32_t grid : {3u, 4u}) {
    reference::DepthImage depth{w, h, std::vector<float>(size_t(w) * h, 0.2f)};
    std::vector<GlintFlareLight> lights;
    const double n = grid;
    for (uint32_t ty = 0; ty < h / tile; ++ty) {
      for (uint32_t tx = 0; tx < w / tile; ++tx) {
        const double cx = tx * tile + 32.0 + offset(rng), cy = ty * tile + 32.0 + offset(rng), size = size_px(rng);
        // The kernel's footprint arithmetic (light_cull.comp, sample_span and texel_range).
        const double cell = size / n, unit = size / (2.0 * n * n);
        const int k = cell <= 1.0 ? 0 : static_cast<int>(std::ceil(std::log2(cell)));
        const bool last = (tx + ty) % 2 != 0;
        const double ext = last ? 2.0 * n * n + 2.0 * n - 2.0 : 2.0 - 2.0 * n;
        uint32_t hole[2];
        for (int axis = 0; axis < 2; ++axis) {
          const double edge = (axis == 0 ? cx : cy) - 0.5 * size + ext * unit;
          const int p = last ? static_cast<int>(std::ceil(edge)) - 1 : static_cast<int>(std::floor(edge));
          hole[axis] = last ? static_cast<uint32_t>((((p >> k) + 1) << k) - 1) : static_cast<uint32_t>((p >> k) << k);
        }
        depth.depth[size_t(hole[1]) * w + hole[0]] = 0.9f;
        GlintFlareLight l{};
        l.position_x = static_cast<float>(cx / w * 2.0 - 1.0);
        l.position_y = static_cast<float>(cy / h * 2.0 - 1.0);
        l.position_z = 0.5f;
        l.size_px = static_cast<float>(size);
        l.enabled = 1;
        lights.push_back(l);
      }
    }
    const std::string what = "one hole N=" + std::to_string(grid);
    const CullRun run = cull_ndc_lights(depth, lights, grid, what);
    // The construction puts each hole in a window: (nearly) every light is visible.
    EXPECT_GE(run.stats.visible, lights.size() - lights.size() / 50) << what;
  }
}

// Lights just past the bottom-right corner of an odd-sized image, read at level 1, whose last
// texel of each axis is 3 pixels wide (it reaches the edge): only the corner pixel is far. The
// samples' windows clamp into that texel; the whole-light early out must take its pixel range up
// to the edge (a range that stopped at 2 texels' worth would fit level 0 and miss the pixel).
TEST_F(OcclusionTest, CullSeesALightPastTheCornerThroughTheLastPixel) {
  const uint32_t w = 97, h = 61;
  reference::DepthImage depth{w, h, std::vector<float>(size_t(w) * h, 0.2f)};
  depth.depth[size_t(h - 1) * w + (w - 1)] = 0.9f;
  std::mt19937 rng(97);
  std::uniform_real_distribution<double> past(0.5, 2.0), size_px(2.05, 4.0);
  std::vector<GlintFlareLight> lights;
  for (int i = 0; i < 200; ++i) {
    GlintFlareLight l{};
    l.position_x = static_cast<float>((w + past(rng)) / w * 2.0 - 1.0);
    l.position_y = static_cast<float>((h + past(rng)) / h * 2.0 - 1.0);
    l.position_z = 0.5f;
    l.size_px = static_cast<float>(size_px(rng));  // cells of 1 to 2 pixels: level 1
    l.enabled = 1;
    lights.push_back(l);
  }
  const CullRun run = cull_ndc_lights(depth, lights, 2, "past the corner");
  EXPECT_EQ(run.stats.visible, lights.size());
}

// A shallow pyramid (max_cell_px) and a depth bias: still exact against the reference.
TEST_F(OcclusionTest, CullWithCappedPyramidAndBias) {
  const auto scene = reference::random_scene(190, 130, 400, 77, false, 150);
  LightCullConfig config;
  config.capacity = 400;
  config.depth_bias = 0.02f;
  config.grid = 2;
  const FloatViewProj vp(scene.view_proj);
  const auto run = run_cull(scene.depth, VK_FORMAT_D32_SFLOAT, false, scene.lights, vp, config, 4);
  expect_cull_matches(run, scene, config, false, 2, "capped + bias");
}

// Capacity overflow: the count is clamped, nothing is written past the capacity, overflow counted.
// Also two frames in one command buffer: the counters reset between them.
TEST_F(OcclusionTest, CullOverflowAndRepeatedFrames) {
  const auto scene = reference::random_scene(150, 100, 500, 5, false, 40);
  for (detail::LightCullPath path : {detail::LightCullPath::groups, detail::LightCullPath::one_group}) {
    for (uint32_t capacity : {1u, 13u}) {
      LightCullConfig config;
      config.capacity = capacity;
      const FloatViewProj vp(scene.view_proj);
      const auto run = run_cull(scene.depth, VK_FORMAT_D32_SFLOAT, false, scene.lights, vp, config, 0, 2, 3, path);
      ASSERT_GT(run.stats.visible, capacity);
      EXPECT_EQ(run.indirect.instance_count, capacity);
      EXPECT_EQ(run.stats.overflow, run.stats.visible - capacity);
      expect_cull_matches(run, scene, config, false, 7,
                          "overflow " + std::to_string(capacity) +
                              (path == detail::LightCullPath::one_group ? ", one workgroup" : ", four dispatches"));
    }
  }
}

// The one-workgroup cull (few lights) and the four dispatches give the same bits: instances,
// per-light results, arguments and statistics, with more lights than one chunk of the workgroup,
// capacity overflow, and dispatch arguments split into rows (groups_per_instance at its largest).
// The path the light count chooses is one_group up to one_group_lights(), the four dispatches above.
TEST_F(OcclusionTest, OneWorkgroupCullGivesTheBitsOfTheFourDispatches) {
  for (bool reversed : {false, true}) {
    const auto scene = reference::random_scene(257, 143, 1500, 41 + reversed, reversed, 90);
    LightCullConfig config;
    // Standard Z: overflow within the first chunk; reversed Z: every visible light finds a slot,
    // also those of later chunks.
    config.capacity = reversed ? 1500 : 200;
    config.grid = 3;
    const FloatViewProj vp(scene.view_proj);
    const VkFormat format = reversed ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_D32_SFLOAT;
    LightCuller probe(context(), config);
    const uint32_t most = probe.max_groups_per_instance();
    ASSERT_GT(uint32_t(scene.lights.size()), probe.one_group_lights()) << "more than one chunk";
    const auto a =
        run_cull(scene.depth, format, reversed, scene.lights, vp, config, 0, 1, most, detail::LightCullPath::groups);
    const auto b =
        run_cull(scene.depth, format, reversed, scene.lights, vp, config, 0, 1, most, detail::LightCullPath::one_group);
    const std::string what = reversed ? "reversed" : "standard";
    ASSERT_EQ(a.stats.overflow > 0u, !reversed) << what << ": overflow " << a.stats.overflow;
    ASSERT_FALSE(b.instances.empty()) << what;
    expect_same_bits(a, b, what);
    EXPECT_TRUE(a.canary_intact && b.canary_intact) << what;
    // The first m lights against the four dispatches, on the path the count picks (the test below
    // checks which) and on the one-workgroup path with shared samples (which GPUs pick, CPU
    // devices not), for m up to one_group_lights() (the workgroup's size W at grid 3): sharing gives
    // each light W / m invocations, at most one per sample and one for the early out: m = W / 10
    // gives 10 (the early out on its own invocation), W / 4 gives 4 (samples 0, 4, 8 on one
    // invocation, the early out before them), W / 2 gives 2, and W one (the per-light build). Each
    // with the configuration's capacity and with room for a quarter of the lights (overflow).
    // (Which lane runs the early out cannot change these bits on finite depth, where the early out
    // gives the fraction the samples give: only NaN depth could tell; docs/OCCLUSION.md.)
    const uint32_t w = probe.one_group_lights();
    for (uint32_t m : {1u, std::max(1u, w / 10), std::max(1u, w / 4), std::max(1u, w / 2), w}) {
      const std::vector<GlintFlareLight> few(scene.lights.begin(), scene.lights.begin() + m);
      reference::Scene first = scene;
      first.lights = few;
      for (uint32_t capacity : {config.capacity, std::max(1u, m / 4)}) {
        LightCullConfig cc = config;
        cc.capacity = capacity;
        const auto d = run_cull(scene.depth, format, reversed, few, vp, cc, 0, 1, 3, detail::LightCullPath::groups);
        for (auto path : {detail::LightCullPath::device, detail::LightCullPath::one_group_shared_samples}) {
          const auto c = run_cull(scene.depth, format, reversed, few, vp, cc, 0, 1, 3, path);
          const std::string lights = what + ", " + std::to_string(m) + " lights, capacity " + std::to_string(capacity) +
                                     (path == detail::LightCullPath::device ? "" : ", shared samples");
          expect_same_bits(c, d, lights);
          EXPECT_TRUE(c.canary_intact && d.canary_intact) << lights;
          expect_cull_matches(c, first, cc, reversed, 8, lights);
        }
        if (m == std::max(1u, w / 2) && capacity < config.capacity) {  // the most lights that share
          EXPECT_GT(d.stats.overflow, 0u) << what << ": no overflow";
        }
      }
    }
  }
}

// The depth-image cull (a workgroup per sample reading its window's pixels, the last workgroup
// culling) gives the bits of the cull that reads the pyramid: instances, results, arguments and
// statistics, both Z conventions, multi-jittered and regular grids of 1 to 4, pyramids capped at
// 2 to 5 levels and uncapped (8 levels: a window may cover the whole 257x143 image), no
// light, one, a few and more than one chunk of the last workgroup (150 lights also in workgroups
// of 32, on every device), capacity overflow, and two
// frames on one command buffer (the count of finished workgroups resets). Lights of up to 90 px
// in scenes with lights on the image's edges, off screen and behind the camera; the runs are
// also checked against the float64 reference.
TEST_F(OcclusionTest, DepthImageCullGivesTheBitsOfThePyramidCull) {
  struct Case {
    uint32_t grid;
    uint32_t max_cell_px;  // 0: every level
    OcclusionPattern pattern;
  };
  uint32_t stream = 901;
  for (bool reversed : {false, true}) {
    for (const Case c : {Case{4, 32, OcclusionPattern::multi_jittered}, Case{3, 8, OcclusionPattern::multi_jittered},
                         Case{2, 0, OcclusionPattern::multi_jittered}, Case{1, 4, OcclusionPattern::multi_jittered},
                         Case{4, 16, OcclusionPattern::regular}}) {
      const auto scene = reference::random_scene(257, 143, 150, stream++, reversed, 90);
      LightCullConfig config;
      config.grid = c.grid;
      config.pattern = c.pattern;
      const FloatViewProj vp(scene.view_proj);
      const VkFormat format = reversed ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_D32_SFLOAT;
      const uint32_t levels = c.max_cell_px == 0 ? 8u : static_cast<uint32_t>(std::ceil(std::log2(c.max_cell_px)));
      for (uint32_t m : {0u, 1u, 9u, 150u}) {
        const std::vector<GlintFlareLight> few(scene.lights.begin(), scene.lights.begin() + m);
        reference::Scene first = scene;
        first.lights = few;
        for (uint32_t capacity : {150u, std::max(1u, m / 4)}) {
          config.capacity = capacity;
          const std::string what = std::string(reversed ? "reversed" : "standard") + ", grid " +
                                   std::to_string(c.grid) + (c.pattern == OcclusionPattern::regular ? " regular" : "") +
                                   ", max_cell_px " + std::to_string(c.max_cell_px) + ", " + std::to_string(m) +
                                   " lights, capacity " + std::to_string(capacity);
          const auto a = run_cull(scene.depth, format, reversed, few, vp, config, c.max_cell_px, 1, 3,
                                  detail::LightCullPath::pyramid);
          const auto b = run_cull(scene.depth, format, reversed, few, vp, config, c.max_cell_px, 2, 3,
                                  detail::LightCullPath::depth);
          expect_same_bits(a, b, what);
          EXPECT_TRUE(b.canary_intact) << what;
          EXPECT_EQ(b.stats.total, m) << what;
          if (m > 0) expect_cull_matches(b, first, config, reversed, levels, what);
          if (m == 150u && capacity < 150u) {
            EXPECT_GT(b.stats.overflow, 0u) << what << ": no overflow";
          }
          if (m == 150u) {  // in workgroups of 32: 5 chunks of lights for the last one, on every device
            const auto d = run_cull(scene.depth, format, reversed, few, vp, config, c.max_cell_px, 2, 3,
                                    detail::LightCullPath::depth, 32);
            expect_same_bits(a, d, what + ", workgroups of 32");
          }
        }
      }
    }
  }
}

// The depth-image cull on the depth formats an engine passes (D24S8 most often; a flare frame of few
// lights takes this path by default): the depth aspect read straight from the caller's image, with
// the pyramid cull's bits, UNORM depth quantized for the reference as CullReadsEveryDepthFormat does.
TEST_F(OcclusionTest, DepthImageCullReadsEveryDepthFormat) {
  uint32_t stream = 951;
  int ran = 0;
  for (VkFormat format : {VK_FORMAT_D16_UNORM, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D24_UNORM_S8_UINT,
                          VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_D32_SFLOAT}) {
    if (!(detail::format_features(context(), format) & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) continue;
    ++ran;
    auto scene = reference::random_scene(201, 117, 100, stream++, false, 70);
    quantize_for_format(scene.depth, format);
    LightCullConfig config;
    config.capacity = 100;
    const FloatViewProj vp(scene.view_proj);
    const std::string what = detail::format_name(format);
    const auto a =
        run_cull(scene.depth, format, false, scene.lights, vp, config, 32, 1, 3, detail::LightCullPath::pyramid);
    const auto b =
        run_cull(scene.depth, format, false, scene.lights, vp, config, 32, 1, 3, detail::LightCullPath::depth);
    expect_same_bits(a, b, what);
    expect_cull_matches(b, scene, config, false, 5, what);
    EXPECT_GT(b.stats.occluded, 0u) << what;
    EXPECT_GT(b.stats.visible, 0u) << what;
  }
  EXPECT_GE(ran, 2) << "D16_UNORM and D32_SFLOAT are sampled by every device (Vulkan's required formats)";
}

// Layer 1 of a two-layer depth image (a stereo engine's second eye): the Hi-Z, the pyramid cull and
// the depth-image cull read that layer alone. Layer 0 holds depth 0, nearer than every light, so a
// read of it would occlude every light; the Hi-Z of layer 1 (D32) is also compared with its reference.
TEST_F(OcclusionTest, CullReadsOneLayerOfAnArrayDepthImage) {
  uint32_t stream = 971;
  int ran = 0;
  for (VkFormat format : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D24_UNORM_S8_UINT}) {
    if (!(detail::format_features(context(), format) & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) continue;
    ++ran;
    auto scene = reference::random_scene(201, 117, 100, stream++, false, 70);
    quantize_for_format(scene.depth, format);
    const VkExtent2D e{scene.depth.width, scene.depth.height};
    detail::OwnedImage img(
        context(), e, format,
        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 1, 2);
    Image layer0 = img.state, layer1 = img.state;
    layer1.view = img.layer_view(1);
    layer1.base_array_layer = 1;
    detail::upload_r32(context(), layer0, std::vector<float>(scene.depth.depth.size(), 0.0f));
    detail::upload_r32(context(), layer1, scene.depth.depth);
    LightCullConfig config;
    config.capacity = 100;
    const FloatViewProj vp(scene.view_proj);
    const std::string what = detail::format_name(format) + " layer 1";
    const auto a = run_cull(scene.depth, format, false, scene.lights, vp, config, 32, 1, 3,
                            detail::LightCullPath::pyramid, 0, &layer1);
    const auto b = run_cull(scene.depth, format, false, scene.lights, vp, config, 32, 1, 3,
                            detail::LightCullPath::depth, 0, &layer1);
    expect_same_bits(a, b, what);
    expect_cull_matches(b, scene, config, false, 5, what);
    EXPECT_GT(b.stats.visible, 0u) << what << ": layer 0 was read";
    if (format == VK_FORMAT_D32_SFLOAT) {  // bit for bit (UNORM reads may differ by an ulp: HiZDepthFormat)
      HiZConfig hc;
      hc.extent = e;
      hc.format = format;
      HiZPyramid hiz(context(), hc);
      poison_pyramid(hiz);
      context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, layer1); });
      expect_pyramid(read_pyramid(hiz), scene.depth, false, what);
    }
    // Layer 0 read back from the layout its Image says (TRANSFER_DST): had a barrier of the cull or
    // the Hi-Z moved layer 0 too, validation would report the layout mismatch and fail the test.
    const auto l0 = detail::download_r32(context(), layer0, 0, e, 1);
    EXPECT_TRUE(std::all_of(l0.begin(), l0.end(), [](float v) { return v == 0.0f; })) << what << ": layer 0 changed";
  }
  EXPECT_GE(ran, 1) << "D32_SFLOAT is sampled by every device";
}

// LightCuller::needs_pyramid: the depth image is read where the pyramid has at most 5 levels and
// the samples' windows (estimated as count x N^2 x 4^(levels + 1) pixels) hold no more than twice
// the image's pixels, for counts the one-workgroup cull takes; the pyramid otherwise (any count over
// a deeper pyramid, even none or one light at N = 1), and on the forced paths as they say.
TEST_F(OcclusionTest, CullReadsTheDepthImageOnlyWhereItsWindowsAreSmallerThanTheImage) {
  LightCullConfig config;  // N = 4
  LightCuller culler(context(), config);
  HiZConfig hc;
  hc.extent = {1920, 1080};
  hc.max_cell_px = 32;  // 5 levels, as LensFlarePass makes for lights of up to 128 px
  HiZPyramid capped(context(), hc);
  ASSERT_EQ(capped.levels(), 5u);
  // 63 x 16 x 4^6 = 4128768 <= 2 x 1920 x 1080 = 4147200 < 64 x 16 x 4^6.
  EXPECT_FALSE(culler.needs_pyramid(capped, 0));
  EXPECT_FALSE(culler.needs_pyramid(capped, 10));
  EXPECT_EQ(culler.needs_pyramid(capped, 63), 63u > culler.one_group_lights());
  EXPECT_TRUE(culler.needs_pyramid(capped, 64));
  hc.max_cell_px = 64;  // 6 levels: deeper than the depth-image cull takes
  HiZPyramid six(context(), hc);
  ASSERT_EQ(six.levels(), 6u);
  EXPECT_TRUE(culler.needs_pyramid(six, 0));
  EXPECT_TRUE(culler.needs_pyramid(six, 1));
  hc.max_cell_px = 0;  // 10 levels
  HiZPyramid full(context(), hc);
  EXPECT_TRUE(culler.needs_pyramid(full, 0));
  EXPECT_TRUE(culler.needs_pyramid(full, 1));
  LightCullConfig one_sample;  // N = 1 over a near-square image: 1 x 1 x 4^10 <= 2 x 1000 x 1000
  one_sample.grid = 1;
  LightCuller single(context(), one_sample);
  hc.extent = {1000, 1000};
  HiZPyramid square(context(), hc);
  ASSERT_EQ(square.levels(), 9u);
  EXPECT_TRUE(single.needs_pyramid(square, 1)) << "a few workgroups would read most of the image";
  detail::LightCullAccess::select_path(culler, detail::LightCullPath::pyramid);
  EXPECT_TRUE(culler.needs_pyramid(capped, 10));
  detail::LightCullAccess::select_path(culler, detail::LightCullPath::depth);
  EXPECT_FALSE(culler.needs_pyramid(full, 1000));
}

// The README's maximum: a million lights, all visible, with more workgroups in their dispatch
// arguments than one row of maxComputeWorkGroupCount[0] holds on lavapipe (65535): the scan writes
// rows, and the largest groups_per_instance the culler reports still fits.
TEST_F(OcclusionTest, AMillionVisibleLightsGiveDispatchArgumentsEveryDeviceAccepts) {
  const uint32_t n = 1000000;
  reference::DepthImage far{256, 256, std::vector<float>(256 * 256, 1.0f)};
  std::vector<GlintFlareLight> lights(n);
  for (uint32_t i = 0; i < n; ++i) {
    GlintFlareLight& l = lights[i];
    l = GlintFlareLight{};
    l.position_x = -0.9f + 1.8f * float(i % 1000) / 999.0f;  // NDC with an identity view_proj
    l.position_y = -0.9f + 1.8f * float(i / 1000) / 999.0f;
    l.position_z = 0.5f;
    l.intensity = l.color_r = l.color_g = l.color_b = 1.0f;
    l.size_px = 2.0f;
    l.enabled = 1;
  }
  const float vp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  LightCullConfig config;
  config.capacity = n;
  config.max_lights = n;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  const uint64_t max_x = props.limits.maxComputeWorkGroupCount[0], max_y = props.limits.maxComputeWorkGroupCount[1];
  const uint32_t most = LightCuller(context(), config).max_groups_per_instance();
  ASSERT_GE(most, 3u);
  for (uint32_t groups : {3u, most}) {
    const auto run = run_cull(far, VK_FORMAT_D32_SFLOAT, false, lights, vp, config, 0, 1, groups);
    const std::string what = "groups_per_instance " + std::to_string(groups);
    EXPECT_EQ(run.stats.total, n) << what;
    EXPECT_EQ(run.stats.visible, n) << what;
    EXPECT_EQ(run.indirect.instance_count, n) << what;
    ASSERT_EQ(run.instances.size(), n) << what;
    for (uint32_t i = 0; i < n; i += 9973) EXPECT_EQ(run.instances[i].light_index, i) << what;
    EXPECT_EQ(run.instances[n - 1].light_index, n - 1) << what;
    // G = n x groups workgroups as rows: x within the device's limit, y rows cover G, no spare row.
    const uint64_t g = uint64_t(n) * groups, x = run.indirect.group_count_x, y = run.indirect.group_count_y;
    EXPECT_EQ(x, std::min(g, max_x)) << what;
    EXPECT_LE(y, max_y) << what;
    EXPECT_GE(x * y, g) << what;
    EXPECT_LT((y - 1) * x, g) << what;
    EXPECT_EQ(run.indirect.group_count_z, 1u) << what;
  }
}

// one_group_lights() is min(W, 16384 / N^2) (W: the workgroup, 64 on CPU devices), and the count
// chooses the path by it: the commands the default path records are those of the one-workgroup
// path up to it and those of the four dispatches above it.
TEST_F(OcclusionTest, TheLightCountChoosesOneWorkgroupUpToOneGroupLights) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  const uint32_t w =
      context().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU
          ? 64u
          : std::min({1024u, props.limits.maxComputeWorkGroupInvocations, props.limits.maxComputeWorkGroupSize[0]});
  const auto scene = reference::random_scene(96, 64, 1100, 77, false, 30);
  const FloatViewProj vp(scene.view_proj);
  auto img = make_depth(scene.depth, VK_FORMAT_D32_SFLOAT);
  HiZConfig hc;
  hc.extent = {scene.depth.width, scene.depth.height};
  HiZPyramid hiz(context(), hc);
  HostBuffer lbuf(scene.lights.size() * sizeof(GlintFlareLight));
  std::memcpy(lbuf.owned.mapped(), scene.lights.data(), scene.lights.size() * sizeof(GlintFlareLight));
  lbuf.owned.flush();
  for (uint32_t grid : {1u, 4u, 9u, 16u}) {
    LightCullConfig config;
    config.grid = grid;
    config.capacity = 1100;
    LightCuller culler(context(), config);
    const uint32_t most = culler.one_group_lights();
    EXPECT_EQ(most, std::min(w, std::max(1u, 16384u / (grid * grid)))) << "N = " << grid;
    HostBuffer inst(config.capacity * sizeof(GlintFlareInstance)), indirect(sizeof(GlintFlareIndirect)),
        stats(sizeof(GlintFlareStats));
    LightCullOutputs out{inst.view, indirect.view, stats.view, {}};
    LightCullFrame frame;
    std::copy(vp.m, vp.m + 16, frame.view_proj);
    // Commands one record() makes (detail::recorded_commands(): barriers, dispatches, fills) with
    // `path`, measured on a culler's second record (the first clears the counters once).
    auto commands = [&](detail::LightCullPath path, uint32_t n) {
      LightCuller c(context(), config);
      detail::LightCullAccess::select_path(c, path);
      uint64_t made = 0;
      context().run_once([&](VkCommandBuffer cmd) {
        hiz.record(cmd, img.state);
        c.record(cmd, hiz, img.state, lbuf.view, n, frame, out);
        const uint64_t before = detail::recorded_commands();
        c.record(cmd, hiz, img.state, lbuf.view, n, frame, out);
        made = detail::recorded_commands() - before;
      });
      return made;
    };
    for (uint32_t n : {most, most + 1}) {
      if (n > scene.lights.size()) continue;
      const uint64_t one = commands(detail::LightCullPath::one_group, n);
      const uint64_t groups = commands(detail::LightCullPath::groups, n);
      ASSERT_LT(one, groups) << "one dispatch records fewer commands than four";
      EXPECT_EQ(commands(detail::LightCullPath::device, n), n <= most ? one : groups)
          << "N = " << grid << ", " << n << " lights";
    }
  }
}

TEST_F(OcclusionTest, ZeroLights) {
  reference::DepthImage d = random_depth(33, 17, 3);
  LightCullConfig config;
  config.capacity = 4;
  float vp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (detail::LightCullPath path : {detail::LightCullPath::groups, detail::LightCullPath::one_group}) {
    const auto run = run_cull(d, VK_FORMAT_D32_SFLOAT, false, {}, vp, config, 0, 1, 3, path);
    EXPECT_EQ(run.indirect.vertex_count, 6u);
    EXPECT_EQ(run.indirect.instance_count, 0u);
    EXPECT_EQ(run.indirect.group_count_x, 0u);
    EXPECT_EQ(run.indirect.group_count_y, 1u);
    EXPECT_EQ(run.stats.total, 0u);
    EXPECT_EQ(run.stats.visible, 0u);
    EXPECT_EQ(run.stats.frustum_culled + run.stats.occluded + run.stats.overflow + run.stats.disabled, 0u);
    EXPECT_TRUE(run.canary_intact);
  }
}

// Texel size (pixels) of the Hi-Z level a light of `size` pixels reads with an N x N grid:
// 2^ceil(log2(size / N)), 1 for cells of at most a pixel.
double texel_px(double size, uint32_t grid) {
  const double cell = size / grid;
  return cell <= 1.0 ? 1.0 : std::exp2(std::ceil(std::log2(cell)));
}

// How far (pixels) from its centre a light's windows reach: half the light, the border footprint's
// extension (< half a cell) and one texel, plus slack.
double reach_px(double size, uint32_t grid) { return size / 2 + size / grid / 2 + texel_px(size, grid) + 2.0; }

struct Fade {
  double max_step = 0.0;  // largest fall of the fraction between two consecutive positions
  bool monotone = true, starts_visible = true, ends_occluded = true, multiples = true;
};

Fade fade_of(const std::vector<GlintFlareLightResult>& results, size_t first, size_t count, uint32_t grid) {
  Fade f;
  const double n2 = double(grid) * grid;
  f.starts_visible = results[first].visible_fraction == 1.0f;
  f.ends_occluded = results[first + count - 1].culled == GLINT_FLARE_OCCLUDED;
  for (size_t i = first; i < first + count; ++i) {
    const double v = results[i].visible_fraction;
    f.multiples = f.multiples && std::fabs(v * n2 - std::round(v * n2)) < 1e-3;
    if (i == first) continue;
    const double prev = results[i - 1].visible_fraction;
    f.monotone = f.monotone && v <= prev;
    f.max_step = std::max(f.max_step, prev - v);
  }
  return f;
}

// One straight occluder edge, in a 640 x 640 tile of its own: near (0.2) on one side of the line
// along = 320 + slope * (across - 320), far (0.9) on the other; `along` is x (or y if along_y).
struct Track {
  bool along_y = false, occluder_after = true;
  double slope = 0.0;
};

// Lights of several sizes slide (in steps of at most 0.45 pixel and 0.9 times the sample spacing
// size / N^2) across fixed occluder edges, one tile per track, from fully visible to fully occluded;
// returns the fade of each (track, size), track-major. The light moves along x (or y).
std::vector<Fade> slide_light(uint32_t grid, OcclusionPattern pattern, const std::vector<Track>& tracks,
                              const std::vector<double>& sizes) {
  const uint32_t tile = 640;
  const auto w = static_cast<uint32_t>(tile * tracks.size());
  reference::DepthImage depth{w, tile, std::vector<float>(size_t(w) * tile)};
  std::vector<GlintFlareLight> lights;
  std::vector<size_t> first;
  for (size_t t = 0; t < tracks.size(); ++t) {
    const Track& tr = tracks[t];
    for (uint32_t y = 0; y < tile; ++y) {
      for (uint32_t x = 0; x < tile; ++x) {
        const double a = (tr.along_y ? y : x) + 0.5, c = (tr.along_y ? x : y) + 0.5;
        const bool after = a >= 320.0 + tr.slope * (c - 320.0);
        depth.depth[size_t(y) * w + t * tile + x] = after == tr.occluder_after ? 0.2f : 0.9f;
      }
    }
    for (double size : sizes) {
      const double reach = reach_px(size, grid) * (1.0 + std::fabs(tr.slope));
      const double step = std::min(0.45, 0.9 * size / (double(grid) * grid));
      const int steps = static_cast<int>(std::ceil(2.0 * reach / step));
      first.push_back(lights.size());
      for (int i = 0; i <= steps; ++i) {
        const double a = tr.occluder_after ? 320.0 - reach + i * step : 320.0 + reach - i * step;
        const double c = 320.37;
        GlintFlareLight l{};
        l.position_x = static_cast<float>((t * tile + (tr.along_y ? c : a)) / w * 2.0 - 1.0);
        l.position_y = static_cast<float>((tr.along_y ? a : c) / tile * 2.0 - 1.0);
        l.position_z = 0.5f;
        l.size_px = static_cast<float>(size);
        l.enabled = 1;
        lights.push_back(l);
      }
    }
  }
  first.push_back(lights.size());
  LightCullConfig config;
  config.grid = grid;
  config.pattern = pattern;
  config.capacity = static_cast<uint32_t>(lights.size());
  const float vp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const auto run = run_cull(depth, VK_FORMAT_D32_SFLOAT, false, lights, vp, config);
  std::vector<Fade> out;
  for (size_t i = 0; i + 1 < first.size(); ++i)
    out.push_back(fade_of(run.results, first[i], first[i + 1] - first[i], grid));
  return out;
}

const std::vector<double> kSlideSizes = {13.0, 48.0, 64.0, 97.0};

// docs/OCCLUSION.md, oblique edges with the light moving along x: a sample's verdict depends on its
// window's first (or last) texel column against a threshold B(u) set by one texel row u of the
// window, so samples of one row u flip one at a time (distinct x offsets), and samples flipping
// together have distinct thresholds. Bound, in samples: min(G, floor(|slope| (G - 1)) + 2) with
// G = floor((size + cell / 2) / T) + 2 texel rows.
double oblique_step_bound(double size, uint32_t grid, double slope) {
  const double t = texel_px(size, grid);
  const double rows = std::floor((size + size / grid / 2.0) / t) + 2.0;
  return std::min(rows, std::floor(std::fabs(slope) * (rows - 1.0)) + 2.0);
}

// The fraction must move in steps no larger than 1/(N x N) as an occluder edge slides
// (docs/OCCLUSION.md, "Monotone fading, and the size of the steps").
// A light slides across an axis-aligned edge (vertical and horizontal, occluder on either side):
// with multi-jittered samples every footprint edge is at its own offset (spacing size / N^2), so
// one sample flips at a time (docs/OCCLUSION.md). The regular grid flips a column of N cells at once
// and must fail the same check (that is what makes this test able to fail).
TEST_F(OcclusionTest, AxisAlignedEdgeMovesTheFractionOneSampleAtATime) {
  const std::vector<Track> all = {{false, false, 0.0}, {false, true, 0.0}, {true, false, 0.0}, {true, true, 0.0}};
  for (uint32_t grid : {2u, 4u, 8u, 16u}) {
    const double n2 = double(grid) * grid;
    for (OcclusionPattern pattern : {OcclusionPattern::multi_jittered, OcclusionPattern::regular}) {
      const bool regular = pattern == OcclusionPattern::regular;
      // The regular grid only has to show that the check can fail: one track, one size.
      const std::vector<Track> tracks = regular ? std::vector<Track>{all[1]} : all;
      const std::vector<double> sizes = regular ? std::vector<double>{48.0} : kSlideSizes;
      const auto fades = slide_light(grid, pattern, tracks, sizes);
      double worst = 0.0;
      for (size_t i = 0; i < fades.size(); ++i) {
        const Fade& f = fades[i];
        const Track& tr = tracks[i / sizes.size()];
        const std::string what = "N=" + std::to_string(grid) + (tr.along_y ? " y" : " x") +
                                 (tr.occluder_after ? " occluder after" : " occluder before") + " size " +
                                 std::to_string(sizes[i % sizes.size()]) + (regular ? " regular" : "");
        EXPECT_TRUE(f.starts_visible && f.ends_occluded) << what;
        EXPECT_TRUE(f.monotone) << what << ": the fraction rose";
        EXPECT_TRUE(f.multiples) << what << ": not a multiple of 1/N^2";
        if (!regular) {
          EXPECT_LE(f.max_step, 1.0 / n2 + 1e-6) << what;
        }
        worst = std::max(worst, f.max_step);
      }
      if (regular) {
        EXPECT_GT(worst, 1.0 / n2 + 1e-6) << "N=" << grid << ": the regular grid passed the 1/N^2 check";
      }
      std::printf("axis-aligned, light moving, N=%2u %-14s: largest step %.4f = %.2f / N^2\n", grid,
                  regular ? "regular" : "multi-jittered", worst, worst * n2);
    }
  }
}

// An oblique edge (light moving along x): monotone, and at most one sample flips per Hi-Z texel row
// that the sample windows' lower (upper) edges reach for a positive (negative) slope
// (docs/OCCLUSION.md), which the test checks; the measured steps are printed for the table.
TEST_F(OcclusionTest, ObliqueEdgeFadesMonotonicallyWithinTheStepBound) {
  const std::vector<Track> tracks = {{false, true, 0.37}, {false, false, -0.61}, {false, true, 1.0}};
  const std::vector<double> sizes = {13.0, 64.0, 97.0};
  for (uint32_t grid : {2u, 4u, 8u, 16u}) {
    const double n2 = double(grid) * grid;
    for (OcclusionPattern pattern : {OcclusionPattern::multi_jittered, OcclusionPattern::regular}) {
      const bool regular = pattern == OcclusionPattern::regular;
      if (regular && grid < 4) continue;
      const auto fades = slide_light(grid, pattern, tracks, sizes);
      double worst = 0.0;
      bool above_bound = false;
      for (size_t i = 0; i < fades.size(); ++i) {
        const Fade& f = fades[i];
        const Track& tr = tracks[i / sizes.size()];
        const double size = sizes[i % sizes.size()];
        const std::string what = "N=" + std::to_string(grid) + " slope " + std::to_string(tr.slope) +
                                 (tr.occluder_after ? " occluder after" : " occluder before") + " size " +
                                 std::to_string(size) + (regular ? " regular" : "");
        EXPECT_TRUE(f.starts_visible && f.ends_occluded) << what;
        EXPECT_TRUE(f.monotone) << what << ": the fraction rose";
        EXPECT_TRUE(f.multiples) << what;
        const double bound = oblique_step_bound(size, grid, tr.slope);
        if (!regular) {
          EXPECT_LE(f.max_step * n2, bound + 1e-3) << what;
        }
        above_bound = above_bound || f.max_step * n2 > bound + 1e-3;
        worst = std::max(worst, f.max_step);
      }
      // The bound rests on distinct sample offsets; the regular grid (N equal offsets per column)
      // breaks it from N = 4, which shows the check can fail.
      if (regular && grid >= 4) {
        EXPECT_TRUE(above_bound) << "N=" << grid << ": the regular grid kept the bound";
      }
      std::printf("oblique, light moving,      N=%2u %-14s: largest step %.4f = %.2f / N^2\n", grid,
                  regular ? "regular" : "multi-jittered", worst, worst * n2);
    }
  }
}

// The other frame: the light (and so its sample windows) stays fixed against the Hi-Z texels and
// the edge moves one pixel at a time. A test reading level k only changes when the edge crosses a
// level-k texel boundary, so steps of 1/N^2 cannot happen here (docs/OCCLUSION.md): the fade stays
// monotone and the step stays within the samples whose windows start in one texel column,
// (floor(N T / s) + 1) / N^2 <= 2/N. Each light sits in its own tile with its own edge position.
TEST_F(OcclusionTest, EdgeMovingOverAFixedLightStaysWithinTheTexelBound) {
  const double size = 24.0;
  for (uint32_t grid : {2u, 4u, 8u, 16u}) {
    const double n2 = double(grid) * grid;
    const double reach = reach_px(size, grid), texel = texel_px(size, grid);
    const int positions = 2 * static_cast<int>(std::ceil(reach)) + 1;
    // Tiles a whole number of texels wide: every light sits at the same place against the texels.
    const uint32_t tile = static_cast<uint32_t>(std::ceil((2.0 * reach + 8.0) / texel) * texel);
    const uint32_t per_row = static_cast<uint32_t>(std::ceil(std::sqrt(double(positions))));
    const uint32_t side = tile * per_row;
    reference::DepthImage d{side, side, std::vector<float>(size_t(side) * side)};
    std::vector<GlintFlareLight> lights;
    for (int q = 0; q < positions; ++q) {
      const uint32_t tx = (q % per_row) * tile, ty = (q / per_row) * tile;
      const double centre = tile / 2.0;
      const double edge = std::floor(centre - reach) + q;  // occluder at local x >= edge
      for (uint32_t y = ty; y < ty + tile; ++y) {
        for (uint32_t x = tx; x < tx + tile; ++x) d.depth[size_t(y) * side + x] = (x - tx + 0.5 >= edge) ? 0.2f : 0.9f;
      }
      GlintFlareLight l{};
      l.position_x = static_cast<float>((tx + centre + 0.37) / side * 2.0 - 1.0);
      l.position_y = static_cast<float>((ty + centre + 0.37) / side * 2.0 - 1.0);
      l.position_z = 0.5f;
      l.size_px = static_cast<float>(size);
      l.enabled = 1;
      lights.push_back(l);
    }
    for (OcclusionPattern pattern : {OcclusionPattern::multi_jittered, OcclusionPattern::regular}) {
      LightCullConfig config;
      config.grid = grid;
      config.pattern = pattern;
      config.capacity = static_cast<uint32_t>(lights.size());
      const float vp[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
      const auto run = run_cull(d, VK_FORMAT_D32_SFLOAT, false, lights, vp, config);
      // Edge from right of the light to left of it: the fraction falls as q grows... reversed: the
      // occluder covers x >= edge, so small q = mostly occluded. Read the sequence backwards.
      std::vector<GlintFlareLightResult> rev(run.results.rbegin(), run.results.rend());
      const Fade f = fade_of(rev, 0, rev.size(), grid);
      const std::string what = "N=" + std::to_string(grid) + (pattern == OcclusionPattern::regular ? " regular" : "");
      EXPECT_TRUE(f.starts_visible && f.ends_occluded && f.monotone && f.multiples) << what;
      // Windows starting in one texel column: multi-jittered offsets are distinct, size / N^2 apart;
      // the regular grid's are N equal ones per column of cells, a cell apart.
      const double cell = size / grid;
      const double bound = pattern == OcclusionPattern::regular ? (std::floor(texel / cell) + 1.0) * grid / n2
                                                                : (std::floor(grid * texel / cell) + 1.0) / n2;
      EXPECT_LE(f.max_step, bound + 1e-6) << what;
      std::printf("axis-aligned, edge moving,  N=%2u %-14s: largest step %.4f = %.2f / N^2 (bound %.2f / N^2)\n", grid,
                  pattern == OcclusionPattern::regular ? "regular" : "multi-jittered", f.max_step, f.max_step * n2,
                  bound * n2);
    }
  }
}

// Bad settings and arguments throw Error naming the field, before anything is recorded or made.
TEST_F(OcclusionTest, BadConfigAndArgumentsThrow) {
  HiZConfig hc;
  expect_error([&] { HiZPyramid(context(), hc); }, ErrorCode::invalid_argument, "HiZConfig::extent.width = 0");
  hc.extent = {16385, 4};
  expect_error([&] { HiZPyramid(context(), hc); }, ErrorCode::invalid_argument, "accepted 1 to 16384");
  hc.extent = {64, 64};
  hc.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  expect_error([&] { HiZPyramid(context(), hc); }, ErrorCode::unsupported_format, "HiZConfig::format");
  hc.format = VK_FORMAT_D32_SFLOAT;
  hc.max_cell_px = 20000;
  expect_error([&] { HiZPyramid(context(), hc); }, ErrorCode::invalid_argument, "HiZConfig::max_cell_px = 20000");
  hc.max_cell_px = 0;
  LightCullConfig cc;
  cc.grid = 17;
  expect_error([&] { LightCuller(context(), cc); }, ErrorCode::invalid_argument, "LightCullConfig::grid = 17");
  cc.grid = 0;
  expect_error([&] { LightCuller(context(), cc); }, ErrorCode::invalid_argument, "accepted 1 to 16");
  cc.grid = 4;
  cc.margin_ndc = std::nanf("");
  expect_error([&] { LightCuller(context(), cc); }, ErrorCode::invalid_argument, "LightCullConfig::margin_ndc");
  cc.margin_ndc = 1.2f;
  cc.capacity = 0;
  expect_error([&] { LightCuller(context(), cc); }, ErrorCode::invalid_argument, "LightCullConfig::capacity = 0");
  cc.capacity = 8;

  // Record-time errors: nothing may be recorded (the command buffer stays valid and empty of our
  // work) and no Vulkan object may be made.
  const auto d = random_depth(64, 64, 4);
  auto img = make_depth(d, VK_FORMAT_D32_SFLOAT);
  auto other = make_depth(random_depth(32, 64, 5), VK_FORMAT_D32_SFLOAT);
  HiZPyramid hiz(context(), hc);
  LightCuller culler(context(), cc);
  HostBuffer lights(10 * sizeof(GlintFlareLight)), inst(8 * sizeof(GlintFlareInstance)), small(8),
      indirect(sizeof(GlintFlareIndirect)), stats(sizeof(GlintFlareStats));
  Buffer no_indirect = indirect.view;
  no_indirect.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  LightCullFrame frame;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  LightCullConfig wide_config = cc;
  // The dispatch arguments are rows of maxComputeWorkGroupCount[0] groups, at most [1] rows, and
  // the group count must stay below 2^32 - [0]: a capacity just above that limit / 65535 cannot
  // take 65535 groups per instance.
  const uint64_t max_x = props.limits.maxComputeWorkGroupCount[0], max_y = props.limits.maxComputeWorkGroupCount[1];
  const uint64_t group_limit = std::min(max_x * max_y, (uint64_t(1) << 32) - max_x);
  wide_config.capacity = uint32_t(group_limit / 65535 + 1);
  LightCuller wide(context(), wide_config);
  HostBuffer wide_inst(size_t(wide_config.capacity) * sizeof(GlintFlareInstance));
  LightCullOutputs wide_out{wide_inst.view, indirect.view, stats.view, {}};
  const uint64_t objects = context().objects_created();
  context().run_once([&](VkCommandBuffer cmd) {
    expect_error([&] { hiz.record(cmd, other.state); }, ErrorCode::unsupported_size, "HiZConfig::extent is 64x64");
    LightCullOutputs out{inst.view, indirect.view, stats.view, {}};
    expect_error([&] { culler.record(cmd, hiz, other.state, lights.view, 10, frame, out); },
                 ErrorCode::invalid_argument, "does not match the Hi-Z pyramid");
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, 11, frame, out); }, ErrorCode::invalid_argument,
                 "lights buffer holds 480 bytes: accepted at least 528");
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, cc.max_lights + 1, frame, out); },
                 ErrorCode::invalid_argument, "count = 1048577");
    LightCullOutputs bad = out;
    bad.indirect = no_indirect;
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, 10, frame, bad); }, ErrorCode::missing_usage,
                 "indirect buffer lacks usage VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT");
    bad = out;
    bad.instances = small.view;
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, 10, frame, bad); }, ErrorCode::invalid_argument,
                 "instances buffer holds 8 bytes: accepted at least 384");
    bad = out;
    bad.stats = {};
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, 10, frame, bad); }, ErrorCode::invalid_argument,
                 "stats buffer is null");
    LightCullFrame big = frame;
    big.groups_per_instance = 65535;
    ASSERT_EQ(wide.max_groups_per_instance(), uint32_t(group_limit / wide_config.capacity));
    ASSERT_LT(wide.max_groups_per_instance(), 65535u);
    expect_error([&] { wide.record(cmd, hiz, img.state, lights.view, 10, big, wide_out); }, ErrorCode::invalid_argument,
                 "maxComputeWorkGroupCount");
    LightCullFrame nan = frame;
    nan.view_proj[5] = std::nanf("");
    expect_error([&] { culler.record(cmd, hiz, img.state, lights.view, 10, nan, out); }, ErrorCode::invalid_argument,
                 "view_proj[5]");
  });
  EXPECT_EQ(context().objects_created(), objects);
  EXPECT_EQ(img.state.layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL) << "a failed record changed the depth state";
}

// Recording a second frame with the same resources makes no Vulkan object.
TEST_F(OcclusionTest, SecondFrameCreatesNoObjects) {
  for (detail::LightCullPath path : {detail::LightCullPath::groups, detail::LightCullPath::one_group}) {
    const auto scene = reference::random_scene(120, 80, 50, 8, false, 30);
    auto img = make_depth(scene.depth, VK_FORMAT_D32_SFLOAT);
    HiZConfig hc;
    hc.extent = {120, 80};
    HiZPyramid hiz(context(), hc);
    LightCuller culler(context(), {});
    detail::LightCullAccess::select_path(culler, path);
    HostBuffer lights(50 * sizeof(GlintFlareLight)), inst(1024 * sizeof(GlintFlareInstance)),
        indirect(sizeof(GlintFlareIndirect)), stats(sizeof(GlintFlareStats)), results(50 * 8);
    std::memcpy(lights.owned.mapped(), scene.lights.data(), 50 * sizeof(GlintFlareLight));
    LightCullOutputs out{inst.view, indirect.view, stats.view, results.view};
    LightCullFrame frame;
    for (int i = 0; i < 16; ++i) frame.view_proj[i] = static_cast<float>(scene.view_proj[i]);
    auto record = [&] {
      context().run_once([&](VkCommandBuffer cmd) {
        hiz.record(cmd, img.state);
        culler.record(cmd, hiz, img.state, lights.view, 50, frame, out);
      });
    };
    record();
    const uint64_t objects = context().objects_created();
    record();
    record();
    EXPECT_EQ(context().objects_created(), objects)
        << (path == detail::LightCullPath::one_group ? "one workgroup" : "four dispatches");
  }
}

}  // namespace
}  // namespace glint::test
