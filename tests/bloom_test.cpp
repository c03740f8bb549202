// Bloom on the GPU (lavapipe in CI) against the float64 reference, and the properties
// docs/BLOOM.md promises, measured on real GPU output. Validation with synchronization validation is on for
// every test (support/gpu_test.h fails a test on any message).
#include <glint/bloom.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "bloom/bloom_internal.h"
#include "core/half.h"
#include "core/pipeline.h"
#include "reference/bloom_reference.h"
#include "support/effects.h"
#include "support/environment.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;

class BloomTest : public GpuTest {};

// Relative L2 error of the light a bloom added (output - input, R, G and B) against the
// reference's; `norm` receives the reference's squared norm (0 would make the ratio meaningless).
double added_light_rel_l2(const CpuImage& gpu, const reference::DoubleImage& ref, const CpuImage& input, double& norm) {
  double diff = 0.0;
  norm = 0.0;
  for (size_t i = 0; i < gpu.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const double want = ref.rgba[i] - input.rgba[i], got = double(gpu.rgba[i]) - input.rgba[i];
    diff += (got - want) * (got - want);
    norm += want * want;
  }
  return std::sqrt(diff / norm);
}

// added_light_rel_l2() of a bloom's output `gpu` of `input` against the float64 reference of
// `config`; unwritten (poisoned, non-finite) texels or a reference that adds no light give +Inf,
// so the caller's bound fails.
double added_light_error(const CpuImage& gpu, const CpuImage& input, const BloomConfig& config) {
  if (!all_finite(gpu)) return std::numeric_limits<double>::infinity();
  double norm = 0.0;
  const double err = added_light_rel_l2(gpu, reference::bloom(input, config), input, norm);
  return norm > 0.0 ? err : std::numeric_limits<double>::infinity();
}

// The configuration the added-light comparisons use: `filter`, fp32 levels (fp32 arithmetic end
// to end, so a 1e-3 bound), 3 iterations, intensity 1; the default guard.
BloomConfig added_light_config(BloomFilter filter) {
  BloomConfig config;
  config.filter = filter;
  config.precision = Precision::fp32;
  config.iterations = 3;
  config.intensity = 1.0f;
  return config;
}

// Runs one bloom of `input` and reads the output back. The output starts poisoned with NaN.
CpuImage run_bloom(Bloom& bloom, const CpuImage& input, VkFormat in_format, VkFormat out_format,
                   Profiler* profiler = nullptr) {
  auto in = make_image(input, in_format);
  auto out = make_poisoned({input.width, input.height}, out_format);
  context().run_once([&](VkCommandBuffer cmd) {
    if (profiler) {
      profiler->reset(cmd);
      profiler->mark(cmd, "start");
    }
    bloom.record(cmd, in.state, out.state, profiler);
  });
  return detail::download(context(), out.state);
}

CpuImage run_bloom(const BloomConfig& config, const CpuImage& input, VkFormat in_format = kF32,
                   VkFormat out_format = kF32) {
  Bloom bloom(context(), config);
  return run_bloom(bloom, input, in_format, out_format);
}

constexpr BloomFilter kFilters[] = {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9};

// Light the bloom added: out - in, summed over RGB, per pixel.
std::vector<double> added_light(const CpuImage& out, const CpuImage& in) {
  std::vector<double> added(size_t(in.width) * in.height);
  for (uint32_t y = 0; y < in.height; ++y)
    for (uint32_t x = 0; x < in.width; ++x) {
      double s = 0;
      for (int c = 0; c < 3; ++c) s += double(out.at(x, y)[c]) - double(in.at(x, y)[c]);
      added[size_t(y) * in.width + x] = s;
    }
  return added;
}

struct Moments {
  double energy = 0, xx = 0, yy = 0;
};
// Second moments of the added light about a centre (cx, cy), excluding the source pixel itself.
Moments moments(const std::vector<double>& added, uint32_t w, uint32_t h, double cx, double cy) {
  Moments m;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const double a = added[size_t(y) * w + x];
      m.energy += a;
      m.xx += a * (x - cx) * (x - cx);
      m.yy += a * (y - cy) * (y - cy);
    }
  m.xx /= m.energy;
  m.yy /= m.energy;
  return m;
}

CpuImage point_source(uint32_t w, uint32_t h, uint32_t px, uint32_t py, float value, float background = 0.05f) {
  CpuImage img(w, h, background);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) img.at(x, y)[3] = 1.0f;
  for (int c = 0; c < 3; ++c) img.at(px, py)[c] = value;
  return img;
}

TEST_F(BloomTest, MipChainOf1080pHalvesDownTo60x33) {
  auto chain = bloom_mip_chain({1920, 1080}, 5);
  const std::vector<std::pair<uint32_t, uint32_t>> expected = {{960, 540}, {480, 270}, {240, 135}, {120, 67}, {60, 33}};
  ASSERT_EQ(chain.size(), expected.size());
  for (size_t i = 0; i < chain.size(); ++i) {
    EXPECT_EQ(chain[i].width, expected[i].first) << "level " << i;
    EXPECT_EQ(chain[i].height, expected[i].second) << "level " << i;
  }
  Bloom bloom(context());
  bloom.prepare({1920, 1080});
  EXPECT_EQ(bloom.levels(), 5u);
  EXPECT_FALSE(bloom.clamped());
}

TEST_F(BloomTest, IterationsAreClampedAtSmallSizesAndReported) {
  struct Case {
    VkExtent2D size;
    uint32_t iterations, levels;
    bool clamped;
  };
  const Case cases[] = {{{64, 64}, 5, 5, false}, {{64, 64}, 8, 5, true},  {{3, 5}, 5, 1, true},    {{1, 1}, 5, 1, true},
                        {{1, 1}, 1, 1, false},   {{4097, 3}, 8, 1, true}, {{320, 240}, 8, 6, true}};
  for (const Case& c : cases) {
    BloomConfig config;
    config.iterations = c.iterations;
    Bloom bloom(context(), config);
    bloom.prepare(c.size);
    EXPECT_EQ(bloom.levels(), c.levels) << c.size.width << "x" << c.size.height;
    EXPECT_EQ(bloom.clamped(), c.clamped) << c.size.width << "x" << c.size.height;
    if (bloom.levels() > 1) {
      for (const LevelSize& l : bloom.level_sizes()) EXPECT_GE(std::min(l.width, l.height), 2u);
    }
  }
}

// Every filter and precision against the float64 reference on random HDR input at an odd size.
// Tolerances: fp32 intermediates 1e-3 relative L2 (fp32 arithmetic lands far below);
// fp16 5e-3 (each fp16 store rounds by up to 2^-11 relative, and the chain stores ~2N times).
TEST_F(BloomTest, MatchesReferenceForEveryFilterAndPrecision) {
  const CpuImage input = random_hdr(97, 61, 7);
  for (BloomFilter filter : kFilters) {
    for (Precision precision : {Precision::fp32, Precision::fp16}) {
      for (VkFormat format : {kF32, kF16}) {
        BloomConfig config;
        config.filter = filter;
        config.precision = precision;
        config.iterations = 4;
        config.radius = 1.3f;
        config.intensity = 0.8f;
        const CpuImage gpu = run_bloom(config, input, format, format);
        ASSERT_TRUE(all_finite(gpu)) << "unwritten (poisoned) texels remain";
        const auto ref = reference::bloom(as_stored(input, format), config);
        const double err = reference::relative_l2(gpu, ref);
        const double tol = (precision == Precision::fp32 && format == kF32) ? 1e-3 : 5e-3;
        EXPECT_LT(err, tol) << bloom_filter_name(filter) << (precision == Precision::fp16 ? " fp16" : " fp32")
                            << (format == kF16 ? " RGBA16F io" : " RGBA32F io");
        // Alpha passes through untouched.
        const CpuImage stored = as_stored(input, format);
        for (size_t i = 3; i < gpu.rgba.size(); i += 4) ASSERT_EQ(gpu.rgba[i], stored.rgba[i]);
      }
    }
  }
}

// Every firefly guard, with and without level0_height (pre-levels, a last step of ratio 1 to 2,
// odd sizes, a level 0 as tall as the input), against the float64 reference. Compared on the light
// added (out - in) so the scene cannot hide an error; fp32 levels, tolerance 1e-3 as above.
TEST_F(BloomTest, MatchesReferenceForEveryGuardAndLevel0Height) {
  struct Case {
    uint32_t w, h, level0_height;
  };
  const Case cases[] = {{97, 61, 0}, {200, 150, 40}, {61, 97, 30}, {40, 30, 24}, {17, 9, 8}, {33, 20, 64}};
  for (BloomFilter filter : kFilters) {
    for (FireflyGuard guard : {FireflyGuard::off, FireflyGuard::karis, FireflyGuard::karis_smooth}) {
      BloomConfig config = added_light_config(filter);
      config.firefly_guard = guard;
      Bloom bloom(context(), config);  // one effect: set_config re-makes only the pyramid
      for (const Case& c : cases) {
        config.level0_height = c.level0_height;
        bloom.set_config(config);
        const CpuImage input = random_hdr(c.w, c.h, c.w * 7 + c.h);
        EXPECT_LT(added_light_error(run_bloom(bloom, input, kF32, kF32), input, config), 1e-3)
            << bloom_filter_name(filter) << " guard " << firefly_guard_name(guard) << " " << c.w << "x" << c.h
            << " level0_height " << c.level0_height;
      }
    }
  }
}

// Where an image is exactly twice the level it upsamples on both axes, cod13 and gauss9 upsample
// and composite through bloom_up_2x.comp and bloom_composite_2x.comp (one invocation per 2x2
// block, the upsample's weights formed per offset, offsets -S .. S with S = floor(r + 1/4) + 1
// taken from the radius at run time; 96x64 has three 2:1 steps, 100x70 the composite and none of
// the upsample steps). Every radius
// that changes S (0.25 to 4), set per frame on one effect (set_config makes no pipeline for a
// radius), against the float64 reference on the light added: an even size whose blocks fill the
// workgroups and one whose last row and column of workgroups are partial. fp32 levels and I/O: 1e-3
// as above. Both store orders of those kernels (COPY_ORDER: through shared memory in copy order,
// what GPUs run, and each block's own outputs, what CPU devices run) on this device, agreeing to
// 2^-20 of each value: the same arithmetic per output, but the two specializations are compiled
// apart, and SPIR-V lets a compiler contract a multiply-add into an FMA in one and not the other
// (a texel placed wrongly differs by far more).
TEST_F(BloomTest, TwoToOneUpsampleAndCompositeMatchReferenceAtEveryRadius) {
  using Order = detail::BloomPath::CopyOrder;
  for (BloomFilter filter : {BloomFilter::cod13, BloomFilter::gauss9}) {
    BloomConfig config = added_light_config(filter);
    Bloom on(context(), config), off(context(), config);
    detail::BloomPath path;
    path.copy_order_2x = Order::on;
    detail::BloomAccess::set_path(on, path);
    path.copy_order_2x = Order::off;
    detail::BloomAccess::set_path(off, path);
    for (VkExtent2D size : {VkExtent2D{96, 64}, VkExtent2D{100, 70}}) {
      const CpuImage input = random_hdr(size.width, size.height, size.width + 3 * size.height);
      for (float radius : {0.25f, 0.8f, 1.0f, 1.3f, 2.5f, 3.75f, 4.0f}) {
        config.radius = radius;
        on.set_config(config);
        off.set_config(config);
        const CpuImage a = run_bloom(on, input, kF32, kF32), b = run_bloom(off, input, kF32, kF32);
        const std::string what = std::string(bloom_filter_name(filter)) + " " + std::to_string(size.width) + "x" +
                                 std::to_string(size.height) + " radius " + std::to_string(radius);
        EXPECT_LT(added_light_error(a, input, config), 1e-3) << what << ", copy order";
        EXPECT_LT(added_light_error(b, input, config), 1e-3) << what << ", block order";
        ASSERT_EQ(a.rgba.size(), b.rgba.size());
        size_t differ = 0;
        for (size_t i = 0; i < a.rgba.size(); ++i)
          differ += !(std::abs(a.rgba[i] - b.rgba[i]) <= 0x1p-20f * std::max(1.0f, std::abs(a.rgba[i])));
        EXPECT_EQ(differ, 0u) << what << ": values where the two store orders differ";
      }
    }
  }
}

// The kernels after the first stage in other workgroup shapes (BloomPath's down_workgroup,
// up_workgroup and composite_workgroup, which the benchmarks compare per device): every output
// is computed by the same expression from the same texels whatever the tile, so the images agree
// to the rounding that the compiler's choice of FMA contraction may change (SPIR-V lets it fuse
// a multiply and an add in one pipeline and not in another): 2^-20 relative, a few fp32 ulps.
// Sizes with 2:1 steps throughout (96x64) and with odd levels (100x70: the tiled bloom_up where a
// level is not twice the next), each with the 2:1 upsample and composite kernels where they apply
// and with the tiled ones everywhere (BloomPath's composite_2x and up_2x off); a wide and a tall
// shape (32x4, 4x32: within the 32 KiB of shared memory that lavapipe has), 3x5 (partial tiles
// everywhere) and one no device can run.
TEST_F(BloomTest, LaterKernelsInOtherWorkgroupShapesGiveTheSameImage) {
  for (BloomFilter filter : {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9}) {
    const BloomConfig config = added_light_config(filter);
    Bloom base(context(), config), other(context(), config);
    for (bool tiled : {false, true}) {
      for (detail::Workgroup2D g :
           {detail::Workgroup2D{32, 4}, detail::Workgroup2D{4, 32}, detail::Workgroup2D{3, 5}}) {
        detail::BloomPath path;
        path.composite_2x = path.up_2x = !tiled;
        detail::BloomAccess::set_path(base, path);
        path.down_workgroup = path.up_workgroup = path.composite_workgroup = g;
        detail::BloomAccess::set_path(other, path);
        for (VkExtent2D size : {VkExtent2D{96, 64}, VkExtent2D{100, 70}}) {
          const CpuImage input = random_hdr(size.width, size.height, size.width + 7 * size.height);
          const CpuImage a = run_bloom(base, input, kF32, kF32), b = run_bloom(other, input, kF32, kF32);
          const std::string what = std::string(bloom_filter_name(filter)) + " " + std::to_string(size.width) + "x" +
                                   std::to_string(size.height) + " in " + std::to_string(g.x) + "x" +
                                   std::to_string(g.y) + (tiled ? ", tiled kernels" : "");
          ASSERT_EQ(a.rgba.size(), b.rgba.size());
          size_t differ = 0;
          for (size_t i = 0; i < a.rgba.size(); ++i)
            differ += !(std::abs(a.rgba[i] - b.rgba[i]) <= 0x1p-20f * std::max(1.0f, std::abs(a.rgba[i])));
          EXPECT_EQ(differ, 0u) << what << ": values where the shapes differ";
          EXPECT_LT(added_light_error(b, input, config), 1e-3) << what;
        }
      }
    }
  }
  Bloom bloom(context(), added_light_config(BloomFilter::cod13));
  detail::BloomPath path;
  path.up_workgroup = {64, 64};
  try {
    detail::BloomAccess::set_path(bloom, path);
    ADD_FAILURE() << "a 64x64 upsample workgroup was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("BloomPath::up_workgroup = 64x64"), std::string::npos) << e.what();
  }
}

// The karis_smooth first step at an exact 2:1 reduction with cod13 and dual runs its own kernel
// on GPUs and wherever ContextOptions::workgroup_2d is set (src/bloom/shaders/bloom_prefilter_boxes.comp:
// the box means of the binomially filtered source as one 12-tap binomial pass per axis, a
// workgroup of W x H making W x 2H texels). Against the float64 reference on the light added, on
// contexts with forced workgroups (8x8 and 3x5: tiles of 8x16 and 3x10, within
// lavapipe's 32 KiB of shared memory for every bloom kernel) and on this program's context (the
// general kernel on lavapipe): interior tiles, partial tiles at the right and bottom, and levels
// of 2 and 3 texels whose tiles touch both edges of an axis (the 11-tap edge case on both sides).
// fp32 levels and I/O: 1e-3 as above (fp32 arithmetic).
TEST_F(BloomTest, SmoothBoxesFirstStepMatchesReference) {
  const VkExtent2D sizes[] = {{160, 96}, {134, 70}, {6, 4}, {4, 10}};
  std::vector<std::unique_ptr<Context>> forced;
  for (VkExtent2D wg : {VkExtent2D{8, 8}, VkExtent2D{3, 5}}) {
    ContextOptions options;
    options.validation = true;
    options = tools::context_options_from_environment(options);
    options.workgroup_2d = wg;
    forced.push_back(std::make_unique<Context>(Context::create(options)));
  }
  std::vector<const Context*> contexts{&context()};
  for (const auto& c : forced) contexts.push_back(c.get());
  for (const Context* ctx : contexts) {
    for (BloomFilter filter : {BloomFilter::cod13, BloomFilter::dual}) {
      const BloomConfig config = added_light_config(filter);
      ASSERT_EQ(config.firefly_guard, FireflyGuard::karis_smooth);
      Bloom bloom(*ctx, config);
      for (VkExtent2D size : sizes) {
        const CpuImage input = random_hdr(size.width, size.height, size.width * 3 + size.height, 0.05f);
        detail::OwnedImage in(*ctx, size, kF32, detail::kToolImageUsage);
        detail::OwnedImage out(*ctx, size, kF32, detail::kToolImageUsage);
        detail::upload(*ctx, in.state, input);
        detail::fill(*ctx, out.state, std::nanf(""));
        ctx->run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
        const detail::Workgroup2D g = detail::choose_workgroup_2d(*ctx);
        EXPECT_LT(added_light_error(detail::download(*ctx, out.state), input, config), 1e-3)
            << bloom_filter_name(filter) << " " << size.width << "x" << size.height << " workgroup " << g.x << "x"
            << g.y;
      }
    }
    if (ctx != &context()) {  // the fixture checks the program's context
      std::string log;
      for (const std::string& m : ctx->validation_log()) log += m + "\n";
      EXPECT_EQ(ctx->validation_messages(), 0u) << log;
    }
  }
}

// level0_height sizes (docs/BLOOM.md "Mip chain"): the same level 0 from 720p, 1080p and 2160p.
TEST(BloomMipChain, Level0HeightStepsToTheSameLevel0) {
  struct Case {
    VkExtent2D in;
    uint32_t level0_height;
    std::vector<std::pair<uint32_t, uint32_t>> pre, chain;
  };
  const std::vector<Case> cases = {
      {{1280, 720}, 540, {}, {{960, 540}, {480, 270}, {240, 135}}},
      {{1920, 1080}, 540, {}, {{960, 540}, {480, 270}, {240, 135}}},
      {{3840, 2160}, 540, {{1920, 1080}}, {{960, 540}, {480, 270}, {240, 135}}},
      {{7680, 4320}, 540, {{3840, 2160}, {1920, 1080}}, {{960, 540}, {480, 270}, {240, 135}}},
      {{1, 4097}, 540, {{1, 2048}, {1, 1024}}, {{1, 540}}},
      {{640, 360}, 540, {}, {{640, 360}, {320, 180}, {160, 90}}},  // level 0 at most the input
      {{1923, 1081}, 540, {}, {{961, 540}, {480, 270}, {240, 135}}},
      {{1920, 1080}, 0, {}, {{960, 540}, {480, 270}, {240, 135}}},
  };
  for (const Case& c : cases) {
    std::vector<std::pair<uint32_t, uint32_t>> pre, chain;
    for (const LevelSize& l : bloom_pre_levels(c.in, c.level0_height)) pre.emplace_back(l.width, l.height);
    for (const LevelSize& l : bloom_mip_chain(c.in, 3, c.level0_height)) chain.emplace_back(l.width, l.height);
    EXPECT_EQ(pre, c.pre) << c.in.width << "x" << c.in.height;
    EXPECT_EQ(chain, c.chain) << c.in.width << "x" << c.in.height;
  }
}

// The error must come from the bloom, not be hidden by it: a wrong threshold is caught.
TEST_F(BloomTest, ReferenceComparisonDetectsAWrongParameter) {
  const CpuImage input = random_hdr(64, 48, 11, 0.05f);
  BloomConfig config;
  config.intensity = 1.0f;
  const CpuImage gpu = run_bloom(config, input);
  BloomConfig other = config;
  other.threshold = 1.2f;
  EXPECT_GT(reference::relative_l2(gpu, reference::bloom(input, other)), 1e-3);
  EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, config)), 1e-3);
}

// The fused dispatches (docs/BLOOM.md "Dispatches": the small levels in one workgroup, the last
// upsample inside the composite) against one dispatch per level, every filter, both level
// precisions, on random input at sizes where the small-levels dispatch starts at level 0, at a
// later level, not at all (one level), and with level0_height's pre-levels.
// Tolerance: the two paths run the same filters, weights, maps and clamps; the fused path skips
// the stores of the levels it keeps in shared memory (fp32) and of A(0). With fp32 levels the
// paths differ by fp32 rounding only (the same sums in another order: each of the at most 2 x 8
// filter stages adds a relative error of a few 2^-24), far below 1e-5. With fp16 levels each
// skipped store is a rounding of relative size at most 2^-10 (2^-11 when rounding to nearest;
// some devices truncate), and since every stage is a positive-weight mean or a sum of positive
// terms a relative error is carried, never amplified: the added light differs by at most
// r 2^-10 relative, r the skipped stores on the longest path (2 per level of the small-levels
// dispatch, 4 with gauss9's two blur passes, plus A(0)). A missing or misplaced level changes
// the bloom by a fraction of the order of 1 / levels, far above both.
TEST_F(BloomTest, FusedDispatchesMatchOneDispatchPerLevel) {
  struct Case {
    uint32_t w, h, iterations, level0_height;
    float radius;  // up to 1 and above: the small-levels kernel has a cod13 path for radius <= 1
  };
  const Case cases[] = {{97, 61, 4, 0, 1.3f},    {300, 200, 5, 0, 1.0f}, {640, 480, 5, 0, 0.6f}, {961, 541, 5, 0, 1.3f},
                        {200, 150, 4, 40, 1.0f}, {2, 2, 5, 0, 1.0f},     {7, 3, 5, 0, 1.3f}};
  const uint32_t capacity_texels = std::min(context().info().max_shared_memory_bytes, 65536u) / 12;
  const detail::BloomPath paths[] = {{true, true}, {true, false}, {false, true}};
  bool top_zero = false, top_later = false, top_none = false;
  for (BloomFilter filter : kFilters) {
    for (Precision precision : {Precision::fp32, Precision::fp16}) {
      BloomConfig config;
      config.filter = filter;
      config.precision = precision;
      config.intensity = 1.0f;
      Bloom fused(context(), config), per_level(context(), config);
      detail::BloomAccess::set_path(per_level, {false, false});
      for (const Case& c : cases) {
        config.iterations = c.iterations;
        config.level0_height = c.level0_height;
        config.radius = c.radius;
        fused.set_config(config);
        per_level.set_config(config);
        const CpuImage input = random_hdr(c.w, c.h, c.w + 3 * c.h);
        const CpuImage want = run_bloom(per_level, input, kF32, kF32);
        const std::vector<LevelSize> chain = per_level.level_sizes();
        const size_t n = chain.size();
        // The small-levels dispatch starts at the first level whose levels below fit its shared memory.
        int expected_top = -1;
        for (size_t t = 0; t + 1 < n && expected_top < 0; ++t) {
          uint64_t texels = 0;
          for (size_t k = t + 1; k < n; ++k) texels += uint64_t(chain[k].width) * chain[k].height;
          if (filter == BloomFilter::gauss9) texels += uint64_t(chain[t + 1].width) * chain[t + 1].height;
          if (texels <= capacity_texels) expected_top = static_cast<int>(t);
        }
        for (const detail::BloomPath& path : paths) {
          detail::BloomAccess::set_path(fused, path);
          const CpuImage got = run_bloom(fused, input, kF32, kF32);
          const int top = detail::BloomAccess::small_levels_top(fused);
          EXPECT_EQ(top, path.fuse_small_levels ? expected_top : -1) << c.w << "x" << c.h;
          top_zero |= top == 0;
          top_later |= top > 0;
          top_none |= path.fuse_small_levels && top < 0;
          ASSERT_TRUE(all_finite(got)) << "unwritten (poisoned) texels remain";
          double skipped = path.fuse_last_up ? 1.0 : 0.0;
          if (top >= 0) skipped += double(n - 1 - size_t(top)) * (filter == BloomFilter::gauss9 ? 4.0 : 2.0);
          const double tol = precision == Precision::fp32 ? 1e-5 : std::max(skipped, 1.0) * std::ldexp(1.0, -10);
          double diff = 0.0, norm = 0.0;
          for (size_t i = 0; i < got.rgba.size(); ++i) {
            if (i % 4 == 3) {
              ASSERT_EQ(got.rgba[i], input.rgba[i]);
              continue;
            }
            const double a = double(want.rgba[i]) - input.rgba[i], b = double(got.rgba[i]) - input.rgba[i];
            diff += (b - a) * (b - a);
            norm += a * a;
          }
          ASSERT_GT(norm, 0.0);
          EXPECT_LT(std::sqrt(diff / norm), tol)
              << bloom_filter_name(filter) << (precision == Precision::fp16 ? " fp16" : " fp32") << " " << c.w << "x"
              << c.h << " radius " << c.radius << " level0_height " << c.level0_height << " small levels "
              << path.fuse_small_levels << " last up " << path.fuse_last_up << " top " << top;
        }
      }
    }
  }
  EXPECT_TRUE(top_zero && top_later && top_none) << "the cases must start the small levels at 0, later, and not at all";
}

TEST_F(BloomTest, AllSizesWorkAndMatchTheReference) {
  const VkExtent2D sizes[] = {{320, 240}, {640, 480}, {1280, 720}, {1920, 1080}, {64, 64},
                              {3, 5},     {1, 1},     {1, 9},      {9, 1}};
  Bloom bloom(context());  // one object, resized each time
  for (VkExtent2D s : sizes) {
    const CpuImage input = random_hdr(s.width, s.height, s.width * 31 + s.height, 0.01f);
    const CpuImage gpu = run_bloom(bloom, input, kF16, kF16);
    ASSERT_TRUE(all_finite(gpu)) << s.width << "x" << s.height;
    const double err = reference::relative_l2(gpu, reference::bloom(as_stored(input, kF16), bloom.config()));
    EXPECT_LT(err, 5e-3) << s.width << "x" << s.height;
  }
}

TEST_F(BloomTest, ZeroIntensityCopiesBitForBit) {
  const CpuImage input = random_hdr(33, 17, 3);
  BloomConfig config;
  config.intensity = 0.0f;
  for (VkFormat format : {kF16, kF32}) {
    const CpuImage stored = as_stored(input, format);
    const CpuImage gpu = run_bloom(config, input, format, format);
    ASSERT_EQ(0, std::memcmp(gpu.rgba.data(), stored.rgba.data(), stored.rgba.size() * 4));
  }
  // In place with intensity 0 records nothing: the image is unchanged and keeps its state.
  auto img = make_image(input, kF32);
  const Image before = img.state;
  Bloom bloom(context(), config);
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, img.state, img.state); });
  EXPECT_EQ(img.state.layout, before.layout);
  const CpuImage after = detail::download(context(), img.state);
  EXPECT_EQ(0, std::memcmp(after.rgba.data(), input.rgba.data(), input.rgba.size() * 4));
}

TEST_F(BloomTest, DimPixelsFarFromBrightOnesAreUnchanged) {
  // Random dim background (luma < threshold - knee = 0.5) and one bright pixel near a corner.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> dim(0.0f, 0.45f);
  CpuImage input(720, 480);
  for (float& v : input.rgba) v = dim(rng);
  for (int c = 0; c < 3; ++c) input.at(10, 10)[c] = 500.0f;
  for (BloomFilter filter : kFilters) {
    BloomConfig config;
    config.filter = filter;
    const CpuImage gpu = run_bloom(config, input);
    // Footprint of the taps of docs/BLOOM.md (the karis_smooth prefilter, every downsample and
    // upsample), derived in support/effects.cpp (over 400 px for gauss9 here).
    const uint32_t reach = 10 + bloom_footprint_px({input.width, input.height}, config);
    ASSERT_LT(reach, input.height) << bloom_filter_name(filter);
    size_t changed_far = 0, changed_near = 0;
    for (uint32_t y = 0; y < input.height; ++y)
      for (uint32_t x = 0; x < input.width; ++x) {
        const bool differs = std::memcmp(gpu.at(x, y), input.at(x, y), 16) != 0;
        const bool far = x > reach || y > reach;
        (far ? changed_far : changed_near) += differs;
      }
    EXPECT_EQ(changed_far, 0u) << bloom_filter_name(filter);
    EXPECT_GT(changed_near, 100u) << bloom_filter_name(filter) << ": the bright pixel must bloom";
  }
}

// Range: the output is finite everywhere, also where the scene itself is not. A NaN
// scene channel counts as 0; the sum is clamped to +-65504 for an RGBA16F output (so a bright
// scene plus bloom does not round to Inf) and to +-FLT_MAX for RGBA32F (docs/BLOOM.md "Composite").
TEST_F(BloomTest, NonFiniteAndHugeScenePixelsGiveAFiniteOutput) {
  const float inf = INFINITY, nan = std::nanf("");
  CpuImage input = random_hdr(48, 40, 21, 0.0f, 4.0f);
  const float bad[][4] = {{nan, 1, 2, nan}, {inf, -inf, 0, 1}, {65400, 65400, 65400, 1}, {-inf, nan, inf, inf}};
  for (uint32_t i = 0; i < 4; ++i)
    for (int c = 0; c < 4; ++c) input.at(8 + 10 * i, 20)[c] = bad[i][c];
  BloomConfig config;
  config.intensity = 1.0f;
  // Both composites: the one that evaluates A(0) itself (the GPU default) and the original.
  for (const bool fuse : {true, false}) {
    Bloom bloom(context(), config);
    detail::BloomAccess::set_path(bloom, {fuse, fuse});
    for (VkFormat out_format : {kF16, kF32}) {
      const CpuImage gpu = run_bloom(bloom, input, kF32, out_format);
      const float limit = out_format == kF16 ? 65504.0f : std::numeric_limits<float>::max();
      for (float v : gpu.rgba) ASSERT_TRUE(std::isfinite(v)) << (out_format == kF16 ? "rgba16f" : "rgba32f");
      // NaN -> 0 before the add: the NaN channels of pixel 0 equal the bloom alone, which the
      // neighbouring finite pixel shows to be positive; +Inf -> the limit; 65400 + bloom clamps to
      // 65504 in RGBA16F (it would round to Inf) and stays above 65400 in RGBA32F.
      const float* p0 = gpu.at(8, 20);
      EXPECT_GT(p0[0], 0.0f);
      EXPECT_LT(p0[0], 100.0f);
      EXPECT_EQ(p0[3], 0.0f);
      EXPECT_EQ(gpu.at(18, 20)[0], limit);
      EXPECT_EQ(gpu.at(18, 20)[1], -limit);
      EXPECT_EQ(gpu.at(28, 20)[0], out_format == kF16 ? 65504.0f : gpu.at(28, 20)[0]);
      EXPECT_GT(gpu.at(28, 20)[0], 65400.0f);
      EXPECT_EQ(gpu.at(38, 20)[0], -limit);
      EXPECT_EQ(gpu.at(38, 20)[2], limit);
      // The reference (fp16 levels, the RGBA32F limit) agrees at the NaN pixel: 0 plus its bloom.
      if (out_format == kF32) {
        const auto ref = reference::bloom(input, config, /*round_intermediates_to_half=*/true);
        EXPECT_NEAR(p0[0], ref.at(8, 20)[0], 5e-3 * std::abs(ref.at(8, 20)[0]));
      }
    }
  }
}

// A classic bloom bug is a vertical streak: the glow of a point must be as wide as it is tall.
TEST_F(BloomTest, PointSourceGlowIsRadiallySymmetric) {
  const uint32_t n = 257;
  const CpuImage input = point_source(n, n, 128, 128, 1000.0f);
  for (BloomFilter filter : kFilters) {
    BloomConfig config;
    config.filter = filter;
    config.intensity = 1.0f;
    const CpuImage gpu = run_bloom(config, input);
    const Moments m = moments(added_light(gpu, input), n, n, 128, 128);
    EXPECT_GT(m.energy, 0.0);
    EXPECT_NEAR(m.xx / m.yy, 1.0, 0.02) << bloom_filter_name(filter) << " xx=" << m.xx << " yy=" << m.yy;
  }
}

// The glow of a single pixel is centred on it: the centroid of the added light is within 0.25 px
// of the pixel for every filter, at the common sizes whose chains have odd levels (1080 -> 135 ->
// 67, 720 -> 45 -> 22, 540 -> 135 -> 67) and at odd sizes, for pixels at several phases (near the
// centre: at small sizes the glow reaches the borders, whose clamp moves any centroid). The dual
// filter's same-UV map between n and floor(n / 2) texels moved it by up to 2 px (docs/BLOOM.md).
TEST_F(BloomTest, GlowOfAPixelIsCentredOnItAtEverySize) {
  const VkExtent2D sizes[] = {{1920, 1080}, {1280, 720}, {960, 540}, {961, 541}, {1333, 751}};
  for (VkExtent2D size : sizes) {
    for (BloomFilter filter : kFilters) {
      BloomConfig config;
      config.filter = filter;
      config.intensity = 50.0f;
      Bloom bloom(context(), config);
      for (int offset : {-20, -11, 7}) {
        const uint32_t px = size.width / 2 + offset, py = size.height / 2 + 3 + offset / 4;
        CpuImage input = point_source(size.width, size.height, px, py, 100.0f, 0.0f);
        const CpuImage gpu = run_bloom(bloom, input, kF32, kF32);
        const std::vector<double> added = added_light(gpu, input);
        double e = 0.0, sx = 0.0, sy = 0.0;
        for (uint32_t y = 0; y < size.height; ++y)
          for (uint32_t x = 0; x < size.width; ++x) {
            const double a = added[size_t(y) * size.width + x];
            e += a;
            sx += a * x;
            sy += a * y;
          }
        ASSERT_GT(e, 0.0);
        EXPECT_NEAR(sx / e, px, 0.25) << bloom_filter_name(filter) << " " << size.width << "x" << size.height;
        EXPECT_NEAR(sy / e, py, 0.25) << bloom_filter_name(filter) << " " << size.width << "x" << size.height;
      }
    }
  }
}

TEST_F(BloomTest, BrighterSourceGivesMoreBloomEnergy) {
  double last = 0.0;
  for (float value : {2.0f, 10.0f, 100.0f, 900.0f}) {
    const CpuImage input = point_source(129, 129, 64, 64, value);
    BloomConfig config;
    const Moments m = moments(added_light(run_bloom(config, input), input), 129, 129, 64, 64);
    EXPECT_GT(m.energy, last) << "brightness " << value;
    last = m.energy;
  }
}

TEST_F(BloomTest, LargerRadiusGivesWiderGlow) {
  const CpuImage input = point_source(129, 129, 64, 64, 500.0f);
  for (BloomFilter filter : kFilters) {
    double last = 0.0;
    for (float radius : {0.5f, 1.0f, 2.0f, 3.0f}) {
      BloomConfig config;
      config.filter = filter;
      config.radius = radius;
      const Moments m = moments(added_light(run_bloom(config, input), input), 129, 129, 64, 64);
      EXPECT_GT(m.xx + m.yy, last * 1.02) << bloom_filter_name(filter) << " radius " << radius;
      last = m.xx + m.yy;
    }
  }
}

TEST_F(BloomTest, UniformImageStaysUniformAtOddSizes) {
  const VkExtent2D sizes[] = {{99, 37}, {3, 5}, {1, 1}, {641, 479}, {2, 7}};
  for (BloomFilter filter : kFilters) {
    for (VkExtent2D s : sizes) {
      CpuImage input(s.width, s.height, 3.0f);
      BloomConfig config;
      config.filter = filter;
      const CpuImage gpu = run_bloom(config, input);
      float lo = gpu.rgba[0], hi = gpu.rgba[0];
      for (size_t i = 0; i < gpu.rgba.size(); i += 4) {
        lo = std::min(lo, gpu.rgba[i]);
        hi = std::max(hi, gpu.rgba[i]);
      }
      // Bloom adds intensity * prefilter(3) = 0.3 * 2 = 0.6; fp16 levels round to ~1e-3.
      EXPECT_LE(hi - lo, 2e-3f) << bloom_filter_name(filter) << " " << s.width << "x" << s.height;
      EXPECT_NEAR(lo, 3.6f, 5e-3f) << bloom_filter_name(filter) << " " << s.width << "x" << s.height;
    }
  }
}

TEST_F(BloomTest, InPlaceEqualsOutOfPlace) {
  const CpuImage input = random_hdr(80, 50, 21);
  BloomConfig config;
  for (const bool fuse : {true, false}) {  // both composites (docs/BLOOM.md "Dispatches")
    Bloom bloom(context(), config);
    detail::BloomAccess::set_path(bloom, {fuse, fuse});
    const CpuImage separate = run_bloom(bloom, input, kF16, kF16);
    auto img = make_image(input, kF16);
    context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, img.state, img.state); });
    const CpuImage in_place = detail::download(context(), img.state);
    EXPECT_EQ(0, std::memcmp(in_place.rgba.data(), separate.rgba.data(), separate.rgba.size() * 4)) << fuse;
  }
}

TEST_F(BloomTest, RecordingAgainCreatesNoVulkanObject) {
  const CpuImage input = random_hdr(64, 40, 2);
  auto in = make_image(input, kF16);
  auto out = make_poisoned({64, 40}, kF16);
  Bloom bloom(context());
  bloom.prepare({64, 40});
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
  const uint64_t before = context().objects_created();
  context().run_once([&](VkCommandBuffer cmd) {
    bloom.record(cmd, in.state, out.state);
    bloom.record(cmd, in.state, out.state);
  });
  EXPECT_EQ(context().objects_created(), before);
  // Per-frame changes (threshold, intensity, radius) rebuild nothing either.
  BloomConfig c = bloom.config();
  c.threshold = 2.0f;
  c.intensity = 0.7f;
  c.radius = 2.0f;
  bloom.set_config(c);
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
  EXPECT_EQ(context().objects_created(), before);
}

TEST_F(BloomTest, ResizeAndShapeChangesRebuildAndStayCorrect) {
  Bloom bloom(context());
  for (VkExtent2D s : {VkExtent2D{64, 64}, VkExtent2D{65, 33}, VkExtent2D{64, 64}}) {
    const CpuImage input = random_hdr(s.width, s.height, s.width + s.height);
    const CpuImage gpu = run_bloom(bloom, input, kF32, kF32);
    EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, bloom.config())), 5e-3);
  }
  BloomConfig c = bloom.config();
  c.filter = BloomFilter::gauss9;
  c.precision = Precision::fp32;
  c.iterations = 3;
  bloom.set_config(c);
  const CpuImage input = random_hdr(64, 64, 99);
  EXPECT_LT(reference::relative_l2(run_bloom(bloom, input, kF32, kF32), reference::bloom(input, c)), 1e-3);
}

// The stages of each dispatch structure (docs/BLOOM.md "Dispatches"). At 640x480 (levels 320x240
// to 20x15) the small levels run from level 2 on wherever levels 3 and 4 (1500 texels, 18000
// bytes) fit the shared memory the dispatch uses (every device with 32 KiB, lavapipe and GPUs);
// levels 2 to 4 need more than its 64 KiB at most.
TEST_F(BloomTest, ProfilerReportsEveryStage) {
  const std::vector<std::string> fused = {"bloom bright-pass + down 0", "bloom downsample", "bloom small levels",
                                          "bloom upsample", "bloom composite"};
  const std::vector<std::string> per_level = {"bloom bright-pass + down 0", "bloom downsample", "bloom upsample",
                                              "bloom composite"};
  for (const bool fuse : {true, false}) {
    Profiler profiler(context());
    Bloom bloom(context());
    detail::BloomAccess::set_path(bloom, {fuse, fuse});
    run_bloom(bloom, random_hdr(640, 480, 4), kF16, kF16, &profiler);
    const bool fits = context().info().max_shared_memory_bytes >= 18000;
    EXPECT_EQ(detail::BloomAccess::small_levels_top(bloom), fuse && fits ? 2 : -1);
    std::vector<std::string> labels;
    for (const auto& s : profiler.results()) {
      labels.push_back(s.label);
      EXPECT_GE(s.ms, 0.0);
    }
    EXPECT_EQ(labels, fuse && fits ? fused : per_level);
    EXPECT_GT(profiler.total_ms(), 0.0);
  }
}

// ---- bad input: a clear error naming the value and range, and nothing recorded ----------------

TEST_F(BloomTest, InvalidConfigIsRejectedWithTheFieldNamed) {
  struct Case {
    const char* field;
    BloomConfig config;
  };
  std::vector<Case> cases;
  auto add = [&](const char* field, auto mutate) {
    BloomConfig c;
    mutate(c);
    cases.push_back({field, c});
  };
  add("threshold", [](BloomConfig& c) { c.threshold = std::nanf(""); });
  add("threshold", [](BloomConfig& c) { c.threshold = -1.0f; });
  add("soft_knee", [](BloomConfig& c) { c.soft_knee = 1.5f; });
  add("intensity", [](BloomConfig& c) { c.intensity = -0.1f; });
  add("intensity", [](BloomConfig& c) { c.intensity = INFINITY; });
  add("iterations", [](BloomConfig& c) { c.iterations = 0; });
  add("iterations", [](BloomConfig& c) { c.iterations = 9; });
  add("radius", [](BloomConfig& c) { c.radius = 0.0f; });
  add("radius", [](BloomConfig& c) { c.radius = 5.0f; });
  add("max_brightness", [](BloomConfig& c) { c.max_brightness = 1e5f; });
  add("filter", [](BloomConfig& c) { c.filter = static_cast<BloomFilter>(7); });
  add("precision", [](BloomConfig& c) { c.precision = static_cast<Precision>(3); });
  for (const Case& c : cases) {
    try {
      Bloom bloom(context(), c.config);
      ADD_FAILURE() << c.field << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
      if (std::string(c.field) != "filter" && std::string(c.field) != "precision") {
        EXPECT_NE(std::string(e.what()).find("accepted"), std::string::npos) << e.what();
      }
    }
    Bloom bloom(context());
    EXPECT_THROW(bloom.set_config(c.config), Error) << c.field;
  }
}

TEST_F(BloomTest, BadImagesAreRejectedAndNothingIsRecorded) {
  const CpuImage input = random_hdr(32, 32, 8);
  auto in = make_image(input, kF16);
  auto out = make_poisoned({32, 32}, kF16);
  auto small = make_poisoned({16, 32}, kF16);
  detail::OwnedImage unorm(context(), {32, 32}, VK_FORMAT_R8G8B8A8_UNORM, detail::kToolImageUsage);
  detail::OwnedImage no_storage(context(), {32, 32}, kF16,
                                VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  Bloom bloom(context());
  struct Case {
    const char* what;
    Image in, out;
    ErrorCode code;
  };
  Image zero = out.state;
  zero.extent = {0, 32};
  Image null_view = out.state;
  null_view.view = VK_NULL_HANDLE;
  const Case cases[] = {
      {"unorm input", unorm.state, out.state, ErrorCode::unsupported_format},
      {"unorm output", in.state, unorm.state, ErrorCode::unsupported_format},
      {"output without storage", in.state, no_storage.state, ErrorCode::missing_usage},
      {"size mismatch", in.state, small.state, ErrorCode::invalid_argument},
      {"zero size", zero, zero, ErrorCode::unsupported_size},
      {"null view", in.state, null_view, ErrorCode::invalid_argument},
  };
  for (const Case& c : cases) {
    Image a = c.in, b = c.out;
    const uint64_t objects = context().objects_created();
    context().run_once([&](VkCommandBuffer cmd) {
      try {
        bloom.record(cmd, a, b);
        ADD_FAILURE() << c.what << ": no error";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), c.code) << c.what << ": " << e.what();
      }
    });
    EXPECT_EQ(context().objects_created(), objects) << c.what;
    EXPECT_EQ(b.layout, c.out.layout) << c.what << ": state must be untouched";
  }
  // The output was never written: still all NaN.
  const CpuImage after = detail::download(context(), out.state);
  EXPECT_TRUE(std::all_of(after.rgba.begin(), after.rgba.end(), [](float v) { return std::isnan(v); }));
}

}  // namespace
}  // namespace glint::test
